// loom's curve geometry on adversarial input: interpolation, curvature, bend radius, arc
// length, fairing and the tube sweep on hostile inputs (offsets of 1e6, a 1e-6 scale,
// spacing from 1 mm to 1 km, nearly coincident points, reversals, opposing end tangents,
// closed loops), against independent oracles: OpenCASCADE's own interpolation
// (GeomAPI_Interpolate), curvature (GeomLProp_CLProps) and arc length
// (GCPnts_AbscissaPoint); closed forms (circle, helix, line); brute-force dense sampling in
// long double.
#include "core/centerline.hpp"
#include "routing/curve/fairing.hpp"
#include "routing/curve/sweep.hpp"
#include "routing/curve/sweep_step.hpp"

#include <GCPnts_AbscissaPoint.hxx>
#include <GeomAPI_Interpolate.hxx>
#include <GeomAdaptor_Curve.hxx>
#include <GeomLProp_CLProps.hxx>
#include <Geom_BSplineCurve.hxx>
#include <TColStd_HArray1OfReal.hxx>
#include <TColgp_HArray1OfPnt.hxx>

#include "common/occt_curve.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <vector>

using loom::Centerline;
using loom::InterpolationOptions;
using loom::KnotMethod;
using loom::Vec3;

namespace {

using loom::test_oracle::to_occt;

Vec3 v3(const gp_Pnt& p) { return Vec3(p.X(), p.Y(), p.Z()); }
gp_Vec gv(const Vec3& v) { return gp_Vec(v.x(), v.y(), v.z()); }

double scale_of(const std::vector<Vec3>& p) {
  loom::AABB b;
  for (const Vec3& q : p) b.extend(q);
  return b.diagonal();
}

/// OpenCASCADE's complete cubic through the points at loom's key parameters with loom's end
/// derivatives (the same conditions: the same curve if both are right).
Handle(Geom_BSplineCurve) occt_interpolant(const std::vector<Vec3>& pts, const Centerline& c) {
  Handle(TColgp_HArray1OfPnt) P = new TColgp_HArray1OfPnt(1, static_cast<int>(pts.size()));
  Handle(TColStd_HArray1OfReal) U = new TColStd_HArray1OfReal(1, static_cast<int>(pts.size()));
  for (std::size_t i = 0; i < pts.size(); ++i) {
    P->SetValue(static_cast<int>(i) + 1, gp_Pnt(pts[i].x(), pts[i].y(), pts[i].z()));
    U->SetValue(static_cast<int>(i) + 1, c.key_parameters()[i]);
  }
  GeomAPI_Interpolate gi(P, U, Standard_False, 1e-300);
  gi.Load(gv(c.derivative(c.u_min(), 1)), gv(c.derivative(c.u_max(), 1)), Standard_False);
  gi.Perform();
  if (!gi.IsDone()) return Handle(Geom_BSplineCurve)();
  return gi.Curve();
}


/// Curvature at u from finite differences of positions in long double: C' and C'' of the
/// Lagrange cubic through four positions spread over u's knot interval (exact for a cubic
/// piece up to rounding; a stencil across a knot would see the third-derivative jump).
long double fd_curvature(const Centerline& c, long double u) {
  const std::vector<double>& bp = c.breakpoints();
  std::size_t k = std::upper_bound(bp.begin(), bp.end(), static_cast<double>(u)) - bp.begin();
  k = std::clamp<std::size_t>(k, 1, bp.size() - 1) - 1;
  const long double a = bp[k], w = bp[k + 1] - bp[k];
  long double x[4], P[4][3];
  for (int j = 0; j < 4; ++j) {
    x[j] = a + w * (0.05L + 0.3L * j);  // inside the interval, off its ends
    const Vec3 p = c.position(static_cast<double>(x[j]));
    for (int i = 0; i < 3; ++i) P[j][i] = p[i];
  }
  long double d1[3] = {0, 0, 0}, d2[3] = {0, 0, 0};
  for (int j = 0; j < 4; ++j) {
    long double den = 1, l1 = 0, l2 = 0;
    for (int m = 0; m < 4; ++m)
      if (m != j) den *= x[j] - x[m];
    for (int m = 0; m < 4; ++m) {
      if (m == j) continue;
      long double prod = 1;
      for (int q = 0; q < 4; ++q)
        if (q != j && q != m) prod *= u - x[q];
      l1 += prod;
      for (int q = 0; q < 4; ++q) {
        if (q == j || q == m) continue;
        long double pr = 1;
        for (int t = 0; t < 4; ++t)
          if (t != j && t != m && t != q) pr *= u - x[t];
        l2 += pr;
      }
    }
    for (int i = 0; i < 3; ++i) {
      d1[i] += P[j][i] * l1 / den;
      d2[i] += P[j][i] * l2 / den;
    }
  }
  const long double cx = d1[1] * d2[2] - d1[2] * d2[1], cy = d1[2] * d2[0] - d1[0] * d2[2],
                    cz = d1[0] * d2[1] - d1[1] * d2[0];
  const long double sp = std::sqrt(d1[0] * d1[0] + d1[1] * d1[1] + d1[2] * d1[2]);
  return std::sqrt(cx * cx + cy * cy + cz * cz) / (sp * sp * sp);
}

/// Brute-force minimum bend radius: n + 1 samples in u, then a grid 1000× finer around the
/// best sample and around `hint` (narrow peaks fall between coarse samples); curvature from
/// fd_curvature. Returns {radius, u}.
std::pair<double, double> brute_min_bend(const Centerline& c, int n, double hint) {
  const long double a = c.u_min(), b = c.u_max();
  long double best = std::numeric_limits<long double>::infinity(), at = a;
  auto consider = [&](long double u) {
    const long double kap = fd_curvature(c, u);
    if (kap > 0 && 1 / kap < best) {
      best = 1 / kap;
      at = u;
    }
  };
  for (int k = 0; k <= n; ++k) consider(a + (b - a) * k / n);
  const long double step = (b - a) / n;
  for (const long double centre : {at, static_cast<long double>(hint)})
    for (int k = -1000; k <= 1000; ++k) consider(std::clamp(centre + step * k / 500, a, b));
  return {static_cast<double>(best), static_cast<double>(at)};
}

/// Points of the helix (a cos t, a sin t, b t), t = t0 + i·dt, i = 0..n.
std::vector<Vec3> helix(double a, double b, double dt, int n) {
  std::vector<Vec3> p;
  for (int i = 0; i <= n; ++i) {
    const double t = i * dt;
    p.emplace_back(a * std::cos(t), a * std::sin(t), b * t);
  }
  return p;
}

/// Distance from q to the centerline: dense samples, then Newton on (C − q)·C' = 0.
double distance_to_curve(const Centerline& c, const std::vector<double>& us, const std::vector<Vec3>& ps,
                         const Vec3& q) {
  std::size_t best = 0;
  double bd = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < ps.size(); ++i) {
    const double dd = (ps[i] - q).squaredNorm();
    if (dd < bd) {
      bd = dd;
      best = i;
    }
  }
  double u = us[best];
  const double lo = us[best == 0 ? 0 : best - 1], hi = us[std::min(best + 1, us.size() - 1)];
  for (int it = 0; it < 40; ++it) {
    Vec3 e[3];
    c.evaluate(u, 2, e);
    const Vec3 r = e[0] - q;
    const double f = r.dot(e[1]), fp = e[1].squaredNorm() + r.dot(e[2]);
    if (!(fp > 0)) break;
    u = std::clamp(u - f / fp, lo, hi);
  }
  return std::min(std::sqrt(bd), (c.position(u) - q).norm());
}

