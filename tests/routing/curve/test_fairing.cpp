// Fairing and bend-radius repair (routing/fairing.hpp, routing/bend_repair.hpp): energy and
// selected-point methods against independent recomputation of deviation and energy, and
// bend radius checked by brute-force curvature sampling.
#include "routing/curve/bend_repair.hpp"
#include "routing/curve/fairing.hpp"

#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <cmath>
#include <limits>
#include <random>

using loom::Centerline;
using loom::FairingOptions;
using loom::FairingStatus;
using loom::InterpolationOptions;
using loom::Vec3;

namespace {

std::vector<Vec3> noisy_sine(unsigned seed, int n, double noise) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> nd(0.0, noise);
  std::vector<Vec3> p;
  for (int i = 0; i <= n; ++i) {
    const double x = 10.0 * i;
    p.emplace_back(x, 20.0 * std::sin(x / 40.0) + nd(rng), nd(rng));
  }
  return p;
}

/// ∫|C''|² du by 3-point Gauss per span (exact for a cubic).
double strain(const Centerline& c) {
  const double x[3] = {-std::sqrt(0.6), 0.0, std::sqrt(0.6)}, w[3] = {5.0 / 9, 8.0 / 9, 5.0 / 9};
  double e = 0.0;
  const auto& bp = c.breakpoints();
  for (std::size_t k = 0; k + 1 < bp.size(); ++k) {
    const double h = 0.5 * (bp[k + 1] - bp[k]), m = 0.5 * (bp[k + 1] + bp[k]);
    for (int q = 0; q < 3; ++q) e += w[q] * h * c.derivative(m + h * x[q], 2).squaredNorm();
  }
  return e;
}

/// ∫κ²ds by a fine midpoint rule in arc length (independent of bending_energy's quadrature).
double bending_energy_brute(const Centerline& c) {
  const int N = 200000;
  double e = 0.0;
  for (int k = 0; k < N; ++k) {
    const double u0 = c.u_min() + (c.u_max() - c.u_min()) * k / N;
    const double u1 = c.u_min() + (c.u_max() - c.u_min()) * (k + 1) / N;
    const double kap = c.curvature(0.5 * (u0 + u1));
    e += kap * kap * (c.position(u1) - c.position(u0)).norm();
  }
  return e;
}

/// Smallest 1/κ over dense samples (independent of min_bend_radius's search).
double brute_min_radius(const Centerline& c, int n = 40000) {
  double r = std::numeric_limits<double>::infinity();
  for (int k = 0; k <= n; ++k) {
    const double kap = c.curvature(c.u_min() + (c.u_max() - c.u_min()) * k / n);
    if (kap > 0) r = std::min(r, 1.0 / kap);
  }
  return r;
}

}  // namespace

TEST(Fairing, EnergyMethodLowersEnergyWithinTolerance) {
  const auto pts = noisy_sine(1, 20, 0.3);
  InterpolationOptions io;
  io.start_tangent = Vec3(1, 0.5, 0);
  io.end_tangent = Vec3(1, 0, 0);
  const Centerline c = Centerline::interpolate(pts, io);
  const double e0 = bending_energy_brute(c);
  double prev_energy = std::numeric_limits<double>::infinity();
  for (double eps : {0.05, 0.2, 1.0, 3.0}) {
    FairingOptions f;
    f.tolerance = eps;
    const loom::FairingResult r = loom::fair_energy(c, f);
    ASSERT_EQ(r.status, FairingStatus::Faired) << "eps " << eps;
    EXPECT_GT(r.alpha, 0.0);
    // Deviation, recomputed from the returned curve.
    double dev = 0.0;
    for (std::size_t i = 0; i < pts.size(); ++i) dev = std::max(dev, (r.curve.position(r.curve.key_parameters()[i]) - pts[i]).norm());
    EXPECT_LE(dev, eps);
    EXPECT_NEAR(r.max_deviation, dev, 1e-9);
    EXPECT_GT(dev, 0.05 * eps);  // it did use the allowance
    // Energies, recomputed independently.
    EXPECT_NEAR(loom::bending_energy(c), e0, 1e-4 * e0);
    const double e1 = bending_energy_brute(r.curve);
    EXPECT_NEAR(loom::bending_energy(r.curve), e1, 1e-4 * e1);
    EXPECT_LT(e1, e0);
    EXPECT_LT(e1, prev_energy);  // more allowance, smoother
    prev_energy = e1;
    // Ends: position and tangent direction kept.
    EXPECT_LE((r.curve.position(r.curve.u_min()) - pts.front()).norm(), 1e-12);
    EXPECT_LE((r.curve.position(r.curve.u_max()) - pts.back()).norm(), 1e-9);
    EXPECT_NEAR(r.curve.derivative(r.curve.u_min(), 1).normalized().dot(io.start_tangent->normalized()), 1.0, 1e-12);
    EXPECT_NEAR(r.curve.derivative(r.curve.u_max(), 1).normalized().dot(io.end_tangent->normalized()), 1.0, 1e-12);
    ASSERT_EQ(r.points.size(), pts.size());
  }
}

