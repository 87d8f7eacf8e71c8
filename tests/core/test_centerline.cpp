// Centerline (core/centerline.hpp): interpolation, evaluation, arc length, curvature and
// bend radius against closed forms, brute force and OpenCASCADE's independent B-spline code.
#include "core/centerline.hpp"

#include <GCPnts_AbscissaPoint.hxx>
#include <GeomAPI_Interpolate.hxx>
#include <GeomAdaptor_Curve.hxx>
#include <GeomLProp_CLProps.hxx>
#include <Geom_BSplineCurve.hxx>
#include <TColStd_HArray1OfReal.hxx>
#include <TColgp_HArray1OfPnt.hxx>

#include "common/occt_curve.hpp"

#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <thread>

using loom::Centerline;
using loom::InterpolationOptions;
using loom::KnotMethod;
using loom::Vec3;

namespace {

using loom::test_oracle::to_occt;

std::vector<Vec3> random_walk(std::mt19937& rng, int n, double step) {
  std::uniform_real_distribution<double> d(-1.0, 1.0);
  std::vector<Vec3> p{Vec3(d(rng), d(rng), d(rng))};
  for (int i = 1; i < n; ++i) {
    Vec3 dir(d(rng) + 1.2, d(rng), d(rng));  // mostly forward: a cable-like route
    p.push_back(p.back() + step * dir.normalized());
  }
  return p;
}

double scale_of(const std::vector<Vec3>& p) {
  loom::AABB b;
  for (const Vec3& q : p) b.extend(q);
  return b.diagonal();
}


Vec3 v3(const gp_Pnt& p) { return Vec3(p.X(), p.Y(), p.Z()); }
Vec3 v3(const gp_Vec& p) { return Vec3(p.X(), p.Y(), p.Z()); }

/// Geometric distance from q to the helix (R cos t, R sin t, c t), by Newton from a start.
double helix_distance(const Vec3& q, double R, double c, double t0) {
  double t = t0;
  for (int it = 0; it < 50; ++it) {
    const Vec3 h(R * std::cos(t), R * std::sin(t), c * t);
    const Vec3 d1(-R * std::sin(t), R * std::cos(t), c);
    const Vec3 d2(-R * std::cos(t), -R * std::sin(t), 0);
    const double f = (h - q).dot(d1), fp = d1.squaredNorm() + (h - q).dot(d2);
    const double dt = f / fp;
    t -= dt;
    if (std::abs(dt) < 1e-15) break;
  }
  return (Vec3(R * std::cos(t), R * std::sin(t), c * t) - q).norm();
}

}  // namespace

// --- interpolation --------------------------------------------------------------------

TEST(Centerline, PassesThroughEveryKeyPoint) {
  std::mt19937 rng(5);
  for (int trial = 0; trial < 20; ++trial) {
    const auto pts = random_walk(rng, 3 + trial, 0.1 + 0.05 * trial);
    const double scale = scale_of(pts);
    for (KnotMethod km : {KnotMethod::ChordLength, KnotMethod::HartleyJudd}) {
      for (int ends = 0; ends < 2; ++ends) {
        InterpolationOptions o;
        o.knots = km;
        if (ends) {
          o.start_tangent = Vec3(1, 0.2, -0.1);
          o.end_tangent = Vec3(0.3, 1, 0);
        }
        const Centerline c = Centerline::interpolate(pts, o);
        ASSERT_EQ(c.key_parameters().size(), pts.size());
        for (std::size_t i = 0; i < pts.size(); ++i)
          EXPECT_LE((c.position(c.key_parameters()[i]) - pts[i]).norm(), 1e-9 * scale)
              << "trial " << trial << " point " << i;
        if (ends) {
          EXPECT_NEAR(c.derivative(c.u_min(), 1).normalized().dot(o.start_tangent->normalized()), 1.0, 1e-12);
          EXPECT_NEAR(c.derivative(c.u_max(), 1).normalized().dot(o.end_tangent->normalized()), 1.0, 1e-12);
        } else {  // natural: C'' = 0 at both ends
          EXPECT_LE(c.derivative(c.u_min(), 2).norm(), 1e-9 * c.derivative(c.u_min(), 1).norm() / scale * 100);
          EXPECT_LE(c.derivative(c.u_max(), 2).norm(), 1e-9 * c.derivative(c.u_max(), 1).norm() / scale * 100);
        }
      }
    }
  }
}

TEST(Centerline, HartleyJuddAndChordLengthParametersDiffer) {
  // Unequal chords: the two methods must give different (but both increasing) parameters.
  const std::vector<Vec3> pts{{0, 0, 0}, {1, 0, 0}, {1.2, 0.3, 0}, {4, 1, 0}, {4.5, 3, 1}};
  InterpolationOptions a, b;
  b.knots = KnotMethod::HartleyJudd;
  const Centerline ca = Centerline::interpolate(pts, a), cb = Centerline::interpolate(pts, b);
  double diff = 0.0;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    diff = std::max(diff, std::abs(ca.key_parameters()[i] - cb.key_parameters()[i]));
    if (i > 0) {
      EXPECT_GT(cb.key_parameters()[i], cb.key_parameters()[i - 1]);
    }
  }
  EXPECT_GT(diff, 1e-3);
  // Chord length: parameter steps equal the chords.
  for (std::size_t i = 1; i < pts.size(); ++i)
    EXPECT_NEAR(ca.key_parameters()[i] - ca.key_parameters()[i - 1], (pts[i] - pts[i - 1]).norm(), 1e-12);
}