/// Facets whose outward normal (by winding) points toward the centerline: turned inside out.
std::size_t inverted_side_facets(const Centerline& c, const loom::SweepResult& res) {
  const std::size_t ring_vertices = static_cast<std::size_t>(res.rings) * res.circumferential;
  std::vector<double> us;
  std::vector<Vec3> ps;
  for (int k = 0; k <= 1000; ++k) {
    us.push_back(c.u_min() + (c.u_max() - c.u_min()) * k / 1000.0);
    ps.push_back(c.position(us.back()));
  }
  std::size_t bad = 0;
  for (std::size_t t = 0; t < res.mesh.triangles.size(); ++t) {
    const auto& f = res.mesh.triangles[t];
    if (f[0] >= ring_vertices || f[1] >= ring_vertices || f[2] >= ring_vertices) continue;
    const auto q = res.mesh.corners(t);
    const Vec3 n = (q[1] - q[0]).cross(q[2] - q[0]);
    const Vec3 g = (q[0] + q[1] + q[2]) / 3.0;
    // Nearest sample of the axis: the facet should face away from it.
    std::size_t best = 0;
    double bd = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < ps.size(); ++i)
      if ((ps[i] - g).squaredNorm() < bd) {
        bd = (ps[i] - g).squaredNorm();
        best = i;
      }
    if (n.dot(g - ps[best]) < 0.0) ++bad;
  }
  return bad;
}

}  // namespace

// --- interpolation against OpenCASCADE ----------------------------------------------------

TEST(GeometryAdversarial, InterpolationAgreesWithOpenCascadeOnHostileScales) {
  struct Case {
    const char* name;
    std::vector<Vec3> pts;
  };
  const std::vector<Vec3> base{{0, 0, 0}, {1, 0.3, 0}, {2, -0.2, 0.5}, {3, 0.4, 0.1}, {4, 0, 0}};
  std::vector<Case> cases;
  {
    Case c{"offset 1e6", {}};
    for (const Vec3& p : base) c.pts.push_back(p + Vec3(1e6, -1e6, 1e6));
    cases.push_back(c);
  }
  {
    Case c{"scale 1e-6", {}};
    for (const Vec3& p : base) c.pts.push_back(1e-6 * p);
    cases.push_back(c);
  }
  cases.push_back({"1 mm then 1 km", {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {1001, 1, 0}, {1001, 1001, 300}}});
  cases.push_back({"1e-9 spans among unit ones", {{0, 0, 0}, {1, 0, 0}, {1, 1e-9, 0}, {1, 1, 0}, {2, 1, 1}}});
  for (const Case& cs : cases) {
    for (KnotMethod km : {KnotMethod::ChordLength, KnotMethod::HartleyJudd})
      for (int tangents = 0; tangents < 2; ++tangents) {
        SCOPED_TRACE(std::string(cs.name) + (km == KnotMethod::HartleyJudd ? " HJ" : " chord") +
                     (tangents ? " tangents" : " natural"));
        InterpolationOptions o;
        o.knots = km;
        if (tangents) {
          o.start_tangent = Vec3(-1, 0.2, 0);  // against the first chord
          o.end_tangent = Vec3(0, 0, -1);
        }
        const Centerline c = Centerline::interpolate(cs.pts, o);
        const double scale = scale_of(cs.pts);
        // Through every key point.
        for (std::size_t i = 0; i < cs.pts.size(); ++i)
          EXPECT_LE((c.position(c.key_parameters()[i]) - cs.pts[i]).norm(), 1e-9 * scale) << i;
        const Handle(Geom_BSplineCurve) oc = occt_interpolant(cs.pts, c);
        ASSERT_FALSE(oc.IsNull());
        double worst = 0.0;
        for (int k = 0; k <= 4000; ++k) {
          const double u = c.u_min() + (c.u_max() - c.u_min()) * k / 4000.0;
          worst = std::max(worst, (c.position(u) - v3(oc->Value(u))).norm());
        }
        EXPECT_LE(worst, 1e-8 * scale);
        // Natural ends: C'' = 0.
        if (!tangents) {
          EXPECT_LE(c.derivative(c.u_min(), 2).norm(), 1e-6 * (1 + c.derivative(c.u_min(), 1).norm()) / scale);
        } else {
          EXPECT_NEAR(c.derivative(c.u_min(), 1).normalized().dot(o.start_tangent->normalized()), 1.0, 1e-9);
          EXPECT_NEAR(c.derivative(c.u_max(), 1).normalized().dot(o.end_tangent->normalized()), 1.0, 1e-9);
        }
        // Arc length against OpenCASCADE's.
        GeomAdaptor_Curve ga(oc);
        const double L = GCPnts_AbscissaPoint::Length(ga, ga.FirstParameter(), ga.LastParameter(), 1e-12 * scale);
        EXPECT_NEAR(c.length(), L, 1e-8 * L);
        // Round trip of arc length.
        for (double f : {0.1, 0.37, 0.5, 0.93}) EXPECT_NEAR(c.arc_length_at(c.parameter_at_length(f * L)), f * L, 1e-9 * L);
      }
  }
}

