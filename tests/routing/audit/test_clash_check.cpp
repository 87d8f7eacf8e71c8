// Clash checks against a test-only exact oracle (dense brute-force segment–triangle and
// segment–segment distances), on scenes with known answers, adversarial scenes where the
// paper's discrete method misses, and random scenes (rapidcheck).
#include "routing/audit/clash_check.hpp"
#include "index/index_test_meshes.hpp"
#include "routing/audit/audit.hpp"

#include "core/error.hpp"
#include "core/mesh.hpp"
#include "index/brute_force_index.hpp"
#include "index/embree_index.hpp"
#include "index/triangle_distance.hpp"

#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <nlohmann/json.hpp>

#include <sys/wait.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <random>
#include <sstream>
#include <tuple>

namespace loom {
namespace {

// ---------------------------------------------------------------------------------------
// Scene building.

using testmesh::box_part;

/// Open rectangle (two triangles) with corners o, o+u, o+u+v, o+v.
Part sheet_part(const std::string& name, const Vec3& o, const Vec3& u, const Vec3& v) {
  Part p;
  p.name = name;
  p.mesh.vertices = {o, o + u, o + u + v, o + v};
  p.mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  p.closed = false;
  return p;
}

CableInput straight_cable(const std::string& id, const Vec3& a, const Vec3& b, double r) {
  CableInput c;
  c.id = id;
  c.curve = Centerline::polyline({a, b});
  c.radius = r;
  return c;
}

/// Clamped uniform cubic B-spline with the given control points (≥ 4): a smooth centerline
/// that does not depend on interpolation.
Centerline cubic_from_controls(const std::vector<Vec3>& cps) {
  const int n = static_cast<int>(cps.size());
  std::vector<double> knots;
  for (int i = 0; i < 4; ++i) knots.push_back(0.0);
  for (int i = 1; i < n - 3; ++i) knots.push_back(static_cast<double>(i));
  for (int i = 0; i < 4; ++i) knots.push_back(static_cast<double>(n - 3));
  return Centerline(3, knots, cps);
}

// ---------------------------------------------------------------------------------------
// The oracle: every centerline is cut into pieces of length ≤ h (chord error ≤ h²κ/8) and
// compared with every triangle / every piece of every other cable.

struct OracleCable {
  std::vector<Vec3> p;
  std::vector<double> s;
};

OracleCable dense(const Centerline& c, double h) {
  OracleCable o;
  for (const auto& sp : c.sample_by_arc_length(h)) {
    o.s.push_back(sp.first);
    o.p.push_back(sp.second);
  }
  return o;
}

/// Winding number of a closed mesh around p.
double winding(const Mesh& m, const Vec3& p) {
  double w = 0.0;
  for (std::size_t t = 0; t < m.triangles.size(); ++t) {
    const auto c = m.corners(t);
    w += triangle_solid_angle(p, c[0], c[1], c[2]);
  }
  return w / (4.0 * M_PI);
}

/// Smallest clearance of a cable to a part (dist 0 inside a closed part).
double oracle_structure(const OracleCable& oc, double r, const Part& part) {
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k + 1 < oc.p.size(); ++k) {
    for (std::size_t t = 0; t < part.mesh.triangles.size(); ++t) {
      const auto c = part.mesh.corners(t);
      best = std::min(best, closest_segment_triangle(oc.p[k], oc.p[k + 1], c[0], c[1], c[2]).dist2);
    }
  }
  double d = std::sqrt(best);
  if (part.closed)
    for (const Vec3& p : oc.p)
      if (winding(part.mesh, p) > 0.5) d = 0.0;
  return d - r;
}

/// Smallest clearance between two cables (self: pairs with |s − t| ≥ π r). Blocks of 16
/// pieces farther apart than `cap` are skipped (the answer is then ≥ cap − radii).
double oracle_pair(const OracleCable& a, double ra, const OracleCable& b, double rb, bool self, double cap) {
  constexpr std::size_t B = 16;
  auto boxes = [&](const OracleCable& o) {
    std::vector<AABB> out;
    for (std::size_t i = 0; i + 1 < o.p.size(); i += B) {
      AABB box;
      for (std::size_t k = i; k <= std::min(o.p.size() - 1, i + B); ++k) box.extend(o.p[k]);
      out.push_back(box);
    }
    return out;
  };
  const auto ba = boxes(a), bb = boxes(b);
  double best = cap * cap;
  for (std::size_t x = 0; x < ba.size(); ++x)
    for (std::size_t y = 0; y < bb.size(); ++y) {
      const Vec3 gap = (ba[x].min - bb[y].max).cwiseMax(bb[y].min - ba[x].max).cwiseMax(Vec3::Zero());
      if (gap.squaredNorm() > best) continue;
      for (std::size_t i = x * B; i < std::min(a.p.size() - 1, (x + 1) * B); ++i)
        for (std::size_t j = y * B; j < std::min(b.p.size() - 1, (y + 1) * B); ++j) {
          const auto r = closest_segment_segment(a.p[i], a.p[i + 1], b.p[j], b.p[j + 1]);
          if (self) {
            const double s = a.s[i] + r.s * (a.s[i + 1] - a.s[i]);
            const double t = b.s[j] + r.t * (b.s[j + 1] - b.s[j]);
            if (std::abs(s - t) < M_PI * ra) continue;
          }
          best = std::min(best, r.dist2);
        }
    }
  return std::sqrt(best) - ra - rb;
}

bool has_structure_clash(const ClashResult& r, int cable, int part) {
  for (const auto& e : r.clashes)
    if (e.kind == ClashKind::CableStructure && e.cable == cable && e.part == part) return true;
  return false;
}
const ClashEntry* find_clash(const ClashResult& r, ClashKind k, int cable, int other_or_part) {
  for (const auto& e : r.clashes)
    if (e.kind == k && e.cable == cable && (k == ClashKind::CableStructure ? e.part : e.other) == other_or_part)
      return &e;
  return nullptr;
}

enum class IndexKind { Embree, Brute };

std::unique_ptr<ObstacleIndex> make_index(IndexKind k, const std::vector<Part>& parts) {
  if (k == IndexKind::Embree) return std::make_unique<EmbreeIndex>(parts);
  return std::make_unique<BruteForceIndex>(parts);
}

ClashResult run(const std::vector<CableInput>& cables, const std::vector<Part>& parts, ClashMethod m,
                double tol, IndexKind ik = IndexKind::Embree, double clearance = 0.0, bool use_index = true) {
  auto index = make_index(ik, parts);
  ClashRequest req;
  req.method = m;
  req.tolerance = tol;
  req.routing_clearance = clearance;
  req.use_index = use_index;
  req.threads = 2;
  return check_clashes(cables, parts, index.get(), req);
}

constexpr double kTol = 0.01;
constexpr double kR = 1.0;

class ClashKnown : public ::testing::TestWithParam<IndexKind> {};

// A cable along x above the top face z = 10 of a box at axis height 10 + r + delta.
std::vector<CableInput> above_box(double delta) {
  return {straight_cable("C", {-20, 5, 10 + kR + delta}, {30, 5, 10 + kR + delta}, kR)};
}

TEST_P(ClashKnown, TouchingClearAndPenetrating) {
  const std::vector<Part> parts{box_part("box", {0, 0, 0}, {10, 10, 10})};
  // Clear by +2·tol: nothing.
  auto clear = run(above_box(2 * kTol), parts, ClashMethod::Certified, kTol, GetParam());
  EXPECT_TRUE(clear.clashes.empty());
  ASSERT_EQ(clear.cables.size(), 1u);
  EXPECT_NEAR(clear.cables[0].min_clearance, 2 * kTol, kTol);
  // Penetrating by 2·tol: one clash at clearance −2·tol ± tol.
  auto pen = run(above_box(-2 * kTol), parts, ClashMethod::Certified, kTol, GetParam());
  ASSERT_EQ(pen.clashes.size(), 1u);
  EXPECT_EQ(pen.clashes[0].part, 0);
  EXPECT_NEAR(pen.clashes[0].clearance, -2 * kTol, kTol);
  EXPECT_GE(pen.clashes[0].s, 20.0 - kTol);
  EXPECT_LE(pen.clashes[0].s, 30.0 + kTol);
  EXPECT_NEAR(pen.clashes[0].point.z(), 10 + kR - 2 * kTol, 1e-9);
  // Touching: whatever is reported is within ±tol of 0.
  auto touch = run(above_box(0.0), parts, ClashMethod::Certified, kTol, GetParam());
  for (const auto& e : touch.clashes) EXPECT_NEAR(e.clearance, 0.0, kTol);
  EXPECT_LE(touch.clashes.size(), 1u);
}

TEST_P(ClashKnown, InsideClosedPartWithNoSurfaceNearby) {
  const std::vector<Part> parts{box_part("hull", {-100, -100, -100}, {100, 100, 100})};
  const std::vector<CableInput> cables{straight_cable("C", {-20, 0, 0}, {20, 0, 0}, kR)};
  for (ClashMethod m : {ClashMethod::Certified, ClashMethod::Discrete}) {
    auto r = run(cables, parts, m, kTol, GetParam());
    ASSERT_EQ(r.clashes.size(), 1u) << clash_method_name(m);
    EXPECT_TRUE(r.clashes[0].inside);
    EXPECT_DOUBLE_EQ(r.clashes[0].clearance, -kR);
    EXPECT_DOUBLE_EQ(r.cables[0].min_clearance, -kR);
  }
}

TEST_P(ClashKnown, CrossingAWallIsOneStretchAtItsDeepestPoint) {
  // A cable passing through a 4-wide wall: one clash stretch, inside, deepest in the middle.
  const std::vector<Part> parts{box_part("wall", {-2, -50, -50}, {2, 50, 50})};
  const std::vector<CableInput> cables{straight_cable("C", {-30, 0, 0}, {30, 0, 0}, kR)};
  auto r = run(cables, parts, ClashMethod::Certified, kTol, GetParam());
  ASSERT_EQ(r.clashes.size(), 1u);
  EXPECT_TRUE(r.clashes[0].inside);
  EXPECT_NEAR(r.clashes[0].s, 30.0, 1.0 + kTol);
  // Stretch ends are known to one chord (≤ 2r).
  EXPECT_NEAR(r.clashes[0].s_begin, 30.0 - 2 - kR, 2 * kR);
  EXPECT_NEAR(r.clashes[0].s_end, 30.0 + 2 + kR, 2 * kR);
}

TEST_P(ClashKnown, ThinRodBetweenSamplesIsMissedByDiscreteOnly) {
  // Discrete samples at x = 0, 2r, 4r, …; a 0.2-thick rod along z at x = r (midway),
  // its near face at y = r − 2·tol below the axis y = 0... i.e. penetrating by 2·tol.
  const double eps = 2 * kTol;
  const std::vector<Part> parts{box_part("rod", {kR - 0.1, kR - eps, -20}, {kR + 0.1, kR - eps + 0.2, 20})};
  const std::vector<CableInput> cables{straight_cable("C", {0, 0, 0}, {20 * kR, 0, 0}, kR)};
  auto cert = run(cables, parts, ClashMethod::Certified, kTol, GetParam());
  ASSERT_EQ(cert.clashes.size(), 1u);
  EXPECT_NEAR(cert.clashes[0].clearance, -eps, kTol);
  EXPECT_NEAR(cert.clashes[0].s, kR, 0.1 + kTol);
  auto disc = run(cables, parts, ClashMethod::Discrete, kTol, GetParam());
  EXPECT_TRUE(disc.clashes.empty()) << "the paper's method misses a rod between samples";
  auto brute = run(cables, parts, ClashMethod::Discrete, kTol, GetParam(), 0.0, false);
  EXPECT_TRUE(brute.clashes.empty());
}

TEST_P(ClashKnown, SheetEdgeGrazingBetweenSamplesIsMissedByDiscreteOnly) {
  // An open sheet in the plane x = r, its edge at y = r − 2·tol: grazes the tube midway.
  const double eps = 2 * kTol;
  const std::vector<Part> parts{sheet_part("sheet", {kR, kR - eps, -30}, {0, 40, 0}, {0, 0, 60})};
  const std::vector<CableInput> cables{straight_cable("C", {0, 0, 0}, {20 * kR, 0, 0}, kR)};
  auto cert = run(cables, parts, ClashMethod::Certified, kTol, GetParam());
  ASSERT_EQ(cert.clashes.size(), 1u);
  EXPECT_FALSE(cert.clashes[0].inside);
  EXPECT_NEAR(cert.clashes[0].clearance, -eps, kTol);
  EXPECT_FALSE(cert.notes.empty());  // says the sheet is open
  auto disc = run(cables, parts, ClashMethod::Discrete, kTol, GetParam());
  EXPECT_TRUE(disc.clashes.empty());
}

TEST_P(ClashKnown, CablesCrossingBetweenSamples) {
  // A along x at z = 0; B along y at height 2r − 2·tol, crossing at x = r, y = 0 with B's
  // samples at y = ±r: every sample pair is farther than 2r.
  const double eps = 2 * kTol;
  const std::vector<CableInput> cables{straight_cable("A", {0, 0, 0}, {10 * kR, 0, 0}, kR),
                                       straight_cable("B", {kR, -5 * kR, 2 * kR - eps}, {kR, 5 * kR, 2 * kR - eps}, kR)};
  const std::vector<Part> parts{box_part("far", {100, 100, 100}, {101, 101, 101})};
  auto cert = run(cables, parts, ClashMethod::Certified, kTol, GetParam());
  const ClashEntry* e = find_clash(cert, ClashKind::CableCable, 0, 1);
  ASSERT_NE(e, nullptr);
  EXPECT_EQ(cert.clashes.size(), 1u);
  EXPECT_NEAR(e->clearance, -eps, kTol);
  EXPECT_NEAR(e->s, kR, 1e-6);
  EXPECT_NEAR(e->s_other, 5 * kR, 1e-6);
  auto disc = run(cables, parts, ClashMethod::Discrete, kTol, GetParam());
  EXPECT_EQ(find_clash(disc, ClashKind::CableCable, 0, 1), nullptr) << "discrete misses the crossing";
  // Clear by 2·tol: nothing.
  const std::vector<CableInput> apart{cables[0], straight_cable("B", {kR, -5 * kR, 2 * kR + eps}, {kR, 5 * kR, 2 * kR + eps}, kR)};
  EXPECT_TRUE(run(apart, parts, ClashMethod::Certified, kTol, GetParam()).clashes.empty());
}

TEST_P(ClashKnown, BundledCablesAreExcusedOnTheirSharedSegment) {
  CableInput a = straight_cable("A", {0, 0, 0}, {50, 0, 0}, kR);
  CableInput b = straight_cable("B", {0, 0, 0}, {50, 0, 0}, kR);
  const std::vector<Part> parts{box_part("far", {100, 100, 100}, {101, 101, 101})};
  auto r = run({a, b}, parts, ClashMethod::Certified, kTol, GetParam());
  EXPECT_NE(find_clash(r, ClashKind::CableCable, 0, 1), nullptr);
  a.segments = {{7, 0.0, 50.0}};
  b.segments = {{7, 0.0, 50.0}};
  for (ClashMethod m : {ClashMethod::Certified, ClashMethod::Discrete}) {
    const auto res = run({a, b}, parts, m, kTol, GetParam());
    EXPECT_TRUE(res.clashes.empty()) << clash_method_name(m) << " " << clash_kind_name(res.clashes[0].kind)
                                     << " s=" << res.clashes[0].s << " t=" << res.clashes[0].s_other;
  }
}

TEST_P(ClashKnown, SelfLoopFoundByBothMethods) {
  // Goes along x, comes back 1.5·r above itself: |s − t| large, distance 1.5 r < 2 r.
  CableInput c;
  c.id = "L";
  c.radius = kR;
  c.curve = Centerline::polyline({{0, 0, 0}, {20, 0, 0}, {20, 0, 1.5 * kR}, {0, 0, 1.5 * kR}});
  const std::vector<Part> parts{box_part("far", {100, 100, 100}, {101, 101, 101})};
  for (ClashMethod m : {ClashMethod::Certified, ClashMethod::Discrete}) {
    auto r = run({c}, parts, m, kTol, GetParam());
    const ClashEntry* e = find_clash(r, ClashKind::Self, 0, 0);
    ASSERT_NE(e, nullptr) << clash_method_name(m);
    EXPECT_NEAR(e->clearance, -0.5 * kR, m == ClashMethod::Certified ? kTol : 0.5);
  }
  // A straight cable never touches itself.
  auto straight = run({straight_cable("S", {0, 0, 0}, {50, 0, 0}, kR)}, parts, ClashMethod::Certified, kTol, GetParam());
  EXPECT_TRUE(straight.clashes.empty());
}

TEST_P(ClashKnown, ClearanceAndKeepOut) {
  std::vector<Part> parts{box_part("box", {0, 0, 0}, {10, 10, 10})};
  // Clearance 1.0 with 2.0 required: a clearance violation, not a clash.
  auto v = run(above_box(1.0), parts, ClashMethod::Certified, kTol, GetParam(), 2.0);
  EXPECT_TRUE(v.clashes.empty());
  ASSERT_EQ(v.violations.size(), 1u);
  EXPECT_EQ(v.violations[0].kind, ViolationKind::Clearance);
  EXPECT_NEAR(v.violations[0].value, 1.0, kTol);
  EXPECT_DOUBLE_EQ(v.violations[0].limit, 2.0);
  // Part clearance adds to the routing clearance.
  parts[0].clearance = 1.5;
  auto v2 = run(above_box(2.5), parts, ClashMethod::Certified, kTol, GetParam(), 2.0);
  ASSERT_EQ(v2.violations.size(), 1u);
  EXPECT_DOUBLE_EQ(v2.violations[0].limit, 3.5);
  // Clearance 3.0 with 2.0 required: nothing.
  parts[0].clearance = 0.0;
  auto ok = run(above_box(3.0), parts, ClashMethod::Certified, kTol, GetParam(), 2.0);
  EXPECT_TRUE(ok.violations.empty());
  EXPECT_TRUE(ok.clashes.empty());
  // Keep-out zone entered: a cable-structure clash flagged keep_out.
  const std::vector<Part> zone{box_part("zone", {0, 0, 0}, {10, 10, 10}, PartRole::KeepOut)};
  auto k = run({straight_cable("C", {-10, 5, 5}, {20, 5, 5}, kR)}, zone, ClashMethod::Certified, kTol, GetParam());
  ASSERT_EQ(k.clashes.size(), 1u);
  EXPECT_TRUE(k.clashes[0].keep_out);
}

TEST_P(ClashKnown, AttachedConnectorIsExcusedOverThePortExitOnly) {
  // Port J1 sits on the +x face of a box (a connector on an avionics box); cable C leaves it
  // along +x. A bracket 0.5 from C's surface within C's straight exit, a keep-out envelope
  // around the port, and cable C2 passing 0.5 over the same box are all still findings.
  const double clearance = 2.0;
  const std::vector<Part> parts{box_part("box", {0, 0, 0}, {10, 10, 10}),
                                box_part("bracket", {13, 6.5, 0}, {18, 9, 10}),
                                box_part("envelope", {10, 3, 3}, {12, 7, 7}, PartRole::KeepOut)};
  Harness h;
  h.ports = {{"J1", Vec3(10, 5, 5), Vec3::UnitX(), 0}, {"J2", Vec3(60, 5, 5), -Vec3::UnitX(), 0},
             {"J3", Vec3(-20, 5, 11.5), Vec3::UnitX(), 0}, {"J4", Vec3(30, 5, 11.5), -Vec3::UnitX(), 0}};
  for (const auto& [id, a, b] : {std::tuple{"C", "J1", "J2"}, std::tuple{"C2", "J3", "J4"}}) {
    Cable c;
    c.id = id;
    c.ports[0] = a;
    c.ports[1] = b;
    c.physical.diameter = 2 * kR;
    c.physical.min_bend_radius = 10.0;
    h.cables.push_back(c);
  }
  std::vector<CableInput> cables{straight_cable("C", {10, 5, 5}, {60, 5, 5}, kR),
                                 straight_cable("C2", {-20, 5, 11.5}, {30, 5, 11.5}, kR)};
  for (auto& c : cables) c.min_bend_radius = 10.0;
  // The same attachments through an index and measured directly on each part.
  std::vector<CableInput> via_index = cables;
  const EmbreeIndex idx(parts);
  attach_ports(h, parts, clearance, via_index, &idx);
  const auto notes = attach_ports(h, parts, clearance, cables);
  ASSERT_EQ(via_index[0].attachments.size(), cables[0].attachments.size());
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes[0].find("port J1 sits on part 'box'"), std::string::npos) << notes[0];
  ASSERT_EQ(cables[0].attachments.size(), 1u) << "the keep-out envelope is never an attachment";
  EXPECT_EQ(cables[0].attachments[0].part, 0);
  EXPECT_DOUBLE_EQ(cables[0].attachments[0].s_end, 10.0);  // max(min bend radius, 2r)
  EXPECT_TRUE(cables[1].attachments.empty());
  for (ClashMethod m : {ClashMethod::Certified, ClashMethod::Discrete}) {
    const auto r = run(cables, parts, m, kTol, GetParam(), clearance);
    const std::string where = clash_method_name(m);
    EXPECT_FALSE(has_structure_clash(r, 0, 0)) << where;
    bool c_box = false, c_bracket = false, c2_box = false;
    for (const auto& v : r.violations) {
      if (v.kind != ViolationKind::Clearance) continue;
      c_box |= v.cable == 0 && v.part == 0;
      c_bracket |= v.cable == 0 && v.part == 1;
      c2_box |= v.cable == 1 && v.part == 0;
    }
    EXPECT_FALSE(c_box) << where << ": the box C is attached to";
    EXPECT_TRUE(c_bracket) << where << ": a bracket next to the exit is not the connector";
    EXPECT_TRUE(c2_box) << where << ": another cable passing the box";
    EXPECT_TRUE(has_structure_clash(r, 0, 2)) << where << ": keep-out is never excused";
  }
  // With the box alone, C has no finding and the box it is attached to does not set its
  // minimum clearance (the rest of C is 50 mm of free space: clearance is that far).
  const std::vector<Part> box_only{parts[0]};
  const std::vector<CableInput> only_c{cables[0]};
  for (ClashMethod m : {ClashMethod::Certified, ClashMethod::Discrete}) {
    const auto r = run(only_c, box_only, m, kTol, GetParam(), clearance);
    EXPECT_TRUE(r.clashes.empty()) << clash_method_name(m);
    EXPECT_TRUE(r.violations.empty()) << clash_method_name(m);
    EXPECT_GT(r.cables[0].min_clearance, clearance) << clash_method_name(m);
  }
}

