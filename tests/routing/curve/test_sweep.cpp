// Sweeps (routing/sweep.hpp, routing/sweep_step.hpp): tube and canal surfaces against the
// exact surfaces (distance to the centerline, envelope of spheres), rotation-minimising
// frames against the Frenet frame, watertightness, junctions, and STEP round trips.
#include "routing/curve/sweep.hpp"
#include "routing/curve/sweep_step.hpp"

#include <BRepCheck_Analyzer.hxx>
#include <BRepGProp.hxx>
#include <GProp_GProps.hxx>
#include <STEPControl_Reader.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS_Shape.hxx>

#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <random>

using loom::Centerline;
using loom::InterpolationOptions;
using loom::Mesh;
using loom::SweepOptions;
using loom::Vec3;

namespace {

/// An S-curve (inflection), a straight run and a helical part, in one cubic.
Centerline s_curve() {
  std::vector<Vec3> p;
  for (int i = 0; i <= 10; ++i) {
    const double x = i * 2.0;
    p.emplace_back(x, 6.0 * std::sin(x / 6.0), 0.0);  // inflection at x = 6π ≈ 18.8
  }
  for (int i = 1; i <= 4; ++i) p.emplace_back(20.0 + 5.0 * i, 6.0 * std::sin(20.0 / 6.0), 0.0);  // straight
  for (int i = 1; i <= 12; ++i) {
    const double t = 0.5 * i;
    p.emplace_back(40.0 + 5.0 * std::sin(t), 6.0 * std::sin(20.0 / 6.0) + 5.0 * (1 - std::cos(t)), 1.5 * t);
  }
  return Centerline::interpolate(p);
}

/// Dense polyline samples of a curve (for brute-force distances).
struct Dense {
  std::vector<double> u;
  std::vector<Vec3> p;
};
Dense dense(const Centerline& c, int n) {
  Dense d;
  for (int k = 0; k <= n; ++k) {
    d.u.push_back(c.u_min() + (c.u_max() - c.u_min()) * k / n);
    d.p.push_back(c.position(d.u.back()));
  }
  return d;
}

/// Distance from q to the curve: best dense sample, then Newton on (C(u) − q)·C'(u) = 0.
double distance_to_curve(const Centerline& c, const Dense& d, const Vec3& q) {
  std::size_t best = 0;
  double bd = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < d.p.size(); ++i) {
    const double dd = (d.p[i] - q).squaredNorm();
    if (dd < bd) {
      bd = dd;
      best = i;
    }
  }
  double u = d.u[best];
  const double lo = d.u[best == 0 ? 0 : best - 1], hi = d.u[std::min(best + 1, d.u.size() - 1)];
  for (int it = 0; it < 30; ++it) {
    Vec3 e[3];
    c.evaluate(u, 2, e);
    const Vec3 r = e[0] - q;
    const double f = r.dot(e[1]), fp = e[1].squaredNorm() + r.dot(e[2]);
    if (!(fp > 0)) break;
    u = std::clamp(u - f / fp, lo, hi);
  }
  return std::min(std::sqrt(bd), (c.position(u) - q).norm());
}

double angle(const Vec3& a, const Vec3& b) { return std::atan2(a.cross(b).norm(), a.dot(b)); }

/// Largest |distance to the curve − r| over the centroid and edge midpoints of the tube's
/// side facets (the caps left out): how far the facets stand off the exact tube.
double worst_facet_error(const Centerline& c, const Dense& d, const loom::SweepResult& res, double r) {
  const std::size_t ring_vertices = static_cast<std::size_t>(res.rings) * res.circumferential;
  double worst = 0.0;
  for (std::size_t t = 0; t < res.mesh.triangles.size(); ++t) {
    const auto& f = res.mesh.triangles[t];
    if (f[0] >= ring_vertices || f[1] >= ring_vertices || f[2] >= ring_vertices) continue;  // caps
    const auto q = res.mesh.corners(t);
    for (const Vec3& p : {Vec3((q[0] + q[1] + q[2]) / 3.0), Vec3(0.5 * (q[0] + q[1])), Vec3(0.5 * (q[1] + q[2])),
                          Vec3(0.5 * (q[0] + q[2]))})
      worst = std::max(worst, std::abs(distance_to_curve(c, d, p) - r));
  }
  return worst;
}

