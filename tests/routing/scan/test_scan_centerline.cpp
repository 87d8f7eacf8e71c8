// Centerline extraction from scanned cables: clouds sampled from known tubes,
// the recovered centerline compared with the true axis (closed-form curves, dense
// polyline oracle, fixed seeds).
#include "routing/scan/scan_centerline.hpp"

#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <cmath>
#include <functional>
#include <random>

namespace loom {
namespace {

constexpr double kPi = 3.14159265358979323846;

/// A known tube: its true axis as a dense polyline with arc length.
struct TrueTube {
  std::vector<Vec3> axis;
  std::vector<double> s;
  double length() const { return s.back(); }
};

TrueTube make_axis(const std::function<Vec3(double)>& curve, int samples = 4000) {
  TrueTube t;
  for (int i = 0; i <= samples; ++i) t.axis.push_back(curve(static_cast<double>(i) / samples));
  t.s.assign(t.axis.size(), 0.0);
  for (std::size_t i = 1; i < t.axis.size(); ++i) t.s[i] = t.s[i - 1] + (t.axis[i] - t.axis[i - 1]).norm();
  return t;
}

struct CloudSpec {
  double diameter = 2.0;
  std::size_t points = 20000;
  double noise = 0.0;     ///< σ as a fraction of d (isotropic Gaussian)
  double outliers = 0.0;  ///< fraction of extra uniform points in the expanded bounding box
  double gap_from = -1, gap_to = -1;  ///< removed stretch, fractions of the length
  std::uint64_t seed = 7;
  /// Seen from one side only (a laser looking along −view): points whose outward normal
  /// faces away from the scanner are not captured. Zero: all around.
  Vec3 view = Vec3::Zero();
};

std::vector<Vec3> sample_tube(const TrueTube& t, const CloudSpec& c) {
  std::mt19937_64 rng(c.seed);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  std::normal_distribution<double> N(0.0, 1.0);
  const double r = 0.5 * c.diameter;
  std::vector<Vec3> pts;
  AABB box;
  while (pts.size() < c.points) {
    const double s = U(rng) * t.length();
    auto it = std::upper_bound(t.s.begin(), t.s.end(), s);
    const std::size_t j = std::clamp<std::size_t>(static_cast<std::size_t>(it - t.s.begin()), 1, t.s.size() - 1);
    const double u = (s - t.s[j - 1]) / (t.s[j] - t.s[j - 1]);
    const Vec3 p = t.axis[j - 1] + u * (t.axis[j] - t.axis[j - 1]);
    const Vec3 T = (t.axis[j] - t.axis[j - 1]).normalized();
    Vec3 n1 = T.unitOrthogonal(), n2 = T.cross(n1);
    const double th = 2 * kPi * U(rng);
    const Vec3 normal = std::cos(th) * n1 + std::sin(th) * n2;
    if (c.view.norm() > 0 && normal.dot(c.view) < 0) continue;
    Vec3 q = p + r * normal;
    box.extend(q);
    if (c.gap_from >= 0 && s >= c.gap_from * t.length() && s <= c.gap_to * t.length()) continue;
    if (c.noise > 0) q += c.noise * c.diameter * Vec3(N(rng), N(rng), N(rng));
    pts.push_back(q);
  }
  const auto n_out = static_cast<std::size_t>(c.outliers * static_cast<double>(c.points));
  for (std::size_t i = 0; i < n_out; ++i) {
    const Vec3 lo = box.min - Vec3::Constant(c.diameter * 2), hi = box.max + Vec3::Constant(c.diameter * 2);
    pts.emplace_back(lo.x() + U(rng) * (hi.x() - lo.x()), lo.y() + U(rng) * (hi.y() - lo.y()),
                     lo.z() + U(rng) * (hi.z() - lo.z()));
  }
  std::shuffle(pts.begin(), pts.end(), rng);
  return pts;
}

/// Distance from p to the true axis and the arc length of the closest point (brute force).
std::pair<double, double> to_axis(const TrueTube& t, const Vec3& p) {
  double best = 1e300, bs = 0;
  for (std::size_t i = 1; i < t.axis.size(); ++i) {
    const Vec3 a = t.axis[i - 1], seg = t.axis[i] - a;
    const double u = std::clamp((p - a).dot(seg) / seg.squaredNorm(), 0.0, 1.0);
    const double d2 = (p - a - u * seg).squaredNorm();
    if (d2 < best) {
      best = d2;
      bs = t.s[i - 1] + u * (t.s[i] - t.s[i - 1]);
    }
  }
  return {std::sqrt(best), bs};
}

struct Errors {
  double rms = 0;       ///< recovered samples → true axis, RMS (outside the gap)
  double max = 0;       ///< same, max
  double coverage = 0;  ///< true axis samples (outside gap, ≥ d from the ends) → recovered curve, max
};

Errors compare(const TrueTube& t, const Centerline& c, double d, double gap_from = -1, double gap_to = -1) {
  Errors e;
  auto in_gap = [&](double s) {
    return gap_from >= 0 && s >= (gap_from * t.length() - d) && s <= (gap_to * t.length() + d);
  };
  const auto samples = c.sample_by_arc_length(0.25 * d);
  double sq = 0;
  int n = 0;
  for (const auto& [s, p] : samples) {
    const auto [dist, ts] = to_axis(t, p);
    if (in_gap(ts)) continue;
    sq += dist * dist;
    e.max = std::max(e.max, dist);
    ++n;
  }
  e.rms = n ? std::sqrt(sq / n) : 1e300;
  for (std::size_t i = 0; i < t.axis.size(); i += 10) {
    if (t.s[i] < d || t.s[i] > t.length() - d || in_gap(t.s[i])) continue;
    double best = 1e300;
    for (std::size_t k = 1; k < samples.size(); ++k) {
      const Vec3 a = samples[k - 1].second, seg = samples[k].second - a;
      const double L2 = seg.squaredNorm();
      const double u = L2 > 0 ? std::clamp((t.axis[i] - a).dot(seg) / L2, 0.0, 1.0) : 0.0;
      best = std::min(best, (t.axis[i] - a - u * seg).norm());
    }
    e.coverage = std::max(e.coverage, best);
  }
  return e;
}

// ---- the four known tubes (d = 2 unless scaled) ----------------------------------------

TrueTube helix() {  // 2 turns, radius 15, rise 50 along z (the largest extent)
  return make_axis([](double u) { return Vec3(15 * std::cos(4 * kPi * u), 15 * std::sin(4 * kPi * u), 60 * u); });
}
TrueTube s_bend() {  // along x with a smooth S in y and a small lift in z
  return make_axis([](double u) {
    const double x = 100 * u;
    return Vec3(x, 15 * std::tanh((x - 50) / 10), 5 * std::sin(kPi * u));
  });
}
TrueTube loop() {  // doubles back along x: out along +x, a U-turn, back along −x (3D)
  return make_axis([](double u) {
    const double t = kPi * u;
    return Vec3(60 * std::sin(t), 15 * (1 - std::cos(t)), 5 * std::sin(t));
  });
}
TrueTube curve3d() {  // a knot-free space curve
  return make_axis([](double u) {
    return Vec3(100 * u, 20 * std::sin(2 * kPi * u), 15 * std::sin(3 * kPi * u + 0.5));
  });
}

struct Shape {
  const char* name;
  TrueTube (*make)();
};
const Shape kShapes[] = {{"helix", helix}, {"s-bend", s_bend}, {"loop", loop}, {"curve3d", curve3d}};

ScanOptions graph_opts(std::optional<double> d = 2.0) {
  ScanOptions o;
  o.method = ScanMethod::Graph;
  o.diameter = d;
  return o;
}

/// The seed paper's method (slabs across the principal axis) with the cloud's diameter.
ScanOptions axis_opts(double d) {
  ScanOptions o;
  o.method = ScanMethod::Axis;
  o.diameter = d;
  return o;
}

// ---- accuracy ------------------------------------------------------------------------

TEST(ScanCenterline, GraphRecoversEveryShapeWithinTwoPercentAtOnePercentNoise) {
  for (const auto& sh : kShapes) {
    const TrueTube t = sh.make();
    for (double noise : {0.0, 0.01}) {
      CloudSpec c;
      c.noise = noise;
      const auto r = extract_centerline(sample_tube(t, c), graph_opts());
      ASSERT_EQ(r.status, ScanStatus::Ok) << sh.name << ": " << r.message;
      const Errors e = compare(t, r.centerline, c.diameter);
      EXPECT_LE(e.rms, 0.02 * c.diameter) << sh.name << " noise " << noise;
      EXPECT_LE(e.coverage, 0.1 * c.diameter) << sh.name << " noise " << noise;
      EXPECT_NEAR(r.centerline.length(), t.length(), 1.5 * c.diameter) << sh.name;
      EXPECT_EQ(r.gaps, 0) << sh.name;
      EXPECT_LE(r.residual_rms, 0.02 * c.diameter + 2.0 * noise * c.diameter) << sh.name;
    }
  }
}

TEST(ScanCenterline, GraphHandlesFivePercentNoise) {
  for (const auto& sh : kShapes) {
    const TrueTube t = sh.make();
    CloudSpec c;
    c.noise = 0.05;
    const auto r = extract_centerline(sample_tube(t, c), graph_opts());
    ASSERT_EQ(r.status, ScanStatus::Ok) << sh.name << ": " << r.message;
    const Errors e = compare(t, r.centerline, c.diameter);
    EXPECT_LE(e.rms, 0.04 * c.diameter) << sh.name;
    EXPECT_LE(e.coverage, 0.2 * c.diameter) << sh.name;
  }
}

TEST(ScanCenterline, GraphRejectsOnePercentOutliers) {
  for (const auto& sh : kShapes) {
    const TrueTube t = sh.make();
    CloudSpec c;
    c.noise = 0.01;
    c.outliers = 0.01;
    const auto cloud = sample_tube(t, c);
    const auto r = extract_centerline(cloud, graph_opts());
    ASSERT_EQ(r.status, ScanStatus::Ok) << sh.name << ": " << r.message;
    const Errors e = compare(t, r.centerline, c.diameter);
    EXPECT_LE(e.rms, 0.02 * c.diameter) << sh.name;
    EXPECT_LE(e.coverage, 0.1 * c.diameter) << sh.name;
    EXPECT_GE(r.outliers, static_cast<std::size_t>(0.9 * 0.01 * c.points)) << sh.name;
  }
}

TEST(ScanCenterline, GraphBridgesATenPercentGapAndReportsIt) {
  for (const auto& sh : kShapes) {
    const TrueTube t = sh.make();
    CloudSpec c;
    c.noise = 0.01;
    c.gap_from = 0.45;
    c.gap_to = 0.55;
    const auto r = extract_centerline(sample_tube(t, c), graph_opts());
    ASSERT_EQ(r.status, ScanStatus::Ok) << sh.name << ": " << r.message;
    const Errors e = compare(t, r.centerline, c.diameter, c.gap_from, c.gap_to);
    EXPECT_LE(e.rms, 0.02 * c.diameter) << sh.name;
    EXPECT_LE(e.coverage, 0.1 * c.diameter) << sh.name;  // both sides, in order
    EXPECT_EQ(r.gaps, 1) << sh.name;
    // The gap is measured along the recovered curve between the ends of the two scanned
    // stretches: between the chord and the arc of the missing stretch (± a diameter).
    auto index_at = [&](double f) {
      return static_cast<std::size_t>(std::lower_bound(t.s.begin(), t.s.end(), f * t.length()) - t.s.begin());
    };
    const std::size_t i0 = index_at(c.gap_from), i1 = index_at(c.gap_to);
    EXPECT_GE(r.largest_gap, (t.axis[i1] - t.axis[i0]).norm() - c.diameter) << sh.name;
    EXPECT_LE(r.largest_gap, 0.1 * t.length() + c.diameter) << sh.name;
  }
}

// ---- the paper's axis blocking: where it works and where it fails ---------------------

TEST(ScanCenterline, AxisMethodWorksOnCurvesThatFollowTheBlockingAxis) {
  for (const auto& sh : {kShapes[1], kShapes[3]}) {
    const TrueTube t = sh.make();
    CloudSpec c;
    c.noise = 0.01;
    ScanOptions o;
    o.method = ScanMethod::Axis;
    o.diameter = c.diameter;
    const auto r = extract_centerline(sample_tube(t, c), o);
    ASSERT_EQ(r.status, ScanStatus::Ok) << sh.name << ": " << r.message;
    const Errors e = compare(t, r.centerline, c.diameter);
    // Straight slabs on bends bias the centre (sagitta); still well inside the tube.
    EXPECT_LE(e.rms, 0.1 * c.diameter) << sh.name;
  }
}

TEST(ScanCenterline, AxisMethodSlabsCutLongArcsOfAHelix) {
  // Documented weakness of the paper's method: slabs have a fixed width along the axis, so
  // where the cable runs across that axis (a helix climbing slowly along z) one slab holds a
  // long curved arc, and its straight centre line misses the axis by a large fraction of d.
  const TrueTube t = helix();
  CloudSpec c;
  c.noise = 0.01;
  const auto cloud = sample_tube(t, c);
  const auto ra = extract_centerline(cloud, axis_opts(c.diameter));
  const auto rg = extract_centerline(cloud, graph_opts());
  ASSERT_EQ(ra.status, ScanStatus::Ok);
  ASSERT_EQ(rg.status, ScanStatus::Ok);
  const double ea = compare(t, ra.centerline, c.diameter).rms, eg = compare(t, rg.centerline, c.diameter).rms;
  EXPECT_GT(ea, 0.1 * c.diameter);
  EXPECT_GT(ea, 10.0 * eg);
}

TEST(ScanCenterline, AxisMethodFailsOnTheDoubledBackLoopWhereGraphSucceeds) {
  // Documented failure of the paper's method: each slab across x holds both passes of
  // the loop, so every block "centre" lies between them and the order is lost.
  const TrueTube t = loop();
  CloudSpec c;
  c.noise = 0.01;
  const auto cloud = sample_tube(t, c);
  const auto ra = extract_centerline(cloud, axis_opts(c.diameter));
  if (ra.status == ScanStatus::Ok) {
    const Errors e = compare(t, ra.centerline, c.diameter);
    EXPECT_GT(std::max(e.rms, e.coverage), 2.0 * c.diameter);
  }
  const auto rg = extract_centerline(cloud, graph_opts());
  ASSERT_EQ(rg.status, ScanStatus::Ok) << rg.message;
  const Errors eg = compare(t, rg.centerline, c.diameter);
  EXPECT_LE(eg.rms, 0.02 * c.diameter);
  EXPECT_LE(eg.coverage, 0.1 * c.diameter);
}

TEST(ScanCenterline, AxisMethodIsNotRobustToOutliersGraphIs) {
  const TrueTube t = s_bend();
  CloudSpec c;
  c.noise = 0.01;
  c.outliers = 0.01;
  const auto cloud = sample_tube(t, c);
  const auto ra = extract_centerline(cloud, axis_opts(c.diameter));
  const auto rg = extract_centerline(cloud, graph_opts());
  ASSERT_EQ(rg.status, ScanStatus::Ok);
  const double eg = compare(t, rg.centerline, c.diameter).rms;
  if (ra.status == ScanStatus::Ok) {
    EXPECT_GT(compare(t, ra.centerline, c.diameter).rms, 2.0 * eg);
  }
}

// ---- diameter -------------------------------------------------------------------------

TEST(ScanCenterline, EstimatesAnUnknownDiameter) {
  for (double d : {0.5, 2.0, 6.0}) {
    for (const auto& sh : {kShapes[0], kShapes[2], kShapes[3]}) {
      // Scale the curve with the diameter so that the tube keeps its proportions.
      const TrueTube base = sh.make();
      TrueTube t = base;
      const double k = d / 2.0;
      for (auto& p : t.axis) p *= k;
      for (auto& s : t.s) s *= k;
      CloudSpec c;
      c.diameter = d;
      c.noise = 0.01;
      const auto cloud = sample_tube(t, c);
      const auto coarse = estimate_tube_diameter(cloud, 3);
      ASSERT_TRUE(coarse.has_value()) << sh.name << " d=" << d;
      EXPECT_NEAR(*coarse, d, 0.25 * d) << sh.name;
      const auto r = extract_centerline(cloud, graph_opts(std::nullopt));
      ASSERT_EQ(r.status, ScanStatus::Ok) << sh.name << ": " << r.message;
      EXPECT_TRUE(r.diameter_estimated);
      EXPECT_NEAR(r.diameter, d, 0.03 * d) << sh.name << " d=" << d;
      EXPECT_LE(compare(t, r.centerline, d).rms, 0.02 * d) << sh.name << " d=" << d;
    }
  }
}

TEST(ScanCenterline, OneSidedScanOfACableOnATrayIsRecovered) {
  // A scanner above a cable lying on a tray sees its upper half only: the block centres must
  // come from the arc (fitted against the radius), not from the centroid of the points,
  // which sits 2r/π ≈ 0.32 d above the axis.
  for (const auto& sh : {kShapes[1], kShapes[3]}) {
    const TrueTube t = sh.make();
    CloudSpec c;
    c.noise = 0.01;
    c.view = Vec3::UnitZ();
    const auto cloud = sample_tube(t, c);
    const auto given = extract_centerline(cloud, graph_opts(2.0));
    ASSERT_EQ(given.status, ScanStatus::Ok) << sh.name << ": " << given.message;
    EXPECT_LE(compare(t, given.centerline, c.diameter).rms, 0.02 * c.diameter) << sh.name << " (d given)";
    const auto estimated = extract_centerline(cloud, graph_opts(std::nullopt));
    ASSERT_EQ(estimated.status, ScanStatus::Ok) << sh.name << ": " << estimated.message;
    EXPECT_NEAR(estimated.diameter, c.diameter, 0.05 * c.diameter) << sh.name;
    EXPECT_LE(compare(t, estimated.centerline, c.diameter).rms, 0.02 * c.diameter) << sh.name << " (d estimated)";
  }
}

TEST(ScanCenterline, GivenDiameterIsReportedAsGiven) {
  const auto r = extract_centerline(sample_tube(s_bend(), {}), graph_opts(2.0));
  ASSERT_EQ(r.status, ScanStatus::Ok);
  EXPECT_FALSE(r.diameter_estimated);
  EXPECT_EQ(r.diameter, 2.0);
}

// ---- degenerate inputs ------------------------------------------------------------------

TEST(ScanCenterline, DegenerateCloudsGiveAStatusNotACrash) {
  EXPECT_EQ(extract_centerline({}, graph_opts()).status, ScanStatus::TooFewPoints);
  std::vector<Vec3> few(10, Vec3(1, 2, 3));
  EXPECT_EQ(extract_centerline(few, graph_opts()).status, ScanStatus::TooFewPoints);
  std::vector<Vec3> same(5000, Vec3(1, 2, 3));
  for (auto m : {ScanMethod::Graph, ScanMethod::Axis}) {
    ScanOptions o = graph_opts();
    o.method = m;
    EXPECT_NE(extract_centerline(same, o).status, ScanStatus::Ok);
    o.diameter.reset();
    EXPECT_NE(extract_centerline(same, o).status, ScanStatus::Ok);
  }
  // A flat square of points is not a tube: the diameter cannot be estimated.
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> U(0, 50);
  std::vector<Vec3> plane;
  for (int i = 0; i < 5000; ++i) plane.emplace_back(U(rng), U(rng), 0.0);
  EXPECT_NE(extract_centerline(plane, graph_opts(std::nullopt)).status, ScanStatus::Ok);
  // Non-finite points are ignored.
  auto cloud = sample_tube(s_bend(), {});
  const auto clean = extract_centerline(cloud, graph_opts());
  cloud.push_back(Vec3(std::nan(""), 0, 0));
  cloud.push_back(Vec3(0, std::numeric_limits<double>::infinity(), 0));
  const auto r = extract_centerline(cloud, graph_opts());
  ASSERT_EQ(r.status, ScanStatus::Ok);
  EXPECT_EQ(r.key_points.size(), clean.key_points.size());
  EXPECT_THROW(extract_centerline(cloud, graph_opts(-1.0)), std::invalid_argument);
  EXPECT_THROW(extract_centerline(cloud, graph_opts(std::nan(""))), std::invalid_argument);
}

// ---- property: straight tubes in any pose ---------------------------------------------

RC_GTEST_PROP(ScanCenterlineProperty, StraightTubeInAnyPoseIsRecovered, ()) {
  const double d = *rc::gen::inRange(5, 60) / 10.0;       // 0.5 .. 6
  const double len = d * *rc::gen::inRange(15, 40);        // 15 .. 40 diameters
  const double ax = *rc::gen::inRange(-100, 101), ay = *rc::gen::inRange(-100, 101),
               az = *rc::gen::inRange(-100, 101);
  RC_PRE(ax * ax + ay * ay + az * az > 100.0);
  const Vec3 dir = Vec3(ax, ay, az).normalized();
  const Vec3 origin(*rc::gen::inRange(-1000, 1000), *rc::gen::inRange(-1000, 1000), *rc::gen::inRange(-1000, 1000));
  const auto seed = static_cast<std::uint64_t>(*rc::gen::inRange(1, 1000000));
  const TrueTube t = make_axis([&](double u) { return Vec3(origin + u * len * dir); }, 50);
  CloudSpec c;
  c.diameter = d;
  c.points = 4000;
  c.noise = 0.01;
  c.seed = seed;
  const auto r = extract_centerline(sample_tube(t, c), graph_opts(d));
  RC_ASSERT(r.status == ScanStatus::Ok);
  for (const auto& k : r.key_points) RC_ASSERT(to_axis(t, k).first <= 0.05 * d);
  RC_ASSERT(std::abs(r.centerline.length() - len) <= 1.5 * d);
}

}  // namespace
}  // namespace loom