TEST(Centerline, AgreesWithOpenCascadeInterpolation) {
  // Same points, parameters and end derivatives → the same complete cubic spline.
  std::mt19937 rng(11);
  for (int trial = 0; trial < 10; ++trial) {
    const auto pts = random_walk(rng, 4 + 3 * trial, 0.5);
    for (KnotMethod km : {KnotMethod::ChordLength, KnotMethod::HartleyJudd}) {
      InterpolationOptions o;
      o.knots = km;
      o.start_tangent = Vec3(1, 1, 0);
      o.end_tangent = Vec3(0, 1, 1);
      const Centerline c = Centerline::interpolate(pts, o);
      Handle(TColgp_HArray1OfPnt) P = new TColgp_HArray1OfPnt(1, static_cast<int>(pts.size()));
      Handle(TColStd_HArray1OfReal) U = new TColStd_HArray1OfReal(1, static_cast<int>(pts.size()));
      for (std::size_t i = 0; i < pts.size(); ++i) {
        P->SetValue(static_cast<int>(i) + 1, gp_Pnt(pts[i].x(), pts[i].y(), pts[i].z()));
        U->SetValue(static_cast<int>(i) + 1, c.key_parameters()[i]);
      }
      GeomAPI_Interpolate gi(P, U, Standard_False, 1e-12);
      const Vec3 t0 = c.derivative(c.u_min(), 1), t1 = c.derivative(c.u_max(), 1);
      gi.Load(gp_Vec(t0.x(), t0.y(), t0.z()), gp_Vec(t1.x(), t1.y(), t1.z()), Standard_False);
      gi.Perform();
      ASSERT_TRUE(gi.IsDone());
      const Handle(Geom_BSplineCurve) oc = gi.Curve();
      const double scale = scale_of(pts);
      double worst = 0.0;
      for (int k = 0; k <= 2000; ++k) {
        const double u = c.u_min() + (c.u_max() - c.u_min()) * k / 2000.0;
        worst = std::max(worst, (c.position(u) - v3(oc->Value(u))).norm());
        gp_Pnt p;
        gp_Vec d1, d2;
        oc->D2(u, p, d1, d2);
        EXPECT_LE((c.derivative(u, 1) - v3(d1)).norm(), 1e-8 * (1 + v3(d1).norm()));
        EXPECT_LE((c.derivative(u, 2) - v3(d2)).norm(), 1e-6 * (1 + v3(d2).norm()));
      }
      EXPECT_LE(worst, 1e-10 * scale) << "trial " << trial;
    }
  }
}

TEST(Centerline, ConvergesAsFourthPowerOnHelixAndCircle) {
  // Points sampled from a helix and a circle with exact end tangents: the geometric error
  // must fall ~16× per halving of the spacing (O(h⁴)).
  const double R = 3.0, pitch = 0.4;
  std::vector<double> err_helix, err_circle;
  for (int n : {8, 16, 32, 64}) {
    const double T = 2.0 * M_PI;
    std::vector<Vec3> h, ci;
    for (int i = 0; i <= n; ++i) {
      const double t = T * i / n;
      h.emplace_back(R * std::cos(t), R * std::sin(t), pitch * t);
      ci.emplace_back(R * std::cos(0.75 * t), R * std::sin(0.75 * t), 0.0);
    }
    InterpolationOptions oh, oc;
    oh.start_tangent = Vec3(0, R, pitch);
    oh.end_tangent = Vec3(-R * std::sin(T), R * std::cos(T), pitch);
    oc.start_tangent = Vec3(0, 1, 0);
    oc.end_tangent = Vec3(-std::sin(0.75 * T), std::cos(0.75 * T), 0);
    const Centerline chx = Centerline::interpolate(h, oh), ccl = Centerline::interpolate(ci, oc);
    double eh = 0, ec = 0;
    for (int k = 0; k <= 40 * n; ++k) {
      const double uh = chx.u_min() + (chx.u_max() - chx.u_min()) * k / (40.0 * n);
      const Vec3 q = chx.position(uh);
      const double t0 = T * k / (40.0 * n);
      eh = std::max(eh, helix_distance(q, R, pitch, t0));
      const double uc = ccl.u_min() + (ccl.u_max() - ccl.u_min()) * k / (40.0 * n);
      ec = std::max(ec, std::abs(ccl.position(uc).norm() - R));
    }
    err_helix.push_back(eh);
    err_circle.push_back(ec);
  }
  for (std::size_t i = 1; i < err_helix.size(); ++i) {
    const double oh = std::log2(err_helix[i - 1] / err_helix[i]);
    const double oc = std::log2(err_circle[i - 1] / err_circle[i]);
    EXPECT_GT(oh, 3.6) << "helix order at refinement " << i << " errors " << err_helix[i - 1] << " → " << err_helix[i];
    EXPECT_GT(oc, 3.6) << "circle order at refinement " << i << " errors " << err_circle[i - 1] << " → " << err_circle[i];
    EXPECT_LT(oh, 4.6);
    EXPECT_LT(oc, 4.6);
  }
}