/// Volume per unit length of a straight stack of regular n-gons of circumradius r, each
/// rotated by π/n against its neighbours and joined by triangles (an antiprism stack): the
/// prismatoid formula h/6·(A + A + 4·A_mid), exact since the section area is quadratic in
/// height; A_mid is the regular 2n-gon of circumradius r·cos(π/2n).
double staggered_area(int n, double r) {
  return n * r * r * std::sin(M_PI / n) * (1.0 + 2.0 * std::cos(M_PI / n)) / 3.0;
}

/// Generalised winding number of a closed triangle mesh around q (1 inside, 0 outside).
double winding_number(const Mesh& m, const Vec3& q) {
  double w = 0.0;
  for (const auto& t : m.triangles) {
    const Vec3 a = m.vertices[t[0]] - q, b = m.vertices[t[1]] - q, c = m.vertices[t[2]] - q;
    const double la = a.norm(), lb = b.norm(), lc = c.norm();
    const double num = a.dot(b.cross(c));
    const double den = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
    w += 2.0 * std::atan2(num, den);
  }
  return w / (4.0 * M_PI);
}

}  // namespace

TEST(Sweep, TubeSurfaceIsWithinChordToleranceOfTheExactTube) {
  const Centerline c = s_curve();
  const double r = 1.0, tol = 0.01;
  ASSERT_GT(c.min_bend_radius().radius, 2.0 * r);  // no self-overlap: distances are exact
  const loom::SweepResult res = loom::sweep_tube(c, r, {tol, true});
  const Dense d = dense(c, 20000);
  const std::size_t ring_vertices = static_cast<std::size_t>(res.rings) * res.circumferential;
  ASSERT_EQ(res.mesh.vertices.size(), ring_vertices + 2);
  double worst_vertex = 0.0;
  for (std::size_t i = 0; i < ring_vertices; ++i)
    worst_vertex = std::max(worst_vertex, std::abs(distance_to_curve(c, d, res.mesh.vertices[i]) - r));
  EXPECT_LE(worst_vertex, 1e-6);  // vertices lie on the exact tube
  // Points inside the facets: within the chord tolerance of the exact tube.
  const double worst_facet = worst_facet_error(c, d, res, r);
  EXPECT_LE(worst_facet, tol);
  EXPECT_GT(worst_facet, 0.05 * tol);  // and not absurdly finer than asked
}

TEST(Sweep, TubeIsWatertightAndOutward) {
  const Centerline c = s_curve();
  const double r = 0.5, tol = 0.005;
  const loom::SweepResult res = loom::sweep_tube(c, r, {tol, true});
  const loom::MeshTopology topo = loom::analyse_topology(res.mesh);
  EXPECT_TRUE(topo.closed);
  EXPECT_EQ(topo.boundary_edges, 0u);
  EXPECT_EQ(topo.nonmanifold_edges, 0u);
  EXPECT_EQ(topo.misoriented_edges, 0u);
  EXPECT_EQ(topo.degenerate_triangles, 0u);
  EXPECT_EQ(loom::first_non_finite_vertex(res.mesh), -1);
  // Volume: staggered section area × length (Pappus) within the axial chord error.
  const int n = res.circumferential;
  const double expected = staggered_area(n, r) * c.length();
  EXPECT_NEAR(res.mesh.signed_volume(), expected, 2e-3 * expected);
  // Without caps it is an open tube with exactly two boundary loops.
  const loom::SweepResult open = loom::sweep_tube(c, r, {tol, false});
  EXPECT_EQ(loom::analyse_topology(open.mesh).boundary_edges, 2u * static_cast<std::size_t>(n));
}