// The attachment excuses the connector's contacts over a port's exit, not a centerline that
// goes into the part the port sits on: a port on the face of a 1 mm plate whose exit points
// into it crosses the plate (clearance −r there), and one on the face of a box whose exit
// points into the box runs inside it. A port inside a connector modelled solid leaves it
// along its exit: excused, as before.
TEST_P(ClashKnown, AnExitIntoThePartItsPortSitsOnIsAClash) {
  const double clearance = 3.0;
  struct Case {
    const char* what;
    Part part;
    Vec3 port;
    bool clash;
    bool discrete_sees_it;  // the discrete method's samples (2r apart) may step over a thin plate
  };
  const std::vector<Case> cases{
      {"through a 1 mm plate", box_part("plate", {-21, -30, -30}, {-20, 30, 30}), Vec3(-21, 5, 5), true, false},
      {"into a box", box_part("box", {-21, -30, -30}, {-1, 30, 30}), Vec3(-21, 5, 5), true, true},
      {"out of a connector holding the port", box_part("connector", {-30, 0, 0}, {-19, 10, 10}), Vec3(-21, 5, 5),
       false, false},
      {"out of the face it sits on", box_part("wall", {-31, -30, -30}, {-21, 30, 30}), Vec3(-21, 5, 5), false,
       false}};
  for (const Case& c : cases) {
    const std::vector<Part> parts{c.part};
    Harness h;
    h.ports = {{"J1", c.port, Vec3::UnitX(), 0}, {"J2", Vec3(90, 5, 5), -Vec3::UnitX(), 0}};
    Cable cab;
    cab.id = "C1";
    cab.ports[0] = "J1";
    cab.ports[1] = "J2";
    cab.physical.diameter = 2 * kR;
    cab.physical.min_bend_radius = 10.0;
    h.cables.push_back(cab);
    std::vector<CableInput> cables{straight_cable("C1", c.port, {90, 5, 5}, kR)};
    cables[0].min_bend_radius = 10.0;
    const auto idx = make_index(GetParam(), parts);
    attach_ports(h, parts, clearance, cables, idx.get());
    ASSERT_EQ(cables[0].attachments.size(), 1u) << c.what;
    for (ClashMethod m : {ClashMethod::Certified, ClashMethod::Discrete}) {
      const auto r = run(cables, parts, m, kTol, GetParam(), clearance);
      const bool expect = c.clash && (m == ClashMethod::Certified || c.discrete_sees_it);
      EXPECT_EQ(has_structure_clash(r, 0, 0), expect) << c.what << ", " << clash_method_name(m);
      if (expect && m == ClashMethod::Certified) {
        ASSERT_FALSE(r.clashes.empty());
        EXPECT_NEAR(r.clashes[0].clearance, -kR, kTol) << c.what;  // the axis is in the part: dist 0
      }
    }
  }
}