// --- arc length, curvature, bend radius ---------------------------------------------------

TEST(Centerline, ArcLengthMatchesOpenCascadeAndInverts) {
  std::mt19937 rng(3);
  for (int trial = 0; trial < 8; ++trial) {
    const auto pts = random_walk(rng, 5 + trial, 1.0);
    const Centerline c = Centerline::interpolate(pts);
    GeomAdaptor_Curve ga(to_occt(c));
    const double Locc = GCPnts_AbscissaPoint::Length(ga, c.u_min(), c.u_max(), 1e-13);
    EXPECT_NEAR(c.length(), Locc, 1e-9 * Locc);
    for (int k = 1; k < 20; ++k) {
      const double u = c.u_min() + (c.u_max() - c.u_min()) * k / 20.0;
      const double s = c.arc_length_at(u);
      EXPECT_NEAR(s, GCPnts_AbscissaPoint::Length(ga, c.u_min(), u, 1e-13), 1e-9 * Locc);
      EXPECT_NEAR(c.parameter_at_length(s), u, 1e-9 * (c.u_max() - c.u_min()));
    }
    EXPECT_EQ(c.parameter_at_length(-1.0), c.u_min());
    EXPECT_EQ(c.parameter_at_length(2.0 * c.length()), c.u_max());
  }
}

// Key points a micrometre apart on a metre-scale route (a dense export): a quadrature
// tolerance of 1e-13 of each span's own micrometre makes the wiggles of noisy points bisect
// to the deepest level (0.5 s per curve; a 200,000-point route takes hours to audit). The
// tolerance is relative to the whole curve, and the lengths must still agree with
// OpenCASCADE's.
TEST(Centerline, DenseNoisyKeyPointsKeepTheirArcLength) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> noise(-1e-3, 1e-3);
  std::vector<Vec3> pts{Vec3(0, 0, 0), Vec3(100, 20, 0)};
  for (int i = 1; i <= 2000; ++i) pts.emplace_back(100.0 + 1e-3 * i, 20.0 + noise(rng), noise(rng));
  pts.emplace_back(200, 0, 30);
  pts.emplace_back(300, 10, 30);
  const Centerline c = Centerline::interpolate(pts);
  GeomAdaptor_Curve ga(to_occt(c));
  const double Locc = GCPnts_AbscissaPoint::Length(ga, c.u_min(), c.u_max(), 1e-12);
  EXPECT_NEAR(c.length(), Locc, 1e-9 * Locc);
  for (int k = 1; k < 10; ++k) {
    const double u = c.u_min() + (c.u_max() - c.u_min()) * k / 10.0;
    EXPECT_NEAR(c.arc_length_at(u), GCPnts_AbscissaPoint::Length(ga, c.u_min(), u, 1e-12), 1e-9 * Locc);
  }
}

TEST(Centerline, HullBoundsAreZeroOnAStraightRunAndHoldOnAnArc) {
  std::vector<Vec3> line;
  for (int i = 0; i <= 50; ++i) line.emplace_back(1.0 + 2.0 * i, -3.0 + 1.0 * i, 0.5 * i);
  const Centerline straight = Centerline::interpolate(line);
  const double a = straight.key_parameters()[3], b = straight.key_parameters()[40];
  EXPECT_LE(straight.hull_bounds(a, b).deviation, 1e-12 * straight.length());
  EXPECT_LE(straight.hull_bounds(a, b).turn_sine, 1e-12);
  // A half circle of radius 10: its middle stands 10 off the chord, its ends are
  // perpendicular to it.
  std::vector<Vec3> arc;
  for (int i = 0; i <= 16; ++i) arc.emplace_back(10.0 * std::cos(M_PI * i / 16), 10.0 * std::sin(M_PI * i / 16), 0.0);
  const Centerline half = Centerline::interpolate(arc);
  EXPECT_GE(half.hull_bounds(half.u_min(), half.u_max()).deviation, 10.0 * (1 - 1e-3));
  EXPECT_GE(half.hull_bounds(half.u_min(), half.u_max()).turn_sine, 0.99);  // end tangents near ⟂ the chord
  const double q = half.key_parameters()[4];
  EXPECT_GT(half.hull_bounds(half.u_min(), q).turn_sine, 0.3);
  EXPECT_LT(half.hull_bounds(half.u_min(), q).turn_sine, 1.0);
}