TEST(Sweep, RotationMinimisingFrameNeverFlipsWhereFrenetDoes) {
  const Centerline c = s_curve();
  const double r = 1.0;
  const auto sec = loom::tube_sections(c, r, {0.01, true});
  const loom::SweepResult res = loom::sweep_tube(c, r, {0.01, true});
  ASSERT_EQ(sec.size(), static_cast<std::size_t>(res.rings));
  // The mesh rings are built on these frames.
  for (std::size_t i = 0; i < sec.size(); ++i) {
    const double phi = (i % 2) * M_PI / res.circumferential;  // odd rings rotated by half a step
    const Vec3 across = sec[i].tangent.cross(sec[i].normal);
    const Vec3 first = sec[i].centre + r * (std::cos(phi) * sec[i].normal + std::sin(phi) * across);
    ASSERT_LE((res.mesh.vertices[i * res.circumferential] - first).norm(), 1e-12);
  }
  double max_frenet_jump = 0.0, max_turn = 0.0;
  int frenet_undefined = 0;
  for (std::size_t i = 0; i < sec.size(); ++i) {
    EXPECT_NEAR(sec[i].normal.norm(), 1.0, 1e-12);
    EXPECT_NEAR(sec[i].normal.dot(sec[i].tangent), 0.0, 1e-12);
    if (i == 0) continue;
    const double tangent_turn = angle(sec[i - 1].tangent, sec[i].tangent);
    // Minimal rotation: the normal turns no more than the tangent does.
    EXPECT_LE(angle(sec[i - 1].normal, sec[i].normal), tangent_turn + 1e-9) << "section " << i;
    max_turn = std::max(max_turn, tangent_turn);
    // Frenet normal of the paper (eq. 10–11) at the same sections, for comparison.
    const Vec3 b0 = c.derivative(sec[i - 1].u, 1).cross(c.derivative(sec[i - 1].u, 2));
    const Vec3 b1 = c.derivative(sec[i].u, 1).cross(c.derivative(sec[i].u, 2));
    if (b0.norm() < 1e-9 || b1.norm() < 1e-9)
      ++frenet_undefined;
    else
      max_frenet_jump = std::max(max_frenet_jump, angle(b0, b1));
  }
  EXPECT_GT(max_frenet_jump, 2.5);  // the Frenet frame flips at the inflection ...
  EXPECT_LE(res.max_frame_turn, max_turn + 1e-9);  // ... ours turns no more than the tangent
  EXPECT_GT(res.max_frame_turn, 0.0);
  (void)frenet_undefined;
}

TEST(Sweep, StraightRunHasAFrameWhereFrenetIsUndefined) {
  const Centerline c = Centerline::interpolate({Vec3(0, 0, 0), Vec3(3, 4, 0)});
  const loom::SweepResult res = loom::sweep_tube(c, 0.25, {0.001, true});
  EXPECT_TRUE(loom::analyse_topology(res.mesh).closed);
  EXPECT_EQ(loom::first_non_finite_vertex(res.mesh), -1);
  EXPECT_NEAR(res.max_frame_turn, 0.0, 1e-12);
  const int n = res.circumferential;
  EXPECT_NEAR(res.mesh.signed_volume(), staggered_area(n, 0.25) * 5.0, 1e-9);
}

TEST(Sweep, ResolutionFollowsTheChordTolerance) {
  const Centerline c = s_curve();
  std::size_t prev = 0;
  for (double tol : {0.1, 0.05, 0.02, 0.01, 0.005}) {
    const loom::SweepResult res = loom::sweep_tube(c, 1.0, {tol, true});
    const int n = res.circumferential;
    // Smallest n with ring sagitta ≤ ¾·tol (staggered rings, see sweep.cpp).
    EXPECT_LE(1.0 - std::cos(M_PI / n), 0.75 * tol + 1e-15);
    EXPECT_GT(1.0 - std::cos(M_PI / (n - 1)), 0.75 * tol);
    EXPECT_GT(res.mesh.triangle_count(), prev);
    prev = res.mesh.triangle_count();
  }
  EXPECT_THROW(loom::sweep_tube(c, 1.0, {0.0, true}), std::invalid_argument);
  EXPECT_THROW(loom::sweep_tube(c, 1.0, {std::nan(""), true}), std::invalid_argument);
  EXPECT_THROW(loom::sweep_tube(c, 0.0, {}), std::invalid_argument);
  EXPECT_THROW(loom::sweep_tube(c, -1.0, {}), std::invalid_argument);
  EXPECT_THROW(loom::sweep_tube(c, std::nan(""), {}), std::invalid_argument);
  EXPECT_THROW(loom::sweep_tube(Centerline(), 1.0, {}), std::invalid_argument);
}

TEST(Sweep, TriangleBudgetIsHeldBeforeTheMeshIsMade) {
  const Centerline c = s_curve();
  const loom::SweepResult full = loom::sweep_tube(c, 1.0, {0.01, true});
  loom::SweepOptions opt{0.01, true};
  opt.max_triangles = full.mesh.triangle_count();  // exactly enough: the same mesh
  EXPECT_EQ(loom::sweep_tube(c, 1.0, opt).mesh.triangle_count(), full.mesh.triangle_count());
  opt.max_triangles -= 1;
  EXPECT_THROW(loom::sweep_tube(c, 1.0, opt), std::invalid_argument);
  opt.end_caps = false;  // the caps' 2n triangles are not counted without caps
  opt.max_triangles = full.mesh.triangle_count() - 2 * static_cast<std::size_t>(full.circumferential);
  EXPECT_EQ(loom::sweep_tube(c, 1.0, opt).mesh.triangle_count(), opt.max_triangles);
}

