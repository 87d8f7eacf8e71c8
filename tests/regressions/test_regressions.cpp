// One test per bug found, with the inputs that exposed it written out in full so that the
// case replays without the generator or seed that found it. Name: area, what broke.
// Bugs of the command line are replayed where the command runs: tests/app/test_cli.cpp,
// CliRegression.* (e.g. given option values taken for "use the default").
// Bad-input regressions replayed elsewhere: CliRegression.NumbersBeyondAnySceneAreRefused,
// .TessellationFinerThanTheFileCanHoldIsExitTwo, .LongPartNamesGiveValidFilesAndQuietStaysQuiet
// (tests/app/test_cli.cpp) and ClashCheck.ARouteWigglingAtTheToleranceIsRefusedNotFlattened
// (tests/routing/test_clash_check.cpp).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "core/centerline.hpp"
#include "core/mesh.hpp"
#include "core/io/mesh_read.hpp"
#include "core/part.hpp"
#include "index/simplify/alpha_sim.hpp"
#include "index/box_pairs.hpp"
#include "index/embree_index.hpp"
#include "index/simplify/extrusion.hpp"
#include "routing/audit/chord_plan.hpp"
#include "routing/audit/clash_check.hpp"
#include "routing/curve/sweep.hpp"

#include "common/brute_geometry.hpp"
#include "common/shared_data.hpp"
#include "index/index_test_meshes.hpp"

namespace {

using loom::Centerline;
using loom::Vec3;

double angle(const Vec3& a, const Vec3& b) { return std::atan2(a.cross(b).norm(), a.dot(b)); }

/// The mesh file `rel` of ../shared/data as a part named `name`.
loom::Part shared_part(const char* name, const char* rel) {
  loom::Part p;
  p.name = name;
  p.mesh = loom::read_mesh_file(std::filesystem::path(LOOM_SHARED_DATA) / rel);
  return p;
}

// SweepProperty (RapidCheck, random seed) found a step
// where the double-reflection normal turned 1e-7 rad more than the tangent (0.0217073 vs
// 0.0217072). Not a sweep bug: double reflection approximates the rotation-minimising
// frame with an O(turn³) local error; the property's bound was too tight. The frame must
// stay within that order, and the tube must stay closed.
TEST(Regression, SweepDoubleReflectionTurnsWithinThirdOrderOfTheTangent) {
  // The original falsifying input (-64,-42,21, -77,1,-79, -23,39,-79, -23,-43,-84,
  // 29,-100,-67, 28,-12,-83; r = 0.15) stopped reaching its case when ring placement began
  // to predict steps from the curvature change (smaller first step); this input reaches it
  // with the current placement (excess 3.6e-8 at a turn of 0.077).
  const std::vector<int> c = {26, -11, -20, 5, -55, 78, 9, 100, 52, -51, -45, 11, 48, 14, -56, 11, -8, -47, -89, 54, 73, 18, -22, 10};
  std::vector<Vec3> p;
  for (std::size_t i = 0; i + 2 < c.size(); i += 3) p.emplace_back(c[i] * 0.1, c[i + 1] * 0.1, c[i + 2] * 0.1);
  const Centerline line = Centerline::interpolate(p);
  const double r = 0.05 + 0.01 * 6;
  const auto sec = loom::tube_sections(line, r, {0.02, true});
  ASSERT_GT(sec.size(), 2u);
  double worst_excess = 0.0;
  for (std::size_t i = 1; i < sec.size(); ++i) {
    const double turn = angle(sec[i - 1].tangent, sec[i].tangent);
    const double excess = angle(sec[i - 1].normal, sec[i].normal) - turn;
    EXPECT_LE(excess, turn * turn * turn + 1e-9) << "section " << i << " turn " << turn;
    worst_excess = std::max(worst_excess, excess);
  }
  // The case is only a regression test if it still exercises the excess it was found for.
  EXPECT_GT(worst_excess, 1e-9);
}

// BoxPairs.EqualsBruteForce (RapidCheck) aborted the process in
// Embree's BVH builder (assertion `diag[dim] > 0.0f`, heuristic_openmerge_array.h) on two
// equal point boxes: re-centred on their own centre, they rounded to float boxes of zero
// size (denormals flushed). The broad phase pads every float box outwards by a normal
// float length, so no set of boxes has zero extent.
TEST(Regression, BoxPairsTwoEqualPointBoxesDoNotAbortTheBuilder) {
  for (const Vec3& p : {Vec3(0, 0, 0), Vec3(1, 1, 1), Vec3(0.1, -2.5, 7.0)}) {
    loom::AABB b;
    b.min = b.max = p;
    const auto pairs = loom::overlapping_box_pairs({b, b}, 2);
    ASSERT_EQ(pairs.size(), 1u);
    EXPECT_EQ(pairs[0], loom::BoxPair(0, 1));
  }
}

/// The closed unit box [0, 1]³ as a part (12 triangles, outward).
loom::Part unit_box_part() {
  loom::Part p;
  p.name = "unit_box";
  p.closed = true;
  for (int k = 0; k < 8; ++k) p.mesh.vertices.push_back(Vec3(k & 1, (k >> 1) & 1, (k >> 2) & 1));
  const std::uint32_t q[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& f : q) {
    p.mesh.triangles.push_back({f[0], f[1], f[2]});
    p.mesh.triangles.push_back({f[0], f[2], f[3]});
  }
  return p;
}

// The segment_closest_approx test (brute force oracle) found
// that a segment through a surface was "not found" with max_radius 0: the search keeps a
// hit only if it beats best² = radius², and 0 does not beat 0. A hit equal to the caller's
// radius counts while nothing has been found (brute force already did so).
TEST(Regression, EmbreeSegmentThroughASurfaceIsFoundWithRadiusZero) {
  const loom::EmbreeIndex e({unit_box_part()});
  const loom::ClosestHit h = e.segment_closest(Vec3(0.5, 0.5, -1.0), Vec3(0.5, 0.5, 2.0), 0.0);
  ASSERT_TRUE(h.found());
  EXPECT_EQ(h.distance, 0.0);
  EXPECT_TRUE(e.segment_closest_on_part(Vec3(0.5, 0.5, -1.0), Vec3(0.5, 0.5, 2.0), 0, 0.0).found());
}

// The first segment_closest_approx
// shrank the search sphere to max_radius / (1 + ε) before any hit, so a surface between
// the two was lost and "nothing within max_radius" came out wrong (the audit's approximate
// run then ended a contact stretch early, ClashApproximate.InsideAHull…). A short segment
// 1.0 above a plate of 8,192 triangles (enough for a BVH below the root: the callback's own
// box test, unshrunk, would catch it in a root leaf), radius 1.1, ε = 1: the shrunk sphere
// (0.05 + 0.55) missed the plate.
TEST(Regression, EmbreeApproximateSegmentQueryKeepsTheCallersRadiusUntilAHit) {
  loom::Part plate;
  plate.name = "plate";
  const int n = 64;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) plate.mesh.vertices.push_back(Vec3(double(i) / n, double(j) / n, 1.0));
  const auto id = [&](int i, int j) { return static_cast<std::uint32_t>(j * (n + 1) + i); };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      plate.mesh.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      plate.mesh.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  const loom::EmbreeIndex e({plate});
  const loom::ClosestHit h = e.segment_closest_approx(Vec3(0.5, 0.5, 2.0), Vec3(0.6, 0.5, 2.0), 1.1, 1.0);  // plate at z = 1
  ASSERT_TRUE(h.found());
  EXPECT_GE(h.distance, 1.0 - 1e-6);  // a surface point, within the radius
  EXPECT_LE(h.distance, 1.1);
}

