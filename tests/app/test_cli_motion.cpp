// `loom audit` on a scene with a hinged door (motion by a shared [[motion]]): a cable that
// clears the door as drawn is hit at 30°; the summary lists it, report.json has one
// cable-motion clash with its pose, the exit status is 1. A bad motion exits 2 naming the
// scene file and the part, writing nothing.
#include "common/run_loom.hpp"
#include "common/test_files.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>

namespace loom {
namespace {

using testing::scratch_dir;
using testing::slurp;
using testing::write_file;
using testing::LoomRun;
using testing::run_loom;

/// A 200 × 4 × 100 door (OBJ, closed) and a vertical cable 150 mm from the hinge at 30°.
std::filesystem::path door_scene(const std::string& motion) {
  const auto d = scratch_dir("loom_cli_motion_");
  write_file(d / "door.obj",
             "v 0 -2 0\nv 200 -2 0\nv 200 2 0\nv 0 2 0\nv 0 -2 100\nv 200 -2 100\nv 200 2 100\nv 0 2 100\n"
             "f 1 3 2\nf 1 4 3\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\nf 2 3 7\nf 2 7 6\nf 3 4 8\nf 3 8 7\nf 4 1 5\nf 4 5 8\n");
  const double x = 150 * std::cos(M_PI / 6), y = 150 * std::sin(M_PI / 6);
  char pts[512];
  std::snprintf(pts, sizeof pts,
                "<port id=\"A\" x=\"%.17g\" y=\"%.17g\" z=\"-50\" dx=\"0\" dy=\"0\" dz=\"1\"/>\n"
                "<port id=\"B\" x=\"%.17g\" y=\"%.17g\" z=\"150\" dx=\"0\" dy=\"0\" dz=\"-1\"/>\n"
                "<segment from=\"A\" to=\"B\"><path interp=\"polyline\"><pt x=\"%.17g\" y=\"%.17g\" z=\"50\"/></path>"
                "</segment>\n",
                x, y, x, y, x, y);
  write_file(d / "h.xml", std::string("<harness name=\"W\" units=\"mm\"><attributes>\n") +
                              "<cable id=\"C1\"><electrical><port id=\"A\"/><port id=\"B\"/></electrical>"
                              "<physical type=\"T\" color=\"red\" diameter=\"4\" min_bend_radius=\"20\"/></cable>\n"
                              "</attributes><structure>\n" + pts + "</structure></harness>\n");
  write_file(d / "s.toml", "[scene]\nname = \"hinge\"\nunits = \"mm\"\n\n" + motion +
                               "\n[[part]]\nname = \"door\"\nfile = \"door.obj\"\nmotion = \"hinge\"\n\n"
                               "[harness]\nfile = \"h.xml\"\n\n[routing]\nclearance = 1.0\n");
  return d;
}

TEST(CliMotion, AuditReportsTheCableMotionClashWithItsPose) {
  const auto d = door_scene(
      "[[motion]]\nname = \"hinge\"\nrotate = { axis_point = [0, 0, 0], axis = [0, 0, 1], from_deg = -60, to_deg = 60 }\n");
  const LoomRun r = run_loom("audit " + (d / "s.toml").string() + " --out " + (d / "out").string());
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_NE(r.out.find("motion C1"), std::string::npos) << r.out;
  const auto j = nlohmann::json::parse(slurp(d / "out" / "report.json"));
  int motion = 0;
  for (const auto& c : j["clashes"]) {
    EXPECT_EQ(c["kind"], "cable-motion") << "the door is clear as drawn: " << c.dump();
    if (c["kind"] != "cable-motion") continue;
    ++motion;
    EXPECT_EQ(c["part"], "door");
    EXPECT_NEAR(c["pose"].get<double>(), 30.0, 1.0);
    EXPECT_EQ(c["pose_unit"], "deg");
  }
  EXPECT_EQ(motion, 1);
}

TEST(CliMotion, BadMotionExitsTwoNamingTheSceneAndWritesNothing) {
  const auto d = door_scene(
      "[[motion]]\nname = \"hinge\"\nrotate = { axis_point = [0, 0, 0], axis = [0, 0, 1], from_deg = 60, to_deg = -60 }\n");
  const LoomRun r = run_loom("audit " + (d / "s.toml").string() + " --out " + (d / "out").string() + " --quiet");
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find((d / "s.toml").string()), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("motion 'hinge'"), std::string::npos) << r.out;
  EXPECT_FALSE(std::filesystem::exists(d / "out" / "report.json"));
}

}  // namespace
}  // namespace loom