TEST_P(ClashKnown, TwoContactsInOneClearanceStretchAreTwoClashes) {
  // Dips into the box top twice (−0.1) and stays within the 2.0 clearance band between.
  const std::vector<Part> parts{box_part("box", {0, 0, 0}, {10, 10, 10})};
  const double lo = 10 + kR - 0.1, mid = 10 + kR + 0.5;
  CableInput c;
  c.id = "W";
  c.radius = kR;
  c.curve = Centerline::polyline({{-5, 5, 20}, {1, 5, lo}, {3, 5, lo}, {4, 5, mid}, {6, 5, mid}, {7, 5, lo},
                                  {9, 5, lo}, {15, 5, 20}});
  auto r = run({c}, parts, ClashMethod::Certified, kTol, GetParam(), 2.0);
  ASSERT_EQ(r.clashes.size(), 2u);
  for (const auto& e : r.clashes) EXPECT_NEAR(e.clearance, -0.1, kTol);
  EXPECT_LT(r.clashes[0].s_end, r.clashes[1].s_begin);
  EXPECT_TRUE(r.violations.empty());
}

TEST_P(ClashKnown, BendRadiusViolation) {
  // Cubic B-spline whose control polygon is a fine regular polygon on a circle of radius
  // 20: bend radius ≈ 20 away from the clamped ends (which straighten out).
  std::vector<Vec3> pts;
  for (int i = 0; i <= 24; ++i) pts.emplace_back(20 * std::cos(i * M_PI / 12), 20 * std::sin(i * M_PI / 12), 0);
  CableInput c;
  c.id = "B";
  c.radius = kR;
  c.curve = cubic_from_controls(pts);
  c.min_bend_radius = 30;
  const std::vector<Part> parts{box_part("far", {100, 100, 100}, {101, 101, 101})};
  auto r = run({c}, parts, ClashMethod::Certified, kTol, GetParam());
  // Oracle: smallest circumradius of three curve points h apart in u (independent of
  // Centerline::min_bend_radius).
  double oracle = std::numeric_limits<double>::infinity();
  const double h = 1e-3;
  for (double u = c.curve.u_min() + h; u < c.curve.u_max() - h; u += 1e-3) {
    const Vec3 a = c.curve.position(u - h), b = c.curve.position(u), d = c.curve.position(u + h);
    const double cr = (a - b).norm() * (b - d).norm() * (d - a).norm() / (2.0 * (b - a).cross(d - a).norm());
    oracle = std::min(oracle, cr);
  }
  ASSERT_EQ(r.violations.size(), 1u);
  EXPECT_EQ(r.violations[0].kind, ViolationKind::BendRadius);
  EXPECT_NEAR(r.violations[0].value, oracle, 0.01 * oracle);
  EXPECT_LT(oracle, 20.0);
  c.min_bend_radius = 10;
  EXPECT_TRUE(run({c}, parts, ClashMethod::Certified, kTol, GetParam()).violations.empty());
}