// Found while writing extrusion_pair_mesh (not landed): the grown outline of a 48-sided
// cylinder seen end on has two vertices whose x differ by one rounding step
// (3.8834821936197748 and ...752), so the slab between those heights had no double
// strictly inside. Its midpoint equalled one end, the edge ending there was not counted as
// crossing it, the slab came out empty, and the solid got an internal crack of width
// 4e-16 (two full cross-sections facing away from each other), measured as a Hausdorff
// distance of 1.11 against 0.25. Spanning is decided from the edges' ends.
TEST(Regression, ExtrusionPairSlabOneRoundingStepThickKeepsItsMaterial) {
  using loom::Extrusion;
  using loom::PolygonWithHoles2;
  using loom::Vec2;
  Extrusion xy;  // u = x, v = y, n = z
  xy.depth_min = 0;
  xy.depth_max = 20;
  const double r[][2] = {{-4.6998064879820269, -1.9467373520048534}, {-3.7835190904341873, -3.3180565361232524},
                         {-2.2845623299736051, -4.6326075317266646}, {-1.6653345369377348e-15, -5.0870446340321855},
                         {1.9467373520048532, -4.6998064879820278},  {3.8834821936197748, -3.4057132446366323},
                         {5.0660457239771155, -1.0076964768729766},  {4.9137077307296124, 1.3166093198595945},
                         {3.8834821936197752, 3.4057132446366318},   {1.9467373520048532, 4.6998064879820278},
                         {-1.6653345369377348e-15, 5.0870446340321855}, {-2.2845623299736051, 4.6326075317266646},
                         {-3.7835190904341873, 3.3180565361232524},  {-4.6998064879820278, 1.9467373520048532},
                         {-5.0870446340321855, -1.8873791418627661e-15}};
  PolygonWithHoles2 outline;
  for (const auto& q : r) outline.outer.emplace_back(q[0], q[1]);
  xy.polygons = {outline};
  Extrusion xz;
  xz.u = Vec3::UnitX();
  xz.v = Vec3::UnitZ();
  xz.n = -Vec3::UnitY();
  xz.depth_min = -5;
  xz.depth_max = 5;
  xz.polygons = {PolygonWithHoles2{{Vec2(-5, 0), Vec2(5, 0), Vec2(5, 20), Vec2(-5, 20)}, {}}};
  const loom::ExtrusionsMesh pm = loom::extrusion_pair_mesh(xy, xz);
  // No face across the solid: every triangle lies on the outline's walls, the planes
  // |x| = 5, |y| = 5 or the ends z = 0, 20.
  for (const auto& t : pm.mesh.triangles) {
    const Vec3 c = (pm.mesh.vertices[t[0]] + pm.mesh.vertices[t[1]] + pm.mesh.vertices[t[2]]) / 3.0;
    const bool end = std::abs(c.z()) < 1e-9 || std::abs(c.z() - 20.0) < 1e-9;
    const bool side = std::abs(std::abs(c.x()) - 5.0) < 1e-9 || std::abs(std::abs(c.y()) - 5.0) < 1e-9 ||
                      std::hypot(c.x(), c.y()) > 4.9;
    EXPECT_TRUE(end || side) << "triangle inside the solid at " << c.transpose();
  }
  EXPECT_GT(pm.mesh.signed_volume(), 0.0);
}

