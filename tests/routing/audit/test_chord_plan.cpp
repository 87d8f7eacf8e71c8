// Chord flattening (routing/chord_plan): every point of the curve lies within eps of the
// polyline, it starts and ends on the curve's ends, arc lengths are monotone and exact there, and
// the count planned is the count made. Oracle: the curve evaluated densely in u against
// the exact point–segment distance to the chords.
#include "routing/audit/chord_plan.hpp"

#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

using namespace loom;

namespace {

/// Distance from p to segment ab (exact up to rounding).
double point_segment(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 ab = b - a;
  const double L2 = ab.squaredNorm();
  const double t = L2 > 0.0 ? std::clamp((p - a).dot(ab) / L2, 0.0, 1.0) : 0.0;
  return (p - (a + t * ab)).norm();
}

/// Largest distance from the curve over [u0, u1], evaluated at `n` points per knot span,
/// to the polyline; the chord nearest the previous point is tried first (the polyline
/// follows the curve), all of them if that one is farther than eps.
double curve_to_polyline(const Centerline& c, double u0, double u1, const Chords& ch, double eps, int n = 200) {
  std::vector<double> us{u0};
  for (double k : c.knots())
    if (k > us.back() && k < u1) us.push_back(k);
  us.push_back(u1);
  double worst = 0.0;
  std::size_t near = 0;
  for (std::size_t i = 0; i + 1 < us.size(); ++i)
    for (int j = 0; j <= n; ++j) {
      const Vec3 p = c.position(us[i] + (us[i + 1] - us[i]) * j / n);
      double d = point_segment(p, ch.p[near], ch.p[near + 1]);
      for (std::size_t k = near; d > eps && k < ch.size() && k <= near + 64; ++k) {
        const double dk = point_segment(p, ch.p[k], ch.p[k + 1]);
        if (dk < d) d = dk, near = k;
      }
      if (d > eps)
        for (std::size_t k = 0; k < ch.size(); ++k) d = std::min(d, point_segment(p, ch.p[k], ch.p[k + 1]));
      worst = std::max(worst, d);
    }
  return worst;
}

/// Clamped uniform B-spline of the given degree on the control points.
Centerline clamped(int degree, const std::vector<Vec3>& cps) {
  const int n = static_cast<int>(cps.size());
  std::vector<double> knots(degree + 1, 0.0);
  for (int i = 1; i < n - degree; ++i) knots.push_back(static_cast<double>(i));
  for (int i = 0; i <= degree; ++i) knots.push_back(static_cast<double>(n - degree));
  return Centerline(degree, knots, cps);
}

void expect_certified(const Centerline& c, double eps, double hmax, double short_len) {
  Chords ch;
  flatten(c, c.u_min(), c.u_max(), eps, hmax, short_len, ch);
  ASSERT_GE(ch.size(), 1u);
  EXPECT_EQ(static_cast<double>(ch.size()), planned_chords(c, eps, hmax, short_len));
  ASSERT_EQ(ch.p.size(), ch.s.size());
  EXPECT_DOUBLE_EQ(ch.s.front(), c.arc_length_at(c.u_min()));
  EXPECT_DOUBLE_EQ(ch.s.back(), c.arc_length_at(c.u_max()));
  for (std::size_t k = 0; k + 1 < ch.s.size(); ++k) EXPECT_LE(ch.s[k], ch.s[k + 1]) << "vertex " << k;
  const double scale = 1e-9 * (1.0 + c.length());
  EXPECT_LT((ch.p.front() - c.position(c.u_min())).norm(), scale);
  EXPECT_LT((ch.p.back() - c.position(c.u_max())).norm(), scale);
  EXPECT_LE(curve_to_polyline(c, c.u_min(), c.u_max(), ch, eps), eps * (1.0 + 1e-9) + scale)
      << "eps " << eps << ", hmax " << hmax;
  double longest = 0.0;
  for (std::size_t k = 0; k < ch.size(); ++k) longest = std::max(longest, (ch.p[k + 1] - ch.p[k]).norm());
  EXPECT_LE(longest, hmax) << "eps " << eps;
}

}  // namespace

TEST(ChordPlan, RandomCubicsStayWithinTheDeviationBound) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> U(-50.0, 50.0);
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<Vec3> cps;
    for (int i = 0; i < 4 + trial % 6; ++i) cps.emplace_back(U(rng), U(rng), U(rng));
    const Centerline c = clamped(3, cps);
    for (double eps : {1e-3, 1e-2, 0.1, 1.0}) expect_certified(c, eps, 2.0, 0.25);
  }
}