TEST(Fairing, AlphaIsHalvedUntilWithinTolerance) {
  const auto pts = noisy_sine(2, 15, 0.5);
  const Centerline c = Centerline::interpolate(pts);
  FairingOptions f;
  f.tolerance = 0.1;
  f.alpha = 1e9;  // far too smooth: must be halved many times
  const loom::FairingResult r = loom::fair_energy(c, f);
  ASSERT_EQ(r.status, FairingStatus::Faired);
  EXPECT_GT(r.iterations, 5);
  EXPECT_DOUBLE_EQ(r.alpha, 1e9 / std::ldexp(1.0, r.iterations - 1));
  // Twice that α would have broken the tolerance (it was tried just before).
  FairingOptions g = f;
  g.alpha = 2.0 * r.alpha;
  g.max_iterations = 1;
  const loom::FairingResult r2 = loom::fair_energy(c, g);
  EXPECT_EQ(r2.status, FairingStatus::Interpolant);
  // Out of halvings: the interpolant itself, deviation 0.
  FairingOptions h = f;
  h.max_iterations = 3;
  const loom::FairingResult r3 = loom::fair_energy(c, h);
  EXPECT_EQ(r3.status, FairingStatus::Interpolant);
  EXPECT_EQ(r3.max_deviation, 0.0);
  EXPECT_EQ(r3.alpha, 0.0);
}

TEST(Fairing, WeightsPinPoints) {
  const auto pts = noisy_sine(3, 12, 0.5);
  const Centerline c = Centerline::interpolate(pts);
  FairingOptions f;
  f.tolerance = 1.0;
  f.alpha = 50.0;
  f.max_iterations = 1;
  f.ends = loom::FairingEnds::Free;
  f.weights.assign(pts.size(), 1.0);
  f.weights[6] = 1e6;
  const loom::FairingResult r = loom::fair_energy(c, f);
  ASSERT_EQ(r.status, FairingStatus::Faired);
  EXPECT_LT((r.points[6] - pts[6]).norm(), 1e-3 * r.max_deviation + 1e-9);
  f.weights.pop_back();
  EXPECT_THROW(loom::fair_energy(c, f), std::invalid_argument);
}

TEST(Fairing, BendingEnergyOfACircleArc) {
  // ∫κ²ds over an arc of radius R and angle φ is φ/R.
  const double R = 7.0, phi = 2.0;
  std::vector<Vec3> p;
  for (int i = 0; i <= 100; ++i) p.emplace_back(R * std::cos(phi * i / 100), R * std::sin(phi * i / 100), 0);
  InterpolationOptions io;
  io.start_tangent = Vec3(0, 1, 0);
  io.end_tangent = Vec3(-std::sin(phi), std::cos(phi), 0);
  EXPECT_NEAR(loom::bending_energy(Centerline::interpolate(p, io)), phi / R, 1e-5);
  EXPECT_EQ(loom::bending_energy(Centerline::interpolate({Vec3(0, 0, 0), Vec3(1, 2, 3)})), 0.0);
}