TEST(GeometryAdversarial, CurvatureAgreesWithOpenCascadeOnUnevenSpacing) {
  const std::vector<Vec3> pts{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {1001, 1, 0}, {1001, 1001, 300}, {1001.5, 1001, 300}};
  const Centerline c = Centerline::interpolate(pts, {KnotMethod::HartleyJudd, Vec3(1, 0, 0), Vec3(1, 0, 0)});
  const Handle(Geom_BSplineCurve) oc = to_occt(c);
  GeomLProp_CLProps props(oc, 2, 1e-12);
  double worst = 0.0;
  for (int k = 0; k <= 20000; ++k) {
    const double u = c.u_min() + (c.u_max() - c.u_min()) * k / 20000.0;
    props.SetParameter(u);
    const double ko = props.Curvature();
    worst = std::max(worst, std::abs(c.curvature(u) - ko) / std::max(ko, 1e-3));
  }
  EXPECT_LE(worst, 1e-7);
}

// --- closed forms ---------------------------------------------------------------------------

TEST(GeometryAdversarial, HelixHasItsClosedFormCurvature) {
  // Helix radius a, pitch 2πb: κ = a/(a² + b²). Dense points, exact end tangents.
  const double a = 5.0, b = 2.0, dt = 0.02;
  const int n = 600;
  const auto pts = helix(a, b, dt, n);
  const double T = n * dt;
  const Centerline c = Centerline::interpolate(
      pts, {KnotMethod::ChordLength, Vec3(0, a, b), Vec3(-a * std::sin(T), a * std::cos(T), b)});
  const double R = (a * a + b * b) / a;
  const loom::BendExtremum e = c.min_bend_radius();
  EXPECT_NEAR(e.radius, R, 1e-4 * R);
  // Everywhere, not only at the minimum.
  for (int k = 0; k <= 1000; ++k) {
    const double u = c.u_min() + (c.u_max() - c.u_min()) * k / 1000.0;
    EXPECT_NEAR(c.curvature(u), 1.0 / R, 1e-4 / R) << u;  // O(h²) between key points
  }
  EXPECT_NEAR(c.length(), T * std::sqrt(a * a + b * b), 1e-7 * T);
  // A straight line at a large offset: no curvature (the doc: infinity for a straight curve).
  const Centerline line = Centerline::interpolate({Vec3(1e6, 1e6, 1e6), Vec3(1e6 + 1, 1e6 + 2, 1e6 + 3),
                                                   Vec3(1e6 + 3, 1e6 + 6, 1e6 + 9), Vec3(1e6 + 4, 1e6 + 8, 1e6 + 12)});
  EXPECT_GT(line.min_bend_radius().radius, 1e6 * line.length());
}

TEST(GeometryAdversarial, MinBendRadiusValueAndPlaceAgainstLongDoubleBruteForce) {
  const std::vector<std::vector<Vec3>> curves{
      {{0, 0, 0}, {10, 0, 0}, {10.5, 0.5, 0}, {10, 1, 0}, {0, 1, 0}},                   // hairpin with a gap
      {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {1001, 1, 0}, {1001, 1001, 300}},               // 1 mm then 1 km
      {{0, 0, 0}, {3, 1, 0}, {3.2, 1.1, 0.05}, {6, 0, 1}, {9, 2, 0}, {12, 0, 0}},        // short span in a run
  };
  for (std::size_t i = 0; i < curves.size(); ++i) {
    SCOPED_TRACE(i);
    const Centerline c = Centerline::interpolate(curves[i]);
    const loom::BendExtremum e = c.min_bend_radius();
    const auto [brute, at] = brute_min_bend(c, 100000, e.u);
    EXPECT_LE(e.radius, brute * (1 + 1e-9));
    EXPECT_GE(e.radius, brute * (1 - 1e-6));
    // The reported place has the reported radius, and its s is the arc length there.
    EXPECT_NEAR(1.0 / c.curvature(e.u), e.radius, 1e-9 * e.radius);
    EXPECT_NEAR(e.s, c.arc_length_at(e.u), 1e-9 * c.length());
    // And it is where the brute force found its minimum (one sample spacing in u, or the
    // same radius within the brute force's accuracy if the minimum is flat).
    const double du = (c.u_max() - c.u_min()) / 100000.0;
    if (std::abs(e.u - at) > 2 * du) {
      EXPECT_NEAR(1.0 / c.curvature(at), e.radius, 1e-4 * e.radius);
    }
  }
}