// α-SIM's CGAL corefinement (the third prism) gave the same solid
// with its vertices and triangles in a different order about one run in three
// (AlphaSim.DeterministicAcrossRuns under ctest). CGAL's box intersection breaks ties of
// equal box bounds by box address, so the intersection points were numbered in heap
// order. mesh_intersection sorts its output; here the heap is disturbed between runs.
TEST(Regression, AlphaSimCorefinementOrderDoesNotFollowTheHeap) {
  LOOM_SHARED_DATA_OR_SKIP(loom::testing::shared_data(""));
  loom::Part motor;
  motor.name = "motor";
  motor.mesh = loom::read_mesh_file(std::filesystem::path(LOOM_SHARED_DATA) / "occt/motor.stl");
  motor.closed = true;
  loom::AlphaSimOptions o;
  o.dim_pre = 0.06 * motor.mesh.bounds().diagonal();
  o.measure = false;
  const loom::AlphaSimPart first = loom::simplify_part(motor, o);
  ASSERT_EQ(first.result.booleans_by, "cgal");
  std::vector<std::unique_ptr<char[]>> clutter;
  for (int run = 0; run < 6; ++run) {
    for (int k = 0; k < 50; ++k) clutter.emplace_back(new char[static_cast<std::size_t>(64 + 97 * ((run * 50 + k) % 13))]);
    const loom::AlphaSimPart again = loom::simplify_part(motor, o);
    ASSERT_EQ(again.mesh.triangles, first.mesh.triangles) << "run " << run;
    ASSERT_EQ(again.mesh.vertices.size(), first.mesh.vertices.size());
    for (std::size_t i = 0; i < first.mesh.vertices.size(); ++i)
      ASSERT_EQ(again.mesh.vertices[i], first.mesh.vertices[i]) << "run " << run << " vertex " << i;
  }
}

// Two turned boxes apart (AlphaSimProperty, comparing CGAL's
// corefinement with OpenCASCADE's Booleans as its oracle): OpenCASCADE's result, 424 mm³
// (528 in another run), lost a piece of the prisms' intersection that the implicit solid
// holds (~12k of 400k random points inside the implicit solid and outside the mesh);
// CGAL's is 580.5 mm³ and holds it. The lost piece holds no surface of the boxes, so the
// containment check passed: the error was silent. With the outlines not grown
// (polygon_growth_factor 0) both give 580.48. CGAL runs the Booleans unless STEP output is
// asked for; this checks that its mesh holds the implicit solid on this input.
TEST(Regression, AlphaSimMeshHoldsTheImplicitSolidOfTwoTurnedBoxes) {
  loom::Part boxes;
  boxes.name = "boxes";
  boxes.mesh.vertices = {Vec3(0.29410672942554594, 8.0909067226088602, 12.508026608452244),Vec3(3.4251289467246071, 10.286102190464078, 11.334222224115747),Vec3(2.9431745245839513, 11.118991078406205, 11.606281106201214),Vec3(-0.18784769271510982, 8.9237956105509877, 12.780085490537711),Vec3(-2.0681998504875434, 8.5200600083049771, 7.0093599446258619),Vec3(-2.5501542726281992, 9.3529488962471046, 7.2814188267113291),Vec3(0.58086794467086178, 11.548144364102322, 6.1076144423748318),Vec3(1.0628223668115175, 10.715255476160195, 5.8355555602893645),Vec3(10.7646917522595, 4.4611491909969176, 1.104336621915555),Vec3(19.43838811592197, 8.7946873702589752, -1.3425876188133072),Vec3(15.512943363225308, 17.774453803845489, 0.646049676361236),Vec3(6.8392469995628371, 13.440915624583434, 3.0929739170900987),Vec3(9.5410660000287191, 4.7668919971882628, -2.6916166648017481),Vec3(5.6156212473320561, 13.746658430774779, -0.70297936962720464),Vec3(14.289317610994527, 18.080196610036836, -3.1499036103560671),Vec3(18.21476236369119, 9.1004301764503204, -5.1385409055306104)};
  boxes.mesh.triangles = {{0,1,2},{0,2,3},{4,5,6},{4,6,7},{4,0,3},{4,3,5},{7,6,2},{7,2,1},{4,7,1},{4,1,0},{5,3,2},{5,2,6},{8,9,10},{8,10,11},{12,13,14},{12,14,15},{12,8,11},{12,11,13},{15,14,10},{15,10,9},{12,15,9},{12,9,8},{13,11,10},{13,10,14}};
  boxes.closed = true;
  loom::AlphaSimOptions o;
  o.dim_pre = 2.0;
  o.detect_lost_space = false;
  o.containment_max_samples = 20000;
  const loom::AlphaSimPart sp = loom::simplify_part(boxes, o);
  ASSERT_EQ(sp.result.booleans_by, "cgal");
  EXPECT_DOUBLE_EQ(sp.result.containment, 1.0);
  ASSERT_TRUE(sp.solid);
  std::vector<loom::Part> mesh(1);
  mesh[0].name = "mesh";
  mesh[0].mesh = sp.mesh;
  mesh[0].closed = true;
  const loom::EmbreeIndex index(mesh);
  const loom::AABB box = sp.mesh.bounds();
  std::mt19937_64 rng(5);
  int outside = 0, inside = 0;
  for (int k = 0; k < 100000; ++k) {
    Vec3 q;
    for (int c = 0; c < 3; ++c) q[c] = std::uniform_real_distribution<double>(box.min[c], box.max[c])(rng);
    if (!sp.solid->contains(q)) continue;
    ++inside;
    if (!index.inside(q) && !index.closest(q, sp.result.tolerance).found()) ++outside;
  }
  EXPECT_GT(inside, 1000);
  EXPECT_EQ(outside, 0);
}

