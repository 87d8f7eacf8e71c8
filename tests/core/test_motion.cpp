// Moving parts: the rigid motions against closed forms, and the scene file's motion keys —
// inline and named [[motion]] tables, and every refusal naming the scene file and the part.
#include "core/motion.hpp"
#include "core/io/scene_load.hpp"
#include "common/test_files.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace loom {
namespace {

using testing::input_error;
using testing::scratch_dir;
using testing::write_file;

constexpr double kDeg = M_PI / 180.0;

TEST(Motion, RotationAboutAnOffsetAxisMatchesClosedForm) {
  Motion m;
  m.kind = MotionKind::Rotate;
  m.axis_point = Vec3(10, 0, 0);
  m.axis = Vec3::UnitZ();
  // (20, 0, 5) is 10 from the axis: at 90° it is at (10, 10, 5).
  EXPECT_LT((m.pose(90.0) * Vec3(20, 0, 5) - Vec3(10, 10, 5)).norm(), 1e-12);
  EXPECT_LT((m.pose(0.0) * Vec3(3, 4, 5) - Vec3(3, 4, 5)).norm(), 1e-12);
  Mesh mesh;
  mesh.vertices = {Vec3(20, 0, 5), Vec3(10, 3, -7)};
  EXPECT_NEAR(m.max_point_speed(mesh), 10.0 * kDeg, 1e-15);
}

TEST(Motion, TranslationAndPoseSamplesBoundTheGap) {
  Motion m;
  m.kind = MotionKind::Translate;
  m.axis = Vec3(0, 1, 0);
  m.from = -5;
  m.to = 15;
  EXPECT_LT((m.pose(3.0) * Vec3(1, 1, 1) - Vec3(1, 4, 1)).norm(), 1e-12);
  Mesh mesh;
  mesh.vertices = {Vec3(0, 0, 0)};
  double gap = 0.0;
  const auto q = pose_samples(m, mesh, 3.0, &gap);
  ASSERT_EQ(q.size(), 8u);  // 20 of travel in steps of at most 3: 7 steps
  EXPECT_EQ(q.front(), -5.0);
  EXPECT_EQ(q.back(), 15.0);
  EXPECT_LE(gap, 3.0);
  for (std::size_t i = 1; i < q.size(); ++i) EXPECT_LE(q[i] - q[i - 1], 3.0 + 1e-12);
}

/// A scene folder with a 10 mm cube (OBJ) and a scene whose parts carry `parts` TOML.
std::filesystem::path scene_with(const std::string& extra, const std::string& part_keys) {
  const auto d = scratch_dir("loom_motion_");
  write_file(d / "cube.obj",
             "v 0 0 0\nv 10 0 0\nv 10 10 0\nv 0 10 0\nv 0 0 10\nv 10 0 10\nv 10 10 10\nv 0 10 10\n"
             "f 1 3 2\nf 1 4 3\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\nf 2 3 7\nf 2 7 6\nf 3 4 8\nf 3 8 7\nf 4 1 5\nf 4 5 8\n");
  write_file(d / "s.toml", "[scene]\nname = \"m\"\nunits = \"mm\"\n" + extra +
                               "\n[[part]]\nname = \"arm\"\nfile = \"cube.obj\"\n" + part_keys +
                               "\n[[part]]\nname = \"fixed\"\nfile = \"cube.obj\"\n");
  return d / "s.toml";
}

TEST(MotionScene, InlineRotationIsReadAndNormalised) {
  const Scene s = load_scene(scene_with(
      "", "motion = { rotate = { axis_point = [0, 0, 0], axis = [0, 0, 2], from_deg = -30, to_deg = 30 } }"));
  ASSERT_TRUE(s.parts[0].motion.has_value());
  EXPECT_EQ(s.parts[0].motion->kind, MotionKind::Rotate);
  EXPECT_EQ(s.parts[0].motion->axis, Vec3::UnitZ());
  EXPECT_EQ(s.parts[0].motion->from, -30.0);
  EXPECT_FALSE(s.parts[1].motion.has_value());
  // Drawn (indexed) in its rest pose: the mesh is unchanged.
  EXPECT_EQ(s.parts[0].mesh.bounds().max, Vec3(10, 10, 10));
}

TEST(MotionScene, NamedMotionIsSharedByParts) {
  const Scene s = load_scene(scene_with(
      "[[motion]]\nname = \"flap\"\ntranslate = { direction = [1, 0, 0], from = 0, to = 50 }\n", "motion = \"flap\""));
  ASSERT_TRUE(s.parts[0].motion.has_value());
  EXPECT_EQ(s.parts[0].motion->name, "flap");
  EXPECT_EQ(s.parts[0].motion->kind, MotionKind::Translate);
  EXPECT_EQ(s.parts[0].motion->to, 50.0);
}

struct BadMotion {
  const char* extra;
  const char* part_keys;
  const char* says;
};

/// Test names show the expected message, not the bytes of the struct.
void PrintTo(const BadMotion& b, std::ostream* os) { *os << b.says; }

class MotionSceneRefuses : public ::testing::TestWithParam<BadMotion> {};

TEST_P(MotionSceneRefuses, NamingTheFileAndThePart) {
  const BadMotion b = GetParam();
  const auto path = scene_with(b.extra, b.part_keys);
  const std::string msg = input_error([&] { load_scene(path); });
  EXPECT_NE(msg.find(path.string()), std::string::npos) << msg;
  EXPECT_NE(msg.find(b.says), std::string::npos) << msg;
  if (std::string(b.extra).empty()) {
    EXPECT_NE(msg.find("part 'arm'"), std::string::npos) << msg;
  }
}

INSTANTIATE_TEST_SUITE_P(
    , MotionSceneRefuses,
    ::testing::Values(
        BadMotion{"", "motion = { rotate = { axis_point = [0, 0, 0], axis = [0, 0, 0], from_deg = 0, to_deg = 30 } }",
                  "axis must not be zero"},
        BadMotion{"", "motion = { rotate = { axis_point = [0, 0, 0], axis = [0, 0, 1], from_deg = 30, to_deg = 0 } }",
                  "is greater than to_deg"},
        BadMotion{"", "motion = { rotate = { axis_point = [0, 0, 0], axis = [0, 0, 1], from_deg = 0, to_deg = 400 } }",
                  "within ±360 degrees"},
        BadMotion{"", "motion = { rotate = { axis_point = [0, 0, 0], axis = [0, 0, 1], from_deg = nan, to_deg = 1 } }",
                  "must be finite"},
        BadMotion{"", "motion = { translate = { direction = [0, 0, 0], from = 0, to = 1 } }",
                  "direction must not be zero"},
        BadMotion{"", "motion = { translate = { direction = [1, 0, 0], from = 5, to = -5 } }", "is greater than to"},
        BadMotion{"", "motion = { translate = { direction = [1, 0, inf], from = 0, to = 1 } }", "must be finite"},
        BadMotion{"", "motion = { spin = 3 }", "unknown key"},
        BadMotion{"", "motion = { }", "exactly one of rotate"},
        BadMotion{"", "motion = \"nope\"", "no [[motion]] named 'nope'"},
        BadMotion{"[[motion]]\nname = \"flap\"\nrotate = { axis_point = [0, 0, 0], axis = [0, 0, 1], from_deg = -400, "
                  "to_deg = 0 }\n",
                  "motion = \"flap\"", "motion 'flap'"}),
    [](const ::testing::TestParamInfo<BadMotion>& i) { return "case" + std::to_string(i.index); });

}  // namespace
}  // namespace loom
