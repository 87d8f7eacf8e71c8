// render.png: the camera's projection against the closed-form look-at/perspective
// matrices, the picture against a brute-force ray/triangle oracle, clash markers where the
// report puts them, and the PNG file.
#include "index/index_test_meshes.hpp"
#include "core/error.hpp"
#include "core/harness_topology.hpp"
#include "core/io/harness_xml.hpp"
#include "routing/curve/cable_geometry.hpp"
#include "routing/view/render.hpp"
#include "routing/curve/sweep.hpp"

#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <Eigen/Dense>

#include <cmath>
#include <fstream>
#include <stdexcept>
#include <random>

namespace loom {
namespace {

const char* kHarness = R"(<harness name="H" units="mm">
  <attributes>
    <cable id="W1"><electrical><port id="A"/><port id="B"/></electrical>
      <physical type="t" color="red" diameter="6" min_bend_radius="10"/></cable>
  </attributes>
  <structure>
    <port id="A" x="-80" y="0" z="10" dx="1" dy="0" dz="0"/>
    <port id="B" x="80" y="0" z="10" dx="-1" dy="0" dz="0"/>
    <segment from="A" to="B"><path interp="polyline"><pt x="0" y="0" z="25"/></path></segment>
  </structure>
</harness>
)";

Scene small_scene() {
  Scene s;
  s.name = "render-test";
  s.harness = parse_harness_xml(kHarness, "test harness");
  s.has_harness = true;
  Part a;
  a.name = "block";
  a.mesh = testmesh::box(Vec3(-30, -30, -20), Vec3(30, 30, 5));
  Part b;
  b.name = "zone";
  b.role = PartRole::KeepOut;
  b.mesh = testmesh::box(Vec3(40, -40, -20), Vec3(70, -10, 0));
  s.parts = {a, b};
  return s;
}

/// Closed-form gluLookAt × gluPerspective, then the viewport: an independent projection.
Eigen::Vector2d glu_project(const RenderCamera& c, int w, int h, const Vec3& p) {
  const Vec3 f = (c.target - c.eye).normalized();
  const Vec3 s = f.cross(c.up).normalized();
  const Vec3 u = s.cross(f);
  Eigen::Matrix4d view = Eigen::Matrix4d::Identity();
  view.block<1, 3>(0, 0) = s.transpose();
  view.block<1, 3>(1, 0) = u.transpose();
  view.block<1, 3>(2, 0) = -f.transpose();
  view(0, 3) = -s.dot(c.eye);
  view(1, 3) = -u.dot(c.eye);
  view(2, 3) = f.dot(c.eye);
  const double fy = 1.0 / std::tan(c.fov_deg * M_PI / 360.0), n = 0.1, fa = 1000.0;
  Eigen::Matrix4d proj = Eigen::Matrix4d::Zero();
  proj(0, 0) = fy * h / w;
  proj(1, 1) = fy;
  proj(2, 2) = (fa + n) / (n - fa);
  proj(2, 3) = 2 * fa * n / (n - fa);
  proj(3, 2) = -1;
  const Eigen::Vector4d clip = proj * view * Eigen::Vector4d(p.x(), p.y(), p.z(), 1.0);
  const double nx = clip.x() / clip.w(), ny = clip.y() / clip.w();
  return {(nx + 1) * 0.5 * w, (1 - ny) * 0.5 * h};
}

RC_GTEST_PROP(RenderCamera, ProjectionMatchesGluMatrices, ()) {
  auto coord = [] { return *rc::gen::inRange(-1000, 1000) / 10.0; };
  RenderCamera c;
  c.eye = Vec3(coord(), coord(), coord());
  c.target = Vec3(coord(), coord(), coord());
  RC_PRE((c.target - c.eye).norm() > 1.0);
  RC_PRE(std::abs((c.target - c.eye).normalized().dot(c.up)) < 0.99);
  c.fov_deg = *rc::gen::inRange(10, 120);
  const int w = *rc::gen::inRange(1, 3000), h = *rc::gen::inRange(1, 3000);
  const Vec3 p(coord(), coord(), coord());
  const auto got = project_to_pixel(c, w, h, p);
  const double depth = (p - c.eye).dot((c.target - c.eye).normalized());
  if (depth <= 0) {
    RC_ASSERT(!got);
  } else {
    RC_PRE(depth > 1e-3);
    RC_ASSERT(got.has_value());
    const Eigen::Vector2d want = glu_project(c, w, h, p);
    RC_ASSERT((*got - want).norm() <= 1e-6 * (1.0 + want.norm()));
  }
}

TEST(RenderCamera, FramesTheBox) {
  AABB b;
  b.extend(Vec3(-10, -5, 0));
  b.extend(Vec3(30, 5, 8));
  for (double aspect : {0.5, 1.0, 2.0}) {
    const int w = static_cast<int>(400 * aspect), h = 400;
    const RenderCamera c = frame_camera(b, aspect);
    const auto centre = project_to_pixel(c, w, h, b.center());
    ASSERT_TRUE(centre);
    EXPECT_NEAR(centre->x(), 0.5 * w, 1e-9);
    EXPECT_NEAR(centre->y(), 0.5 * h, 1e-9);
    for (int k = 0; k < 8; ++k) {
      const Vec3 corner(k & 1 ? b.max.x() : b.min.x(), k & 2 ? b.max.y() : b.min.y(), k & 4 ? b.max.z() : b.min.z());
      const auto p = project_to_pixel(c, w, h, corner);
      ASSERT_TRUE(p);
      EXPECT_GE(p->x(), 0.0);
      EXPECT_LE(p->x(), w);
      EXPECT_GE(p->y(), 0.0);
      EXPECT_LE(p->y(), h);
    }
  }
}

TEST(RenderSize, Parses) {
  RenderOptions o;
  parse_render_size("1600x900", "--render-size", o);
  EXPECT_EQ(o.width, 1600);
  EXPECT_EQ(o.height, 900);
  for (const char* bad : {"", "x", "abc", "0x5", "10x", "10x10x", "-3x4", "20000x10", "12 x 3"})
    EXPECT_THROW(parse_render_size(bad, "--render-size", o), InputError) << bad;
}

/// Möller–Trumbore: does the ray origin + t·dir (t > 0) hit the triangle?
bool ray_hits(const Vec3& o, const Vec3& d, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 e1 = b - a, e2 = c - a, p = d.cross(e2);
  const double det = e1.dot(p);
  if (std::abs(det) < 1e-14) return false;
  const Vec3 s = o - a;
  const double u = s.dot(p) / det;
  if (u < 0 || u > 1) return false;
  const Vec3 q = s.cross(e1);
  const double v = d.dot(q) / det;
  if (v < 0 || u + v > 1) return false;
  return e2.dot(q) / det > 0;
}

TEST(Render, MatchesBruteForceAndMarksClashes) {
  const Scene scene = small_scene();
  nlohmann::json report = {
      {"clashes", {{{"kind", "cable-structure"}, {"cable", "W1"}, {"part", "block"}, {"point", {-20.0, 0.0, 5.0}}},
                   {{"kind", "cable-structure"}, {"cable", "W1"}, {"part", "zone"}, {"point", {50.0, -20.0, 0.0}}}}},
      {"violations", {{{"kind", "bend-radius"}, {"cable", "W1"}, {"point", {0.0, 0.0, 25.0}}}}}};
  RenderOptions opt;
  opt.width = 320;
  opt.height = 240;
  RenderStats st;
  const Image img = render_scene(scene, scene.harness, report, opt, &st);
  ASSERT_EQ(img.rgb.size(), 320u * 240u * 3u);
  EXPECT_EQ(st.rays, 320u * 240u);
  EXPECT_EQ(st.markers, 3u);
  EXPECT_GT(st.tube_triangles, 0u);

  // The camera render_scene chose: it frames the harness (the cable tube).
  const HarnessTopology topo(scene.harness);
  const auto cl = cable_centerline(topo, 0);
  ASSERT_TRUE(cl);
  SweepOptions so;
  so.chord_tolerance = 0.1 * 3.0;
  const Mesh tube = sweep_tube(*cl, 3.0, so).mesh;
  const RenderCamera cam = frame_camera(tube.bounds(), 320.0 / 240.0);

  // Markers: the pixel at each projected point has the marker's colour.
  const double mr = std::max(4.0, 240 / 120.0);
  std::vector<Eigen::Vector2d> marks;
  for (const auto* key : {"clashes", "violations"})
    for (const auto& e : report[key]) {
      const Vec3 p(e["point"][0].get<double>(), e["point"][1].get<double>(), e["point"][2].get<double>());
      const auto px = project_to_pixel(cam, 320, 240, p);
      ASSERT_TRUE(px);
      marks.push_back(*px);
      const auto c = img.at(static_cast<int>(px->x()), static_cast<int>(px->y()));
      if (std::string(key) == "clashes") {
        EXPECT_EQ(c, (std::array<std::uint8_t, 3>{224, 32, 32}));
      } else {
        EXPECT_EQ(c, (std::array<std::uint8_t, 3>{255, 140, 0}));
      }
    }

  // Coverage: a pixel is background exactly when the brute-force ray misses every triangle
  // (parts and tube), away from the markers; silhouette pixels may differ in rounding.
  std::vector<const Mesh*> meshes = {&scene.parts[0].mesh, &scene.parts[1].mesh, &tube};
  const std::array<std::uint8_t, 3> bg{244, 245, 247};
  std::mt19937 rng(9);
  std::size_t checked = 0, disagree = 0, covered = 0;
  const Vec3 f = (cam.target - cam.eye).normalized();
  const Vec3 r = f.cross(cam.up).normalized(), u = r.cross(f);
  const double th = std::tan(cam.fov_deg * M_PI / 360.0);
  while (checked < 1500) {
    const int x = static_cast<int>(rng() % 320), y = static_cast<int>(rng() % 240);
    bool near_mark = false;
    for (const auto& m : marks) near_mark |= (m - Eigen::Vector2d(x + 0.5, y + 0.5)).norm() < mr + 3;
    if (near_mark) continue;
    const Vec3 d = f + (2.0 * (x + 0.5) / 320 - 1) * th * (320.0 / 240.0) * r + (1 - 2.0 * (y + 0.5) / 240) * th * u;
    bool hit = false;
    for (const Mesh* m : meshes)
      for (std::size_t t = 0; t < m->triangles.size() && !hit; ++t)
        hit = ray_hits(cam.eye, d, m->vertices[m->triangles[t][0]], m->vertices[m->triangles[t][1]],
                       m->vertices[m->triangles[t][2]]);
    const bool drawn = img.at(x, y) != bg;
    disagree += hit != drawn;
    covered += hit;
    ++checked;
  }
  EXPECT_GT(covered, checked / 20) << "the picture is (nearly) blank";
  EXPECT_LT(covered, checked) << "no background at all";
  EXPECT_LE(disagree, checked / 100) << disagree << " of " << checked << " pixels disagree with the oracle";
}

TEST(Render, EmptySceneAndBadSize) {
  Scene empty;
  RenderOptions opt;
  opt.width = 8;
  opt.height = 8;
  const Image img = render_scene(empty, empty.harness, nlohmann::json::object(), opt);
  for (std::size_t i = 0; i < img.rgb.size(); i += 3) EXPECT_EQ(img.rgb[i], 244);
  opt.width = 0;
  EXPECT_THROW(render_scene(empty, empty.harness, nlohmann::json::object(), opt), InputError);
}

// The tubes' triangle budget: at the triangles the scene needs the render runs, one below
// it the render is refused with the cable named (routes folding back on themselves
// thousands of times ran the machine out of memory here).
TEST(Render, TubeTriangleBudgetIsHeldAndNamesTheCable) {
  const Scene scene = small_scene();
  RenderOptions opt;
  opt.width = 16;
  opt.height = 16;
  RenderStats st;
  render_scene(scene, scene.harness, nlohmann::json::object(), opt, &st);
  ASSERT_GT(st.tube_triangles, 0u);
  opt.max_tube_triangles = st.tube_triangles;
  RenderStats again;
  EXPECT_NO_THROW(render_scene(scene, scene.harness, nlohmann::json::object(), opt, &again));
  EXPECT_EQ(again.tube_triangles, st.tube_triangles);
  opt.max_tube_triangles = st.tube_triangles - 1;
  try {
    render_scene(scene, scene.harness, nlohmann::json::object(), opt);
    FAIL() << "accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("render: cable 'W1'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("more than the " + std::to_string(st.tube_triangles - 1) + " allowed"),
              std::string::npos)
        << e.what();
  }
}