// The bunny at dim_pre = 2% of its diagonal ended with all three
// projections replaced by their convex hulls ("eroded"). Each verification round found
// one to six fresh random samples 1.2–70× the tolerance outside a shape, in slivers that
// silhouette triangles (seen nearly edge-on) project to between the lattice nodes; each
// repair closed the points found, the next round found others, and after three rounds
// the plane became its hull. The slivers' edges are checked exactly (segment_gaps)
// and every triangle is tested whole against every shape (AlphaShape2D::triangle_gaps), so
// no plane depends on random samples to be repaired.
TEST(Regression, AlphaSimBunnyIsNotThreeConvexHulls) {
  LOOM_SHARED_DATA_OR_SKIP(loom::testing::shared_data(""));
  const loom::Part bunny = shared_part("bunny", "trimesh/bunny.ply");
  loom::AlphaSimOptions o;
  o.dim_pre = 0.02 * bunny.mesh.bounds().diagonal();
  const loom::AlphaSimPart sp = loom::simplify_part(bunny, o);
  EXPECT_EQ(sp.result.status, loom::AlphaSimStatus::Ok) << sp.result.reason;
  for (const auto& p : sp.result.projections) {
    EXPECT_NE(p.status, loom::ProjectionStatus::Eroded) << p.plane;
    EXPECT_LT(p.area, p.hull_area) << p.plane;  // not the hull
  }
  EXPECT_DOUBLE_EQ(sp.result.containment, 1.0);
  EXPECT_LE(sp.result.triangles_after, bunny.mesh.triangle_count() / 10);
}

// The actuator's CAD file tessellated at 0.01 mm / 2.5° (94,586
// triangles) came out with 544 triangles (644 in the bench, at its scene size) where ~280
// do: after the third outline's
// corefinement, faces whose boundary touches itself (a vertex used twice, or two copies of
// a vertex at one point) kept every triangle and vertex, since their boundary could not be
// walked as loops. merge_face_vertices gives the triangulation the boundary's chords
// between kept vertices as constraints, which needs no loops (the wing's files at that
// tessellation: 1,344 -> 980 triangles).
TEST(Regression, AlphaSimFacesTouchingThemselvesAreMerged) {
  loom::TessellationParams tp;
  tp.linear_deflection = 0.01;
  tp.angular_deflection_deg = 2.5;
  loom::Part actuator;
  actuator.name = "actuator";
  for (const auto& nm :
       loom::read_cad_file(std::filesystem::path(LOOM_SOURCE_DIR) / "examples/wing-section/actuator.step", tp, false))
    actuator.mesh.append(nm.mesh);
  actuator.closed = loom::analyse_topology(actuator.mesh).closed;
  ASSERT_GT(actuator.mesh.triangle_count(), 90000u);
  loom::AlphaSimOptions o;
  o.dim_pre = 8.0;  // the scene's
  o.scene_size = 3000.0;
  o.measure = false;
  const loom::AlphaSimPart sp = loom::simplify_part(actuator, o);
  ASSERT_EQ(sp.result.status, loom::AlphaSimStatus::Ok) << sp.result.reason;
  EXPECT_EQ(sp.result.booleans_by, "cgal") << sp.result.booleans_note;
  EXPECT_LE(sp.result.triangles_after, 320u);
  EXPECT_TRUE(sp.result.closed_after);
}

}  // namespace

// A random-sample verification (4 samples per L_max², fresh ones each round) passed shapes
// that did not hold every triangle of the part: on the bunny at dim_pre = 4% of its
// diagonal the implicit solid left 4 of 209,916 points of a lattice on the triangles
// (L_max/4 apart, corners and edges included) outside by more than the tolerance: slivers
// the random samples, a few per L_max², never fell in. Every triangle is now tested whole
// against every shape (AlphaShape2D::triangle_gaps) and what is found is repaired.
TEST(Regression, AlphaSimRandomSamplesMissedSliversOfTheSurface) {
  LOOM_SHARED_DATA_OR_SKIP(loom::testing::shared_data(""));
  const loom::Part bunny = shared_part("bunny", "trimesh/bunny.ply");
  loom::AlphaSimOptions o;
  o.dim_pre = 0.04 * bunny.mesh.bounds().diagonal();
  const loom::AlphaSimPart sp = loom::simplify_part(bunny, o);
  EXPECT_EQ(sp.result.status, loom::AlphaSimStatus::Ok) << sp.result.reason;
  EXPECT_DOUBLE_EQ(sp.result.containment, 1.0);
  ASSERT_TRUE(sp.solid);
  std::size_t out = 0, points = 0;
  for (const auto& f : bunny.mesh.triangles) {
    const loom::Vec3 a = bunny.mesh.vertices[f[0]], b = bunny.mesh.vertices[f[1]], c = bunny.mesh.vertices[f[2]];
    const double longest = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
    const int n = std::max(1, static_cast<int>(std::ceil(longest / (sp.result.l_max / 4.0))));
    for (int i = 0; i <= n; ++i)
      for (int j = 0; i + j <= n; ++j, ++points)
        out += sp.solid->contains(a + (b - a) * (double(i) / n) + (c - a) * (double(j) / n), sp.result.tolerance) ? 0 : 1;
  }
  EXPECT_GT(points, 200000u);
  EXPECT_EQ(out, 0u);
}

