// Exact B-spline operations (core/bspline_ops, core/io/kbl_curve): on random curves of every
// degree 1..7 with random (also unclamped) knots, each result evaluates to the original curve
// — the oracle is the original's own evaluation, and for the KBL spans the Cox–de Boor
// recursion of tests/core/kbl_oracle.hpp.
#include "kbl_oracle.hpp"

#include "core/bspline_ops.hpp"
#include "core/io/kbl_curve.hpp"

#include <gtest/gtest.h>

#include <random>

namespace loom {
namespace {

/// A random curve: degree p, n control points in a 100 mm box, non-decreasing knots with
/// occasional repeats (multiplicity at most p), unclamped unless `clamp`.
Centerline random_curve(std::mt19937& rng, int p, bool clamp) {
  std::uniform_real_distribution<double> coord(-50, 50), step(0.2, 2.0), coin(0, 1);
  const int n = p + 1 + static_cast<int>(rng() % 6);
  std::vector<Vec3> cps;
  for (int i = 0; i < n; ++i) cps.emplace_back(coord(rng), coord(rng), coord(rng));
  std::vector<double> knots{0.0};
  int run = 1;  // multiplicity of the last knot: at most p (a C0 joint), never a gap in the curve
  while (static_cast<int>(knots.size()) < n + p + 1) {
    const bool repeat = run < p && coin(rng) < 0.2;
    knots.push_back(knots.back() + (repeat ? 0.0 : step(rng)));
    run = repeat ? run + 1 : 1;
  }
  if (!(knots[static_cast<std::size_t>(p)] < knots[static_cast<std::size_t>(n)])) return random_curve(rng, p, clamp);
  if (clamp) {
    for (int i = 0; i <= p; ++i) knots[static_cast<std::size_t>(i)] = knots[static_cast<std::size_t>(p)];
    for (int i = n; i < n + p + 1; ++i) knots[static_cast<std::size_t>(i)] = knots[static_cast<std::size_t>(n)];
  }
  return Centerline(p, std::move(knots), std::move(cps));
}

double max_gap(const Centerline& a, double a0, double a1, const Centerline& b) {
  double worst = 0;
  for (int i = 0; i <= 200; ++i) {
    const double u = a0 + (a1 - a0) * i / 200;
    worst = std::max(worst, (a.position(u) - b.position(b.u_min() + (b.u_max() - b.u_min()) * (u - a0) / (a1 - a0))).norm());
  }
  return worst;
}

TEST(BSplineOps, EveryOperationKeepsTheCurve) {
  std::mt19937 rng(20261121);
  for (int p = 1; p <= 7; ++p)
    for (int trial = 0; trial < 20; ++trial) {
      SCOPED_TRACE("degree " + std::to_string(p) + " trial " + std::to_string(trial));
      const Centerline c = random_curve(rng, p, trial % 2 == 0);
      const Centerline cl = clamped(c);
      EXPECT_LT(max_gap(c, c.u_min(), c.u_max(), cl), 1e-9);
      EXPECT_LT((cl.control_points().front() - c.position(c.u_min())).norm(), 1e-9);
      EXPECT_LT((cl.control_points().back() - c.position(c.u_max())).norm(), 1e-9);
      // A part of it, in its own parameters.
      const double a = c.u_min() + 0.3 * (c.u_max() - c.u_min()), b = c.u_min() + 0.8 * (c.u_max() - c.u_min());
      const Centerline part = sub_curve(c, a, b);
      EXPECT_DOUBLE_EQ(part.u_min(), a);
      EXPECT_DOUBLE_EQ(part.u_max(), b);
      EXPECT_LT(max_gap(c, a, b, part), 1e-9);
      // Its Bézier pieces, put back together; one and two degrees up.
      const auto pieces = bezier_pieces(c);
      EXPECT_EQ(pieces.size() + 1, c.breakpoints().size());
      EXPECT_LT(max_gap(c, c.u_min(), c.u_max(), from_bezier_pieces(p, pieces, c.breakpoints())), 1e-9);
      for (int q = p + 1; q <= std::min(7, p + 2); ++q) EXPECT_LT(max_gap(c, c.u_min(), c.u_max(), elevated(c, q)), 1e-9);
      // Reversed: C(first knot + last knot − u).
      const Centerline r = reversed(c);
      for (int i = 0; i <= 20; ++i) {
        const double u = c.u_min() + (c.u_max() - c.u_min()) * i / 20;
        EXPECT_LT((r.position(c.knots().front() + c.knots().back() - u) - c.position(u)).norm(), 1e-9);
      }
      // As KBL centre curves: each span a uniform curve of the oracle's convention.
      const auto spans = kbl_uniform_spans(c);
      ASSERT_EQ(spans.size(), pieces.size());
      const auto& br = c.breakpoints();
      for (std::size_t k = 0; k < spans.size(); ++k) {
        kbl_oracle::Curve o{p, spans[k]};
        for (int i = 0; i <= 10; ++i)
          EXPECT_LT((o.at(i / 10.0) - c.position(br[k] + (br[k + 1] - br[k]) * i / 10.0)).norm(), 1e-7);
      }
    }
}

TEST(BSplineOps, JoinTakesTheHigherDegreeAndRefusesAGap) {
  std::mt19937 rng(7);
  const Centerline a = random_curve(rng, 2, true), b0 = random_curve(rng, 5, false);
  // b moved to start where a ends.
  std::vector<Vec3> cps = b0.control_points();
  const Vec3 shift = a.position(a.u_max()) - b0.position(b0.u_min());
  for (auto& q : cps) q += shift;
  const Centerline b(5, b0.knots(), cps);
  const Centerline j = join(a, b);
  EXPECT_EQ(j.degree(), 5);
  EXPECT_NEAR(j.length(), a.length() + b.length(), 1e-9);
  EXPECT_LT((j.position(j.u_max()) - b.position(b.u_max())).norm(), 1e-9);
  std::vector<Vec3> far = cps;
  for (auto& q : far) q += Vec3(1e-3, 0, 0);
  EXPECT_THROW(join(a, Centerline(5, b0.knots(), far)), std::invalid_argument);
}

}  // namespace
}  // namespace loom