// A wall on the −y side hides the cable from the default direction (front-right-above,
// from −y). The framing camera turns to the +y side, where nothing hides it; a camera given
// on the −y side sees the cable through the wall, tinted (the pixel differs from the same
// picture without the cable).
TEST(Render, CameraTurnsAwayFromTheWallAndStructureIsSeeThrough) {
  Scene scene = small_scene();
  Part wall;
  wall.name = "wall";
  wall.mesh = testmesh::box(Vec3(-400, -40, -300), Vec3(400, -30, 400));
  scene.parts = {wall};
  RenderOptions opt;
  opt.width = 160;
  opt.height = 120;
  RenderStats st;
  render_scene(scene, scene.harness, nlohmann::json::object(), opt, &st);
  EXPECT_GT(st.visible_cable_share, 0.99);

  const HarnessTopology topo(scene.harness);
  const auto cl = cable_centerline(topo, 0);
  ASSERT_TRUE(cl);
  SweepOptions so;
  so.chord_tolerance = 0.3;
  const AABB box = sweep_tube(*cl, 3.0, so).mesh.bounds();
  opt.camera = frame_camera(box, 160.0 / 120.0);  // the default direction: eye at −y
  ASSERT_LT(opt.camera->eye.y(), -40.0);
  const Image through = render_scene(scene, scene.harness, nlohmann::json::object(), opt, &st);
  Scene no_cable = scene;
  no_cable.harness = Harness{};
  const Image plain = render_scene(no_cable, no_cable.harness, nlohmann::json::object(), opt);
  const auto px = project_to_pixel(*opt.camera, 160, 120, Vec3(0, 0, 24));
  ASSERT_TRUE(px);
  const auto a = through.at(static_cast<int>(px->x()), static_cast<int>(px->y()));
  const auto b = plain.at(static_cast<int>(px->x()), static_cast<int>(px->y()));
  EXPECT_NE(a, b) << "the cable behind the wall does not show through";
  EXPECT_NE(b, (std::array<std::uint8_t, 3>{244, 245, 247})) << "the wall is not in front of the cable";
}

TEST(Render, WritesPng) {
  Image img;
  img.width = 5;
  img.height = 3;
  img.rgb.assign(5 * 3 * 3, 100);
  const auto file = std::filesystem::temp_directory_path() / "loom-test-render.png";
  write_png(file, img);
  std::ifstream in(file, std::ios::binary);
  std::vector<unsigned char> b((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_GE(b.size(), 33u);
  const unsigned char sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  EXPECT_TRUE(std::equal(sig, sig + 8, b.begin()));
  auto be32 = [&](std::size_t o) { return (b[o] << 24) | (b[o + 1] << 16) | (b[o + 2] << 8) | b[o + 3]; };
  EXPECT_EQ(be32(16), 5);  // IHDR width
  EXPECT_EQ(be32(20), 3);  // IHDR height
  std::filesystem::remove(file);
}

}  // namespace
}  // namespace loom