TEST(Fairing, DegenerateInput) {
  const Centerline straight = Centerline::interpolate({Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(2, 0, 0)});
  FairingOptions f;
  f.tolerance = 0.01;
  const loom::FairingResult r = loom::fair_energy(straight, f);
  EXPECT_LE(r.max_deviation, 0.01);
  EXPECT_EQ(loom::bending_energy(r.curve), 0.0);
  const Centerline two = Centerline::interpolate({Vec3(0, 0, 0), Vec3(1, 0, 0)});
  EXPECT_NO_THROW(loom::fair_energy(two, f));
  f.tolerance = 0.0;
  EXPECT_THROW(loom::fair_energy(straight, f), std::invalid_argument);
  f.tolerance = std::nan("");
  EXPECT_THROW(loom::fair_energy(straight, f), std::invalid_argument);
  f.tolerance = 0.1;
  EXPECT_THROW(loom::fair_energy(Centerline(3, {0, 0, 0, 0, 1, 1, 1, 1}, {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(2, 1, 0), Vec3(3, 1, 0)}), f),
               std::invalid_argument);  // no key parameters
  // Repeated points keep one parameter each and fair like the merged data.
  std::vector<Vec3> rep = noisy_sine(4, 10, 0.4);
  rep.insert(rep.begin() + 5, rep[5]);
  const loom::FairingResult rr = loom::fair_energy(Centerline::interpolate(rep), f);
  EXPECT_EQ(rr.points.size(), rep.size());
  EXPECT_EQ(rr.points[5], rr.points[6]);
}

TEST(Fairing, SelectedPointMethodRevisesBadPoints) {
  // A smooth arc with one point pushed out: curvature changes sign around it.
  std::vector<Vec3> p;
  for (int i = 0; i <= 12; ++i) p.emplace_back(10.0 * i, 0.02 * (10.0 * i) * (120 - 10.0 * i), 0.0);
  p[6].y() += 4.0;
  p[6].z() += 1.0;
  FairingOptions f;
  f.tolerance = 5.0;
  const Centerline c0 = Centerline::interpolate(p);
  const loom::FairingResult r = loom::fair_selected_points(p, {}, f);
  EXPECT_TRUE(r.status == FairingStatus::Faired || r.status == FairingStatus::ToleranceLimit) << int(r.status);
  EXPECT_GT(r.iterations, 0);
  EXPECT_LE(r.max_deviation, f.tolerance + 1e-12);
  for (std::size_t i = 0; i < p.size(); ++i) {
    EXPECT_LE((r.points[i] - p[i]).norm(), f.tolerance + 1e-12);
    EXPECT_LE((r.curve.position(r.curve.key_parameters()[i]) - r.points[i]).norm(), 1e-9);  // interpolates them
  }
  const double e_after = loom::bending_energy(r.curve);
  EXPECT_LT(e_after, loom::bending_energy(c0));
  EXPECT_NEAR(e_after, bending_energy_brute(r.curve), 1e-4 * e_after);
  // A fair arc has no bad point: returned unchanged.
  std::vector<Vec3> arc;
  for (int i = 0; i <= 12; ++i) arc.emplace_back(10 * std::cos(0.2 * i), 10 * std::sin(0.2 * i), 0.5 * i);
  const loom::FairingResult a = loom::fair_selected_points(arc, {}, f);
  EXPECT_EQ(a.status, FairingStatus::AlreadyFair);
  EXPECT_EQ(a.max_deviation, 0.0);
  EXPECT_EQ(a.iterations, 0);
}

