// One test per routing bug of `loom route` on adversarial scenes
// (tests/routing/route/test_route_adversarial.cpp), inputs written out in full.
#include "index/index_test_meshes.hpp"
#include "routing/view/render.hpp"
#include "routing/route/route_pipeline.hpp"
#include "routing/route/route_report.hpp"
#include "routing/view/view_html.hpp"

#include "core/io/harness_xml.hpp"
#include "core/io/scene_load.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <string>

namespace loom {
namespace {

/// One closed box [-20, 30]³ (mm) and a one-cable harness J1 → J2 (diameter 2, bend 10),
/// clearance 3 mm, Informed RRT*, seed 7.
Scene box_scene(const std::string& j1, const std::string& j2, double time_limit = 0.3) {
  Scene sc;
  sc.name = "regression";
  Part p;
  p.name = "box";
  p.mesh = testmesh::box(Vec3(-20, -20, -20), Vec3(30, 30, 30));
  p.closed = true;
  sc.parts.push_back(p);
  sc.harness = parse_harness_xml(
      "<harness name=\"H\" units=\"mm\"><attributes><cable id=\"C1\"><electrical><port id=\"J1\"/><port id=\"J2\"/>"
      "</electrical><physical type=\"T\" color=\"red\" diameter=\"2\" min_bend_radius=\"10\"/></cable></attributes>"
      "<structure>" + j1 + j2 + "<segment from=\"J1\" to=\"J2\"/></structure></harness>",
      "harness.xml");
  sc.has_harness = true;
  sc.routing.clearance = {3.0, "test"};
  sc.routing.time_limit = {time_limit, "test"};
  sc.routing.seed = 7;
  sc.simplify.dim_pre = {2.0, "test"};
  return sc;
}

// Two ports at one point leaving the same way: the stub ends coincide, the segment is
// "solved" without planning, its hairpin cannot be rounded, and the bend re-plan handed
// plan_path two equal ends — std::invalid_argument "plan: start and goal ports coincide"
// (exit 2 naming nothing). The hairpin is routed and reported: a bend-radius violation
// and a self contact, exit 1.
TEST(RouteRegression, TwoPortsAtOnePointAreReportedNotThrown) {
  const Scene sc = box_scene("<port id=\"J1\" x=\"-80\" y=\"5\" z=\"5\" dx=\"1\" dy=\"0\" dz=\"0\"/>",
                             "<port id=\"J2\" x=\"-80\" y=\"5\" z=\"5\" dx=\"1\" dy=\"0\" dz=\"0\"/>");
  RouteReport rep;
  ASSERT_NO_THROW(rep = route_scene(sc, RouteOptions{}));
  EXPECT_TRUE(rep.unrouted.empty());
  EXPECT_EQ(rep.exit_code(), 1);
  bool bend = false;
  for (const auto& v : rep.audit.result.violations) bend = bend || v.kind == ViolationKind::BendRadius;
  EXPECT_TRUE(bend);
}

// A port on a face of the box (x = −20) leaving along the face's outward normal (−x): the
// stub check started exactly `required` (r + clearance = 4) from the face, found the face
// at exactly 4 and called the port blocked ("faces a wall ... comes within 4 of part 'box'
// (needs 4)", exit 3). The most common connector there is cannot be unroutable.
TEST(RouteRegression, PortOnAFaceLeavingAlongItsNormalIsRouted) {
  const Scene sc = box_scene("<port id=\"J1\" x=\"-20\" y=\"5\" z=\"5\" dx=\"-1\" dy=\"0\" dz=\"0\"/>",
                             "<port id=\"J2\" x=\"90\" y=\"5\" z=\"5\" dx=\"-1\" dy=\"0\" dz=\"0\"/>");
  const RouteReport rep = route_scene(sc, RouteOptions{});
  EXPECT_TRUE(rep.unrouted.empty()) << (rep.unrouted.empty() ? "" : rep.unrouted[0].message);
  EXPECT_NE(rep.exit_code(), 3);
}

// Same with a stub (max(min bend 1, 2r) = 2) shorter than the required distance 4: the stub
// end lay within 4 of the face, so the port was blocked whatever faced it. A port on its
// connector leaves straight until clear of it.
TEST(RouteRegression, PortOnAFaceWithAStubShorterThanTheClearanceIsRouted) {
  Scene sc = box_scene("<port id=\"J1\" x=\"-20\" y=\"5\" z=\"5\" dx=\"-1\" dy=\"0\" dz=\"0\"/>",
                       "<port id=\"J2\" x=\"90\" y=\"5\" z=\"5\" dx=\"-1\" dy=\"0\" dz=\"0\"/>");
  sc.harness.cables[0].physical.min_bend_radius = 1.0;
  const RouteReport rep = route_scene(sc, RouteOptions{});
  EXPECT_TRUE(rep.unrouted.empty()) << (rep.unrouted.empty() ? "" : rep.unrouted[0].message);
  EXPECT_NE(rep.exit_code(), 3);
}

// A port on the face x = −20 whose connector points 45° off the face normal (−x, +z): the
// stub check measured every part from `required` along the exit, where the face is only
// required·cos 45° away, and called the port blocked ("faces a wall ... comes within
// 2.8354981925580561 of part 'box' (needs 4)", exit 3), though the audit excuses the part a
// port sits on over its straight exit and the exit's end is 7.07 from the face. The part
// the port sits on is excused over the exit (not crossed), every other part checked.
TEST(RouteRegression, PortOnAFaceLeavingAtAnAngleIsRouted) {
  const Scene sc = box_scene(
      "<port id=\"J1\" x=\"-20\" y=\"5\" z=\"5\" dx=\"-0.70710678118654757\" dy=\"0\" dz=\"0.70710678118654757\"/>",
      "<port id=\"J2\" x=\"90\" y=\"5\" z=\"5\" dx=\"-1\" dy=\"0\" dz=\"0\"/>");
  const RouteReport rep = route_scene(sc, RouteOptions{});
  EXPECT_TRUE(rep.unrouted.empty()) << (rep.unrouted.empty() ? "" : rep.unrouted[0].message);
  EXPECT_NE(rep.exit_code(), 3);
}

// A cable that could not be routed (its port inside the box) was drawn anyway in cables.ply,
// render.png and view.html: its segment has no path, so the drawing code took the straight
// line between the ports, through the box. README: "Blocked cables are reported, never drawn".
TEST(RouteRegression, AnUnroutedCableIsNeverDrawn) {
  const Scene sc = box_scene("<port id=\"J1\" x=\"0\" y=\"5\" z=\"5\" dx=\"-1\" dy=\"0\" dz=\"0\"/>",
                             "<port id=\"J2\" x=\"90\" y=\"5\" z=\"5\" dx=\"-1\" dy=\"0\" dz=\"0\"/>");
  const RouteReport rep = route_scene(sc, RouteOptions{});
  ASSERT_EQ(rep.unrouted.size(), 1u);
  const auto dir = std::filesystem::temp_directory_path() / "loom_route_regression_unrouted";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  write_route_outputs(rep, dir, 0.1);
  std::ifstream ply(dir / "cables.ply", std::ios::binary);
  std::string line, vertices;
  while (std::getline(ply, line) && line != "end_header")
    if (line.rfind("element vertex", 0) == 0) vertices = line;
  EXPECT_EQ(vertices, "element vertex 0");
  std::filesystem::remove_all(dir);

  const nlohmann::json report = route_report_json(rep);
  RenderOptions ro;
  ro.width = 64;
  ro.height = 48;
  RenderStats rs;
  render_scene(sc, rep.routed, report, ro, &rs);
  EXPECT_EQ(rs.tube_triangles, 0u);
  ViewStats vs;
  view_data_json(sc, rep.routed, report, ViewOptions{}, &vs);
  EXPECT_EQ(vs.cables_drawn, 0u);
}

// The wing section's harness in three classes with its branch points left to the router
// (examples/wing-classes, positions removed): the bend-feasible plans and re-plans made after
// every segment was planned kept clear only of the bundles routed before theirs, so later
// bundles, planned around their old routes, were crossed (12 cable-cable clashes, 102
// violations, 21 segregation findings); data and power nodes placed 30 mm apart, and
// breakouts of segments still to be routed not grown by the separation of their classes,
// left data legs no start (8 of 24 cables unrouted). Re-plans now keep clear of every other
// bundle and refresh their own; nodes and breakouts keep the separation.
TEST(RouteRegression, WingClassesWithRouterPlacedBranchPointsIsClean) {
  Scene sc = load_scene(std::string(LOOM_SOURCE_DIR) + "/examples/wing-classes/scene.toml");
  for (auto& b : sc.harness.branches) b.position.reset();
  RouteOptions opt;
  opt.threads = 2;
  const RouteReport rep = route_scene(sc, opt);
  EXPECT_TRUE(rep.unrouted.empty()) << rep.unrouted.size() << " unrouted, first: "
                                    << (rep.unrouted.empty() ? "" : rep.unrouted.front().message);
  EXPECT_TRUE(rep.audit.result.clashes.empty()) << rep.audit.result.clashes.size();
  EXPECT_TRUE(rep.audit.result.violations.empty()) << rep.audit.result.violations.size();
  EXPECT_TRUE(rep.audit.segregation.empty()) << rep.audit.segregation.size();
}

}  // namespace
}  // namespace loom