INSTANTIATE_TEST_SUITE_P(Indices, ClashKnown, ::testing::Values(IndexKind::Embree, IndexKind::Brute),
                         [](const auto& param_info) { return param_info.param == IndexKind::Embree ? "Embree" : "Brute"; });

TEST(ClashCheck, BadInputIsRejected) {
  const std::vector<Part> parts{box_part("box", {0, 0, 0}, {1, 1, 1})};
  BruteForceIndex idx(parts);
  ClashRequest req;
  CableInput no_curve;
  no_curve.id = "X";
  no_curve.radius = 1;
  EXPECT_THROW(check_clashes({no_curve}, parts, &idx, req), std::invalid_argument);
  CableInput zero = straight_cable("Z", {0, 0, 0}, {1, 0, 0}, 0.0);
  EXPECT_THROW(check_clashes({zero}, parts, &idx, req), std::invalid_argument);
  EXPECT_THROW(check_clashes({}, parts, nullptr, req), std::invalid_argument);
  // No cables: nothing to report.
  EXPECT_TRUE(check_clashes({}, parts, &idx, req).clashes.empty());
}

// Regression: a route wiggling on the scale
// of the tolerance (2,000 key points 1 µm apart, or a fine tolerance on a tight zigzag) made
// the certified audit flatten it into chords without end. It is refused up front, naming
// the cable and the chord count, before any chord is made.
TEST(ClashCheck, ARouteWigglingAtTheToleranceIsRefusedNotFlattened) {
  const std::vector<Part> parts{box_part("box", {0, 0, 0}, {1, 1, 1})};
  BruteForceIndex idx(parts);
  std::vector<Vec3> cps;
  for (int i = 0; i < 40; ++i) cps.emplace_back(10.0 + 1e-4 * i, (i % 2) ? 1.0 : -1.0, 0.0);
  CableInput c;
  c.id = "wiggle";
  c.curve = cubic_from_controls(cps);
  c.radius = 1.0;
  ClashRequest req;
  req.tolerance = 1e-12;
  try {
    check_clashes({c}, parts, &idx, req);
    FAIL() << "accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'wiggle' would need"), std::string::npos) << e.what();
  }
  req.tolerance = 0.0;  // the default (r/100): a few thousand chords, audited
  EXPECT_NO_THROW(check_clashes({c}, parts, &idx, req));
}

// A route 10⁸ long (a key point typed in the wrong units) needs its chords for its
// length, not its curvature, and the refusal says so.
TEST(ClashCheck, AFarTooLongRouteIsRefusedForItsLength) {
  const std::vector<Part> parts{box_part("box", {0, 0, 0}, {1, 1, 1})};
  BruteForceIndex idx(parts);
  try {
    check_clashes({straight_cable("far", {0, 5, 0}, {1e8, 5, 0}, 1.0)}, parts, &idx, ClashRequest{});
    FAIL() << "accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'far' would need 5000000"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("check its key points and units"), std::string::npos) << e.what();
  }
}

// Regression: key points far closer together than the cable is
// thick (2,000 points 1 µm apart on one bundle segment of the wing harness, shared by 11
// cables) gave every cable a chord per knot span, and the pair pass's broad phase 26,000
// mutually overlapping chord blocks: 288 million candidate pairs, 34 s and 4.6 GB for an
// audit that takes 0.3 s without them. Runs of short spans whose control points stay within
// the chord error are one chord (ChordPlan). The findings must still match the oracle,
// with about as many chords as the same curves need without the dense points.
TEST(ClashCheck, DenseKeyPointsAuditLikeTheOracleWithFewChords) {
  auto route = [](double z, int dense) {
    std::vector<Vec3> pts;
    auto at = [z](double x) { return Vec3(x, 5.0 * std::sin(x / 30.0), z); };
    for (double x = 0.0; x < 40.0; x += 10.0) pts.push_back(at(x));
    for (int i = 0; i <= dense; ++i) pts.push_back(at(40.0 + 2.0 * i / std::max(dense, 1)));
    for (double x = 50.0; x <= 100.0; x += 10.0) pts.push_back(at(x));
    return Centerline::interpolate(pts);
  };
  const std::vector<Part> parts{box_part("wall", {60, -10, -3}, {62, 10, 3})};
  auto cables_with = [&](int dense) {
    std::vector<CableInput> cs(3);
    for (int i = 0; i < 3; ++i) {
      cs[i].id = "C" + std::to_string(i);
      cs[i].curve = route(1.5 * i, dense);
      cs[i].radius = 1.0;
    }
    return cs;
  };
  const auto packed = cables_with(2000), sparse = cables_with(1);
  const double tol = 0.01;
  const ClashResult rd = run(packed, parts, ClashMethod::Certified, tol);
  const ClashResult rs = run(sparse, parts, ClashMethod::Certified, tol);
  std::printf("samples: dense key points %lld, sparse %lld\n", static_cast<long long>(rd.counters.samples), static_cast<long long>(rs.counters.samples));
  EXPECT_LT(rd.counters.samples, 2 * rs.counters.samples + 100)
      << "dense " << rd.counters.samples << " sparse " << rs.counters.samples;
  const double oracle_err = 0.001;
  for (int c = 0; c < 3; ++c) {
    const OracleCable oc = dense(packed[c].curve, 0.05);
    const double truth = oracle_structure(oc, 1.0, parts[0]);
    ASSERT_LT(truth, -tol - oracle_err);  // every cable crosses the wall
    EXPECT_TRUE(has_structure_clash(rd, c, 0)) << "cable " << c;
    for (int d = c + 1; d < 3; ++d) {
      const double pair = oracle_pair(oc, 1.0, dense(packed[d].curve, 0.05), 1.0, false, 5.0);
      const bool hit = find_clash(rd, ClashKind::CableCable, c, d) != nullptr;
      EXPECT_EQ(hit, pair < 0.0) << c << "/" << d << " oracle " << pair;
      EXPECT_TRUE(std::abs(pair) > tol + oracle_err) << "ambiguous scene";
    }
  }
  EXPECT_EQ(rd.clashes.size(), rs.clashes.size());
}