TEST(Centerline, ArcLengthTableIsBuiltOnceOnFirstUseAndTravelsWithCopies) {
  // The arc-length table is built on first use: copies taken before and after it exists,
  // moved-from and moved-to curves, and threads asking for it at the same time all see
  // the same lengths as OpenCASCADE.
  std::mt19937 rng(11);
  const auto pts = random_walk(rng, 9, 1.0);
  const Centerline c = Centerline::interpolate(pts);
  GeomAdaptor_Curve ga(to_occt(c));
  const double Locc = GCPnts_AbscissaPoint::Length(ga, c.u_min(), c.u_max(), 1e-13);
  const Centerline before = c;  // copied while the table is not built
  EXPECT_NEAR(c.length(), Locc, 1e-9 * Locc);
  const Centerline after = c;  // copied with the table
  Centerline moved_from = c;
  const Centerline moved = std::move(moved_from);
  for (const Centerline* k : {&before, &after, &moved}) EXPECT_EQ(k->length(), c.length());
  const Centerline shared = Centerline::interpolate(pts);
  std::vector<double> seen(8, 0.0);
  std::vector<std::thread> threads;
  for (std::size_t t = 0; t < seen.size(); ++t)
    threads.emplace_back([&shared, &seen, t] { seen[t] = shared.arc_length_at(shared.u_max() * (t + 1) / 9.0); });
  for (std::thread& t : threads) t.join();
  for (std::size_t t = 0; t < seen.size(); ++t)
    EXPECT_NEAR(seen[t], GCPnts_AbscissaPoint::Length(ga, c.u_min(), c.u_max() * (t + 1) / 9.0, 1e-13), 1e-9 * Locc);
}

TEST(Centerline, SamplesAtEqualArcSpacing) {
  std::mt19937 rng(8);
  const auto pts = random_walk(rng, 9, 2.0);
  const Centerline c = Centerline::interpolate(pts);
  const double spacing = 0.37;
  const auto smp = c.sample_by_arc_length(spacing);
  ASSERT_GE(smp.size(), 2u);
  const double step = c.length() / static_cast<double>(smp.size() - 1);
  EXPECT_LE(step, spacing);
  EXPECT_GT(step, spacing * 0.9);  // not needlessly dense
  EXPECT_LE((smp.front().second - pts.front()).norm(), 1e-12);
  EXPECT_LE((smp.back().second - pts.back()).norm(), 1e-9);
  for (std::size_t i = 0; i < smp.size(); ++i) {
    EXPECT_NEAR(smp[i].first, step * i, 1e-9 * c.length());
    // The point is where the (independent) parameter_at_length puts it.
    EXPECT_LE((smp[i].second - c.position(c.parameter_at_length(smp[i].first))).norm(), 1e-9 * c.length());
  }
  EXPECT_THROW(c.sample_by_arc_length(0.0), std::invalid_argument);
  EXPECT_THROW(c.sample_by_arc_length(std::nan("")), std::invalid_argument);
}

TEST(Centerline, CurvatureMatchesOpenCascade) {
  std::mt19937 rng(21);
  const auto pts = random_walk(rng, 12, 1.0);
  const Centerline c = Centerline::interpolate(pts, {KnotMethod::HartleyJudd, Vec3(1, 0, 0), std::nullopt});
  const Handle(Geom_BSplineCurve) oc = to_occt(c);
  for (int k = 0; k <= 500; ++k) {
    const double u = c.u_min() + (c.u_max() - c.u_min()) * k / 500.0;
    GeomLProp_CLProps props(oc, u, 2, 1e-12);
    const double ko = props.Curvature();
    EXPECT_NEAR(c.curvature(u), ko, 1e-9 * (1.0 + ko));
  }
}

TEST(Centerline, MinBendRadiusAgreesWithBruteForce) {
  std::mt19937 rng(42);
  for (int trial = 0; trial < 10; ++trial) {
    const auto pts = random_walk(rng, 6 + trial, 1.0);
    const Centerline c = Centerline::interpolate(pts);
    const loom::BendExtremum b = c.min_bend_radius();
    double brute = std::numeric_limits<double>::infinity(), at = 0;
    const int N = 200000;
    for (int k = 0; k <= N; ++k) {
      const double u = c.u_min() + (c.u_max() - c.u_min()) * k / N;
      const double kap = c.curvature(u);
      if (kap > 0 && 1.0 / kap < brute) {
        brute = 1.0 / kap;
        at = u;
      }
    }
    // Brute force, refined by a fine grid around its best sample and around b.u (narrow
    // curvature peaks fall between coarse samples).
    const double h = (c.u_max() - c.u_min()) / N;
    for (double centre : {at, b.u})
      for (int k = -20000; k <= 20000; ++k) {
        const double u = std::clamp(centre + 2.0 * h * k / 20000.0, c.u_min(), c.u_max());
        const double kap = c.curvature(u);
        if (kap > 0) brute = std::min(brute, 1.0 / kap);
      }
    EXPECT_LE(b.radius, brute * (1 + 1e-9)) << "trial " << trial;
    EXPECT_GE(b.radius, brute * (1 - 1e-9)) << "trial " << trial;
    EXPECT_NEAR(1.0 / c.curvature(b.u), b.radius, 1e-9 * b.radius);
    EXPECT_NEAR(b.s, c.arc_length_at(b.u), 1e-9 * c.length());
  }
}

TEST(Centerline, CircleThroughExactPointsHasItsRadius) {
  // Many points on a circle of radius 5 → κ ≈ 1/5 everywhere away from the ends.
  std::vector<Vec3> p;
  for (int i = 0; i <= 200; ++i) p.emplace_back(5 * std::cos(0.01 * i), 5 * std::sin(0.01 * i), 0);
  const Centerline c = Centerline::interpolate(p, {KnotMethod::ChordLength, Vec3(0, 1, 0),
                                                   Vec3(-std::sin(2.0), std::cos(2.0), 0)});
  EXPECT_NEAR(c.min_bend_radius().radius, 5.0, 5e-4);  // curvature converges as O(h²)
  EXPECT_NEAR(c.length(), 10.0, 1e-8);
}