// fill_pinches visited the pinched vertices in the order of their
// handles (heap addresses), and filling around one vertex changes its neighbours, so the
// same part came out differently as the heap moved: the tube at 1% of its diagonal gave
// 152 or 168 triangles, from run to run and within one process. The vertices are
// visited in the order of their points. Memory held between the runs moves the heap.
TEST(Regression, AlphaSimPinchFillsDoNotFollowTheHeap) {
  LOOM_SHARED_DATA_OR_SKIP(loom::testing::shared_data(""));
  const loom::Part tube = shared_part("tube", "trimesh/tube.obj");
  loom::AlphaSimOptions o;
  o.dim_pre = 0.01 * tube.mesh.bounds().diagonal();
  o.measure = false;
  const loom::AlphaSimPart first = loom::simplify_part(tube, o);
  std::vector<std::unique_ptr<char[]>> held;
  for (int run = 1; run < 12; ++run) {
    held.emplace_back(new char[static_cast<std::size_t>(run * 7919 % 200000 + 1000)]);
    const loom::AlphaSimPart again = loom::simplify_part(tube, o);
    EXPECT_EQ(again.result.triangles_after, first.result.triangles_after) << "run " << run;
    EXPECT_TRUE(again.mesh.vertices == first.mesh.vertices && again.mesh.triangles == first.mesh.triangles)
        << "run " << run;
  }
}

// With one ray per inside test (what α-SIM wanted for its
// watertight output, 3× fewer rays), α-SIM's containment check found 0.9999931 of the
// motor's samples inside (CgalBooleansGiveTheSolidOfOpenCascade). Embree's float ray test
// put crossings that lie 1e-5..6e-3 of a triangle's width from a shared edge (more than the
// barycentric grazing margin, 1e-6) on the neighbouring triangle, whose exact test then
// missed, or on neither: the crossing was lost and the parity flipped. The majority of
// three rays had hidden it. A crossing within the float rounding of the ray test (the
// culling pad, over the cosine of the incidence) of an edge grazes, and when every ray
// grazes the winding number decides. Four points that one ray classified wrongly: a fine
// sphere (96 × 48) with a box 4000 units away, so the index centre is 2000 away from it.
TEST(Regression, EmbreeOneRayInsideKeepsCrossingsNearSharedEdges) {
  using loom::testmesh::box;
  using loom::testmesh::uv_sphere;
  std::vector<loom::Part> parts(2);
  parts[0].name = "fine";
  parts[0].mesh = uv_sphere(Vec3::Zero(), 1.0, 96, 48);
  parts[0].closed = true;
  parts[1].name = "far";
  parts[1].mesh = box(Vec3::Constant(4000), Vec3::Constant(4001));
  parts[1].closed = true;
  loom::EmbreeOptions one;
  one.inside_rays = 1;
  const loom::EmbreeIndex e(parts, one);
  const struct {
    Vec3 p;
    bool inside;
  } cases[] = {{Vec3(0.43480167302257899, -0.96345855721236473, -0.41832604705775012), false},
               {Vec3(-0.17824256649075543, -0.55859443028242328, 0.067049945044918235), true},
               {Vec3(0.18683456229730644, -0.76237505427020036, -0.64231826484776589), false},
               {Vec3(0.52977313759478561, 0.08655659338384547, 0.4868321903933317), true}};
  for (const auto& c : cases) EXPECT_EQ(e.inside(c.p), c.inside) << c.p.transpose();
}

// A direct test of chord flattening (tests/routing/test_chord_plan)
// found chords up to 2.9× longer than the longest allowed (kMaxChordRadii · r, which keeps
// the self rule |s − t| ≥ πr sharp): a span was cut into its arc length / hmax chords
// uniformly in u, so where the speed varies along the span the fast end's chords were
// longer. The count comes from a bound on |C'| over the span (length_chords). One
// span whose speed grows from 3 to 294: 50 chords before, the last ~5.9 long.
TEST(Regression, ChordsStayWithinTheLongestAllowedWhereTheSpeedVaries) {
  const Centerline c(3, {0, 0, 0, 0, 1, 1, 1, 1}, {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(2, 0, 0), Vec3(100, 0, 0)});
  const double hmax = 2.0, eps = 1.0;
  loom::Chords ch;
  loom::flatten(c, c.u_min(), c.u_max(), eps, hmax, 0.0, ch);
  ASSERT_GE(ch.size(), 50u);
  for (std::size_t k = 0; k < ch.size(); ++k) EXPECT_LE((ch.p[k + 1] - ch.p[k]).norm(), hmax) << "chord " << k;
  EXPECT_EQ(static_cast<double>(ch.size()), loom::planned_chords(c, eps, hmax, 0.0));
}

