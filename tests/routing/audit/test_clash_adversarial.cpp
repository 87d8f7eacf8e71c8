// Adversarial scenes for the certified clash audit (DESIGN §4–§5): each test builds a
// scene aimed at one way the audit could miss a clash, report a false one, split or merge
// a stretch, or depend on the thread count, and checks the report against a closed-form
// answer or a small brute-force oracle (dense samples, written here for the scene at hand).
// Inputs are printed at full precision (%.17g) so that a failure replays.
#include "routing/audit/clash_check.hpp"
#include "index/index_test_meshes.hpp"

#include "core/mesh.hpp"
#include "index/embree_index.hpp"
#include "index/triangle_distance.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

namespace loom {
namespace {

constexpr double kR = 1.0;     // cable radius of most scenes
constexpr double kTol = 0.01;  // certified tolerance of most scenes (r / 100)

std::string g17(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}
std::string g17(const Vec3& v) { return "(" + g17(v.x()) + ", " + g17(v.y()) + ", " + g17(v.z()) + ")"; }

using testmesh::box_part;

CableInput cable(const std::string& id, Centerline curve, double r = kR) {
  CableInput c;
  c.id = id;
  c.curve = std::move(curve);
  c.radius = r;
  return c;
}

CableInput straight(const std::string& id, const Vec3& a, const Vec3& b, double r = kR) {
  return cable(id, Centerline::polyline({a, b}), r);
}

/// Clamped uniform cubic B-spline with the given control points (≥ 4).
Centerline cubic(const std::vector<Vec3>& cps) {
  const int n = static_cast<int>(cps.size());
  std::vector<double> knots(4, 0.0);
  for (int i = 1; i < n - 3; ++i) knots.push_back(i);
  for (int i = 0; i < 4; ++i) knots.push_back(n - 3);
  return Centerline(3, knots, cps);
}

ClashResult audit(const std::vector<CableInput>& cables, const std::vector<Part>& parts, double tol = kTol,
                  int threads = 2, double rel_error = -1.0) {
  const EmbreeIndex index(parts);
  ClashRequest req;
  req.tolerance = tol;
  req.threads = threads;
  if (rel_error >= 0.0) req.distance_rel_error = rel_error;
  return check_clashes(cables, parts, &index, req);
}

std::vector<const ClashEntry*> entries(const ClashResult& r, ClashKind k, int cable, int other_or_part) {
  std::vector<const ClashEntry*> out;
  for (const auto& e : r.clashes)
    if (e.kind == k && e.cable == cable && (k == ClashKind::CableStructure ? e.part : e.other) == other_or_part)
      out.push_back(&e);
  return out;
}

std::string describe(const ClashResult& r) {
  std::string s;
  for (const auto& e : r.clashes)
    s += std::string(clash_kind_name(e.kind)) + " cable " + std::to_string(e.cable) + " part " +
         std::to_string(e.part) + " other " + std::to_string(e.other) + " clearance " + g17(e.clearance) + " s " +
         g17(e.s) + " t " + g17(e.s_other) + " [" + g17(e.s_begin) + ", " + g17(e.s_end) + "]" +
         (e.inside ? " inside" : "") + "\n";
  return s.empty() ? "(no clashes)\n" : s;
}

/// A far-away part: the certified audit needs an index, the scene's findings are elsewhere.
std::vector<Part> far_part() { return {box_part("far", {1000, 1000, 1000}, {1001, 1001, 1001})}; }

/// Brute-force self oracle: smallest |C(s) − C(t)| − 2r over samples h apart in arc length
/// with |s − t| ≥ π r (error ≤ h: each sample is within h/2 of any curve point between).
double oracle_self(const Centerline& c, double r, double h) {
  const auto sp = c.sample_by_arc_length(h);
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < sp.size(); ++i)
    for (std::size_t j = i + 1; j < sp.size(); ++j)
      if (sp[j].first - sp[i].first >= M_PI * r) best = std::min(best, (sp[i].second - sp[j].second).norm());
  return best - 2.0 * r;
}

// ---------------------------------------------------------------------------------------
// Self-interference at the |s − t| ≥ π r boundary.

/// A V of two straight legs of length `leg` meeting at the origin at angle theta, in z = 0.
Centerline v_shape(double theta, double leg1, double leg2) {
  const Vec3 d1(1, 0, 0), d2(std::cos(theta), std::sin(theta), 0);
  return Centerline::polyline({leg1 * d1, Vec3::Zero(), leg2 * d2});
}

// Points a and b from the corner of a V (angle θ) are |s − t| = a + b apart along the
// cable and g·sin(θ/2) apart at best for a + b = g: the deepest self contact the rule
// allows is at g = π r exactly, clearance π r sin(θ/2) − 2 r. For θ = 60° that is −0.43 r,
// a clash of nearly half the radius that lies only next to the excused band.
TEST(ClashAdversarial, SelfContactOfAVeeIsDeepestAtThePiRBoundary) {
  for (double theta_deg : {30.0, 45.0, 60.0, 70.0}) {
    for (double leg1 : {10.0, 9.3, 7.77}) {
      const double theta = theta_deg * M_PI / 180.0;
      const double truth = M_PI * kR * std::sin(0.5 * theta) - 2.0 * kR;
      const CableInput c = cable("V", v_shape(theta, leg1 * kR, 10.0 * kR));
      const ClashResult r = audit({c}, far_part());
      const auto self = entries(r, ClashKind::Self, 0, 0);
      const std::string in = "theta " + g17(theta) + " leg1 " + g17(leg1) + " truth " + g17(truth) + "\n" + describe(r);
      ASSERT_EQ(self.size(), 1u) << in;
      EXPECT_NEAR(self[0]->clearance, truth, kTol) << in;
      EXPECT_GE(std::abs(self[0]->s_other - self[0]->s), M_PI * kR - kTol) << in;
    }
  }
  // At 90° the same bound is π r sin 45° − 2 r = +0.22 r: no self contact.
  const ClashResult clear = audit({cable("V", v_shape(0.5 * M_PI, 10.0, 10.0))}, far_part());
  EXPECT_TRUE(entries(clear, ClashKind::Self, 0, 0).empty()) << describe(clear);
}

// A smooth hairpin (a cubic whose control polygon turns back on itself): the oracle is a
// dense brute force over sample pairs with |s − t| ≥ π r.
TEST(ClashAdversarial, SmoothHairpinsMatchTheSelfOracle) {
  for (double gap : {0.3, 1.0, 1.8, 2.6, 3.4}) {
    const Centerline c = cubic({{0, 0, 0}, {6, 0, 0}, {9, 0, 0}, {10, gap / 2, 0}, {9, gap, 0}, {6, gap, 0}, {0, gap, 0}});
    const double oracle_err = 0.005;
    const double truth = oracle_self(c, kR, oracle_err);
    const ClashResult r = audit({cable("H", c)}, far_part());
    const auto self = entries(r, ClashKind::Self, 0, 0);
    const std::string in = "gap " + g17(gap) + " truth " + g17(truth) + "\n" + describe(r);
    if (truth < -kTol - oracle_err) {
      ASSERT_EQ(self.size(), 1u) << in;
      EXPECT_NEAR(self[0]->clearance, truth, kTol + oracle_err) << in;
    } else if (truth > kTol + oracle_err) {
      EXPECT_TRUE(self.empty()) << in;
    }
  }
}

// Random zigzags (polylines with sharp corners of any angle, some folding back, and
// cubics through the same points) against the brute-force self oracle, with no margin
// beyond the tolerance and the oracle's own error.
TEST(ClashAdversarial, RandomFoldsMatchTheSelfOracle) {
  std::mt19937 rng(20261127);
  std::uniform_real_distribution<double> U(0, 1);
  const double oracle_err = 0.01;
  int judged = 0, clashes = 0;
  for (int trial = 0; trial < 24; ++trial) {
    std::vector<Vec3> pts{Vec3::Zero()};
    for (int k = 0; k < 4; ++k) {
      const double len = 1.5 + 4.0 * U(rng), az = 2 * M_PI * U(rng), el = 0.3 * (U(rng) - 0.5);
      pts.push_back(pts.back() + len * Vec3(std::cos(az) * std::cos(el), std::sin(az) * std::cos(el), std::sin(el)));
    }
    for (const bool smooth : {false, true}) {
      const Centerline c = smooth ? Centerline::interpolate(pts) : Centerline::polyline(pts);
      const double truth = oracle_self(c, kR, oracle_err);
      const ClashResult r = audit({cable("Z", c)}, far_part());
      const auto self = entries(r, ClashKind::Self, 0, 0);
      std::string in = "trial " + std::to_string(trial) + (smooth ? " cubic" : " polyline") + " through";
      for (const Vec3& p : pts) in += " " + g17(p);
      in += "\ntruth " + g17(truth) + "\n" + describe(r);
      double reported = std::numeric_limits<double>::infinity();
      for (const ClashEntry* e : self) reported = std::min(reported, e->clearance);
      if (truth < -kTol - oracle_err) {
        ++judged;
        ++clashes;
        EXPECT_NEAR(reported, truth, kTol + oracle_err) << in;
      } else if (truth > kTol + oracle_err) {
        ++judged;
        EXPECT_TRUE(self.empty()) << in;
      }
    }
  }
  EXPECT_GT(clashes, 5) << "the scenes should fold onto themselves often";
  EXPECT_GT(judged, 30);
}

// ---------------------------------------------------------------------------------------
// Inside closed parts.

// A keep-out envelope around a box (both closed, one inside the other): a cable through
// both is in contact with each over one contiguous stretch, so one entry per part.
TEST(ClashAdversarial, NestedClosedPartsGiveOneStretchEach) {
  const std::vector<Part> parts{box_part("envelope", {-10, -10, -10}, {10, 10, 10}, PartRole::KeepOut),
                                box_part("box", {-4, -4, -4}, {4, 4, 4})};
  const std::vector<Part> reversed{parts[1], parts[0]};
  for (const auto* ps : {&parts, &reversed}) {
    const int env = ps == &parts ? 0 : 1, box = 1 - env;
    const ClashResult r = audit({straight("C", {-30, 0.3, 0.2}, {30, 0.3, 0.2})}, *ps);
    const auto e_env = entries(r, ClashKind::CableStructure, 0, env);
    const auto e_box = entries(r, ClashKind::CableStructure, 0, box);
    ASSERT_EQ(e_env.size(), 1u) << describe(r);
    ASSERT_EQ(e_box.size(), 1u) << describe(r);
    EXPECT_DOUBLE_EQ(e_env[0]->clearance, -kR);
    EXPECT_DOUBLE_EQ(e_box[0]->clearance, -kR);
    EXPECT_NEAR(e_env[0]->s_begin, 20.0 - kR, 2 * kR) << describe(r);
    EXPECT_NEAR(e_env[0]->s_end, 40.0 + kR, 2 * kR) << describe(r);
    EXPECT_NEAR(e_box[0]->s_begin, 26.0 - kR, 2 * kR) << describe(r);
    EXPECT_NEAR(e_box[0]->s_end, 34.0 + kR, 2 * kR) << describe(r);
  }
}

// A cable that starts and ends inside two overlapping closed parts, far from both surfaces:
// its axis is inside each, so it clashes with each (clearance −r).
TEST(ClashAdversarial, CableInsideTwoOverlappingPartsClashesWithBoth) {
  const std::vector<Part> parts{box_part("a", {-100, -100, -100}, {60, 100, 100}),
                                box_part("b", {-60, -100, -100}, {100, 100, 100})};
  for (int threads : {1, 2}) {
    const ClashResult r = audit({straight("C", {-20, 0, 0}, {20, 0, 0})}, parts, kTol, threads);
    for (int p = 0; p < 2; ++p) {
      const auto e = entries(r, ClashKind::CableStructure, 0, p);
      ASSERT_EQ(e.size(), 1u) << "part " << p << "\n" << describe(r);
      EXPECT_TRUE(e[0]->inside);
      EXPECT_DOUBLE_EQ(e[0]->clearance, -kR);
    }
  }
}

// The seed's discrete method on the same scene, through the index and by brute force: a
// sample inside two closed parts clashes with each (it named the first only).
TEST(ClashAdversarial, DiscreteSamplesInsideTwoOverlappingPartsClashWithBoth) {
  const std::vector<Part> parts{box_part("a", {-100, -100, -100}, {60, 100, 100}),
                                box_part("b", {-60, -100, -100}, {100, 100, 100})};
  const EmbreeIndex index(parts);
  for (const bool use_index : {true, false}) {
    ClashRequest req;
    req.method = ClashMethod::Discrete;
    req.use_index = use_index;
    const ClashResult r = check_clashes({straight("C", {-20, 0, 0}, {20, 0, 0})}, parts,
                                        use_index ? &index : nullptr, req);
    for (int p = 0; p < 2; ++p) {
      const auto e = entries(r, ClashKind::CableStructure, 0, p);
      ASSERT_EQ(e.size(), 1u) << "part " << p << (use_index ? " (index)" : " (brute force)") << "\n" << describe(r);
      EXPECT_TRUE(e[0]->inside);
    }
  }
}

// A cable that ends deep inside a part: the stretch runs to the cable's end (to one chord).
TEST(ClashAdversarial, StretchEndingDeepInsideAPartEndsAtTheCableEnd) {
  const std::vector<Part> parts{box_part("hull", {0, -200, -200}, {400, 200, 200})};
  const ClashResult r = audit({straight("C", {-10, 0, 0}, {300, 0, 0})}, parts);
  ASSERT_EQ(r.clashes.size(), 1u) << describe(r);
  EXPECT_NEAR(r.clashes[0].s_begin, 10.0 - kR, 2 * kR) << describe(r);
  EXPECT_NEAR(r.clashes[0].s_end, 310.0, 2 * kR) << describe(r);
  // And one starting deep inside: the stretch starts at 0.
  const ClashResult r2 = audit({straight("C", {300, 0, 0}, {-10, 0, 0})}, parts);
  ASSERT_EQ(r2.clashes.size(), 1u) << describe(r2);
  EXPECT_NEAR(r2.clashes[0].s_begin, 0.0, 2 * kR) << describe(r2);
  EXPECT_NEAR(r2.clashes[0].s_end, 300.0 + kR, 2 * kR) << describe(r2);
}

// Two closed boxes sharing a face; the cable passes from one into the other through it:
// each box is in contact over one stretch (the axis inside it). A cable whose axis lies in
// the shared face (strictly inside neither) touches both at distance 0.
TEST(ClashAdversarial, CrossingASharedFaceIsOneStretchPerBox) {
  const std::vector<Part> parts{box_part("left", {-10, -5, -5}, {0, 5, 5}), box_part("right", {0, -5, -5}, {10, 5, 5})};
  const ClashResult r = audit({straight("C", {-30, 0.25, 0.5}, {30, 0.25, 0.5})}, parts);
  for (int p = 0; p < 2; ++p) {
    const auto e = entries(r, ClashKind::CableStructure, 0, p);
    ASSERT_EQ(e.size(), 1u) << describe(r);
    EXPECT_DOUBLE_EQ(e[0]->clearance, -kR);
  }
  // Axis in the shared face itself (inside neither strictly): distance 0 to both.
  const ClashResult on = audit({straight("C", {0, -30, 0.5}, {0, 30, 0.5})}, parts);
  for (int p = 0; p < 2; ++p) {
    const auto e = entries(on, ClashKind::CableStructure, 0, p);
    ASSERT_EQ(e.size(), 1u) << describe(on);
    EXPECT_NEAR(e[0]->clearance, -kR, kTol);
  }
}

// An open box (its top face removed): no inside. A cable entering through the bottom face
// and ending in the middle clashes once, where it crosses the face (−r, not inside); one
// passing 2·tol clear of the rim's edge is clear and one 2·tol into it is not.
TEST(ClashAdversarial, OpenMeshHasNoInsideButItsSurfaceCounts) {
  Part open = box_part("open", {-10, -10, -10}, {10, 10, 10});
  Mesh& m = open.mesh;
  // Drop the two triangles of the face z = 10.
  const std::size_t n_before = m.triangles.size();
  std::vector<std::array<std::uint32_t, 3>> kept;
  for (std::size_t t = 0; t < n_before; ++t) {
    const auto c = m.corners(t);
    if (!(c[0].z() == 10 && c[1].z() == 10 && c[2].z() == 10)) kept.push_back(m.triangles[t]);
  }
  m.triangles = kept;
  ASSERT_EQ(m.triangles.size(), n_before - 2);
  open.closed = analyse_topology(m).closed;
  ASSERT_FALSE(open.closed);
  const std::vector<Part> parts{open};
  const ClashResult mid = audit({straight("C", {-5, 0, -30}, {-5, 0, 5})}, parts);
  // It crosses the bottom face z = −10: one stretch there, nothing from "inside".
  const auto e = entries(mid, ClashKind::CableStructure, 0, 0);
  ASSERT_EQ(e.size(), 1u) << describe(mid);
  EXPECT_NEAR(e[0]->s, 20.0, kR + kTol) << describe(mid);
  EXPECT_FALSE(e[0]->inside);
  EXPECT_NEAR(e[0]->clearance, -kR, kTol);
  // Parallel to the rim x = 10 edge at z = 10, outside: clear by +2 tol, then −2 tol.
  for (double delta : {2 * kTol, -2 * kTol}) {
    const double off = (kR + delta) / std::sqrt(2.0);
    const ClashResult rim = audit({straight("C", {10 + off, -30, 10 + off}, {10 + off, 30, 10 + off})}, parts);
    EXPECT_EQ(rim.clashes.size(), delta < 0 ? 1u : 0u) << "delta " << g17(delta) << "\n" << describe(rim);
  }
}

// Key points exactly on a box's corners and edges: the axis enters at one corner, runs
// along the diagonal and leaves at the opposite one; another runs along an edge (distance 0,
// never strictly inside). One stretch each, at −r.
TEST(ClashAdversarial, AxisThroughCornersAndAlongAnEdge) {
  const std::vector<Part> parts{box_part("box", {0, 0, 0}, {10, 10, 10})};
  const ClashResult diag = audit({cable("D", Centerline::polyline({{-5, -5, -5}, {0, 0, 0}, {10, 10, 10}, {15, 15, 15}}))}, parts);
  const auto d = entries(diag, ClashKind::CableStructure, 0, 0);
  ASSERT_EQ(d.size(), 1u) << describe(diag);
  EXPECT_DOUBLE_EQ(d[0]->clearance, -kR);
  EXPECT_TRUE(d[0]->inside) << describe(diag);
  const ClashResult edge = audit({cable("E", Centerline::polyline({{-5, 0, 10}, {0, 0, 10}, {10, 0, 10}, {15, 0, 10}}))}, parts);
  const auto e = entries(edge, ClashKind::CableStructure, 0, 0);
  ASSERT_EQ(e.size(), 1u) << describe(edge);
  EXPECT_NEAR(e[0]->clearance, -kR, kTol);
}

// ---------------------------------------------------------------------------------------
// Clearance and bends.

// Clearance violations: a part with its own clearance 2 beside a cable whose surface is
// 2 ± 2·tol away.
TEST(ClashAdversarial, ClearanceBandEdges) {
  for (double delta : {-2 * kTol, 2 * kTol}) {
    std::vector<Part> parts{box_part("box", {0, 0, 0}, {10, 10, 10})};
    parts[0].clearance = 2.0;
    const double z = 10 + kR + 2.0 + delta;
    const ClashResult r = audit({straight("C", {-20, 5, z}, {30, 5, z})}, parts);
    EXPECT_TRUE(r.clashes.empty()) << describe(r);
    ASSERT_EQ(r.violations.size(), delta < 0 ? 1u : 0u) << "delta " << g17(delta);
    if (delta < 0) {
      EXPECT_NEAR(r.violations[0].value, 2.0 + delta, kTol);
      EXPECT_DOUBLE_EQ(r.violations[0].limit, 2.0);
    }
  }
}

// A cable leaving a connector on a box face along its normal: the box is excused over the
// straight exit [0, s_end] only. Beyond it the clearance to the box is s − r while below the
// required clearance: a violation whose smallest value is s_end − r, just past the exit.
TEST(ClashAdversarial, ClearanceRightAfterAnAttachedExit) {
  for (double s_end : {2.0, 3.0, 2.5}) {
    const std::vector<Part> parts{box_part("box", {0, 0, 0}, {10, 10, 10})};
    CableInput c = straight("C", {10, 5, 5}, {40, 5, 5});
    c.attachments = {{0, 0.0, s_end, "J1"}};
    const double required = 3.0;
    const EmbreeIndex index(parts);
    ClashRequest req;
    req.tolerance = kTol;
    req.routing_clearance = required;
    req.threads = 1;
    const ClashResult r = check_clashes({c}, parts, &index, req);
    const std::string in = "s_end " + g17(s_end);
    EXPECT_TRUE(r.clashes.empty()) << in << "\n" << describe(r);
    ASSERT_EQ(r.violations.size(), 1u) << in;
    EXPECT_NEAR(r.violations[0].value, s_end - kR, kTol) << in;
    EXPECT_NEAR(r.violations[0].s, s_end, kTol) << in;
  }
}

// Bend radius of a cubic with a near-cusp (control points almost folding back): the
// smallest radius against the analytic curvature |C'×C''|/|C'|³ sampled densely in u.
TEST(ClashAdversarial, BendRadiusAtANearCusp) {
  for (double lift : {1.0, 0.1, 0.01}) {
    const Centerline c = cubic({{0, 0, 0}, {10, 0, 0}, {5, lift, 0}, {12, 2 * lift, 0}, {20, 0, 0}});
    double oracle = std::numeric_limits<double>::infinity();
    const int n = 400000;
    for (int i = 0; i <= n; ++i) {
      const double u = c.u_min() + (c.u_max() - c.u_min()) * i / n;
      const Vec3 d1 = c.derivative(u, 1), d2 = c.derivative(u, 2);
      const double sp = d1.norm();
      if (sp > 0) oracle = std::min(oracle, sp * sp * sp / d1.cross(d2).norm());
    }
    CableInput in = cable("K", c);
    in.min_bend_radius = 1e6;
    const ClashResult r = audit({in}, far_part());
    ASSERT_EQ(r.violations.size(), 1u);
    const double got = r.violations[0].value;
    EXPECT_LE(got, oracle * (1 + 1e-6) + 1e-12) << "lift " << g17(lift) << " oracle " << g17(oracle);
    EXPECT_GE(got, oracle * (1 - 1e-2) - 1e-9) << "lift " << g17(lift) << " oracle " << g17(oracle);
  }
}

// ---------------------------------------------------------------------------------------
// Scale and tolerance.

/// A box, a cable 3·tol into its top face and one 3·tol clear of its side, all scaled by
/// `scale` about the origin and moved by `shift`.
struct ScaledScene {
  std::vector<Part> parts;
  std::vector<CableInput> cables;
};
ScaledScene scaled_scene(double scale, const Vec3& shift) {
  auto at = [&](double x, double y, double z) { return Vec3(scale * Vec3(x, y, z) + shift); };
  ScaledScene s;
  s.parts.push_back(box_part("box", at(0, 0, 0), at(10, 10, 10)));
  const double pen = 10 + kR - 3 * kTol, clr = 10 + kR + 3 * kTol;
  s.cables.push_back(straight("in", at(-20, 5, pen), at(30, 5, pen), scale * kR));
  s.cables.push_back(straight("out", at(clr, -20, 5), at(clr, 30, 5), scale * kR));
  // Two cables crossing 3·tol into each other, and two crossing 3·tol apart.
  s.cables.push_back(straight("x1", at(-20, 30, 0), at(20, 30, 0), scale * kR));
  s.cables.push_back(straight("x2", at(0, 20, 2 * kR - 3 * kTol), at(0, 40, 2 * kR - 3 * kTol), scale * kR));
  s.cables.push_back(straight("x3", at(-20, 50, 0), at(20, 50, 0), scale * kR));
  s.cables.push_back(straight("x4", at(0, 45, 2 * kR + 3 * kTol), at(0, 60, 2 * kR + 3 * kTol), scale * kR));
  return s;
}

TEST(ClashAdversarial, FindingsDoNotDependOnSceneScaleOrPlace) {
  for (const auto& [scale, shift] : {std::pair{1.0, Vec3(0, 0, 0)}, std::pair{1e-3, Vec3(0, 0, 0)},
                                     std::pair{1e-3, Vec3(-2.5, 7.25, 1.0)}, std::pair{1.0, Vec3(1e7, -3e6, 5e6)},
                                     std::pair{1e3, Vec3(0, 0, 0)}}) {
    const ScaledScene s = scaled_scene(scale, shift);
    const std::string in = "scale " + g17(scale) + " shift " + g17(shift);
    ClashResult r;
    try {
      r = audit(s.cables, s.parts, scale * kTol);
    } catch (const std::invalid_argument& e) {
      // Refusing a tolerance the index cannot certify is a correct answer; a wrong report is not.
      std::printf("%s: refused: %s\n", in.c_str(), e.what());
      continue;
    }
    ASSERT_EQ(r.clashes.size(), 2u) << in << "\n" << describe(r);
    const auto in_box = entries(r, ClashKind::CableStructure, 0, 0);
    ASSERT_EQ(in_box.size(), 1u) << in << "\n" << describe(r);
    EXPECT_NEAR(in_box[0]->clearance, -3 * kTol * scale, kTol * scale) << in;
    const auto x = entries(r, ClashKind::CableCable, 2, 3);
    ASSERT_EQ(x.size(), 1u) << in << "\n" << describe(r);
    EXPECT_NEAR(x[0]->clearance, -3 * kTol * scale, kTol * scale) << in;
  }
}

// A tolerance above the radius: still nothing reported beyond +tol, nothing missed beyond −tol.
TEST(ClashAdversarial, ToleranceLargerThanTheRadius) {
  const double tol = 1.5 * kR;
  const std::vector<Part> parts{box_part("box", {0, 0, 0}, {10, 10, 10})};
  // Structure: clear by 2·tol → nothing; inside → found.
  const ClashResult far = audit({straight("C", {-20, 5, 10 + kR + 2 * tol}, {30, 5, 10 + kR + 2 * tol})}, parts, tol);
  EXPECT_TRUE(far.clashes.empty()) << describe(far);
  const ClashResult in = audit({straight("C", {-20, 5, 5}, {30, 5, 5})}, parts, tol);
  EXPECT_EQ(entries(in, ClashKind::CableStructure, 0, 0).size(), 1u) << describe(in);
  // Cable–cable: clearance −1.8 r < −tol reported; +2·tol not.
  const std::vector<Part> none = far_part();
  const ClashResult deep = audit({straight("A", {0, 0, 0}, {20, 0, 0}), straight("B", {10, -10, 0.2 * kR}, {10, 10, 0.2 * kR})}, none, tol);
  EXPECT_EQ(entries(deep, ClashKind::CableCable, 0, 1).size(), 1u) << describe(deep);
  const double z = 2 * kR + 2 * tol;
  const ClashResult apart = audit({straight("A", {0, 0, 0}, {20, 0, 0}), straight("B", {10, -10, z}, {10, 10, z})}, none, tol);
  EXPECT_TRUE(apart.clashes.empty()) << describe(apart);
}

// A slab thinner than the tolerance: crossed → clash at −r; passed at +2·tol → nothing.
TEST(ClashAdversarial, PartThinnerThanTheTolerance) {
  const double t = 0.1 * kTol;
  const std::vector<Part> parts{box_part("foil", {5, -10, -10}, {5 + t, 10, 10})};
  const ClashResult cross = audit({straight("C", {0, 1, 2}, {20, 1, 2})}, parts);
  const auto e = entries(cross, ClashKind::CableStructure, 0, 0);
  ASSERT_EQ(e.size(), 1u) << describe(cross);
  EXPECT_NEAR(e[0]->clearance, -kR, kTol);
  EXPECT_NEAR(e[0]->s, 5.0, kR);
  const double x = 5 + t + kR + 2 * kTol;
  EXPECT_TRUE(audit({straight("C", {x, -20, 0}, {x, 20, 0})}, parts).clashes.empty());
  const double y = 5 + t + kR - 2 * kTol;
  EXPECT_EQ(audit({straight("C", {y, -20, 0}, {y, 20, 0})}, parts).clashes.size(), 1u);
}

// Cables shorter than 2r and than π r: one chord; structure findings still exact, no self.
TEST(ClashAdversarial, VeryShortCables) {
  const std::vector<Part> parts{box_part("box", {0, 0, 0}, {10, 10, 10})};
  for (double len : {1e-6, 0.1 * kR, 1.5 * kR, 3.0 * kR}) {
    for (double delta : {-3 * kTol, 3 * kTol}) {
      const double z = 10 + kR + delta;
      const ClashResult r = audit({straight("S", {5, 5, z}, {5 + len, 5, z})}, parts);
      EXPECT_EQ(r.clashes.size(), delta < 0 ? 1u : 0u) << "len " << g17(len) << " delta " << g17(delta) << "\n"
                                                      << describe(r);
    }
    // A short cable deep inside the box.
    const ClashResult in = audit({straight("S", {5, 5, 5}, {5 + len, 5, 5})}, parts);
    ASSERT_EQ(in.clashes.size(), 1u) << "len " << g17(len);
    EXPECT_TRUE(in.clashes[0].inside);
  }
}

// Contacts exactly at chord vertices (s = 2 r k on a straight cable) and at the cable's ends.
TEST(ClashAdversarial, ContactAtAChordVertexOrAnEnd) {
  for (double x : {0.0, 2 * kR, 4 * kR, 20 * kR}) {
    for (double delta : {-3 * kTol, 3 * kTol}) {
      // A thin rod along z whose face is at y = r + delta, its edge at x.
      const std::vector<Part> parts{box_part("rod", {x, kR + delta, -20}, {x + 0.2, kR + delta + 0.2, 20})};
      const ClashResult r = audit({straight("C", {0, 0, 0}, {20 * kR, 0, 0})}, parts);
      const std::string in = "x " + g17(x) + " delta " + g17(delta) + "\n" + describe(r);
      ASSERT_EQ(r.clashes.size(), delta < 0 ? 1u : 0u) << in;
      if (delta < 0) {
        EXPECT_NEAR(r.clashes[0].clearance, delta, kTol) << in;
      }
    }
  }
}

// ---------------------------------------------------------------------------------------
// Cable–cable.

// Two straight cables crossing at a tiny angle, 3·tol into each other: one long contact
// stretch, deepest at the crossing (closed form), one entry; apart by 3·tol: nothing.
TEST(ClashAdversarial, CablesCrossingAtATinyAngle) {
  for (double angle : {1e-2, 1e-3, 1e-5}) {
    for (double delta : {-3 * kTol, 3 * kTol}) {
      const double z = 2 * kR + delta, half = 30.0;
      const Vec3 d(std::cos(angle), std::sin(angle), 0);
      const Vec3 centre(10.37, 0, z);
      const ClashResult r =
          audit({straight("A", {-20, 0, 0}, {40, 0, 0}), straight("B", centre - half * d, centre + half * d)}, far_part());
      const auto e = entries(r, ClashKind::CableCable, 0, 1);
      const std::string in = "angle " + g17(angle) + " delta " + g17(delta) + "\n" + describe(r);
      if (delta < 0) {
        ASSERT_EQ(e.size(), 1u) << in;
        EXPECT_NEAR(e[0]->clearance, delta, kTol) << in;
      } else {
        EXPECT_TRUE(e.empty()) << in;
      }
    }
  }
}

// B runs beside straight A and dips into it three times (−0.1 r), clear by +0.3 r between:
// three entries, each at its dip's deepest point (dense oracle of B's distance to A's axis).
TEST(ClashAdversarial, ParallelContactsSplitIntoOneEntryPerStretch) {
  std::vector<Vec3> cps;
  const double hi = 2 * kR + 0.3 * kR, lo = 2 * kR - 0.1 * kR;
  for (int i = 0; i <= 24; ++i) cps.emplace_back(2.0 * i, 0, (i % 8 == 4) ? lo - 0.35 * kR : hi + 0.2 * kR);
  const Centerline cb = cubic(cps);
  // Oracle: distance of B's points to A's axis (the x axis), sampled densely.
  std::vector<std::pair<double, double>> dips;  // (s, clearance) of each contact stretch's deepest
  bool in_contact = false;
  for (const auto& [s, p] : cb.sample_by_arc_length(0.001)) {
    const double cl = std::hypot(p.y(), p.z()) - 2 * kR;
    if (cl < 0) {
      if (!in_contact) dips.push_back({s, cl});
      if (cl < dips.back().second) dips.back() = {s, cl};
    }
    in_contact = cl < 0;
  }
  ASSERT_EQ(dips.size(), 3u);
  for (const auto& d : dips) ASSERT_LT(d.second, -0.05);
  for (int threads : {1, 2}) {
    const ClashResult r = audit({straight("A", {-5, 0, 0}, {55, 0, 0}), cable("B", cb)}, far_part(), kTol, threads);
    const auto e = entries(r, ClashKind::CableCable, 0, 1);
    ASSERT_EQ(e.size(), 3u) << describe(r);
    for (std::size_t k = 0; k < 3; ++k) {
      EXPECT_NEAR(e[k]->clearance, dips[k].second, kTol) << describe(r);
      EXPECT_NEAR(e[k]->s_other, dips[k].first, 0.5) << describe(r);  // the bottom of a shallow dip is flat
    }
  }
}

// Two cables bundled in one harness segment over [0, 40] (contacts excused there) that then
// part and cross again outside it: the crossing is reported, the bundle is not.
TEST(ClashAdversarial, BundledCablesCrossingOutsideTheirSegment) {
  CableInput a = cable("A", Centerline::polyline({{0, 0, 0}, {40, 0, 0}, {60, 0, 0}}));
  CableInput b = cable("B", Centerline::polyline({{0, 1.5, 0}, {40, 1.5, 0}, {50, 10, 0}, {50, 10, 1.5}, {50, -10, 1.5}}));
  a.segments = {{3, 0.0, 40.0}, {4, 40.0, 60.0}};
  const double lb = b.curve.length();
  b.segments = {{3, 0.0, 40.0}, {5, 40.0, lb}};
  // They part at branch point J, where both may touch (a breakout).
  a.junctions = {{"J", Vec3(40, 0.75, 0), 4.0}};
  b.junctions = a.junctions;
  const ClashResult r = audit({a, b}, far_part());
  const auto e = entries(r, ClashKind::CableCable, 0, 1);
  ASSERT_EQ(e.size(), 1u) << describe(r);
  EXPECT_NEAR(e[0]->s, 50.0, kTol) << describe(r);
  EXPECT_NEAR(e[0]->clearance, 1.5 - 2 * kR, kTol) << describe(r);
}

// Two cables bundled in one segment part at a branch point J at a shallow angle, still in
// contact beyond J's excused ball: the contact outside the ball is a clash, deepest where
// it leaves the ball. Oracle: dense sample pairs, excused by the same rule (both in one
// segment, or both within the junction radius of J).
// Without a junction (radius 0 here) the contact right after the bundle segment counts.
TEST(ClashAdversarial, ContactJustOutsideAJunctionMatchesTheOracle) {
  for (double deg : {3.0, 5.0, 10.0}) {
    for (double jr : {0.0, 2.0, 3.0}) {
      const double slope = std::tan(deg * M_PI / 180.0);
      // A starts 0.37 earlier: its chords do not end where the segment does.
      CableInput a = cable("A", Centerline::polyline({{-0.37, 0, 0}, {40, 0, 0}, {80, 0, 0}}));
      CableInput b = cable("B", Centerline::polyline({{0, 1.5, 0}, {40, 1.5, 0}, {80, 1.5 + 40 * slope, 0}}));
      a.segments = {{3, 0.0, 40.37}, {4, 40.37, 80.37}};
      b.segments = {{3, 0.0, 40.0}, {5, 40.0, b.curve.length()}};
      const Vec3 junction(40, 0.75, 0);
      if (jr > 0.0) a.junctions = {{"J", junction, jr}};
      b.junctions = a.junctions;
      const double h = 0.01, oracle_err = h;
      const auto sa = a.curve.sample_by_arc_length(h), sb = b.curve.sample_by_arc_length(h);
      double truth = std::numeric_limits<double>::infinity();
      for (const auto& [s, p] : sa) {
        if (s < 35 || s > 55) continue;
        for (const auto& [t, q] : sb) {
          if (t < 35 || t > 55) continue;
          const bool bundled = s <= 40.37 && t <= 40;
          const bool at_j = (p - junction).norm() <= jr && (q - junction).norm() <= jr;
          if (!bundled && !at_j) truth = std::min(truth, (p - q).norm() - 2 * kR);
        }
      }
      const ClashResult r = audit({a, b}, far_part());
      const auto e = entries(r, ClashKind::CableCable, 0, 1);
      const std::string in = "deg " + g17(deg) + " junction radius " + g17(jr) + " truth " + g17(truth) + "\n" + describe(r);
      if (truth < -kTol - oracle_err) {
        ASSERT_EQ(e.size(), 1u) << in;
        EXPECT_NEAR(e[0]->clearance, truth, kTol + oracle_err) << in;
      } else if (truth > kTol + oracle_err) {
        EXPECT_TRUE(e.empty()) << in;
      }
    }
  }
}

// ---------------------------------------------------------------------------------------
// Threads.

bool same_report(const ClashResult& x, const ClashResult& y, std::string* why) {
  if (x.clashes.size() != y.clashes.size() || x.violations.size() != y.violations.size()) {
    *why = "sizes differ";
    return false;
  }
  for (std::size_t i = 0; i < x.clashes.size(); ++i) {
    const ClashEntry &a = x.clashes[i], &b = y.clashes[i];
    if (a.kind != b.kind || a.cable != b.cable || a.part != b.part || a.other != b.other || a.clearance != b.clearance ||
        a.point != b.point || a.s != b.s || a.s_other != b.s_other || a.s_begin != b.s_begin || a.s_end != b.s_end ||
        a.inside != b.inside) {
      *why = "clash " + std::to_string(i) + " differs";
      return false;
    }
  }
  for (std::size_t i = 0; i < x.violations.size(); ++i) {
    const Violation &a = x.violations[i], &b = y.violations[i];
    if (a.kind != b.kind || a.cable != b.cable || a.part != b.part || a.value != b.value || a.s != b.s) {
      *why = "violation " + std::to_string(i) + " differs";
      return false;
    }
  }
  for (std::size_t i = 0; i < x.cables.size(); ++i)
    if (x.cables[i].min_clearance != y.cables[i].min_clearance) {
      *why = "min clearance of cable " + std::to_string(i) + " differs";
      return false;
    }
  return true;
}

// Many cables crowded among boxes, several touching each other and themselves: the report
// of 1 and 2 threads is the same, bit for bit (with exact and approximate queries).
TEST(ClashAdversarial, OneAndTwoThreadsGiveTheSameReport) {
  for (std::uint32_t seed : {1u, 2u, 3u}) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> U(0, 1);
    std::vector<Part> parts;
    for (int i = 0; i < 6; ++i) {
      const Vec3 lo(40 * U(rng), 40 * U(rng), 10 * U(rng));
      parts.push_back(box_part("p" + std::to_string(i), lo, lo + Vec3(2 + 6 * U(rng), 2 + 6 * U(rng), 2 + 6 * U(rng))));
    }
    // A keep-out envelope around the first box (overlapping closed parts).
    const AABB b0 = parts[0].mesh.bounds();
    parts.push_back(box_part("envelope", b0.min - Vec3::Constant(3), b0.max + Vec3::Constant(3), PartRole::KeepOut));
    std::vector<CableInput> cables;
    for (int i = 0; i < 8; ++i) {
      std::vector<Vec3> cps;
      for (int k = 0; k < 7; ++k) cps.emplace_back(50 * U(rng), 50 * U(rng), 20 * U(rng));
      cables.push_back(cable("C" + std::to_string(i), cubic(cps), 0.5 + U(rng)));
    }
    // Bundle segments shared by some of them, and a shared junction (excused contacts).
    for (int i = 0; i < 8; ++i) {
      const double len = cables[i].curve.length();
      cables[i].segments = {{i % 3, 0.0, 0.5 * len}, {3 + i, 0.5 * len, len}};
      cables[i].junctions = {{"J", cables[0].curve.position(0.5 * (cables[0].curve.u_min() + cables[0].curve.u_max())), 6.0}};
    }
    for (double eps : {0.0, 0.25}) {
      const ClashResult one = audit(cables, parts, kTol, 1, eps), two = audit(cables, parts, kTol, 2, eps);
      std::string why;
      EXPECT_TRUE(same_report(one, two, &why)) << "seed " << seed << " eps " << g17(eps) << ": " << why << "\n1 thread:\n"
                                               << describe(one) << "2 threads:\n" << describe(two);
      EXPECT_GT(one.clashes.size(), 0u);
    }
  }
}

}  // namespace
}  // namespace loom