std::string report_difference(const ClashResult& x, const ClashResult& y);  // below

/// A polyline that folds back on itself `folds` times: key points 1 µm apart along x,
/// alternating between y = 0 and y = amplitude.
Centerline folded_route(int folds, double amplitude) {
  std::vector<Vec3> pts;
  for (int i = 0; i <= folds; ++i) pts.emplace_back(1e-3 * i, (i % 2) ? amplitude : 0.0, 0.0);
  return Centerline::polyline(pts);
}

/// check_clashes' refusal message, or "" if the audit ran.
std::string refusal(const std::vector<CableInput>& cables, const std::vector<Part>& parts, const ClashRequest& req) {
  BruteForceIndex idx(parts);
  try {
    check_clashes(cables, parts, &idx, req);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

// Regression: a route folding back on itself thousands of
// times (2,000 zigzags of 50 mm on a wing-harness segment shared by 11 cables) made the
// certified pair pass enumerate ~10⁹ overlapping chord-block pairs (Embree's allocation
// failed at 17 GB; at 20,000 zigzags the process was killed at 24 GB) and the discrete
// grid store contacts until 20 GB. Both bound their work before doing it
// (ClashLimits) and refuse with a message naming a cable; this scene is refused by the
// default limits in about a second.
TEST(ClashLimits, ARouteFoldingBackThousandsOfTimesIsRefusedBeforeItsPairsAreMade) {
  const std::vector<Part> parts{box_part("box", {0, 100, 0}, {1, 101, 1})};
  CableInput c;
  c.id = "fold";
  c.curve = folded_route(6000, 50.0);
  c.radius = 1.0;
  ClashRequest req;
  req.threads = 2;
  req.check_structure = false;
  std::string why = refusal({c}, parts, req);
  EXPECT_NE(why.find("cable 'fold' among them"), std::string::npos) << why;
  EXPECT_NE(why.find("pairs of chord blocks come within reach"), std::string::npos) << why;
  EXPECT_NE(why.find("folds back"), std::string::npos) << why;
  req.method = ClashMethod::Discrete;  // refused by its contacts here, by its sample pairs for more folds
  why = refusal({c}, parts, req);
  EXPECT_NE(why.find("'fold'"), std::string::npos) << why;
  EXPECT_NE(why.find("folds back"), std::string::npos) << why;
}

// Each limit refuses the audit as soon as the work passes it, and at exactly the work
// done the audit runs and reports what it reports without limits.
TEST(ClashLimits, EachLimitRefusesJustBelowTheWorkAndAllowsItAtTheWork) {
  const std::vector<Part> parts{box_part("box", {0, 100, 0}, {1, 101, 1})};
  std::vector<CableInput> cables(2);
  for (int i = 0; i < 2; ++i) {
    cables[i].id = "F" + std::to_string(i);
    cables[i].curve = folded_route(60, 20.0);
    cables[i].radius = 1.0;
  }
  cables[1].curve = Centerline::polyline({Vec3(-5, 10, 0.5), Vec3(5, 10, 0.5)});  // crosses every fold
  ClashRequest req;
  req.threads = 2;
  BruteForceIndex idx(parts);
  const ClashResult full = check_clashes(cables, parts, &idx, req);
  const ClashCounters& n = full.counters;
  ASSERT_GT(n.block_pairs, 0);
  ASSERT_GT(n.pair_contacts, 0);
  ASSERT_GE(n.block_overlaps_estimate, n.block_pairs);  // few blocks: every one counted
  ASSERT_FALSE(full.clashes.empty());
  auto same = [&](const ClashRequest& r) {
    const ClashResult got = check_clashes(cables, parts, &idx, r);
    return report_difference(full, got);
  };
  ClashRequest lim = req;
  lim.limits.max_block_overlaps = static_cast<std::size_t>(n.block_overlaps_estimate);
  EXPECT_EQ(same(lim), "");
  lim.limits.max_block_overlaps -= 1;
  EXPECT_NE(refusal(cables, parts, lim).find("pairs of chord blocks come within reach"), std::string::npos);
  lim = req;
  lim.limits.max_block_pairs = static_cast<std::size_t>(n.block_pairs);
  EXPECT_EQ(same(lim), "");
  lim.limits.max_block_pairs -= 1;
  EXPECT_NE(refusal(cables, parts, lim).find("more than " + std::to_string(n.block_pairs - 1) + " pairs of chord blocks"),
            std::string::npos);
  lim = req;
  lim.limits.max_pair_contacts = static_cast<std::size_t>(n.pair_contacts);
  EXPECT_EQ(same(lim), "");
  lim.limits.max_pair_contacts -= 1;
  EXPECT_NE(refusal(cables, parts, lim).find(" pairs of chords are in contact"), std::string::npos);
  // The discrete method: its sample-pair bound and its contacts, with and without an index.
  ClashRequest disc = req;
  disc.method = ClashMethod::Discrete;
  const ClashResult dfull = check_clashes(cables, parts, &idx, disc);
  ASSERT_GT(dfull.counters.pair_contacts, 0);
  ASSERT_GT(dfull.counters.pair_tests, 0);
  for (bool use_index : {true, false}) {
    ClashRequest d = disc;
    d.use_index = use_index;
    d.limits.max_pair_contacts = static_cast<std::size_t>(dfull.counters.pair_contacts) - 1;
    EXPECT_NE(refusal(cables, parts, d).find("pairs of samples are in contact"), std::string::npos) << use_index;
  }
  // The bound counts each sample's whole neighbourhood, so at least the pairs tested.
  ClashRequest d = disc;
  d.limits.max_sample_pairs = static_cast<std::size_t>(dfull.counters.pair_tests) / 2;
  EXPECT_NE(refusal(cables, parts, d).find("the discrete method would compare about"), std::string::npos);
  d.limits.max_sample_pairs = static_cast<std::size_t>(dfull.counters.pair_tests) * 100;
  EXPECT_EQ(report_difference(dfull, check_clashes(cables, parts, &idx, d)), "");
}

TEST(ClashCheck, DefaultToleranceSaysWhereItCameFrom) {
  std::string source;
  const std::vector<CableInput> cables{straight_cable("A", {0, 0, 0}, {10, 0, 0}, 2.0),
                                       straight_cable("B", {0, 5, 0}, {10, 5, 0}, 0.5)};
  EXPECT_DOUBLE_EQ(default_clash_tolerance(cables, &source), 0.005);
  EXPECT_EQ(source, "smallest cable radius / 100");
  // No cable: nothing is checked, and the report must not claim a derivation.
  const double t = default_clash_tolerance({}, &source);
  EXPECT_GT(t, 0.0);
  EXPECT_EQ(source, "no cables to derive it from");
}

TEST(ClashCheck, DiscreteWithAndWithoutIndexAgree) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(-20, 20);
  std::vector<Part> parts;
  for (int i = 0; i < 4; ++i) {
    const Vec3 lo(U(rng), U(rng), U(rng));
    parts.push_back(box_part("b" + std::to_string(i), lo, lo + Vec3(6, 4, 5)));
  }
  std::vector<CableInput> cables;
  for (int i = 0; i < 4; ++i) {
    CableInput c;
    c.id = "C" + std::to_string(i);
    c.radius = 0.8 + 0.3 * i;
    c.curve = cubic_from_controls({{U(rng), U(rng), U(rng)}, {U(rng), U(rng), U(rng)}, {U(rng), U(rng), U(rng)},
                                   {U(rng), U(rng), U(rng)}});
    cables.push_back(c);
  }
  auto a = run(cables, parts, ClashMethod::Discrete, kTol, IndexKind::Embree, 1.0, true);
  auto b = run(cables, parts, ClashMethod::Discrete, kTol, IndexKind::Embree, 1.0, false);
  ASSERT_EQ(a.clashes.size(), b.clashes.size());
  for (std::size_t i = 0; i < a.clashes.size(); ++i) {
    EXPECT_EQ(a.clashes[i].kind, b.clashes[i].kind);
    EXPECT_EQ(a.clashes[i].part, b.clashes[i].part);
    EXPECT_EQ(a.clashes[i].other, b.clashes[i].other);
    EXPECT_NEAR(a.clashes[i].clearance, b.clashes[i].clearance, 1e-9);
  }
  EXPECT_EQ(a.violations.size(), b.violations.size());
}

// ---------------------------------------------------------------------------------------
// Random scenes: certified has no miss and no false clash outside ±tolerance; discrete's
// misses are counted (and there are some over the whole run).

struct MissCount {
  int certified_missed = 0, certified_false = 0, discrete_missed = 0, truth_clashes = 0;
};
MissCount g_miss;

/// Cable "C<i>": a cubic through n random control points in [0, extent], radius 0.5–2
/// (coordinates drawn x, y, z in sequence: the same scene whatever the compiler's argument order).
CableInput random_cable(std::mt19937& rng, int i, int n, const Vec3& extent) {
  std::uniform_real_distribution<double> U(0, 1);
  std::vector<Vec3> pts;
  for (int k = 0; k < n; ++k) {
    const double x = extent.x() * U(rng), y = extent.y() * U(rng), z = extent.z() * U(rng);
    pts.emplace_back(x, y, z);
  }
  CableInput c;
  c.id = "C" + std::to_string(i);
  c.radius = 0.5 + 1.5 * U(rng);
  c.curve = cubic_from_controls(pts);
  return c;
}

/// Returns a description of every disagreement with the oracle (empty: none).
std::string random_scene_check(std::uint32_t seed) {
  std::string fail;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(0, 1);
  // Boxes and thin rods in disjoint cells of a 3×3×1 grid of 20-unit cells (no overlaps).
  std::vector<Part> parts;
  for (int cx = 0; cx < 3; ++cx)
    for (int cy = 0; cy < 3; ++cy) {
      if (U(rng) < 0.3) continue;
      const Vec3 cell(cx * 20.0, cy * 20.0, 0.0);
      const Vec3 lo = cell + Vec3(2 + 6 * U(rng), 2 + 6 * U(rng), 2 + 6 * U(rng));
      const bool rod = U(rng) < 0.5;
      const Vec3 size = rod ? Vec3(0.2 + 0.2 * U(rng), 0.2 + 0.2 * U(rng), 8.0) : Vec3(2 + 8 * U(rng), 2 + 8 * U(rng), 2 + 8 * U(rng));
      parts.push_back(box_part("p" + std::to_string(parts.size()), lo, (lo + size).cwiseMin(cell + Vec3(19.5, 19.5, 19.5))));
    }
  if (parts.empty()) parts.push_back(box_part("p0", {5, 5, 5}, {8, 8, 8}));
  std::vector<CableInput> cables;
  const int nc = 2 + static_cast<int>(U(rng) * 2);
  for (int i = 0; i < nc; ++i) cables.push_back(random_cable(rng, i, 5, Vec3(60, 60, 20)));
  const double tol = 0.02;
  auto cert = run(cables, parts, ClashMethod::Certified, tol, IndexKind::Embree);
  auto disc = run(cables, parts, ClashMethod::Discrete, tol, IndexKind::Embree);
  // Oracle: pieces of 0.05 on curves of bend radius ≳ 1 deviate ≤ 0.0003.
  std::vector<OracleCable> oc;
  for (const auto& c : cables) oc.push_back(dense(c.curve, 0.05));
  const double oracle_err = 0.001;
  for (std::size_t c = 0; c < cables.size(); ++c) {
    for (std::size_t p = 0; p < parts.size(); ++p) {
      const double truth = oracle_structure(oc[c], cables[c].radius, parts[p]);
      const bool cert_hit = has_structure_clash(cert, static_cast<int>(c), static_cast<int>(p));
      const bool disc_hit = has_structure_clash(disc, static_cast<int>(c), static_cast<int>(p));
      if (truth < -tol - oracle_err) {
        ++g_miss.truth_clashes;
        if (!cert_hit) fail += "seed " + std::to_string(seed) + ": missed cable " + std::to_string(c) + " part " +
                               std::to_string(p) + " truth " + std::to_string(truth) + "\n";
        if (!disc_hit) ++g_miss.discrete_missed;
      }
      if (truth > tol + oracle_err && cert_hit)
        fail += "seed " + std::to_string(seed) + ": false clash cable " + std::to_string(c) + " part " +
                std::to_string(p) + " truth " + std::to_string(truth) + "\n";
    }
    for (std::size_t d = c; d < cables.size(); ++d) {
      const bool self = c == d;
      const double truth = oracle_pair(oc[c], cables[c].radius, oc[d], cables[d].radius, self,
                                       cables[c].radius + cables[d].radius + 1.0);
      const ClashKind k = self ? ClashKind::Self : ClashKind::CableCable;
      const bool cert_hit = find_clash(cert, k, static_cast<int>(c), static_cast<int>(d)) != nullptr;
      // Self contacts too are judged at the tolerance: the |s − t| ≥ π r rule is applied on
      // each chord pair exactly (closest points outside the excused band).
      if ((truth < -tol - oracle_err && !cert_hit) || (truth > tol + oracle_err && cert_hit))
        fail += "seed " + std::to_string(seed) + (self ? ": self " : ": pair ") + std::to_string(c) + "/" +
                std::to_string(d) + " truth " + std::to_string(truth) + " reported " + (cert_hit ? "yes" : "no") + "\n";
      if (!self && truth < -tol - oracle_err) {
        ++g_miss.truth_clashes;
        if (find_clash(disc, k, static_cast<int>(c), static_cast<int>(d)) == nullptr) ++g_miss.discrete_missed;
      }
    }
  }
  return fail;
}

RC_GTEST_PROP(ClashRandom, CertifiedMatchesOracle, ()) {
  const auto seed = *rc::gen::inRange<std::uint32_t>(0, 1u << 30);
  const std::string fail = random_scene_check(seed);
  RC_ASSERT(fail == "");
}

TEST(ClashRandom, DiscreteMissesAreCounted) {
  // Fixed seeds; the counts are printed so that the paper's failure is documented.
  g_miss = {};
  for (std::uint32_t seed = 1; seed <= 40; ++seed) EXPECT_EQ(random_scene_check(seed), "");
  std::printf("random scenes: %d true clashes, discrete missed %d\n", g_miss.truth_clashes, g_miss.discrete_missed);
  EXPECT_GT(g_miss.truth_clashes, 0);
  EXPECT_GT(g_miss.discrete_missed, 0) << "the discrete method is expected to miss some clashes";
}

// ---------------------------------------------------------------------------------------
// Cut-short sphere-tracing queries: the same report, bit for bit, as full queries.

/// Every field of two reports, compared exactly ("" when identical).
std::string report_difference(const ClashResult& x, const ClashResult& y) {
  if (x.clashes.size() != y.clashes.size()) return "clash count";
  for (std::size_t i = 0; i < x.clashes.size(); ++i) {
    const ClashEntry &a = x.clashes[i], &b = y.clashes[i];
    if (a.kind != b.kind || a.cable != b.cable || a.part != b.part || a.other != b.other ||
        a.clearance != b.clearance || a.point != b.point || a.s != b.s || a.s_other != b.s_other ||
        a.s_begin != b.s_begin || a.s_end != b.s_end || a.keep_out != b.keep_out || a.inside != b.inside)
      return "clash " + std::to_string(i);
  }
  if (x.violations.size() != y.violations.size()) return "violation count";
  for (std::size_t i = 0; i < x.violations.size(); ++i) {
    const Violation &a = x.violations[i], &b = y.violations[i];
    if (a.kind != b.kind || a.cable != b.cable || a.part != b.part || a.value != b.value || a.limit != b.limit ||
        a.s != b.s || a.point != b.point)
      return "violation " + std::to_string(i);
  }
  if (x.cables.size() != y.cables.size()) return "cable count";
  for (std::size_t i = 0; i < x.cables.size(); ++i) {
    const CableCheckSummary &a = x.cables[i], &b = y.cables[i];
    if (a.length != b.length || a.min_clearance != b.min_clearance || a.min_clearance_exact != b.min_clearance_exact ||
        a.min_bend_radius != b.min_bend_radius || a.min_bend_s != b.min_bend_s)
      return "cable summary " + std::to_string(i);
  }
  const ClashCounters &a = x.counters, &b = y.counters;
  if (a.distance_queries != b.distance_queries || a.inside_queries != b.inside_queries ||
      a.pair_tests != b.pair_tests || a.samples != b.samples)
    return "counters";
  return "";
}

/// The reference request of the comparisons below: certified at kTol, one thread, exact
/// sphere-tracing queries.
ClashRequest exact_request(double clearance) {
  ClashRequest req;
  req.tolerance = kTol;
  req.routing_clearance = clearance;
  req.threads = 1;
  req.distance_rel_error = 0.0;
  return req;
}

/// A scene with free stretches inside a closed part, a wall crossed, and parts passed at a
/// distance within and beyond the clearance band.
struct AuditScene {
  std::vector<Part> parts;
  std::vector<CableInput> cables;
};
AuditScene hull_and_parts_scene() {
  return {{box_part("hull", {-100, -100, -100}, {100, 100, 100}), box_part("wall", {150, -50, -50}, {154, 50, 50}),
           box_part("near", {200, 4, -5}, {260, 10, 5}), box_part("far", {300, 40, -5}, {360, 50, 5})},
          {straight_cable("A", {-60, 0, 0}, {400, 0, 0}, kR), straight_cable("B", {-300, 20, 0}, {500, 20, 0}, 2 * kR)}};
}

/// Random scene `seed`: 8 boxes in a 200 × 200 × 60 volume, then `spheres` closed UV
/// spheres of 96 × 48 facets, then 3 wandering cubic cables.
AuditScene random_audit_scene(std::uint32_t seed, int spheres) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(0, 1);
  AuditScene sc;
  for (int i = 0; i < 8; ++i) {
    const Vec3 lo(200 * U(rng), 200 * U(rng), 60 * U(rng));
    sc.parts.push_back(box_part("p" + std::to_string(i), lo, lo + Vec3(2 + 20 * U(rng), 2 + 20 * U(rng), 2 + 20 * U(rng))));
  }
  for (int i = 0; i < spheres; ++i) {
    const Vec3 c(200 * U(rng), 200 * U(rng), 60 * U(rng));
    sc.parts.push_back(testmesh::make_part("s" + std::to_string(i), testmesh::uv_sphere(c, 5 + 20 * U(rng), 96, 48), true));
  }
  for (int i = 0; i < 3; ++i) sc.cables.push_back(random_cable(rng, i, 6, Vec3(200, 200, 60)));
  return sc;
}

