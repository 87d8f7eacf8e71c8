// The view of moving parts: each drawn at rest, at both ends of its motion (translucent
// "swept") and at the pose of each cable-motion clash of the report ("clash-pose"), the
// copies moved exactly as the motion says (closed form of a quarter turn).
#include "routing/view/motion_view.hpp"
#include "routing/view/view_html.hpp"

#include <gtest/gtest.h>

namespace loom {
namespace {

Scene hinge_scene() {
  Scene sc;
  sc.name = "hinge";
  Part p;
  p.name = "door";
  p.mesh.vertices = {Vec3(0, 0, 0), Vec3(10, 0, 0), Vec3(10, 0, 5)};
  p.mesh.triangles = {{0, 1, 2}};
  Motion m;
  m.kind = MotionKind::Rotate;
  m.axis = Vec3::UnitZ();
  m.from = -90;
  m.to = 45;
  p.motion = m;
  sc.parts.push_back(p);
  Part fixed = p;
  fixed.name = "wall";
  fixed.motion.reset();
  sc.parts.push_back(fixed);
  return sc;
}

TEST(MotionView, ExtremePosesAndClashPosesAreDrawn) {
  const Scene sc = hinge_scene();
  const nlohmann::json report = {
      {"clashes",
       {{{"kind", "cable-motion"}, {"part", "door"}, {"pose", 30.0}, {"cable", "C1"}, {"clearance", -1.0},
         {"point", {0, 0, 0}}},
        {{"kind", "cable-structure"}, {"part", "door"}, {"cable", "C1"}, {"clearance", -1.0}, {"point", {0, 0, 0}}},
        {{"kind", "cable-motion"}, {"part", "wall"}, {"pose", 10.0}}}}};
  const auto v = motion_view_meshes(sc, report);
  ASSERT_EQ(v.size(), 3u);  // from, to, the one clash on a moving part
  EXPECT_EQ(v[0].role, "swept");
  EXPECT_EQ(v[1].role, "swept");
  EXPECT_EQ(v[2].role, "clash-pose");
  // −90° about Z takes (10, 0, 0) to (0, −10, 0).
  EXPECT_LT((v[0].mesh.vertices[1] - Vec3(0, -10, 0)).norm(), 1e-12);
  EXPECT_NE(v[2].name.find("30"), std::string::npos);

  const std::string page = view_data_json(sc, Harness{}, report, ViewOptions{});
  const auto j = nlohmann::json::parse(page);
  int swept = 0, hit = 0;
  for (const auto& p : j["parts"]) swept += p["role"] == "swept", hit += p["role"] == "clash-pose";
  EXPECT_EQ(swept, 2);
  EXPECT_EQ(hit, 1);
  EXPECT_EQ(j["parts"].size(), 5u);
}

}  // namespace
}  // namespace loom