// --- degenerate input -------------------------------------------------------------------

TEST(Centerline, TwoPointsGiveAStraightSegment) {
  const Centerline c = Centerline::interpolate({Vec3(1, 2, 3), Vec3(4, 6, 3)});
  EXPECT_NEAR(c.length(), 5.0, 1e-12);
  EXPECT_EQ(c.curvature(0.5 * (c.u_min() + c.u_max())), 0.0);
  EXPECT_TRUE(std::isinf(c.min_bend_radius().radius));
  EXPECT_LE((c.position(c.parameter_at_length(2.5)) - Vec3(2.5, 4, 3)).norm(), 1e-12);
  // With end tangents it bends, finitely.
  const Centerline t = Centerline::interpolate({Vec3(0, 0, 0), Vec3(1, 0, 0)}, {KnotMethod::ChordLength,
                                                                               Vec3(0, 1, 0), Vec3(0, -1, 0)});
  EXPECT_TRUE(std::isfinite(t.min_bend_radius().radius));
  EXPECT_GT(t.length(), 1.0);
}

TEST(Centerline, RepeatedPointsAreMerged) {
  const std::vector<Vec3> a{{0, 0, 0}, {1, 0, 0}, {2, 1, 0}, {3, 1, 1}};
  const std::vector<Vec3> b{{0, 0, 0}, {0, 0, 0}, {1, 0, 0}, {2, 1, 0}, {2, 1, 0}, {2, 1, 0}, {3, 1, 1}};
  const Centerline ca = Centerline::interpolate(a), cb = Centerline::interpolate(b);
  ASSERT_EQ(cb.key_parameters().size(), b.size());
  EXPECT_EQ(cb.key_parameters()[0], cb.key_parameters()[1]);
  EXPECT_EQ(cb.key_parameters()[3], cb.key_parameters()[5]);
  for (int k = 0; k <= 100; ++k) {
    const double u = ca.u_min() + (ca.u_max() - ca.u_min()) * k / 100.0;
    EXPECT_LE((ca.position(u) - cb.position(u)).norm(), 1e-12);
  }
  EXPECT_THROW(Centerline::interpolate({Vec3(1, 1, 1), Vec3(1, 1, 1), Vec3(1, 1, 1)}), std::invalid_argument);
  EXPECT_THROW(Centerline::interpolate({Vec3(1, 1, 1)}), std::invalid_argument);
  EXPECT_THROW(Centerline::interpolate({}), std::invalid_argument);
}

TEST(Centerline, CollinearPointsGiveAStraightLine) {
  const Centerline c = Centerline::interpolate({Vec3(0, 0, 0), Vec3(1, 1, 1), Vec3(3, 3, 3), Vec3(3.5, 3.5, 3.5)});
  EXPECT_TRUE(std::isinf(c.min_bend_radius().radius));
  EXPECT_NEAR(c.length(), 3.5 * std::sqrt(3.0), 1e-12);
  for (int k = 0; k <= 50; ++k) {
    const Vec3 p = c.position(c.u_min() + (c.u_max() - c.u_min()) * k / 50.0);
    EXPECT_NEAR(p.x(), p.y(), 1e-12);
    EXPECT_NEAR(p.y(), p.z(), 1e-12);
  }
}

TEST(Centerline, ReversalIsAFoldWithZeroBendRadius) {
  // A 180° reversal: defined, finite, and reported as a fold (bend radius 0).
  const Centerline c = Centerline::interpolate({Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(2, 0, 0), Vec3(1, 0, 0)});
  const loom::BendExtremum b = c.min_bend_radius();
  EXPECT_EQ(b.radius, 0.0);
  EXPECT_NEAR(c.position(b.u).y(), 0.0, 1e-12);
  for (int k = 0; k <= 200; ++k) {
    const double u = c.u_min() + (c.u_max() - c.u_min()) * k / 200.0;
    EXPECT_TRUE(loom::is_finite(c.position(u)));
    EXPECT_TRUE(std::isfinite(c.curvature(u)));
  }
  // A slightly offset reversal is a finite tight bend.
  const Centerline d = Centerline::interpolate({Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 0.01, 0), Vec3(0, 0.01, 0)});
  EXPECT_GT(d.min_bend_radius().radius, 0.0);
  EXPECT_LT(d.min_bend_radius().radius, 0.5);
}

TEST(Centerline, ClosedLoopClosesAndStaysFinite) {
  std::vector<Vec3> p;
  for (int i = 0; i < 8; ++i) p.emplace_back(std::cos(i * M_PI / 4), std::sin(i * M_PI / 4), 0.1 * (i % 2));
  p.push_back(p.front());
  const Centerline c = Centerline::interpolate(p, {KnotMethod::HartleyJudd, Vec3(0, 1, 0), Vec3(0, 1, 0)});
  EXPECT_LE((c.position(c.u_min()) - c.position(c.u_max())).norm(), 1e-12);
  EXPECT_NEAR(c.derivative(c.u_min(), 1).normalized().dot(c.derivative(c.u_max(), 1).normalized()), 1.0, 1e-12);
  EXPECT_GT(c.min_bend_radius().radius, 0.1);
  EXPECT_TRUE(std::isfinite(c.length()));
}