// Regression: a route with 200,000 key points 10 nm apart made the
// render's tube sweep place at least four rings per knot span (15 GB, 50 s). A run of
// intervals that stays within half the axial tolerance of a straight tube is crossed in
// one step; the tube must stay within the chord tolerance of the exact one.
TEST(Sweep, DenseKeyPointsAreCrossedInFewRingsWithinTolerance) {
  auto route = [](int dense) {
    std::vector<Vec3> pts;
    auto at = [](double x) { return Vec3(x, 5.0 * std::sin(x / 30.0), 0.0); };
    for (double x = 0.0; x < 40.0; x += 10.0) pts.push_back(at(x));
    for (int i = 0; i <= dense; ++i) pts.push_back(at(40.0 + 2.0 * i / std::max(dense, 1)));
    for (double x = 50.0; x <= 100.0; x += 10.0) pts.push_back(at(x));
    return Centerline::interpolate(pts);
  };
  const Centerline packed = route(2000), sparse = route(1);
  const double r = 1.0, tol = 0.01;
  const loom::SweepResult rp = loom::sweep_tube(packed, r, {tol, true});
  const loom::SweepResult rs = loom::sweep_tube(sparse, r, {tol, true});
  EXPECT_LT(rp.rings, 2 * rs.rings) << "dense " << rp.rings << " sparse " << rs.rings;
  EXPECT_LE(worst_facet_error(packed, dense(packed, 40000), rp, r), tol);
}

TEST(Sweep, CanalSurfaceTouchesEveryMovingSphere) {
  // Every vertex of the canal surface lies on the envelope of the spheres S(s) of radius
  // r(s): min over s of (|v − C(s)| − r(s)) is 0 (on one sphere, outside all others).
  const Centerline c = s_curve();
  const double L = c.length();
  auto r = [](double s) { return 1.0 + 0.3 * std::sin(s / 3.0); };
  const double tol = 0.01;
  const loom::SweepResult res = loom::sweep_canal(c, r, {tol, true});
  EXPECT_TRUE(loom::analyse_topology(res.mesh).closed);
  EXPECT_GT(res.mesh.signed_volume(), 0.0);
  std::vector<double> ss;
  std::vector<Vec3> cs;
  for (int k = 0; k <= 8000; ++k) {
    ss.push_back(L * k / 8000.0);
    cs.push_back(c.position(c.parameter_at_length(ss.back())));
  }
  const std::size_t nv = static_cast<std::size_t>(res.rings) * res.circumferential;
  double worst = 0.0;
  for (std::size_t i = 0; i < nv; i += 7) {
    const Vec3& v = res.mesh.vertices[i];
    double best = std::numeric_limits<double>::infinity();
    std::size_t bk = 0;
    for (std::size_t k = 0; k < ss.size(); ++k) {
      const double f = (v - cs[k]).norm() - r(ss[k]);
      if (f < best) {
        best = f;
        bk = k;
      }
    }
    // Refine between the neighbouring samples.
    const double a = ss[bk == 0 ? 0 : bk - 1], b = ss[std::min(bk + 1, ss.size() - 1)];
    for (int k = 0; k <= 200; ++k) {
      const double s = a + (b - a) * k / 200.0;
      best = std::min(best, (v - c.position(c.parameter_at_length(s))).norm() - r(s));
    }
    worst = std::max(worst, std::abs(best));
  }
  EXPECT_LE(worst, 1e-4);
  // A radius law steeper than the centerline (|r'| ≥ 1) has no envelope.
  EXPECT_THROW(loom::sweep_canal(c, [](double s) { return 1.0 + 2.0 * s; }, {tol, true}), std::invalid_argument);
  EXPECT_THROW(loom::sweep_canal(c, [](double) { return -1.0; }, {tol, true}), std::invalid_argument);
  EXPECT_THROW(loom::sweep_canal(c, nullptr, {tol, true}), std::invalid_argument);
}