// --- degenerate key points -----------------------------------------------------------------

TEST(GeometryAdversarial, NearlyCoincidentPointsStayFinite) {
  for (double gap : {1e-13, 1e-12, 2e-12, 1e-11, 1e-9}) {
    SCOPED_TRACE(gap);
    const std::vector<Vec3> pts{{0, 0, 0}, {1, 0, 0}, {1 + gap, gap, 0}, {2, 1, 0}, {3, 1, 1}};
    Centerline c;
    try {
      c = Centerline::interpolate(pts);
    } catch (const std::invalid_argument&) {
      continue;  // a clear refusal is a documented result
    }
    for (std::size_t i = 0; i < pts.size(); ++i)
      EXPECT_LE((c.position(c.key_parameters()[i]) - pts[i]).norm(), 1e-9) << i;
    for (int k = 0; k <= 2000; ++k) {
      const double u = c.u_min() + (c.u_max() - c.u_min()) * k / 2000.0;
      ASSERT_TRUE(loom::is_finite(c.position(u)));
      ASSERT_TRUE(std::isfinite(c.curvature(u)));
    }
    const loom::BendExtremum e = c.min_bend_radius();
    EXPECT_TRUE(e.radius >= 0.0);
    EXPECT_TRUE(std::isfinite(c.length()));
    const loom::SweepResult t = loom::sweep_tube(c, 0.05, {0.005, true});
    EXPECT_EQ(loom::first_non_finite_vertex(t.mesh), -1);
    EXPECT_TRUE(loom::analyse_topology(t.mesh).closed);
  }
}

TEST(GeometryAdversarial, OpposingEndTangentsMakeAFiniteLoopThroughBothPoints) {
  InterpolationOptions o;
  o.start_tangent = Vec3(-1, 0, 0);
  o.end_tangent = Vec3(-1, 0, 0);
  const std::vector<Vec3> pts{{0, 0, 0}, {1, 0, 0}};
  const Centerline c = Centerline::interpolate(pts, o);
  EXPECT_LE((c.position(c.u_min()) - pts[0]).norm(), 1e-15);
  EXPECT_LE((c.position(c.u_max()) - pts[1]).norm(), 1e-15);
  const Handle(Geom_BSplineCurve) oc = occt_interpolant(pts, c);
  for (int k = 0; k <= 100; ++k) {
    const double u = c.u_min() + (c.u_max() - c.u_min()) * k / 100.0;
    EXPECT_LE((c.position(u) - v3(oc->Value(u))).norm(), 1e-12);
  }
  // Collinear opposing tangents: the curve runs back along the line, a fold.
  EXPECT_EQ(c.min_bend_radius().radius, 0.0);
}

TEST(GeometryAdversarial, ClosedLoopWithoutTangentsIsFinite) {
  std::vector<Vec3> p;
  for (int i = 0; i < 12; ++i) p.emplace_back(10 * std::cos(i * M_PI / 6), 10 * std::sin(i * M_PI / 6), 0);
  p.push_back(p.front());
  const Centerline c = Centerline::interpolate(p);
  EXPECT_LE((c.position(c.u_min()) - c.position(c.u_max())).norm(), 1e-12);
  const auto [brute, at] = brute_min_bend(c, 100000, c.min_bend_radius().u);
  (void)at;
  EXPECT_NEAR(c.min_bend_radius().radius, brute, 1e-4 * brute);
}

// --- sweep ----------------------------------------------------------------------------------

TEST(GeometryAdversarial, TubeOnHostileScalesIsWatertightFiniteAndWithinTolerance) {
  struct Case {
    const char* name;
    Vec3 offset;
    double scale;
  };
  for (const Case& cs : {Case{"plain", Vec3::Zero(), 1.0}, Case{"offset 1e6", Vec3(1e6, -1e6, 1e6), 1.0},
                         Case{"scale 1e-3", Vec3::Zero(), 1e-3}, Case{"scale 1e3", Vec3::Zero(), 1e3}}) {
    SCOPED_TRACE(cs.name);
    std::vector<Vec3> pts = helix(5.0, 1.0, 0.3, 30);
    for (Vec3& q : pts) q = cs.offset + cs.scale * q;
    const Centerline c = Centerline::interpolate(pts);
    const double r = 1.0 * cs.scale, tol = 0.01 * cs.scale;
    ASSERT_GT(c.min_bend_radius().radius, 2 * r);
    const loom::SweepResult res = loom::sweep_tube(c, r, {tol, true});
    EXPECT_EQ(loom::first_non_finite_vertex(res.mesh), -1);
    const loom::MeshTopology topo = loom::analyse_topology(res.mesh);
    EXPECT_TRUE(topo.closed);
    EXPECT_EQ(topo.boundary_edges, 0u);
    EXPECT_EQ(topo.nonmanifold_edges, 0u);
    EXPECT_EQ(topo.misoriented_edges, 0u);
    EXPECT_EQ(topo.degenerate_triangles, 0u);
    // Facet points within the chord tolerance of the exact tube (the offset's rounding,
    // ~1e-10, is far below it).
    std::vector<double> us;
    std::vector<Vec3> ps;
    for (int k = 0; k <= 20000; ++k) {
      us.push_back(c.u_min() + (c.u_max() - c.u_min()) * k / 20000.0);
      ps.push_back(c.position(us.back()));
    }
    const std::size_t ring_vertices = static_cast<std::size_t>(res.rings) * res.circumferential;
    double worst = 0.0;
    for (std::size_t t = 0; t < res.mesh.triangles.size(); t += 3) {
      const auto& f = res.mesh.triangles[t];
      if (f[0] >= ring_vertices || f[1] >= ring_vertices || f[2] >= ring_vertices) continue;
      const auto q = res.mesh.corners(t);
      for (const Vec3& p : {Vec3((q[0] + q[1] + q[2]) / 3.0), Vec3(0.5 * (q[0] + q[1])), Vec3(0.5 * (q[1] + q[2])),
                            Vec3(0.5 * (q[0] + q[2]))})
        worst = std::max(worst, std::abs(distance_to_curve(c, us, ps, p) - r));
    }
    EXPECT_LE(worst, tol);
    EXPECT_EQ(inverted_side_facets(c, res), 0u);
    EXPECT_FALSE(res.folded);
  }
}