TEST(ChordPlan, QuadraticsAndStraightLines) {
  expect_certified(clamped(2, {{0, 0, 0}, {10, 20, 0}, {20, 0, 5}, {30, 10, 5}}), 1e-3, 5.0, 0.1);
  const Centerline line = clamped(1, {{0, 0, 0}, {10, 0, 0}, {10, 10, 0}});
  EXPECT_EQ(deviation_chords(line, line.u_min(), line.u_max(), 1e-6), 1.0);
  // A polyline is flattened exactly: one chord per leg unless hmax asks for more.
  Chords ch;
  flatten(line, line.u_min(), line.u_max(), 1e-6, 100.0, 0.0, ch);
  EXPECT_EQ(ch.size(), 2u);
  expect_certified(line, 1e-6, 3.0, 0.0);
}

// Key points far closer than the cable is thick (a dense export) give thousands of short
// spans; runs of them within eps of one chord become that chord.
TEST(ChordPlan, DenseShortSpansMergeAndStayCertified) {
  std::vector<Vec3> pts;
  auto at = [](double x) { return Vec3(x, 5.0 * std::sin(x / 30.0), 0.0); };
  for (double x = 0.0; x < 40.0; x += 10.0) pts.push_back(at(x));
  for (int i = 0; i <= 2000; ++i) pts.push_back(at(40.0 + 2.0 * i / 2000.0));
  for (double x = 50.0; x <= 100.0; x += 10.0) pts.push_back(at(x));
  const Centerline c = Centerline::interpolate(pts);
  const double eps = 0.005, hmax = 2.0;
  expect_certified(c, eps, hmax, 0.25);
  Chords ch;
  flatten(c, c.u_min(), c.u_max(), eps, hmax, 0.25, ch);
  // ~100 mm of curve at chords of at most 2 mm: about 50, not one per span (2,000+).
  EXPECT_LT(ch.size(), 200u);
}

// Dense key points round a bend tighter than hmax: runs of short spans may not be merged
// where their hull strays more than eps from the chord.
TEST(ChordPlan, DenseShortSpansRoundABendAreNotMergedPastEps) {
  std::vector<Vec3> pts;
  for (int i = 0; i <= 600; ++i) {
    const double t = M_PI * i / 600.0;
    pts.emplace_back(2.0 * std::cos(t), 2.0 * std::sin(t), 0.0);  // 0.01 mm apart on a 2 mm radius
  }
  const Centerline c = Centerline::interpolate(pts);
  for (double eps : {0.001, 0.005, 0.02}) expect_certified(c, eps, 2.0, 0.25);
}

// Two calls over adjacent stretches continue one polyline.
TEST(ChordPlan, ContinuesFromTheLastVertex) {
  const Centerline c = clamped(3, {{0, 0, 0}, {10, 30, 0}, {20, -30, 10}, {30, 0, 0}, {40, 20, 5}});
  const double um = 0.5 * (c.u_min() + c.u_max());
  Chords both;
  flatten(c, c.u_min(), um, 1e-3, 2.0, 0.25, both);
  const std::size_t first = both.size();
  flatten(c, um, c.u_max(), 1e-3, 2.0, 0.25, both);
  EXPECT_GT(both.size(), first);
  EXPECT_DOUBLE_EQ(both.s.back(), c.arc_length_at(c.u_max()));
  EXPECT_LE(curve_to_polyline(c, c.u_min(), c.u_max(), both, 1e-3), 1e-3 * (1.0 + 1e-9) + 1e-9);
}

RC_GTEST_PROP(ChordPlanProps, EveryCubicStaysWithinEps, ()) {
  const int n = *rc::gen::inRange(4, 9);
  std::vector<Vec3> cps;
  for (int i = 0; i < n; ++i)
    cps.emplace_back(*rc::gen::inRange(-1000, 1000) / 10.0, *rc::gen::inRange(-1000, 1000) / 10.0,
                     *rc::gen::inRange(-1000, 1000) / 10.0);
  const double eps = std::pow(10.0, -*rc::gen::inRange(0, 4));
  const double hmax = *rc::gen::inRange(1, 20);
  const Centerline c = clamped(3, cps);
  RC_PRE(c.length() > 0.0);
  Chords ch;
  flatten(c, c.u_min(), c.u_max(), eps, hmax, 0.25, ch);
  RC_ASSERT(static_cast<double>(ch.size()) == planned_chords(c, eps, hmax, 0.25));
  RC_ASSERT(curve_to_polyline(c, c.u_min(), c.u_max(), ch, eps, 60) <= eps * (1.0 + 1e-9) + 1e-9 * (1.0 + c.length()));
}