namespace {
/// Expects two sweep results to be the same, bit for bit.
void expect_same_sweep(const loom::SweepResult& a, const loom::SweepResult& b) {
  EXPECT_EQ(a.rings, b.rings);
  EXPECT_EQ(a.circumferential, b.circumferential);
  EXPECT_EQ(a.max_frame_turn, b.max_frame_turn);
  EXPECT_EQ(a.mesh.vertices, b.mesh.vertices);
  EXPECT_EQ(a.mesh.triangles, b.mesh.triangles);
  ASSERT_EQ(a.sections.size(), b.sections.size());
  for (std::size_t i = 0; i < a.sections.size(); ++i) {
    EXPECT_EQ(a.sections[i].u, b.sections[i].u);
    EXPECT_EQ(a.sections[i].normal, b.sections[i].normal);
  }
}
}  // namespace

TEST(Sweep, SweepIntoAReusedResultEqualsAFreshSweep) {
  // One SweepResult swept into again and again (longer, shorter, longer cable; caps on and
  // off; tube and canal) holds exactly what a new one would.
  const Centerline big = s_curve();
  const Centerline small = Centerline::interpolate({Vec3(0, 0, 0), Vec3(3, 1, 0), Vec3(6, 0, 2)});
  auto r = [](double s) { return 0.5 + 0.1 * std::sin(s); };
  loom::SweepResult reused;
  for (int round = 0; round < 2; ++round)
    for (const Centerline* c : {&big, &small, &big}) {
      for (bool caps : {true, false}) {
        const SweepOptions o{0.01, caps};
        loom::sweep_tube(*c, 1.0, o, reused);
        expect_same_sweep(reused, loom::sweep_tube(*c, 1.0, o));
        EXPECT_EQ(loom::analyse_topology(reused.mesh).closed, caps);
      }
      loom::sweep_canal(*c, r, {0.02, true}, reused);
      expect_same_sweep(reused, loom::sweep_canal(*c, r, {0.02, true}));
    }
  // The sections it reports are the ones tube_sections places, and ring i's vertices are
  // at its section's radius around its centre.
  loom::sweep_tube(big, 1.0, {0.01, true}, reused);
  const auto sec = loom::tube_sections(big, 1.0, {0.01, true});
  ASSERT_EQ(reused.sections.size(), sec.size());
  for (std::size_t i = 0; i < sec.size(); ++i) {
    EXPECT_EQ(reused.sections[i].point, sec[i].point);
    for (int j = 0; j < reused.circumferential; ++j)
      EXPECT_NEAR((reused.mesh.vertices[i * reused.circumferential + j] - sec[i].centre).norm(), 1.0, 1e-12);
  }
}

TEST(Sweep, RingStepsMeetTheAxialToleranceAndUseMostOfIt) {
  // Each step between rings keeps the outer-fibre sagitta κ(1 + rκ)(|C'|Δu)²/8 within half
  // the chord tolerance, κ and |C'| taken as their largest at the step's start, middle and
  // end (recomputed here from the curve) — and the step is not much shorter than that
  // allows (the step prediction from the curvature's derivative is close, not timid).
  const Centerline c = s_curve();
  const double r = 1.0, tol = 0.01, tol_axial = 0.5 * tol;
  const auto sec = loom::tube_sections(c, r, {tol, true});
  ASSERT_GT(sec.size(), 10u);
  std::vector<double> use;  // step / longest step allowed, curvature-limited steps only
  for (std::size_t i = 0; i + 1 < sec.size(); ++i) {
    const double a = sec[i].u, b = sec[i + 1].u, du = b - a;
    double kmax = 0.0, vmax = 0.0;
    for (double u : {a, 0.5 * (a + b), b}) {
      const Vec3 d1 = c.derivative(u, 1), d2 = c.derivative(u, 2);
      kmax = std::max(kmax, d1.cross(d2).norm() / std::pow(d1.norm(), 3));
      vmax = std::max(vmax, d1.norm());
    }
    const double k = kmax * (1.0 + r * kmax);
    const double sagitta = k * (vmax * du) * (vmax * du) / 8.0;
    EXPECT_LE(sagitta, tol_axial * (1.0 + 1e-6)) << "step " << i;
    const double allowed = std::sqrt(8.0 * tol_axial / k) / vmax;
    // Steps are also capped at a quarter of their knot span (and the last one at the end).
    const auto& bp = c.breakpoints();
    const std::size_t span = std::min<std::size_t>(std::upper_bound(bp.begin(), bp.end(), a) - bp.begin(), bp.size() - 1);
    if (i + 2 < sec.size() && allowed < 0.24 * (bp[span] - bp[span - 1])) use.push_back(du / allowed);
  }
  ASSERT_GT(use.size(), sec.size() / 2);
  std::sort(use.begin(), use.end());
  EXPECT_GT(use[use.size() / 10], 0.9);  // 90% of the steps use ≥ 90% of what is allowed
}