TEST(Centerline, NonFiniteInputIsRejectedWithAReason) {
  const double nan = std::nan(""), inf = std::numeric_limits<double>::infinity();
  try {
    Centerline::interpolate({Vec3(0, 0, 0), Vec3(1, nan, 0), Vec3(2, 0, 0)});
    FAIL() << "NaN accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("key point 1 is not finite"), std::string::npos) << e.what();
  }
  EXPECT_THROW(Centerline::interpolate({Vec3(0, 0, 0), Vec3(inf, 0, 0)}), std::invalid_argument);
  EXPECT_THROW(Centerline::polyline({Vec3(0, 0, 0), Vec3(nan, 0, 0)}), std::invalid_argument);
  EXPECT_THROW(Centerline::interpolate({Vec3(0, 0, 0), Vec3(1, 0, 0)}, {KnotMethod::ChordLength, Vec3(nan, 0, 0),
                                                                        std::nullopt}),
               std::invalid_argument);
  EXPECT_THROW(Centerline::interpolate({Vec3(0, 0, 0), Vec3(1, 0, 0)}, {KnotMethod::ChordLength, Vec3(0, 0, 0),
                                                                        std::nullopt}),
               std::invalid_argument);
  // Raw-data constructor checks.
  const std::vector<Vec3> cp{{0, 0, 0}, {1, 0, 0}, {2, 1, 0}, {3, 1, 0}};
  EXPECT_NO_THROW(Centerline(3, {0, 0, 0, 0, 1, 1, 1, 1}, cp));
  EXPECT_THROW(Centerline(3, {0, 0, 0, 1, 1, 1, 1}, cp), std::invalid_argument);
  EXPECT_THROW(Centerline(3, {0, 0, 0, 0, 1, 0.5, 1, 1}, cp), std::invalid_argument);
  EXPECT_THROW(Centerline(3, {0, 0, 0, 0, 0, 0, 0, 0}, cp), std::invalid_argument);
  EXPECT_THROW(Centerline(3, {0, 0, 0, 0, 1, 1, 1, 1}, {cp[0], cp[1], Vec3(nan, 0, 0), cp[3]}),
               std::invalid_argument);
}

TEST(Centerline, PolylineIsExactAndKinksHaveZeroRadius) {
  const Centerline c = Centerline::polyline({Vec3(0, 0, 0), Vec3(2, 0, 0), Vec3(2, 3, 0), Vec3(2, 3, 0)});
  EXPECT_EQ(c.degree(), 1);
  EXPECT_NEAR(c.length(), 5.0, 1e-12);
  EXPECT_LE((c.position(c.parameter_at_length(3.0)) - Vec3(2, 1, 0)).norm(), 1e-12);
  const loom::BendExtremum b = c.min_bend_radius();
  EXPECT_EQ(b.radius, 0.0);
  EXPECT_NEAR(b.s, 2.0, 1e-12);
  const Centerline straight = Centerline::polyline({Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(2, 0, 0)});
  EXPECT_TRUE(std::isinf(straight.min_bend_radius().radius));
}

TEST(Centerline, BasisFunctionsFormAPartitionOfUnity) {
  const std::vector<double> U{0, 0, 0, 0, 0.3, 0.5, 0.5, 0.9, 1, 1, 1, 1};
  double d[3 * 4];
  for (int k = 0; k <= 100; ++k) {
    const double u = k / 100.0;
    loom::bspline_basis(U, 3, u, 2, d);
    EXPECT_NEAR(d[0] + d[1] + d[2] + d[3], 1.0, 1e-14);
    EXPECT_NEAR(d[4] + d[5] + d[6] + d[7], 0.0, 1e-11);
    EXPECT_NEAR(d[8] + d[9] + d[10] + d[11], 0.0, 1e-9);
  }
}

TEST(Centerline, EvaluationMatchesTheBasisFunctionSum) {
  // Oracle: C⁽ᵏ⁾(u) = Σ N⁽ᵏ⁾ᵢ(u)·Pᵢ from the basis functions (Piegl & Tiller A2.3), independent
  // of the per-span Taylor coefficients evaluate() uses (unrolled for cubics, a loop for
  // other degrees). evaluate_in_interval() must give evaluate()'s values exactly.
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> coord(-5.0, 5.0);
  for (int degree : {1, 2, 3, 5}) {
    const int ncp = 12;
    std::vector<Vec3> P;
    for (int i = 0; i < ncp; ++i) P.emplace_back(coord(rng), coord(rng), coord(rng));
    std::vector<double> U(degree + 1, 0.0);
    for (int i = 1; i < ncp - degree; ++i) U.push_back(i + 0.37 * (i % 3));  // non-uniform interior knots
    U.resize(U.size() + degree + 1, U.back() + 1.0);
    const Centerline c(degree, U, P);
    const double scale = scale_of(P);
    const std::vector<double>& bp = c.breakpoints();
    std::vector<double> N(4 * (degree + 1));
    for (std::size_t k = 0; k + 1 < bp.size(); ++k)
      for (int q = 0; q < 7; ++q) {
        const double u = bp[k] + (bp[k + 1] - bp[k]) * q / 7.0;  // interval k, left end included
        Vec3 d[4], e[4];
        c.evaluate(u, 3, d);
        c.evaluate_in_interval(k, u, 3, e);
        const int i0 = loom::bspline_basis(U, degree, u, 3, N.data());
        for (int order = 0; order <= 3; ++order) {
          Vec3 ref = Vec3::Zero();
          for (int j = 0; j <= degree; ++j) ref += N[order * (degree + 1) + j] * P[i0 + j];
          // Derivatives scale as scale / (knot spacing)^order; knot spacing is ~1 here.
          EXPECT_LE((d[order] - ref).norm(), 1e-12 * scale * (1.0 + ref.norm() / scale))
              << "degree " << degree << " order " << order << " u " << u;
          EXPECT_EQ(d[order], e[order]) << "degree " << degree << " order " << order << " u " << u;
        }
      }
    Vec3 d[3];
    EXPECT_THROW(c.evaluate_in_interval(bp.size() - 1, bp.back(), 2, d), std::out_of_range);
  }
}