TEST(GeometryAdversarial, TubeOfAZeroLengthCableIsFiniteOrRefused) {
  const Centerline c(3, {0, 0, 0, 0, 1, 1, 1, 1}, std::vector<Vec3>(4, Vec3(1, 2, 3)));
  EXPECT_EQ(c.length(), 0.0);
  try {
    const loom::SweepResult res = loom::sweep_tube(c, 0.5, {0.01, true});
    EXPECT_EQ(loom::first_non_finite_vertex(res.mesh), -1);
    EXPECT_TRUE(loom::analyse_topology(res.mesh).closed);
  } catch (const std::invalid_argument&) {
  }
}

// --- fairing --------------------------------------------------------------------------------

TEST(GeometryAdversarial, EnergyFairingKeepsItsToleranceOnHostileInput) {
  const std::vector<std::vector<Vec3>> inputs{
      {{0, 0, 0}, {10, 0, 0}, {10.5, 0.5, 0}, {10, 1, 0}, {0, 1, 0}},                  // hairpin
      {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {1001, 1, 0}, {1001, 1001, 300}},              // 1 mm then 1 km
      {{1e6, 1e6, 0}, {1e6 + 1, 1e6 + 0.5, 0}, {1e6 + 2, 1e6 - 0.3, 0}, {1e6 + 3, 1e6 + 0.2, 0.1}, {1e6 + 4, 1e6, 0}},
      {{0, 0, 0}, {1, 1, 1}, {2, 2, 2}, {3, 3, 3}},                                     // collinear
  };
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    SCOPED_TRACE(i);
    InterpolationOptions o;
    o.start_tangent = inputs[i][1] - inputs[i][0];
    o.end_tangent = inputs[i].back() - inputs[i][inputs[i].size() - 2];
    const Centerline c = Centerline::interpolate(inputs[i], o);
    for (double eps : {1e-3, 0.1}) {
      loom::FairingOptions fo;
      fo.tolerance = eps;
      const loom::FairingResult r = loom::fair_energy(c, fo);
      double dev = 0.0;
      for (std::size_t k = 0; k < inputs[i].size(); ++k)
        dev = std::max(dev, (r.curve.position(c.key_parameters()[k]) - inputs[i][k]).norm());
      EXPECT_LE(dev, eps * (1 + 1e-9));
      EXPECT_NEAR(dev, r.max_deviation, 1e-9 * (1 + dev));
      EXPECT_LE(loom::bending_energy(r.curve), loom::bending_energy(c) * (1 + 1e-9) + 1e-300);
      // Ends and end tangents kept (PositionAndTangent).
      EXPECT_LE((r.curve.position(r.curve.u_min()) - inputs[i].front()).norm(), 1e-9 * (1 + inputs[i].front().norm()));
      EXPECT_NEAR(r.curve.derivative(r.curve.u_min(), 1).normalized().dot(o.start_tangent->normalized()), 1.0, 1e-9);
      EXPECT_NEAR(r.curve.derivative(r.curve.u_max(), 1).normalized().dot(o.end_tangent->normalized()), 1.0, 1e-9);
      for (int k = 0; k <= 200; ++k)
        ASSERT_TRUE(loom::is_finite(r.curve.position(r.curve.u_min() + (r.curve.u_max() - r.curve.u_min()) * k / 200)));
    }
  }
}

TEST(GeometryAdversarial, BendingEnergyOfAHelixIsItsClosedForm) {
  const double a = 5.0, b = 2.0, dt = 0.02;
  const int n = 300;
  const double T = n * dt;
  const Centerline c = Centerline::interpolate(
      helix(a, b, dt, n), {KnotMethod::ChordLength, Vec3(0, a, b), Vec3(-a * std::sin(T), a * std::cos(T), b)});
  const double kappa = a / (a * a + b * b), L = T * std::sqrt(a * a + b * b);
  EXPECT_NEAR(loom::bending_energy(c), kappa * kappa * L, 1e-6 * kappa * kappa * L);
}

// --- more sweep ------------------------------------------------------------------------------