/// The certified audit with and without cut-short queries (same index, one thread), both
/// with exact sphere-tracing queries (approximate ones move the samples).
std::string cut_short_difference(const std::vector<CableInput>& cables, const std::vector<Part>& parts,
                                 double clearance) {
  const EmbreeIndex index(parts);
  ClashRequest req = exact_request(clearance);
  const ClashResult cut = check_clashes(cables, parts, &index, req);
  req.cut_short_queries = false;
  const ClashResult full = check_clashes(cables, parts, &index, req);
  return report_difference(cut, full);
}

TEST(ClashCutShort, FarCableKeepsItsSmallestSampledClearance) {
  // Every sample is farther from the box than its cut (thr + max_step / 2 ≈ 26): the
  // smallest sampled clearance comes from samples whose full query is run only at the end.
  const std::vector<Part> parts{box_part("box", {0, 0, 0}, {10, 10, 10})};
  const std::vector<CableInput> cables{straight_cable("C", {-300, 5, 60}, {300, 5, 60}, kR)};
  EXPECT_EQ(cut_short_difference(cables, parts, 0.0), "");
  const ClashResult r = run(cables, parts, ClashMethod::Certified, kTol);
  ASSERT_EQ(r.cables.size(), 1u);
  // Oracle: the exact clearance is 50 − r; samples are at most max_step = 50 r apart, so
  // the smallest sampled one is within 25 r (Lipschitz) of it along the cable.
  const double truth = oracle_structure(dense(cables[0].curve, 0.5), kR, parts[0]);
  EXPECT_NEAR(truth, 50.0 - kR, 1e-9);
  EXPECT_GE(r.cables[0].min_clearance, truth - kTol);
  EXPECT_LE(r.cables[0].min_clearance, std::hypot(50.0, 25.0 * kR) - kR + kTol);
  EXPECT_FALSE(r.cables[0].min_clearance_exact);
}