TEST(BendRepair, RepairsOrReportsFailure) {
  // An L-shaped route with a sharp corner at (100, 0).
  const std::vector<Vec3> pts{{0, 0, 0}, {50, 0, 0}, {100, 0, 0}, {100, 50, 0}, {100, 100, 0}, {150, 100, 20}};
  loom::BendRepairOptions o;
  o.interpolation.start_tangent = Vec3(1, 0, 0);
  o.min_bend_radius = 5.0;
  o.max_deviation = 1.0;
  const loom::BendRepairResult ok = loom::repair_bend_radius(pts, o);
  EXPECT_EQ(ok.status, loom::BendRepairStatus::AlreadySatisfied);
  EXPECT_GE(brute_min_radius(ok.curve), 5.0);

  for (double R : {20.0, 40.0}) {
    o.min_bend_radius = R;
    o.max_deviation = 30.0;
    const loom::BendRepairResult r = loom::repair_bend_radius(pts, o);
    ASSERT_TRUE(r.status == loom::BendRepairStatus::Faired || r.status == loom::BendRepairStatus::PointsInserted)
        << r.reason;
    EXPECT_GE(brute_min_radius(r.curve), R * (1 - 1e-9)) << "R " << R;
    EXPECT_GE(r.worst.radius, R);
    EXPECT_TRUE(r.reason.empty());
    // The repaired route stays near the original path: every key point of the original is
    // within max_deviation of the repaired curve... approximately (dense sampling).
    for (const Vec3& q : pts) {
      double d = std::numeric_limits<double>::infinity();
      for (int k = 0; k <= 20000; ++k)
        d = std::min(d, (r.curve.position(r.curve.u_min() + (r.curve.u_max() - r.curve.u_min()) * k / 20000.0) - q).norm());
      EXPECT_LE(d, o.max_deviation * 1.01);
    }
  }
  // Too little freedom: a clear failure naming the reason, the worst radius below the limit.
  o.min_bend_radius = 40.0;
  o.max_deviation = 0.5;
  const loom::BendRepairResult bad = loom::repair_bend_radius(pts, o);
  EXPECT_EQ(bad.status, loom::BendRepairStatus::Failed);
  EXPECT_FALSE(bad.reason.empty());
  EXPECT_LT(bad.worst.radius, 40.0);
  EXPECT_NEAR(bad.worst.radius, brute_min_radius(bad.curve), 1e-3 * bad.worst.radius);
  // Legs too short for the radius.
  o.min_bend_radius = 500.0;
  o.max_deviation = 1000.0;
  const loom::BendRepairResult shortlegs = loom::repair_bend_radius(pts, o);
  EXPECT_EQ(shortlegs.status, loom::BendRepairStatus::Failed);
  EXPECT_FALSE(shortlegs.reason.empty());
  o.min_bend_radius = 0.0;
  EXPECT_THROW(loom::repair_bend_radius(pts, o), std::invalid_argument);
}

RC_GTEST_PROP(FairingProperty, EnergyFairingKeepsToleranceAndLowersStrain, ()) {
  const int n = *rc::gen::inRange(3, 20);
  const auto noise = *rc::gen::container<std::vector<int>>(3 * n, rc::gen::inRange(-100, 100));
  std::vector<Vec3> p;
  for (int i = 0; i < n; ++i)
    p.emplace_back(5.0 * i + 0.02 * noise[3 * i], 0.02 * noise[3 * i + 1], 0.02 * noise[3 * i + 2]);
  const double eps = 0.01 * *rc::gen::inRange(1, 200);
  const Centerline c = Centerline::interpolate(p);
  FairingOptions f;
  f.tolerance = eps;
  f.ends = *rc::gen::element(loom::FairingEnds::Free, loom::FairingEnds::Position, loom::FairingEnds::PositionAndTangent);
  const loom::FairingResult r = loom::fair_energy(c, f);
  double dev = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    RC_ASSERT(loom::is_finite(r.points[i]));
    dev = std::max(dev, (r.curve.position(c.key_parameters()[i]) - p[i]).norm());
  }
  RC_ASSERT(dev <= eps * (1 + 1e-12));
  // The minimiser of α∫|q''|² + Σβ|q − p|² never has more strain than the interpolant.
  RC_ASSERT(strain(r.curve) <= strain(c) * (1 + 1e-9) + 1e-15);
  RC_ASSERT(std::isfinite(loom::bending_energy(r.curve)));
}
