// `loom scan` on adversarial clouds (DESIGN §4): clouds of tubes around closed-form
// centerlines (straight, arc, helix, S-bend, tight U-bends) with fixed-seed noise, uneven
// density, gaps, outliers and one-sided views, against an independent oracle (dense
// polyline of the true axis, Hausdorff both ways); hostile but valid clouds must give a
// correct answer or a status with a reason, never a crash, NaN or a confident wrong result.
#include "routing/scan/scan_centerline.hpp"
#include "routing/scan/scan_oracle.hpp"

#include <gtest/gtest.h>

#include <cstdio>

namespace loom {
namespace {
using namespace scan_test;

struct Case {
  const char* name;
  TrueAxis axis;
};

std::vector<Case> shapes() {
  std::vector<Case> v;
  const Vec3 dir = Vec3(1, 2, 0.5).normalized();
  v.push_back({"straight", make_axis([&](double u) { return Vec3(Vec3(3, -4, 5) + 60.0 * u * dir); })});
  v.push_back({"arc", make_axis([](double u) { const double t = 1.5 * kPi * u; return Vec3(12 * std::cos(t), 12 * std::sin(t), 0); })});
  v.push_back({"helix", make_axis([](double u) { const double t = 4 * kPi * u; return Vec3(10 * std::cos(t), 10 * std::sin(t), 15 * t / (2 * kPi)); })});
  v.push_back({"sbend", make_axis([](double u) { const double x = 60 * u; return Vec3(x, 8 * std::sin(2 * kPi * x / 60), 0); })});
  for (double R : {4.0, 3.0, 2.0}) {
    // straight 20, half circle radius R, straight 20 back
    v.push_back({R == 4.0 ? "ubend-R2d" : R == 3.0 ? "ubend-R1.5d" : "ubend-R1d", make_axis([R](double u) {
                   const double L = 20, A = kPi * R, tot = 2 * L + A, s = u * tot;
                   if (s < L) return Vec3(s, 0, 0);
                   if (s < L + A) { const double t = (s - L) / R; return Vec3(L + R * std::sin(t), R - R * std::cos(t), 0); }
                   return Vec3(L - (s - L - A), 2 * R, 0);
                 })});
  }
  for (double pitch : {2.6, 2.2}) {
    v.push_back({pitch == 2.6 ? "coil-gap0.3d" : "coil-gap0.1d", make_axis([pitch](double u) {
                   const double t = 2.6 * kPi * u;
                   return Vec3(8 * std::cos(t), 8 * std::sin(t), pitch * t / (2 * kPi));
                 })});
  }
  return v;
}

constexpr double kD = 2.0;  ///< true diameter of every synthetic cable (radius 1)
/// README: centerline error ≤ 0.02 d (RMS) at 1% noise; the bounds below are in d.
constexpr double kRms = 0.02;
/// Largest distance of the recovered curve from the true axis, and of the true axis (more
/// than a diameter from the ends) from the recovered curve: measured ≤ 0.026 d on these.
constexpr double kMax = 0.05;
/// Ends: the recovered curve stops short of the scanned end by at most this (measured 0.07 d).
constexpr double kEnds = 0.1;

struct Variant {
  const char* name;
  ScanSpec spec;
  bool estimate = false;
};

std::vector<Variant> variants() {
  std::vector<Variant> v;
  ScanSpec s;
  s.radius = 0.5 * kD;
  v.push_back({"clean", s});
  s.noise = 0.01;
  v.push_back({"noise 1%", s});
  v.push_back({"noise 1%, diameter estimated", s, true});
  ScanSpec n5 = s;
  n5.noise = 0.05;
  v.push_back({"noise 5%", n5});
  ScanSpec one = s;
  one.view = Vec3(0.3, 0.2, 1.0).normalized();
  v.push_back({"one side", one});
  v.push_back({"one side, diameter estimated", one, true});
  ScanSpec out = s;
  out.outliers = 0.05;
  v.push_back({"5% outliers", out});
  v.push_back({"5% outliers, diameter estimated", out, true});
  ScanSpec gap = s;
  gap.gaps = {{0.3, 0.38}};
  v.push_back({"8% gap", gap});
  ScanSpec sparse = s;
  sparse.points = 3000;
  v.push_back({"3000 points", sparse});
  ScanSpec uneven = s;  // denser in the middle than at the ends (uneven ends: see the report)
  uneven.density = [](double f) { return 0.25 + 0.75 * std::pow(std::sin(kPi * f), 2); };
  v.push_back({"density 4:1", uneven});
  return v;
}

TEST(ScanAdversarial, SmoothShapesAreRecoveredWithinTheStatedAccuracyUnderEveryScanDefect) {
  const auto all = shapes();
  for (std::size_t k = 0; k < 4; ++k) {  // straight, arc, helix, sbend
    const Case& c = all[k];
    for (const Variant& v : variants()) {
      const auto cloud = scan_tube(c.axis, v.spec);
      ScanOptions o;
      if (!v.estimate) o.diameter = kD;
      const ScanResult r = extract_centerline(cloud, o);
      ASSERT_EQ(r.status, ScanStatus::Ok) << c.name << ", " << v.name << ": " << r.message;
      const Deviation all_of = measure(c.axis, r.centerline, 0.1 * kD, 0.0, v.spec.gaps, kD);
      const Deviation inner = measure(c.axis, r.centerline, 0.1 * kD, kD, v.spec.gaps, kD);
      EXPECT_LE(all_of.rms, kRms * kD) << c.name << ", " << v.name;
      EXPECT_LE(all_of.to_truth, kMax * kD) << c.name << ", " << v.name;
      EXPECT_LE(inner.to_scan, kMax * kD) << c.name << ", " << v.name;
      EXPECT_LE(all_of.to_scan, kEnds * kD) << c.name << ", " << v.name;
      EXPECT_NEAR(r.diameter, kD, 0.01 * kD) << c.name << ", " << v.name;
      EXPECT_NEAR(r.centerline.length(), c.axis.length(), 0.5 * kD) << c.name << ", " << v.name;
      EXPECT_EQ(r.gaps, v.spec.gaps.empty() ? 0 : 1) << c.name << ", " << v.name;
      EXPECT_TRUE(std::isfinite(r.residual_rms) && std::isfinite(r.residual_max) && std::isfinite(r.diameter_spread));
    }
  }
}

TEST(ScanAdversarial, ABendOfTwoDiametersStaysWithinATenthOfADiameter) {
  // The tightest bend kept within a tenth of d: a U-turn of radius 2 d between straight legs
  // (measured 0.08 d: the block length is 2 d, so a block spans a radian of the bend; the
  // README's 0.02 d is for smooth cables; R = 1.5 d gives 0.23 d and R = d 0.85 d).
  const Case c = shapes()[4];
  ScanSpec s;
  s.radius = 0.5 * kD;
  s.noise = 0.01;
  ScanOptions o;
  o.diameter = kD;
  const ScanResult r = extract_centerline(scan_tube(c.axis, s), o);
  ASSERT_EQ(r.status, ScanStatus::Ok) << r.message;
  EXPECT_LE(measure(c.axis, r.centerline, 0.1 * kD).hausdorff(), 0.1 * kD);
}

/// Recovered-curve error (to the truth, in d) of the sine cloud moved and scaled.
double moved(const Vec3& offset, double scale, std::optional<double> d) {
  const TrueAxis t0 = shapes()[3].axis;
  ScanSpec s;
  s.radius = 0.5 * kD;
  s.noise = 0.01;
  auto cloud = scan_tube(t0, s);
  for (auto& p : cloud) p = scale * p + offset;
  TrueAxis t = t0;
  for (auto& p : t.p) p = scale * p + offset;
  for (auto& x : t.s) x *= scale;
  ScanOptions o;
  if (d) o.diameter = *d * scale;
  const ScanResult r = extract_centerline(cloud, o);
  EXPECT_EQ(r.status, ScanStatus::Ok) << r.message;
  if (r.status != ScanStatus::Ok) return 1e300;
  EXPECT_NEAR(r.diameter / scale, kD, 0.01 * kD);
  return measure(t, r.centerline, 0.1 * kD * scale).hausdorff() / (kD * scale);
}

TEST(ScanAdversarial, HugeOffsetsAndAnyScaleKeepTheAccuracy) {
  for (double off : {1e5, 1e6, 1e7})
    for (auto d : {std::optional<double>(kD), std::optional<double>()})
      EXPECT_LE(moved(Vec3(off, -off, 0.5 * off), 1.0, d), kEnds) << "offset " << off;
  for (double k : {1e-6, 1e-3, 1e3, 1e6})
    EXPECT_LE(moved(Vec3::Zero(), k, std::nullopt), kEnds) << "scale " << k;
}

TEST(ScanAdversarial, RepeatedAndFarAwayPointsDoNotDisturbIt) {
  const TrueAxis t = shapes()[3].axis;
  ScanSpec s;
  s.radius = 0.5 * kD;
  s.noise = 0.01;
  const auto base = scan_tube(t, s);
  std::vector<std::vector<Vec3>> clouds;
  clouds.push_back(base);
  clouds.back().insert(clouds.back().end(), base.begin(), base.end());  // every point twice
  for (double far : {1e12, 1e30, 1e300}) {
    clouds.push_back(base);
    clouds.back().push_back(Vec3(far, 0, 0));
    clouds.back().push_back(Vec3(0, -far, far));
  }
  clouds.push_back(base);  // NaN and inf coordinates are skipped
  clouds.back().push_back(Vec3(std::nan(""), 1, 2));
  clouds.back().push_back(Vec3(1, -std::numeric_limits<double>::infinity(), 2));
  for (const auto& cloud : clouds)
    for (auto d : {std::optional<double>(kD), std::optional<double>()}) {
      ScanOptions o;
      o.diameter = d;
      const ScanResult r = extract_centerline(cloud, o);
      ASSERT_EQ(r.status, ScanStatus::Ok) << r.message;
      EXPECT_NEAR(r.diameter, kD, 0.01 * kD);
      EXPECT_LE(measure(t, r.centerline, 0.1 * kD).hausdorff(), kEnds * kD);
    }
}

/// Runs both methods, diameter given and estimated; every run must end in a status other
/// than ok, with a message.
void expect_refused(const std::vector<Vec3>& cloud, const char* what) {
  for (auto m : {ScanMethod::Graph, ScanMethod::Axis})
    for (auto d : {std::optional<double>(kD), std::optional<double>()}) {
      ScanOptions o;
      o.method = m;
      o.diameter = d;
      const ScanResult r = extract_centerline(cloud, o);
      EXPECT_NE(r.status, ScanStatus::Ok) << what << ", " << to_string(m) << (d ? ", given" : ", estimated");
      EXPECT_FALSE(r.message.empty()) << what;
    }
}

TEST(ScanAdversarial, CloudsThatAreNotOneTubeAreRefusedWithAReason) {
  expect_refused({}, "empty");
  expect_refused({Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)}, "three points");
  expect_refused(std::vector<Vec3>(5000, Vec3(1e6, 2, 3)), "all points equal");
  std::vector<Vec3> line, disc;
  const Vec3 dir = Vec3(1, 2, 0.5).normalized();
  for (int i = 0; i < 3000; ++i) line.push_back(0.02 * i * dir);
  expect_refused(line, "collinear");
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  while (disc.size() < 5000) {
    const Vec3 p(10 * U(rng), 10 * U(rng), 0.0);
    if (p.norm() < 10) disc.push_back(p);
  }
  expect_refused(disc, "planar disc");
  // Two separate parallel cables 10 d apart (graph: refused as more than one cable; the
  // axis method's slabs see a two-cable blob: its fits or its diameter disagree).
  ScanSpec s;
  s.radius = 0.5 * kD;
  s.noise = 0.01;
  auto two = scan_tube(make_axis([](double u) { return Vec3(60 * u, 0, 0); }), s);
  s.seed = 99;
  s.points = 13000;
  const auto other = scan_tube(make_axis([](double u) { return Vec3(10 + 40 * u, 20, 0); }), s);
  two.insert(two.end(), other.begin(), other.end());
  for (auto d : {std::optional<double>(kD), std::optional<double>()}) {
    ScanOptions o;
    o.diameter = d;
    EXPECT_EQ(extract_centerline(two, o).status, ScanStatus::NotATube);
  }
}

TEST(ScanAdversarial, AGivenDiameterFarFromTheTruthIsRefusedNotUsed) {
  ScanSpec s;
  s.radius = 0.5 * kD;
  s.noise = 0.01;
  for (std::size_t k = 0; k < 4; ++k) {
    const auto cloud = scan_tube(shapes()[k].axis, s);
    for (double wrong : {0.5, 1.5, 2.0, 10.0, 0.1}) {
      ScanOptions o;
      o.diameter = wrong * kD;
      const ScanResult r = extract_centerline(cloud, o);
      EXPECT_EQ(r.status, ScanStatus::NotATube) << shapes()[k].name << " given " << wrong << " d";
    }
  }
}

}  // namespace
}  // namespace loom