TEST(ClashCutShort, InsideAHullAndAlongPartsTheReportIsUnchanged) {
  // The depth of the free stretches inside the hull needs the full queries.
  const AuditScene sc = hull_and_parts_scene();
  for (double clearance : {0.0, 3.0}) EXPECT_EQ(cut_short_difference(sc.cables, sc.parts, clearance), "") << clearance;
}

TEST(ClashCutShort, RandomScenesGiveTheSameReport) {
  for (std::uint32_t seed = 1; seed <= 20; ++seed) {
    const AuditScene sc = random_audit_scene(seed, 0);
    EXPECT_EQ(cut_short_difference(sc.cables, sc.parts, seed % 2 == 0 ? 2.0 : 0.0), "") << "seed " << seed;
  }
}

/// The certified audit with (1 + ε)-approximate sphere-tracing queries against the exact
/// one: the same findings, each to the tolerance ("" when so, else what differs). Sample
/// positions differ, so stretch ends may move by one chord (≤ 2r) and the deepest point of
/// a stretch at constant depth may be another of its points; the smallest clearance of a
/// cable beyond the band is an upper bound in both (any sampled surface point).
std::string approximate_difference(const std::vector<CableInput>& cables, const std::vector<Part>& parts,
                                   double clearance, double rel_error, bool* samples_moved = nullptr,
                                   ClashCounters* approximate_counters = nullptr) {
  const EmbreeIndex index(parts);
  ClashRequest req = exact_request(clearance);
  const ClashResult x = check_clashes(cables, parts, &index, req);
  req.distance_rel_error = rel_error;
  const ClashResult y = check_clashes(cables, parts, &index, req);
  if (samples_moved) *samples_moved = x.counters.samples != y.counters.samples;
  if (approximate_counters) *approximate_counters = y.counters;
  if (x.counters.deferred_chords != 0) return "the exact audit deferred chords";
  if (x.clashes.size() != y.clashes.size())
    return "clash count " + std::to_string(x.clashes.size()) + " vs " + std::to_string(y.clashes.size());
  for (std::size_t i = 0; i < x.clashes.size(); ++i) {
    const ClashEntry &a = x.clashes[i], &b = y.clashes[i];
    const double chord = 2.0 * cables[a.cable].radius + kTol;
    if (a.kind != b.kind || a.cable != b.cable || a.part != b.part || a.other != b.other || a.keep_out != b.keep_out ||
        a.inside != b.inside || std::abs(a.clearance - b.clearance) > kTol || std::abs(a.s_begin - b.s_begin) > chord ||
        std::abs(a.s_end - b.s_end) > chord)
      return "clash " + std::to_string(i) + ": clearance " + full_precision(a.clearance) + " vs " +
             full_precision(b.clearance) + ", stretch " + full_precision(a.s_begin) + ".." + full_precision(a.s_end) +
             " vs " + full_precision(b.s_begin) + ".." + full_precision(b.s_end);
  }
  if (x.violations.size() != y.violations.size()) return "violation count";
  for (std::size_t i = 0; i < x.violations.size(); ++i) {
    const Violation &a = x.violations[i], &b = y.violations[i];
    if (a.kind != b.kind || a.cable != b.cable || a.part != b.part || std::abs(a.value - b.value) > kTol ||
        a.limit != b.limit)
      return "violation " + std::to_string(i) + ": " + full_precision(a.value) + " vs " + full_precision(b.value);
  }
  for (std::size_t i = 0; i < x.cables.size(); ++i) {
    const CableCheckSummary &a = x.cables[i], &b = y.cables[i];
    if (a.min_clearance_exact != b.min_clearance_exact || a.min_bend_radius != b.min_bend_radius)
      return "cable summary " + std::to_string(i);
    if (a.min_clearance_exact && std::abs(a.min_clearance - b.min_clearance) > kTol)
      return "cable " + std::to_string(i) + " min clearance " + full_precision(a.min_clearance) + " vs " +
             full_precision(b.min_clearance);
    if (!a.min_clearance_exact && (b.min_clearance < clearance - kTol) != (a.min_clearance < clearance - kTol))
      return "cable " + std::to_string(i) + " inexact min clearance on the wrong side of the band";
  }
  return "";
}

TEST(ClashApproximate, InsideAHullAndAlongPartsTheFindingsAreTheExactOnes) {
  const AuditScene sc = hull_and_parts_scene();
  for (double clearance : {0.0, 3.0})
    for (double eps : {0.1, 0.25, 1.0})
      EXPECT_EQ(approximate_difference(sc.cables, sc.parts, clearance, eps), "") << clearance << " eps " << eps;
}