TEST(GeometryAdversarial, SectionArcLengthsIncreaseAndMatchTheCurve) {
  const std::vector<std::vector<Vec3>> inputs{
      {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {1001, 1, 0}, {1001, 1001, 300}},  // 1 mm then 1 km
      {{0, 0, 0}, {10, 0, 0}, {10.5, 0.5, 0}, {10, 1, 0}, {0, 1, 0}},      // hairpin with a gap
  };
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    SCOPED_TRACE(i);
    const Centerline c = Centerline::interpolate(inputs[i]);
    const double tol = 0.01;
    const auto sec = loom::tube_sections(c, 0.1, {tol, true});
    ASSERT_GE(sec.size(), 2u);
    EXPECT_EQ(sec.front().s, 0.0);
    EXPECT_EQ(sec.back().s, c.length());
    for (std::size_t k = 0; k < sec.size(); ++k) {
      if (k > 0) {
        EXPECT_GT(sec[k].s, sec[k - 1].s) << k;
      }
      // Simpson steps on |C'|: measured ≤ 5.3e-5 on the 1 mm / 1 km curve, whose speed
      // nearly vanishes in its first spans; 6e-6 on the hairpin.
      EXPECT_NEAR(sec[k].s, c.arc_length_at(sec[k].u), 1e-2 * tol) << k;
      EXPECT_NEAR(sec[k].tangent.norm(), 1.0, 1e-12);
      EXPECT_NEAR(sec[k].normal.norm(), 1.0, 1e-12);
      EXPECT_NEAR(sec[k].normal.dot(sec[k].tangent), 0.0, 1e-12);
    }
  }
}

TEST(GeometryAdversarial, InterpolatedArcAtTheBendLimitIsWithinItsInterpolationError) {
  // A circle arc of radius R through key points every h: the cubic's bend radius differs
  // from R by O(h²). Measured here so that a bend check at exactly the limit knows its slack.
  const double R = 18.0;
  for (int n : {8, 32, 128}) {
    std::vector<Vec3> p;
    const double sweep = 0.5 * M_PI;
    for (int i = 0; i <= n; ++i) p.emplace_back(R * std::cos(sweep * i / n), R * std::sin(sweep * i / n), 0);
    const Centerline c = Centerline::interpolate(p, {KnotMethod::ChordLength, Vec3(0, 1, 0), Vec3(-1, 0, 0)});
    const double h = R * sweep / n;
    const double err = std::abs(c.min_bend_radius().radius - R) / R;
    EXPECT_LE(err, 0.5 * (h / R) * (h / R)) << n;  // O(h²) with a constant below ½
  }
}

TEST(GeometryAdversarial, StepExportOfHostileCurvesIsASolidOfTheTubesVolume) {
  // Pappus: a tube that does not fold has volume πr²L. Written solids must have it (within
  // the chord tolerance over the surface); a folded tube may be refused, never thrown.
  struct Case {
    const char* name;
    Centerline c;
    double r;
  };
  std::vector<Vec3> off = helix(5.0, 1.0, 0.3, 20);
  for (Vec3& q : off) q += Vec3(1e6, -1e6, 1e6);
  const std::vector<Case> cases{
      {"hairpin with a gap", Centerline::interpolate({{0, 0, 0}, {10, 0, 0}, {10.5, 0.5, 0}, {10, 1, 0}, {0, 1, 0}}), 0.05},
      {"helix at 1e6", Centerline::interpolate(off), 0.5},
      {"1 mm then 1 km", Centerline::interpolate({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {1001, 1, 0}, {1001, 1001, 300}}), 0.1},
      {"near-coincident", Centerline::interpolate({{0, 0, 0}, {1, 0, 0}, {1 + 1e-9, 1e-9, 0}, {2, 1, 0}, {3, 1, 1}}), 0.05},
  };
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "loom_geometry_adversarial";
  int checked = 0;
  for (const Case& cs : cases) {
    SCOPED_TRACE(cs.name);
    const double tol = 0.01 * cs.r;
    const bool folds = loom::sweep_tube(cs.c, cs.r, {tol, true}).folded;
    loom::StepExportResult res;
    ASSERT_NO_THROW(res = loom::write_tube_step(cs.c, cs.r, dir / "tube.step", {tol, true}));
    if (folds) continue;
    ++checked;
    ASSERT_EQ(res.status, loom::StepExportStatus::Written) << res.message;
    const double V = M_PI * cs.r * cs.r * cs.c.length();
    EXPECT_NEAR(res.volume, V, 1e-3 * V);
  }
  EXPECT_GE(checked, 3);
  std::filesystem::remove_all(dir);
}

TEST(GeometryAdversarial, NearReversalBendRadiusAgainstBruteForce) {
  // A hairpin whose legs are δ apart: a finite bend of radius ~δ/2 (or a fold) in a narrow
  // stretch of one knot interval, between the bend search's samples.
  for (double delta : {1e-1, 1e-2, 1e-3, 1e-4, 1e-5}) {
    SCOPED_TRACE(delta);
    for (const auto& pts : {std::vector<Vec3>{{0, 0, 0}, {1, 0, 0}, {1, delta, 0}, {0, delta, 0}},
                            std::vector<Vec3>{{0, 0, 0}, {2, 0, 0}, {3, 0, 0}, {3, delta, 0}, {2.5, delta, 0}, {0, delta, 0}},
                            std::vector<Vec3>{{0, 0, 0}, {1, 0.3, 0}, {2, 0, 0}, {1.5, delta, 0.2}, {0, 1, 1}}}) {
      const Centerline c = Centerline::interpolate(pts);
      const loom::BendExtremum e = c.min_bend_radius();
      const auto [brute, at] = brute_min_bend(c, 200000, e.u);
      (void)at;
      if (e.radius == 0.0) continue;  // reported as a fold: no finite radius to compare
      EXPECT_LE(e.radius, brute * (1 + 1e-6)) << "loom misses a tighter bend";
    }
  }
}