// --- properties -----------------------------------------------------------------------

RC_GTEST_PROP(CenterlineProperty, InterpolatesFiniteAndLongerThanItsPolygon, ()) {
  const int n = *rc::gen::inRange(2, 25);
  const auto coords = *rc::gen::container<std::vector<int>>(3 * n, rc::gen::inRange(-1000, 1000));
  const bool hj = *rc::gen::arbitrary<bool>();
  const bool tangents = *rc::gen::arbitrary<bool>();
  std::vector<Vec3> p;
  for (int i = 0; i < n; ++i) p.emplace_back(coords[3 * i] * 0.01, coords[3 * i + 1] * 0.01, coords[3 * i + 2] * 0.01);
  // Duplicate a random point now and then (zero chords).
  if (n > 2 && *rc::gen::arbitrary<bool>()) p.insert(p.begin() + n / 2, p[n / 2]);
  std::vector<Vec3> distinct;
  for (const Vec3& q : p)
    if (distinct.empty() || (q - distinct.back()).norm() > 1e-9) distinct.push_back(q);
  RC_PRE(distinct.size() >= 2u);
  InterpolationOptions o;
  o.knots = hj ? KnotMethod::HartleyJudd : KnotMethod::ChordLength;
  if (tangents) {
    o.start_tangent = Vec3(1, 0, 0);
    o.end_tangent = Vec3(0, 0, 1);
  }
  const Centerline c = Centerline::interpolate(p, o);
  const double scale = scale_of(p);
  double poly = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    RC_ASSERT((c.position(c.key_parameters()[i]) - p[i]).norm() <= 1e-9 * scale);
    if (i > 0) poly += (p[i] - p[i - 1]).norm();
  }
  RC_ASSERT(c.length() >= poly * (1 - 1e-12));
  double prev = 0.0;
  for (int k = 0; k <= 64; ++k) {
    const double u = c.u_min() + (c.u_max() - c.u_min()) * k / 64.0;
    RC_ASSERT(loom::is_finite(c.position(u)));
    RC_ASSERT(loom::is_finite(c.derivative(u, 3)));
    RC_ASSERT(std::isfinite(c.curvature(u)));
    const double s = c.arc_length_at(u);
    RC_ASSERT(s >= prev - 1e-12 * c.length());
    prev = s;
  }
  const loom::BendExtremum b = c.min_bend_radius();
  RC_ASSERT(!std::isnan(b.radius));
  RC_ASSERT(b.radius >= 0.0);
}

RC_GTEST_PROP(CenterlineProperty, HullBoundsHoldOnDenseSamples, ()) {
  const int n = *rc::gen::inRange(2, 12);
  const auto coords = *rc::gen::container<std::vector<int>>(3 * n, rc::gen::inRange(-1000, 1000));
  std::vector<Vec3> p;
  for (int i = 0; i < n; ++i) p.emplace_back(coords[3 * i] * 0.01, coords[3 * i + 1] * 0.01, coords[3 * i + 2] * 0.01);
  std::vector<Vec3> distinct;
  for (const Vec3& q : p)
    if (distinct.empty() || (q - distinct.back()).norm() > 1e-6) distinct.push_back(q);
  RC_PRE(distinct.size() >= 2u);
  const Centerline c = Centerline::interpolate(distinct);
  const double t0 = *rc::gen::inRange(0, 1000) / 1000.0, t1 = *rc::gen::inRange(0, 1000) / 1000.0;
  const double a = c.u_min() + (c.u_max() - c.u_min()) * std::min(t0, t1);
  const double b = c.u_min() + (c.u_max() - c.u_min()) * std::max(t0, t1);
  RC_PRE(b > a);
  const Vec3 pa = c.position(a), pb = c.position(b);
  const Centerline::HullBounds hb = c.hull_bounds(a, b);
  const double dev = hb.deviation, turn = hb.turn_sine;
  const double scale = scale_of(distinct);
  const Vec3 chord = pb - pa;
  for (int k = 0; k <= 256; ++k) {
    const double u = a + (b - a) * k / 256.0;
    RC_ASSERT(std::sqrt(loom::point_segment_dist2(c.position(u), pa, pb)) <= dev + 1e-12 * scale);
    if (turn < 1.0) {
      const Vec3 t = c.derivative(u, 1);
      RC_ASSERT(t.dot(chord) > 0.0);
      RC_ASSERT(t.cross(chord).norm() / (t.norm() * chord.norm()) <= turn + 1e-9);
    }
  }
}