TEST(Sweep, DegenerateCentrelinesGiveClosedFiniteMeshes) {
  std::vector<Vec3> loop;
  for (int i = 0; i < 10; ++i) loop.emplace_back(10 * std::cos(i * M_PI / 5), 10 * std::sin(i * M_PI / 5), 0);
  loop.push_back(loop.front());
  const std::vector<Centerline> curves{
      Centerline::interpolate(loop),                                                          // closed loop
      Centerline::interpolate({Vec3(0, 0, 0), Vec3(5, 0, 0), Vec3(10, 0, 0), Vec3(5, 0, 0)}),  // reversal (fold)
      Centerline::polyline({Vec3(0, 0, 0), Vec3(5, 0, 0), Vec3(5, 5, 0)}),                     // kink
      Centerline::interpolate({Vec3(0, 0, 0), Vec3(0, 0, 0), Vec3(1, 1, 1)}),                   // repeated point
  };
  for (std::size_t i = 0; i < curves.size(); ++i) {
    const loom::SweepResult res = loom::sweep_tube(curves[i], 0.5, {0.01, true});
    EXPECT_EQ(loom::first_non_finite_vertex(res.mesh), -1) << "curve " << i;
    const loom::MeshTopology topo = loom::analyse_topology(res.mesh);
    EXPECT_TRUE(topo.closed) << "curve " << i;
    EXPECT_EQ(topo.degenerate_triangles, 0u) << "curve " << i;
    EXPECT_TRUE(std::isfinite(res.max_frame_turn));
    // The reversal and the kink bend more tightly than any radius: the tube folds there.
    EXPECT_EQ(res.folded, i == 1 || i == 2) << "curve " << i;
  }
}

TEST(Sweep, BranchJunctionHasNoGaps) {
  // Three segments meet at J; their tubes end there and a junction sphere closes the
  // wedges. Every point of the ball around J and of each solid tube near J must be inside
  // at least one of the closed meshes.
  const Vec3 J(1, 2, 3);
  const double r = 0.8, tol = 0.01;
  const std::vector<Vec3> dirs{Vec3(1, 0, 0), Vec3(-0.5, 0.8, 0.1).normalized(), Vec3(-0.3, -0.7, 0.6).normalized()};
  std::vector<Mesh> parts;
  std::vector<Centerline> segs;
  for (const Vec3& d : dirs) {
    InterpolationOptions o;
    o.start_tangent = d;
    segs.push_back(Centerline::interpolate({J, J + 3.0 * d, J + 6.0 * d + Vec3(0, 0, 1)}, o));
    parts.push_back(loom::sweep_tube(segs.back(), r, {tol, true}).mesh);
  }
  const loom::SweepResult sphere = loom::sweep_junction(J, r, {tol, true});
  EXPECT_TRUE(loom::analyse_topology(sphere.mesh).closed);
  EXPECT_GT(sphere.mesh.signed_volume(), 0.0);
  for (const Vec3& v : sphere.mesh.vertices) {
    EXPECT_GE((v - J).norm(), r);
    EXPECT_LE((v - J).norm(), r + tol);
  }
  parts.push_back(sphere.mesh);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  int checked = 0;
  for (int k = 0; k < 3000; ++k) {
    Vec3 q;
    if (k % 2 == 0) {  // in the ball
      Vec3 d;
      do d = Vec3(u(rng), u(rng), u(rng)); while (d.norm() > 1.0);
      q = J + r * d;
    } else {  // in a solid tube near J, at most r − tol from its axis
      const Centerline& c = segs[k % 3];
      const double s = 1.5 * r * std::abs(u(rng));
      const double uu = c.parameter_at_length(s);
      const Vec3 t = c.derivative(uu, 1).normalized();
      Vec3 d(u(rng), u(rng), u(rng));
      d -= d.dot(t) * t;
      if (d.norm() > 1.0) continue;
      q = c.position(uu) + (r - tol) * d;
    }
    bool inside = false;
    for (const Mesh& m : parts) inside = inside || winding_number(m, q) > 0.5;
    EXPECT_TRUE(inside) << "gap at " << q.transpose();
    ++checked;
  }
  EXPECT_GT(checked, 2000);
  // Without the junction sphere, the wedges between the tubes are gaps.
  parts.pop_back();
  int gaps = 0;
  for (int k = 0; k < 500; ++k) {
    Vec3 d;
    do d = Vec3(u(rng), u(rng), u(rng)); while (d.norm() > 1.0);
    bool inside = false;
    for (const Mesh& m : parts) inside = inside || winding_number(m, J + r * d) > 0.5;
    gaps += !inside;
  }
  EXPECT_GT(gaps, 0);
}