TEST(GeometryAdversarial, SelectedPointFairingStaysWithinEpsilonOnHostileInput) {
  const std::vector<std::vector<Vec3>> inputs{
      {{0, 0, 0}, {10, 0, 0}, {10.5, 0.5, 0}, {10, 1, 0}, {0, 1, 0}},                              // hairpin
      {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {1001, 1, 0}, {1001, 1001, 300}},                          // 1 mm then 1 km
      {{0, 0, 0}, {1, 0.2, 0}, {2, -0.2, 0}, {3, 0.2, 0}, {4, -0.2, 0}, {5, 0.2, 0}, {6, 0, 0}},     // zigzag
      {{0, 0, 0}, {1, 0, 0}, {1, 0, 0}, {2, 1, 0}, {3, 0, 0}, {4, 1, 0}, {5, 0, 0}},                 // repeated point
  };
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    SCOPED_TRACE(i);
    loom::FairingOptions fo;
    fo.tolerance = 0.05;
    const loom::FairingResult r = loom::fair_selected_points(inputs[i], {}, fo);
    ASSERT_EQ(r.points.size(), inputs[i].size());
    double dev = 0.0;
    for (std::size_t k = 0; k < inputs[i].size(); ++k) {
      dev = std::max(dev, (r.points[k] - inputs[i][k]).norm());
      // The faired curve passes through its faired points.
      EXPECT_LE((r.curve.position(r.curve.key_parameters()[k]) - r.points[k]).norm(), 1e-9 * scale_of(inputs[i]));
    }
    EXPECT_LE(dev, fo.tolerance * (1 + 1e-12));
    EXPECT_NEAR(dev, r.max_deviation, 1e-12);
  }
}

TEST(GeometryAdversarial, CanalFoldIsReportedLikeTheTubes) {
  std::vector<Vec3> p;
  for (int i = 0; i <= 100; ++i) p.emplace_back(3 * std::cos(M_PI * i / 100), 3 * std::sin(M_PI * i / 100), 0);
  const Centerline c = Centerline::interpolate(p, {KnotMethod::ChordLength, Vec3(0, 1, 0), Vec3(0, -1, 0)});
  const double L = c.length();
  // Radius 1 → 4 along the bend of radius 3: it folds once r exceeds 3.
  const loom::SweepResult grow = loom::sweep_canal(c, [L](double s) { return 1.0 + 3.0 * s / L; }, {0.01, true});
  EXPECT_TRUE(grow.folded);
  EXPECT_GT(grow.fold_s, 0.5 * L);  // where r·κ first exceeds 1: s = 2L/3
  EXPECT_LT(grow.fold_s, 0.75 * L);
  const loom::SweepResult thin = loom::sweep_canal(c, [L](double s) { return 1.0 + s / L; }, {0.01, true});
  EXPECT_FALSE(thin.folded);
}

TEST(GeometryAdversarial, TubeAroundABendJustWiderThanItsRadiusStaysWithinTolerance) {
  // Bend radius 1.2 r: the inner side is a saddle of curvature 1/(R − r) = 5/r across the
  // axis; the facets must still lie within the chord tolerance of the exact tube.
  const double r = 1.0, R = 1.2, tol = 0.01;
  std::vector<Vec3> p;
  for (int i = 0; i <= 400; ++i) p.emplace_back(R * std::cos(M_PI * i / 400), R * std::sin(M_PI * i / 400), 0.05 * i / 400);
  // End tangents: a natural end (C'' = 0) would overshoot the curvature next to it by ~25%.
  const Centerline c = Centerline::interpolate(
      p, {KnotMethod::ChordLength, Vec3(0, R * M_PI, 0.05), Vec3(0, -R * M_PI, 0.05)});
  ASSERT_GT(c.min_bend_radius().radius, 1.15 * r);
  const loom::SweepResult res = loom::sweep_tube(c, r, {tol, true});
  EXPECT_FALSE(res.folded);
  EXPECT_EQ(inverted_side_facets(c, res), 0u);
  std::vector<double> us;
  std::vector<Vec3> ps;
  for (int k = 0; k <= 4000; ++k) {
    us.push_back(c.u_min() + (c.u_max() - c.u_min()) * k / 4000.0);
    ps.push_back(c.position(us.back()));
  }
  const std::size_t ring_vertices = static_cast<std::size_t>(res.rings) * res.circumferential;
  double worst = 0.0;
  for (std::size_t t = 0; t < res.mesh.triangles.size(); t += 3) {  // every third: time
    const auto& f = res.mesh.triangles[t];
    if (f[0] >= ring_vertices || f[1] >= ring_vertices || f[2] >= ring_vertices) continue;
    const auto q = res.mesh.corners(t);
    for (const Vec3& x : {Vec3((q[0] + q[1] + q[2]) / 3.0), Vec3(0.5 * (q[0] + q[1])), Vec3(0.5 * (q[1] + q[2])),
                          Vec3(0.5 * (q[0] + q[2]))})
      worst = std::max(worst, std::abs(distance_to_curve(c, us, ps, x) - r));
  }
  EXPECT_LE(worst, tol);
  const loom::MeshTopology topo = loom::analyse_topology(res.mesh);
  EXPECT_TRUE(topo.closed);
  EXPECT_EQ(topo.misoriented_edges, 0u);
}