// Every stretch bending tighter than a limit, each at its tightest point, against a
// brute-force walk of 2·10⁵ curvature samples: the same stretches (in order), each
// stretch's radius within 1e-6 of the brute-force minimum over it (refined around it), and
// the tightest of them is min_bend_radius().
TEST(Centerline, BendStretchesBelowALimitAgreeWithBruteForce) {
  // An S: two quarter arcs of radius 5 joined by a straight run, and a straight exit.
  std::vector<Vec3> pts;
  for (int i = 0; i <= 12; ++i) {
    const double a = M_PI / 2 * i / 12;
    pts.emplace_back(5 * std::sin(a), 5 - 5 * std::cos(a), 0);  // (0,0) → (5,5), turning left
  }
  for (int i = 1; i <= 6; ++i) pts.emplace_back(5, 5 + 5.0 * i, 0);  // straight up to (5, 35)
  for (int i = 1; i <= 12; ++i) {
    const double a = M_PI / 2 * i / 12;
    pts.emplace_back(10 - 5 * std::cos(a), 35 + 5 * std::sin(a), 0);  // turning right to (10, 40)
  }
  for (int i = 1; i <= 6; ++i) pts.emplace_back(10 + 5.0 * i, 40, 0);
  const Centerline c = Centerline::interpolate(pts);
  for (double limit : {3.5, 4.0, 6.0, 50.0}) {
    const std::vector<loom::BendExtremum> got = c.bend_stretches_below(limit);
    // Brute force: stretches of consecutive samples with κ > 1/limit, and their minimum radius.
    struct Stretch {
      double u0, u1, radius;
    };
    std::vector<Stretch> want;
    const int N = 200000;
    bool in = false;
    for (int k = 0; k <= N; ++k) {
      const double u = c.u_min() + (c.u_max() - c.u_min()) * k / N;
      const double kap = c.curvature(u);
      if (kap > 1.0 / limit) {
        if (!in) want.push_back({u, u, std::numeric_limits<double>::infinity()});
        in = true;
        want.back().u1 = u;
        want.back().radius = std::min(want.back().radius, 1.0 / kap);
      } else {
        in = false;
      }
    }
    ASSERT_EQ(got.size(), want.size()) << "limit " << limit;
    // Narrow curvature peaks fall between the samples: refine each stretch's brute-force
    // minimum on a fine grid around its best sample and around the reported point.
    const double h = (c.u_max() - c.u_min()) / N;
    for (std::size_t i = 0; i < got.size(); ++i) {
      double best_u = want[i].u0;
      for (int k = 0; k <= N; ++k) {
        const double u = c.u_min() + (c.u_max() - c.u_min()) * k / N;
        if (u < want[i].u0 || u > want[i].u1) continue;
        if (1.0 / c.curvature(u) <= want[i].radius) best_u = u;
      }
      for (double centre : {best_u, got[i].u})
        for (int k = -20000; k <= 20000; ++k) {
          const double u = std::clamp(centre + 2.0 * h * k / 20000.0, c.u_min(), c.u_max());
          const double kap = c.curvature(u);
          if (kap > 0) want[i].radius = std::min(want[i].radius, 1.0 / kap);
        }
    }
    for (std::size_t i = 0; i < got.size(); ++i) {
      EXPECT_GE(got[i].u, want[i].u0 - 1e-3) << "limit " << limit << " stretch " << i;
      EXPECT_LE(got[i].u, want[i].u1 + 1e-3) << "limit " << limit << " stretch " << i;
      EXPECT_LE(got[i].radius, want[i].radius * (1 + 1e-9)) << "limit " << limit << " stretch " << i;
      EXPECT_GE(got[i].radius, want[i].radius * (1 - 1e-6)) << "limit " << limit << " stretch " << i;
      EXPECT_NEAR(got[i].s, c.arc_length_at(got[i].u), 1e-9 * c.length());
    }
    if (!got.empty()) {
      const auto tightest = std::min_element(got.begin(), got.end(), [](const auto& a, const auto& b) {
        return a.radius < b.radius;
      });
      EXPECT_EQ(tightest->radius, c.min_bend_radius().radius) << "limit " << limit;
    }
  }
  // The two arcs (radius ~5, ~3.9 where the interpolant meets the straight run) are two
  // stretches below 6; nothing is below 3.5.
  EXPECT_EQ(c.bend_stretches_below(6.0).size(), 2u);
  EXPECT_TRUE(c.bend_stretches_below(3.5).empty());
  // A polyline's corners are stretches of radius 0, one per corner, at the corners.
  const Centerline poly = Centerline::polyline({Vec3(0, 0, 0), Vec3(10, 0, 0), Vec3(10, 10, 0), Vec3(0, 10, 0), Vec3(0, 20, 0)});
  const auto corners = poly.bend_stretches_below(1.0);
  ASSERT_EQ(corners.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(corners[i].radius, 0.0);
    EXPECT_NEAR(corners[i].s, 10.0 * static_cast<double>(i + 1), 1e-9);
  }
  EXPECT_TRUE(poly.bend_stretches_below(0.0).empty());
}