TEST(SweepStep, TubeRoundTripsThroughStep) {
  const Centerline c = s_curve();
  const double r = 0.7;
  const auto dir = std::filesystem::temp_directory_path() / ("loom_test_sweep_step_" + std::to_string(::getpid()));
  const auto path = dir / "tube.step";
  const loom::StepExportResult res = loom::write_tube_step(c, r, path, {0.01, true});
  ASSERT_EQ(res.status, loom::StepExportStatus::Written) << res.message;
  // Pappus: the exact tube has volume πr²L; our lateral face is within the chord tolerance.
  const double exact = M_PI * r * r * c.length();
  EXPECT_NEAR(res.volume, exact, 1e-4 * exact);
  STEPControl_Reader reader;
  ASSERT_EQ(reader.ReadFile(path.string().c_str()), IFSelect_RetDone);
  reader.TransferRoots();
  const TopoDS_Shape shape = reader.OneShape();
  int solids = 0;
  for (TopExp_Explorer ex(shape, TopAbs_SOLID); ex.More(); ex.Next()) ++solids;
  EXPECT_EQ(solids, 1);
  EXPECT_TRUE(BRepCheck_Analyzer(shape).IsValid());
  GProp_GProps props;
  BRepGProp::VolumeProperties(shape, props, 1e-7);
  EXPECT_NEAR(std::abs(props.Mass()), exact, 1e-4 * exact);
  EXPECT_FALSE(std::filesystem::exists(path.string() + ".tmp"));
  std::filesystem::remove_all(dir);
}

RC_GTEST_PROP(SweepProperty, RandomTubesAreClosedFiniteAndOnTheTube, ()) {
  const int n = *rc::gen::inRange(2, 8);
  const auto coords = *rc::gen::container<std::vector<int>>(3 * n, rc::gen::inRange(-100, 100));
  std::vector<Vec3> p;
  for (int i = 0; i < n; ++i) p.emplace_back(coords[3 * i] * 0.1, coords[3 * i + 1] * 0.1, coords[3 * i + 2] * 0.1);
  std::vector<Vec3> distinct;
  for (const Vec3& q : p)
    if (distinct.empty() || (q - distinct.back()).norm() > 1e-9) distinct.push_back(q);
  RC_PRE(distinct.size() >= 2u);
  const Centerline c = Centerline::interpolate(p);
  const double r = 0.05 + 0.01 * *rc::gen::inRange(0, 20);
  const auto sec = loom::tube_sections(c, r, {0.02, true});
  const loom::SweepResult res = loom::sweep_tube(c, r, {0.02, true});
  RC_ASSERT(loom::first_non_finite_vertex(res.mesh) == -1);
  RC_ASSERT(loom::analyse_topology(res.mesh).closed);
  RC_ASSERT(res.mesh.signed_volume() > 0.0);
  for (std::size_t i = 0; i < sec.size(); ++i) {
    RC_ASSERT((sec[i].point - c.position(sec[i].u)).norm() <= 1e-9 * (1 + c.length()));
    for (int j = 0; j < res.circumferential; ++j)
      RC_ASSERT(std::abs((res.mesh.vertices[i * res.circumferential + j] - sec[i].point).norm() - r) <= 1e-9);
    if (i > 0) {
      // Double reflection approximates the rotation-minimising frame with a local error of
      // O(turn³) (Wang et al. 2008), so the normal may turn that much more than the tangent.
      const double turn = angle(sec[i - 1].tangent, sec[i].tangent);
      RC_ASSERT(angle(sec[i - 1].normal, sec[i].normal) <= turn + turn * turn * turn + 1e-9);
    }
  }
}