TEST(GeometryAdversarial, HullBoundsHoldOnHostileCurvesAgainstDenseSampling) {
  // deviation ≥ max distance of C from the chord, turn_sine ≥ max sine between C' and the
  // chord (unless 1: "may turn against it"), measured by dense sampling of [a, b].
  const std::vector<Centerline> curves{
      Centerline::interpolate({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {1001, 1, 0}, {1001, 1001, 300}}),
      Centerline::interpolate({{0, 0, 0}, {10, 0, 0}, {10.5, 0.5, 0}, {10, 1, 0}, {0, 1, 0}}),
      Centerline::interpolate({{0, 0, 0}, {1, 0, 0}, {1 + 1e-9, 1e-9, 0}, {2, 1, 0}, {3, 1, 1}}),
      Centerline(3, {0, 1, 2, 3, 4, 5, 6, 7, 8}, {{0, 0, 0}, {1, 2, 0}, {3, 2, 1}, {4, 0, 0}, {6, 1, 1}}),  // unclamped
  };
  for (std::size_t i = 0; i < curves.size(); ++i) {
    const Centerline& c = curves[i];
    const double w = c.u_max() - c.u_min();
    for (int t = 0; t < 60; ++t) {
      const double a = c.u_min() + w * std::fmod(0.137 * t * t + 0.05 * t, 1.0);
      const double b = std::min(c.u_max(), a + w * std::pow(0.5, t % 12));
      if (!(b > a)) continue;
      const loom::Centerline::HullBounds hb = c.hull_bounds(a, b);
      const Vec3 pa = c.position(a), pb = c.position(b);
      const Vec3 dir = (pb - pa).normalized();
      double dev = 0.0, sine = 0.0;
      for (int k = 0; k <= 2000; ++k) {
        const double u = a + (b - a) * k / 2000.0;
        Vec3 d[2];
        c.evaluate(u, 1, d);
        const Vec3 q = d[0] - pa;
        const double along = std::clamp(q.dot(pb - pa) / (pb - pa).squaredNorm(), 0.0, 1.0);
        dev = std::max(dev, (d[0] - (pa + along * (pb - pa))).norm());
        if (d[1].norm() > 0) sine = std::max(sine, d[1].cross(dir).norm() / d[1].norm());
      }
      const double scale = (pb - pa).norm() + hb.deviation;
      EXPECT_GE(hb.deviation, dev - 1e-12 * (1 + scale)) << i << " [" << a << ", " << b << "]";
      if (hb.turn_sine < 1.0) {
        EXPECT_GE(hb.turn_sine, sine - 1e-9) << i << " [" << a << ", " << b << "]";
      }
    }
  }
}

TEST(GeometryAdversarial, SectionsStayIncreasingWhereSimpsonStepsMeetHullJumps) {
  // A wild start (the speed nearly vanishes: Simpson's s drifts) followed by a dense run of
  // key points 1e-3 apart around a bend (knot intervals ≪ r: hull jumps set s exactly).
  for (double sign : {1.0, -1.0}) {
    std::vector<Vec3> p{{0, 0, 0}, {1, 0, 0}, {1, sign, 0}, {30, sign, 0}};
    for (int i = 1; i <= 3000; ++i) {
      const double t = 1e-3 * i;
      p.emplace_back(30 + 5 * std::sin(t / 5), sign + 5 * (1 - std::cos(t / 5)), 0.1 * t);
    }
    const Centerline c = Centerline::interpolate(p);
    const auto sec = loom::tube_sections(c, 1.0, {0.01, true});
    for (std::size_t k = 1; k < sec.size(); ++k) ASSERT_GT(sec[k].s, sec[k - 1].s) << k << " of " << sec.size();
    const loom::StepExportResult res = loom::write_tube_step(
        c, 1.0, std::filesystem::temp_directory_path() / "loom_geometry_adversarial_jump.step", {0.01, true});
    EXPECT_EQ(res.status, loom::StepExportStatus::Written) << res.message;
    std::filesystem::remove(std::filesystem::temp_directory_path() / "loom_geometry_adversarial_jump.step");
  }
}

TEST(GeometryAdversarial, LargeSparseSolveWithWildSpacingAgreesWithOpenCascade) {
  // > 48 unknowns: the sparse LU path, with spacing alternating 1 mm and 1 km.
  for (int tangents = 0; tangents < 2; ++tangents) {
    SCOPED_TRACE(tangents);
    std::vector<Vec3> pts{{0, 0, 0}};
    for (int i = 1; i < 120; ++i) {
      const double step = i % 2 ? 1e-3 : 1e3;
      pts.push_back(pts.back() + step * Vec3(1, 0.3 * std::sin(i), 0.2 * std::cos(0.7 * i)).normalized());
    }
    InterpolationOptions o;
    if (tangents) {
      o.start_tangent = Vec3(0, 1, 0);
      o.end_tangent = Vec3(0, 0, 1);
    }
    const Centerline c = Centerline::interpolate(pts, o);
    const double scale = scale_of(pts);
    for (std::size_t i = 0; i < pts.size(); ++i)
      ASSERT_LE((c.position(c.key_parameters()[i]) - pts[i]).norm(), 1e-9 * scale) << i;
    const Handle(Geom_BSplineCurve) oc = occt_interpolant(pts, c);
    ASSERT_FALSE(oc.IsNull());
    double worst = 0.0;
    for (int k = 0; k <= 20000; ++k) {
      const double u = c.u_min() + (c.u_max() - c.u_min()) * k / 20000.0;
      worst = std::max(worst, (c.position(u) - v3(oc->Value(u))).norm());
    }
    EXPECT_LE(worst, 1e-9 * scale);
  }
}