// --- the certified audit on adversarial routes (tests/routing/audit/test_clash_adversarial.cpp).

namespace {

std::string regression_g17(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

loom::CableInput regression_cable(const char* id, const std::vector<Vec3>& polyline, double r) {
  loom::CableInput c;
  c.id = id;
  c.curve = Centerline::polyline(polyline);
  c.radius = r;
  return c;
}

loom::ClashResult regression_audit(const std::vector<loom::CableInput>& cables, const std::vector<loom::Part>& parts,
                                   double tol) {
  const loom::EmbreeIndex index(parts);
  loom::ClashRequest req;
  req.tolerance = tol;
  req.threads = 2;
  return loom::check_clashes(cables, parts, &index, req);
}

}  // namespace

// The certified self pass dropped a chord pair whenever its closest points were less than
// π r apart along the cable, although other points of the same two chords, π r or more
// apart, were in contact. Beside a fold that is where the contact is deepest: a V of 60°
// (legs of 10 r, chords ending at the corner) touches itself at clearance
// π r sin 30° − 2 r = −0.429 r exactly π r from the corner along both legs, and the audit
// reported −2e-16 (the 45° V: −0.586 for −0.798). Such a pair is measured at its
// closest points at least π r apart (on the band's edge |s − t| = π r).
TEST(Regression, SelfContactBesideAFoldWasExcusedWithTheFold) {
  const double r = 1.0, tol = 0.01, theta = M_PI / 3.0;
  const std::vector<Vec3> v{Vec3(10, 0, 0), Vec3::Zero(), 10.0 * Vec3(std::cos(theta), std::sin(theta), 0)};
  const std::vector<loom::Part> far{loom::testmesh::box_part("far", Vec3::Constant(1000), Vec3::Constant(1001))};
  const loom::ClashResult res = regression_audit({regression_cable("V", v, r)}, far, tol);
  const double truth = M_PI * r * std::sin(0.5 * theta) - 2.0 * r;
  const std::string in = "V (10,0,0) (0,0,0) (" + regression_g17(v[2].x()) + ", " + regression_g17(v[2].y()) +
                         ", 0) r " + regression_g17(r) + " tol " + regression_g17(tol);
  ASSERT_EQ(res.clashes.size(), 1u) << in;
  EXPECT_EQ(res.clashes[0].kind, loom::ClashKind::Self) << in;
  EXPECT_NEAR(res.clashes[0].clearance, truth, tol) << in << " reported " << regression_g17(res.clashes[0].clearance);
}

// The certified structure pass kept one inside part, the first the index named: a cable
// whose axis lay inside two overlapping closed parts (a keep-out zone drawn around a box)
// clashed with one of them only — or, crossing into the inner one, had the outer one's
// stretch cut in two. Every closed part holding the axis is tracked.
TEST(Regression, CableInsideTwoOverlappingClosedPartsClashedWithOneOnly) {
  const std::vector<loom::Part> parts{loom::testmesh::box_part("a", Vec3(-100, -100, -100), Vec3(60, 100, 100)),
                                      loom::testmesh::box_part("b", Vec3(-60, -100, -100), Vec3(100, 100, 100))};
  const loom::ClashResult res = regression_audit({regression_cable("C", {Vec3(-20, 0, 0), Vec3(20, 0, 0)}, 1.0)}, parts, 0.01);
  ASSERT_EQ(res.clashes.size(), 2u) << "cable (-20,0,0)-(20,0,0) r 1 in boxes a [-100,60]x[-100,100]^2 and b [-60,100]x[-100,100]^2";
  EXPECT_EQ(res.clashes[0].part + res.clashes[1].part, 1);
  for (const auto& e : res.clashes) EXPECT_TRUE(e.inside);
}

// A proven-clear stretch inside a closed part was recorded at its first sample only, so a
// clash stretch running to the cable's end inside a part ended at the last sample of the
// sphere trace, up to its longest step (50 r) short: s_end 270.85 for 310.
TEST(Regression, InsideStretchEndedAtTheLastProvenClearSample) {
  const std::vector<loom::Part> parts{loom::testmesh::box_part("hull", Vec3(0, -200, -200), Vec3(400, 200, 200))};
  const loom::ClashResult res =
      regression_audit({regression_cable("C", {Vec3(-10, 0, 0), Vec3(300, 0, 0)}, 1.0)}, parts, 0.01);
  ASSERT_EQ(res.clashes.size(), 1u);
  EXPECT_NEAR(res.clashes[0].s_end, 310.0, 2.0) << "cable (-10,0,0)-(300,0,0) r 1 in [0,400]x[-200,200]^2, s_end "
                                                << regression_g17(res.clashes[0].s_end);
}

// The certified cable–cable pass dropped a chord pair whenever its closest points were
// excused (both in one bundle segment, or both within a shared junction's radius),
// although other points of the same two chords, outside the excused region, were in
// contact. Where two cables part at a junction still touching, the clash is deepest just
// outside the junction's ball: B leaving A at 5° from a branch point J of radius 3 touches
// it at clearance −0.252 r on the ball's edge, and the audit reported −0.167 r (leaving a
// bundle segment without a junction, −0.5 r: missed). Such a pair is measured at its
// closest points outside the excused region.
TEST(Regression, ContactLeavingAJunctionWasExcusedWithItsClosestPoints) {
  const double r = 1.0, tol = 0.01, slope = std::tan(5.0 * M_PI / 180.0), jr = 3.0;
  loom::CableInput a = regression_cable("A", {Vec3(-0.37, 0, 0), Vec3(40, 0, 0), Vec3(80, 0, 0)}, r);
  loom::CableInput b = regression_cable("B", {Vec3(0, 1.5, 0), Vec3(40, 1.5, 0), Vec3(80, 1.5 + 40 * slope, 0)}, r);
  a.segments = {{3, 0.0, 40.37}, {4, 40.37, 80.37}};
  b.segments = {{3, 0.0, 40.0}, {5, 40.0, b.curve.length()}};
  a.junctions = {{"J", Vec3(40, 0.75, 0), jr}};
  b.junctions = a.junctions;
  // Closed form: B's point (x, 1.5 + (x − 40)·slope) where it leaves J's ball, against A's
  // axis y = 0 — the deepest contact outside the excused region to within 1e-4 r (pairs
  // with A's point just outside the ball instead come within 3e-5 of it).
  const double x = 40.0 + (-(0.75 * slope) + std::sqrt(0.75 * 0.75 * slope * slope + (1 + slope * slope) * (jr * jr - 0.5625))) /
                              (1 + slope * slope);
  const double truth = 1.5 + (x - 40.0) * slope - 2.0 * r;
  const std::vector<loom::Part> far{loom::testmesh::box_part("far", Vec3::Constant(1000), Vec3::Constant(1001))};
  const loom::ClashResult res = regression_audit({a, b}, far, tol);
  const std::string in = "A (-0.37,0,0) (40,0,0) (80,0,0); B (0,1.5,0) (40,1.5,0) (80, " +
                         regression_g17(1.5 + 40 * slope) + ", 0); r 1; junction (40,0.75,0) radius 3; truth " +
                         regression_g17(truth);
  ASSERT_EQ(res.clashes.size(), 1u) << in;
  EXPECT_NEAR(res.clashes[0].clearance, truth, tol) << in << " reported " << regression_g17(res.clashes[0].clearance);
}

// The certified structure pass excused an observation of a part the cable is attached to
// (its connector) when the observation's point lay within the port's exit range, and the
// closest point of the first chord past the exit is often the exit's end itself: the rest
// of that chord, not excused, went unmeasured. A cable leaving a box face along its normal,
// attached over s ∈ [0, 3], is 2.0 from the box just past the exit with 3.0 required; the
// violation was not reported at all. Chords end where attachments do, and a chord is
// excused only if it lies within the range.
TEST(Regression, ClearanceJustPastAPortExitWasExcusedWithTheExit) {
  const std::vector<loom::Part> parts{loom::testmesh::box_part("box", Vec3(0, 0, 0), Vec3(10, 10, 10))};
  loom::CableInput c = regression_cable("C", {Vec3(10, 5, 5), Vec3(40, 5, 5)}, 1.0);
  const double s_end = 3.0;
  c.attachments = {{0, 0.0, s_end, "J1"}};
  const loom::EmbreeIndex index(parts);
  loom::ClashRequest req;
  req.tolerance = 0.01;
  req.routing_clearance = 3.0;
  req.threads = 2;
  const loom::ClashResult res = loom::check_clashes({c}, parts, &index, req);
  const std::string in = "cable (10,5,5)-(40,5,5) r 1, attached to box [0,10]^3 over s in [0, " + regression_g17(s_end) +
                         "], clearance 3";
  EXPECT_TRUE(res.clashes.empty()) << in;
  ASSERT_EQ(res.violations.size(), 1u) << in;
  EXPECT_NEAR(res.violations[0].value, s_end - 1.0, 0.01) << in << " value " << regression_g17(res.violations[0].value);
}

// A port on the face of a 1 mm plate whose exit pointed into the plate: the cable went
// through the plate it is mounted on, and the audit said clean (exit 0), because the
// attachment excused every contact with the plate over the exit. The centerline inside
// the part, or touching it past the first tolerance of the exit, is excused only where the
// part holds the port (deeper than the tolerance: a connector modelled solid).
TEST(Regression, AnExitThroughThePlateItsPortSitsOnWasExcused) {
  const std::vector<loom::Part> parts{loom::testmesh::box_part("plate", Vec3(-21, -30, -30), Vec3(-20, 30, 30))};
  loom::CableInput c = regression_cable("C1", {Vec3(-21, 5, 5), Vec3(90, 5, 5)}, 1.0);
  c.attachments = {{0, 0.0, 10.0, "J1", 0.0}};  // what attach_ports gives: on the face, exit 10
  const loom::ClashResult res = regression_audit({c}, parts, 0.01);
  const std::string in = "cable (-21,5,5)-(90,5,5) r 1 from a port on the -x face of plate x in [-21,-20], exit 10";
  ASSERT_EQ(res.clashes.size(), 1u) << in;
  EXPECT_NEAR(res.clashes[0].clearance, -1.0, 0.01) << in << " clearance " << regression_g17(res.clashes[0].clearance);
  EXPECT_GT(res.clashes[0].s, 0.0) << in;
  EXPECT_LT(res.clashes[0].s, 1.0 + 0.01) << in;
}

// EmbreeIndex's one-ray inside test is documented exact on a watertight mesh,
// but Embree's float ray test can report neither of two triangles when the ray passes
// within its rounding of their common edge (embree issue #387), and only reported
// triangles were checked for grazing. Here α-SIM's own simplified mesh of a sliver
// triangle (watertight, float32 corners): the point lies 1.45e-4 inside it (brute-force
// winding number 1), the first ray passes 3e-8 from the edge 10–11, Embree reports no
// crossing at all and the point came out outside; 57 of 200,000 points on the sliver did
// (α-SIM then called its mesh "contains only 0.9991 of the samples" and kept the original).
// A missed crossing can as well make an outside point inside. Each ray runs through
// the candidate's whole box both ways: a closed part crosses a line an even number of
// times, so an odd count shows a crossing Embree missed and the ray is discarded.
TEST(Regression, EmbreeInsideRayMissedACrossingAtASharedEdge) {
  loom::Mesh m;
  m.vertices = {{0, 0, 0},
                {0, 0, 3.814697265625e-06},
                {1.8574701238921465e-12, 1.8574701238921465e-12, 3.8147009036038071e-06},
                {1.8767876497349789e-07, 1.914322780294242e-07, 4.1900548239937052e-06},
                {5.0000004768371582, 5.099998950958252, 10.000002861022949},
                {5.0000481605529785, 5.1000475883483887, 9.9999074935913086},
                {5.0005674362182617, 5.1005773544311523, 0},
                {5.0005674362182617, 5.1005773544311523, 9.9988269805908203},
                {5.0495047569274902, 5.0495047569274902, 9.9009943008422852},
                {6.7391319274902344, 6.7391319274902344, 6.5217399597167969},
                {6.7391319274902344, 6.8043498992919922, 6.5217399597167969},
                {9.7762308120727539, 9.7807073593139648, 0.44754126667976379},
                {10, 10, 0},
                {10, 10, 3.814697265625e-06}};
  m.triangles = {{6, 0, 3},   {0, 1, 3},   {7, 6, 3},   {4, 7, 3},   {5, 7, 4},   {2, 1, 0},
                 {9, 0, 12},  {9, 2, 0},   {9, 8, 2},   {13, 9, 12}, {0, 6, 12},  {1, 2, 3},
                 {2, 8, 3},   {3, 8, 4},   {9, 10, 8},  {5, 4, 8},   {10, 5, 8},  {5, 10, 7},
                 {10, 11, 7}, {6, 7, 11},  {6, 11, 12}, {11, 13, 12}, {13, 11, 9}, {11, 10, 9}};
  std::vector<loom::Part> parts(1);
  parts[0].name = "sliver";
  parts[0].mesh = m;
  parts[0].closed = true;
  const Vec3 p(8.770733702553196, 8.7951213564424418, 2.4387653889246428);
  ASSERT_GT(loom::test_oracle::mesh_winding_number(m, p), 0.5);
  ASSERT_GT(loom::test_oracle::mesh_distance(m, p), 1e-4);
  // The sliver triangle α-SIM simplified; points on it are inside or on the mesh.
  const Vec3 a(0, 0, 0), b(10, 10, 0), c(5, 5.1, 10);
  for (int rays : {1, 3}) {
    loom::EmbreeOptions eo;
    eo.inside_rays = rays;
    const loom::EmbreeIndex index(parts, eo);
    EXPECT_TRUE(index.inside(p)) << rays << " rays";
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    int wrong = 0;
    for (int i = 0; i < 50000; ++i) {
      double s = unit(rng), t = unit(rng);
      if (s + t > 1.0) s = 1.0 - s, t = 1.0 - t;
      const Vec3 q = a + s * (b - a) + t * (c - a);
      const double d = loom::test_oracle::mesh_distance(m, q);
      if (d < 1e-6) continue;  // on the surface: inside() may say either
      const bool truth = loom::test_oracle::mesh_winding_number(m, q) > 0.5;
      if (index.inside(q) != truth && ++wrong <= 3)
        ADD_FAILURE() << std::setprecision(17) << rays << " rays: (" << q.x() << ", " << q.y() << ", " << q.z()
                      << ") inside " << !truth << ", winding number says " << truth << ", distance " << d;
    }
    EXPECT_EQ(wrong, 0) << rays << " rays";
  }
}

// A cable with two tight corners far apart got one bend-radius violation, at the tighter
// (the report's "one entry per contiguous stretch" held for clashes only): mending it and
// auditing again showed the second. A polyline with corners at s = 10 and s = 60 (radius 0,
// minimum 5) gives a violation at each.
TEST(Regression, OnlyTheTightestBendOfACableWasReported) {
  const std::vector<loom::Part> parts{loom::testmesh::box_part("box", Vec3(0, 0, -100), Vec3(10, 10, -90))};
  loom::CableInput c =
      regression_cable("C", {Vec3(0, 0, 0), Vec3(10, 0, 0), Vec3(10, 50, 0), Vec3(60, 50, 0)}, 1.0);
  c.min_bend_radius = 5.0;
  const loom::ClashResult res = regression_audit({c}, parts, 0.01);
  const std::string in = "polyline (0,0,0) (10,0,0) (10,50,0) (60,50,0), r 1, min bend radius 5";
  ASSERT_EQ(res.violations.size(), 2u) << in;
  EXPECT_NEAR(res.violations[0].s, 10.0, 1e-9) << in;
  EXPECT_NEAR(res.violations[1].s, 60.0, 1e-9) << in;
  for (const auto& v : res.violations) EXPECT_EQ(v.value, 0.0) << in;
}