TEST(ClashApproximate, RandomScenesGiveTheExactFindings) {
  // The cut-short scenes again, plus finely tessellated spheres (where the approximation
  // saves the most leaves and its bounds are loosest).
  int moved_scenes = 0;
  std::int64_t deferred = 0, measured = 0;
  for (std::uint32_t seed = 1; seed <= 20; ++seed) {
    const AuditScene sc = random_audit_scene(seed, 3);
    bool moved = false;
    ClashCounters counters;
    EXPECT_EQ(approximate_difference(sc.cables, sc.parts, seed % 2 == 0 ? 2.0 : 0.0, 0.25, &moved, &counters), "")
        << "seed " << seed;
    moved_scenes += moved ? 1 : 0;
    deferred += counters.deferred_chords;
    measured += counters.deferred_measured;
  }
  EXPECT_GE(moved_scenes, 10);  // the approximation did change the sampling: it was exercised
  // Chords in band were deferred, and some of them were never measured exactly (they could
  // not be the deepest of their stretch): the deferral was exercised both ways.
  EXPECT_GT(deferred, 0);
  EXPECT_GT(measured, 0);
  EXPECT_LT(measured, deferred);
}

TEST(ClashApproximate, RejectsABadRelativeError) {
  const std::vector<Part> parts{box_part("box", {0, 0, 0}, {10, 10, 10})};
  const std::vector<CableInput> cables{straight_cable("C", {-30, 5, 20}, {30, 5, 20}, kR)};
  const EmbreeIndex index(parts);
  ClashRequest req;
  for (double bad : {-0.5, std::numeric_limits<double>::infinity(), std::numeric_limits<double>::quiet_NaN()}) {
    req.distance_rel_error = bad;
    EXPECT_THROW(check_clashes(cables, parts, &index, req), std::invalid_argument) << bad;
  }
}

// ---------------------------------------------------------------------------------------
// `loom audit` through the binary: exit codes and report.json on tiny scenes.

namespace fs = std::filesystem;

struct CliRun {
  int status = -1;
  std::string report;  ///< report.json text ("" if not written)
};

CliRun loom_audit(const std::string& args, const std::string& tag) {
  const fs::path out = fs::temp_directory_path() / ("loom-test-audit-" + tag + "-" + std::to_string(::getpid()));
  fs::remove_all(out);
  const std::string cmd = std::string(LOOM_EXE) + " audit " + args + " --quiet --out " + out.string() + " 2>/dev/null";
  CliRun r;
  const int raw = std::system(cmd.c_str());
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  std::ifstream in(out / "report.json");
  if (in) {
    std::stringstream ss;
    ss << in.rdbuf();
    r.report = ss.str();
  }
  fs::remove_all(out);
  return r;
}

const std::string kAuditData = std::string(LOOM_TEST_DATA) + "/audit/";

TEST(AuditCli, CleanSceneExitsZeroWithAFullReport) {
  const CliRun r = loom_audit(kAuditData + "clean.toml", "clean");
  ASSERT_EQ(r.status, 0);
  ASSERT_FALSE(r.report.empty());
  EXPECT_EQ(r.report.find("null"), std::string::npos) << "no NaN/inf (written as null) in the report";
  const auto j = nlohmann::json::parse(r.report);
  EXPECT_EQ(j["scene"], "tiny-clean");
  EXPECT_EQ(j["units"], "mm");
  EXPECT_EQ(j["method"], "certified");
  EXPECT_DOUBLE_EQ(j["tolerance"].get<double>(), 0.01);  // radius 1 / 100
  EXPECT_DOUBLE_EQ(j["free_space_rel_error"].get<double>(), 0.25);  // ClashRequest's default
  EXPECT_TRUE(j["clashes"].empty());
  EXPECT_TRUE(j["violations"].empty());
  ASSERT_EQ(j["cables"].size(), 1u);
  EXPECT_EQ(j["cables"][0]["id"], "C1");
  EXPECT_TRUE(j["cables"][0]["routed"].get<bool>());
  EXPECT_NEAR(j["cables"][0]["length"].get<double>(), 50.0, 1e-9);
  for (const char* k : {"load", "index", "route", "check"}) EXPECT_TRUE(j["timing_ms"].contains(k)) << k;
  EXPECT_GT(j["counters"]["distance_queries"].get<long>(), 0);
}

TEST(AuditCli, ClashExitsOne) {
  for (const char* extra : {"", "--method discrete", "--no-index", "--method discrete --spacing 0.5 --threads 1"}) {
    const CliRun r = loom_audit(kAuditData + "clash.toml " + extra, "clash");
    ASSERT_EQ(r.status, 1) << extra;
    const auto j = nlohmann::json::parse(r.report);
    ASSERT_EQ(j["clashes"].size(), 1u) << extra;
    const auto& c = j["clashes"][0];
    EXPECT_EQ(c["kind"], "cable-structure");
    EXPECT_EQ(c["cable"], "C1");
    EXPECT_EQ(c["part"], "box");
    EXPECT_DOUBLE_EQ(c["clearance"].get<double>(), -1.0);  // axis inside: dist 0, clearance −r
    // Inside a closed part every point is equally deep (dist 0): s lies in the box.
    EXPECT_GE(c["s"].get<double>(), 20.0 - 1.0);
    EXPECT_LE(c["s"].get<double>(), 30.0 + 1.0);
    EXPECT_EQ(c["point"].size(), 3u);
  }
}

TEST(AuditCli, RoutesReplaceTheHarness) {
  EXPECT_EQ(loom_audit(kAuditData + "clean.toml --routes " + kAuditData + "harness_clash.xml", "routes").status, 1);
  EXPECT_EQ(loom_audit(kAuditData + "clash.toml --routes " + kAuditData + "harness_clear.xml", "routes2").status, 0);
}

TEST(AuditCli, BadInputExitsTwoAndWritesNothing) {
  const CliRun missing = loom_audit(kAuditData + "bad.toml", "bad");
  EXPECT_EQ(missing.status, 2);
  EXPECT_TRUE(missing.report.empty());
  EXPECT_EQ(loom_audit(kAuditData + "no-such-scene.toml", "nofile").status, 2);
  EXPECT_EQ(loom_audit(kAuditData + "clean.toml --method bogus", "method").status, 2);
  EXPECT_EQ(loom_audit(kAuditData + "clean.toml --method certified --no-index", "noidx").status, 2);
  EXPECT_EQ(loom_audit(kAuditData + "clean.toml --spacing -1", "spacing").status, 2);
  EXPECT_EQ(loom_audit(kAuditData + "clean.toml --routes " + kAuditData + "missing.xml", "noroutes").status, 2);
}

// Regression: the CLI ran out of memory on a route folding back on
// itself thousands of times; it exits 2 with the reason and writes no report.
TEST(AuditCli, ARouteFoldingBackOnItselfExitsTwoAndWritesNothing) {
  const fs::path dir = fs::temp_directory_path() / ("loom-test-fold-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  // The same file with `folds` folds: 2 folds audit (the file itself is good input), 6,000
  // are refused.
  auto write = [&](const std::string& name, int folds) {
    std::ofstream x(dir / name);
    x << R"(<?xml version="1.0" encoding="UTF-8"?>
<harness name="fold" units="mm">
  <attributes>
    <cable id="C1">
      <electrical><port id="J1"/><port id="J2"/></electrical>
      <physical type="AWG20" color="red" diameter="2" min_bend_radius="10"/>
    </cable>
  </attributes>
  <structure>
    <port id="J1" x="-20" y="30" z="40" dx="1" dy="0" dz="0"/>
    <port id="J2" x="30" y="30" z="40" dx="-1" dy="0" dz="0"/>
    <segment from="J1" to="J2">
      <path interp="polyline">)";
    for (int i = 0; i <= folds; ++i) x << "<pt x=\"" << 1e-3 * i << "\" y=\"" << ((i % 2) ? 80 : 30) << "\" z=\"40\"/>";
    x << R"(</path>
    </segment>
  </structure>
</harness>
)";
  };
  write("fold.xml", 6000);
  write("fold2.xml", 2);
  const CliRun few = loom_audit(kAuditData + "clean.toml --routes " + (dir / "fold2.xml").string(), "fold2");
  EXPECT_NE(few.status, 2);
  EXPECT_FALSE(few.report.empty());
  for (const char* method : {"certified", "discrete"}) {
    const CliRun r = loom_audit(kAuditData + "clean.toml --routes " + (dir / "fold.xml").string() + " --method " + method,
                                std::string("fold-") + method);
    EXPECT_EQ(r.status, 2) << method;
    EXPECT_TRUE(r.report.empty()) << method;
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace loom
