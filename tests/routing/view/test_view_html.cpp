// view.html: decimation invariants, the page's data against the scene and report,
// and the page itself opened in headless Chromium as a person would (WebGL pixels, the clash
// list, a click selecting a clash, a screenshot).
#include "index/index_test_meshes.hpp"
#include "core/io/harness_xml.hpp"
#include "routing/view/view_assets.hpp"
#include "routing/view/view_html.hpp"

#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <random>
#include <regex>
#include <sstream>
#include <string>

namespace loom {
namespace {

std::string read_text(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// A UV sphere of radius r at c: (rings × segs) quads as triangles.
Mesh sphere_mesh(const Vec3& c, double r, int rings, int segs) {
  Mesh m;
  for (int i = 0; i <= rings; ++i)
    for (int j = 0; j < segs; ++j) {
      const double th = M_PI * i / rings, ph = 2 * M_PI * j / segs;
      m.vertices.push_back(c + r * Vec3(std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th)));
    }
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segs; ++j) {
      const auto a = static_cast<std::uint32_t>(i * segs + j), b = static_cast<std::uint32_t>(i * segs + (j + 1) % segs);
      const auto c2 = a + static_cast<std::uint32_t>(segs), d = b + static_cast<std::uint32_t>(segs);
      m.triangles.push_back({a, c2, d});
      m.triangles.push_back({a, d, b});
    }
  return m;
}

// ---------------------------------------------------------------------------------------------
TEST(ViewAssets, InlinedThreeJsIsTheInstalledFile) {
  // Oracle: the Debian files the build step read.
  EXPECT_EQ(view_assets::three_js(), read_text("/usr/share/javascript/three/three.min.js"));
  EXPECT_EQ(view_assets::orbit_controls_js(),
            read_text("/usr/share/javascript/three/examples/js/controls/OrbitControls.js"));
  EXPECT_NE(view_assets::three_js().find("REVISION=\"111\""), std::string::npos);
}

RC_GTEST_PROP(Decimate, StaysWithinBudgetAndBox, ()) {
  const int rings = *rc::gen::inRange(2, 40);
  const int segs = *rc::gen::inRange(3, 60);
  const Mesh m = sphere_mesh(Vec3(1, -2, 3), 5.0, rings, segs);
  const std::size_t budget = *rc::gen::inRange<std::size_t>(0, m.triangles.size() + 10);
  const Mesh d = decimate_vertex_clustering(m, budget);
  RC_ASSERT(d.triangles.size() <= budget);
  if (m.triangles.size() <= budget) RC_ASSERT(d.triangles.size() == m.triangles.size());
  const AABB b = m.bounds();
  for (const Vec3& v : d.vertices) {
    RC_ASSERT(v.allFinite());
    RC_ASSERT(((v - b.min).array() >= -1e-9).all());
    RC_ASSERT(((b.max - v).array() >= -1e-9).all());
  }
  for (const auto& t : d.triangles) {
    RC_ASSERT(t[0] != t[1] && t[1] != t[2] && t[0] != t[2]);
    for (auto i : t) RC_ASSERT(i < d.vertices.size());
  }
}

TEST(Decimate, DegenerateInputs) {
  EXPECT_TRUE(decimate_vertex_clustering(Mesh{}, 0).empty());
  EXPECT_TRUE(decimate_vertex_clustering(testmesh::box(Vec3::Zero(), Vec3::Ones()), 0).empty());
  Mesh point;  // every vertex in one place
  point.vertices = {Vec3(1, 1, 1), Vec3(1, 1, 1), Vec3(1, 1, 1)};
  point.triangles = {{0, 1, 2}, {0, 2, 1}};
  EXPECT_TRUE(decimate_vertex_clustering(point, 1).empty());
  // A budget the mesh fits is a copy.
  const Mesh s = sphere_mesh(Vec3::Zero(), 1.0, 8, 8);
  const Mesh d = decimate_vertex_clustering(s, s.triangles.size());
  EXPECT_EQ(d.vertices, s.vertices);
  EXPECT_EQ(d.triangles, s.triangles);
  // A fine sphere decimated to a quarter keeps a sensible part of it (not collapsed to nothing).
  const Mesh fine = sphere_mesh(Vec3::Zero(), 1.0, 60, 80);
  const Mesh q = decimate_vertex_clustering(fine, fine.triangles.size() / 4);
  EXPECT_LE(q.triangles.size(), fine.triangles.size() / 4);
  EXPECT_GE(q.triangles.size(), fine.triangles.size() / 40);
}

// ---------------------------------------------------------------------------------------------
const char* kHarness = R"(<harness name="H" units="mm">
  <attributes>
    <cable id="W1"><electrical><port id="A"/><port id="B"/></electrical>
      <physical type="t" color="red" diameter="4" min_bend_radius="10"/></cable>
    <cable id="W2"><electrical><port id="C"/><port id="D"/></electrical>
      <physical type="t" color="blue" diameter="3" min_bend_radius="10"/></cable>
  </attributes>
  <structure>
    <port id="A" x="-80" y="0" z="0" dx="1" dy="0" dz="0"/>
    <port id="B" x="80" y="0" z="0" dx="-1" dy="0" dz="0"/>
    <port id="C" x="-80" y="30" z="10" dx="1" dy="0" dz="0"/>
    <port id="D" x="80" y="30" z="10" dx="-1" dy="0" dz="0"/>
    <segment from="A" to="B"><path interp="polyline"><pt x="0" y="0" z="5"/></path></segment>
    <segment from="C" to="D"><path interp="polyline"><pt x="0" y="40" z="30"/></path></segment>
  </structure>
</harness>
)";

struct Fixture {
  Scene scene;
  nlohmann::json report;
};

Fixture small_scene() {
  Fixture f;
  f.scene.name = "view-test";
  f.scene.harness = parse_harness_xml(kHarness, "test harness");
  f.scene.has_harness = true;
  Part box;
  box.name = "block";
  box.mesh = testmesh::box(Vec3(-20, -20, -40), Vec3(20, 20, 2));
  Part ball;
  ball.name = "ball";
  ball.mesh = sphere_mesh(Vec3(40, 60, 0), 15.0, 40, 60);  // 4800 triangles
  Part zone;
  zone.name = "zone";
  zone.role = PartRole::KeepOut;
  zone.mesh = testmesh::box(Vec3(-60, 50, -10), Vec3(-30, 80, 20));
  f.scene.parts = {box, ball, zone};
  f.report = nlohmann::json::parse(R"({
    "clashes": [
      {"kind": "cable-structure", "cable": "W1", "part": "block", "clearance": -1.25, "point": [-10.004, 0.0, 2.0], "s": 70.1},
      {"kind": "cable-structure", "cable": "W1", "part": "block", "clearance": -0.5, "point": [10.0, 0.0, 2.5], "s": 90.2},
      {"kind": "cable-cable", "cable": "W1", "other": "W2", "clearance": -0.1, "point": [60.0, 10.0, 3.0], "s": 140.0}
    ],
    "violations": [
      {"kind": "bend-radius", "cable": "W2", "value": 4.0, "limit": 10.0, "point": [0.0, 40.0, 30.0], "s": 88.0}
    ],
    "clamps": [
      {"id": "clamp-1", "point": [0.0, 0.0, 12.0], "part": "block", "bundle_diameter": 4.2, "placed": true},
      {"id": "K7", "part": "block"},
      {"id": "K8", "point": [30.0, 0.0, 12.0], "part": null, "bundle_diameter": 4.2, "placed": false}
    ]})");
  return f;
}

TEST(ViewData, MatchesSceneAndReport) {
  const Fixture f = small_scene();
  ViewOptions opt;
  opt.triangle_budget = 1000;  // forces the ball (4800) to be decimated
  ViewStats st;
  const auto d = nlohmann::json::parse(view_data_json(f.scene, f.scene.harness, f.report, opt, &st));
  const double q = d["quantum"].get<double>();
  // The rule: min(0.01 unit, 1e-5 × scene diagonal); this scene is ~200 mm across.
  EXPECT_DOUBLE_EQ(q, std::min(0.01, 1e-5 * f.scene.bounds().size().norm()));
  EXPECT_LT(q, 0.01);
  EXPECT_EQ(st.part_triangles, 12u + 4800u + 12u);
  EXPECT_LE(st.shown_triangles, opt.triangle_budget);
  std::size_t tris = 0;
  for (const auto& p : d["parts"]) tris += p["t"].size() / 3;
  EXPECT_EQ(tris, st.shown_triangles);
  EXPECT_EQ(d["parts"][2]["role"], "keep_out");
  ASSERT_EQ(d["clashes"].size(), f.report["clashes"].size());
  for (std::size_t i = 0; i < d["clashes"].size(); ++i) {
    const auto& a = d["clashes"][i];
    const auto& b = f.report["clashes"][i];
    EXPECT_EQ(a["cable"], b["cable"]);
    for (int k = 0; k < 3; ++k)
      EXPECT_NEAR(a["p"][k].get<double>() * q, b["point"][k].get<double>(), 0.5 * q + 1e-12);
  }
  ASSERT_EQ(d["violations"].size(), 1u);
  EXPECT_EQ(d["violations"][0]["kind"], "bend-radius");
  // Clamps with a point are drawn (a clamp without one cannot be placed on the page).
  ASSERT_EQ(d["clamps"].size(), 2u);
  EXPECT_EQ(st.clamps, 2u);
  EXPECT_EQ(d["clamps"][0]["id"], "clamp-1");
  EXPECT_EQ(d["clamps"][0]["part"], "block");
  EXPECT_TRUE(d["clamps"][0]["placed"].get<bool>());
  EXPECT_NEAR(d["clamps"][0]["d"].get<double>(), 4.2, q);
  EXPECT_NEAR(d["clamps"][0]["p"][2].get<double>() * q, 12.0, 0.5 * q + 1e-12);
  EXPECT_FALSE(d["clamps"][1].contains("part"));
  EXPECT_FALSE(d["clamps"][1]["placed"].get<bool>());
  // Cables run from their first port to their second and pass their path point.
  ASSERT_EQ(d["cables"].size(), 2u);
  EXPECT_EQ(st.cables_drawn, 2u);
  const auto& p = d["cables"][0]["p"];
  ASSERT_GE(p.size(), 6u);
  EXPECT_NEAR(p[0].get<double>() * q, -80.0, q);
  EXPECT_NEAR(p[p.size() - 3].get<double>() * q, 80.0, q);
  bool passes = false;
  for (std::size_t i = 0; i + 2 < p.size(); i += 3)
    passes |= std::abs(p[i].get<double>() * q) < 1.0 && std::abs(p[i + 2].get<double>() * q - 5.0) < 0.2;
  EXPECT_TRUE(passes);
  EXPECT_NEAR(d["cables"][0]["radius"].get<double>(), 2.0, q);
}

TEST(ViewData, EmptyReportAndNoParts) {
  Fixture f = small_scene();
  f.scene.parts.clear();
  ViewStats st;
  const auto d = nlohmann::json::parse(view_data_json(f.scene, f.scene.harness, nlohmann::json::object(), {}, &st));
  EXPECT_TRUE(d["clashes"].empty());
  EXPECT_TRUE(d["violations"].empty());
  EXPECT_TRUE(d["parts"].empty());
  EXPECT_EQ(st.shown_triangles, 0u);
  EXPECT_EQ(st.cables_drawn, 2u);
  // A clash without a point cannot be placed: kept as null so indices stay the report's.
  const nlohmann::json bad = {{"clashes", {{{"kind", "cable-structure"}, {"cable", "W1"}}}}};
  const auto d2 = nlohmann::json::parse(view_data_json(f.scene, f.scene.harness, bad, {}, &st));
  ASSERT_EQ(d2["clashes"].size(), 1u);
  EXPECT_TRUE(d2["clashes"][0].is_null());
  EXPECT_EQ(st.clashes, 0u);
}

// ---------------------------------------------------------------------------------------------
/// Runs headless Chromium on a page; returns its output (the DOM for --dump-dom).
std::string chromium(const std::filesystem::path& dir, const std::string& url, const std::string& mode) {
  const auto profile = dir / "chromium-profile";
  std::filesystem::create_directories(profile);
  const auto out = dir / "chromium.out";
  // SwiftShader: WebGL rendered on the CPU (no GPU here).
  const std::string cmd = "chromium --headless --no-sandbox --disable-gpu --use-angle=swiftshader "
                          "--enable-unsafe-swiftshader --disable-background-networking --disable-component-update "
                          "--disable-sync --no-first-run --user-data-dir='" +
                          profile.string() + "' --window-size=1200,800 --virtual-time-budget=5000 " + mode + " '" +
                          url + "' > '" + out.string() + "' 2>/dev/null";
  const int rc = std::system(cmd.c_str());
  EXPECT_EQ(rc, 0) << cmd;
  return read_text(out);
}

std::string body_attr(const std::string& dom, const std::string& name) {
  const std::regex re("<body[^>]*\\sdata-" + name + "=\"([^\"]*)\"");
  std::smatch m;
  return std::regex_search(dom, m, re) ? m[1].str() : std::string("<missing>");
}

TEST(ViewPage, OpensInHeadlessChromium) {
  ASSERT_EQ(std::system("command -v chromium > /dev/null"), 0) << "Debian package chromium is not installed";
  const Fixture f = small_scene();
  const auto dir = std::filesystem::path(LOOM_BINARY_DIR) / "test-view-html";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const auto page = dir / "view.html";
  const ViewStats st = write_view_html(page, f.scene, f.scene.harness, f.report);
  EXPECT_EQ(st.bytes, std::filesystem::file_size(page));
  const std::string url = "file://" + page.string();

  // 1. The page loads, WebGL draws the scene (pixels not background) with red clash markers.
  const std::string dom = chromium(dir, url + "#select=clash:1", "--dump-dom");
  ASSERT_EQ(body_attr(dom, "ready"), "1") << dom.substr(0, 2000);
  EXPECT_EQ(body_attr(dom, "webgl"), "ok");
  const long pixels = std::stol(body_attr(dom, "pixels"));
  const long nonbg = std::stol(body_attr(dom, "nonbg-pixels"));
  const long red = std::stol(body_attr(dom, "red-pixels"));
  EXPECT_GT(pixels, 100000);
  EXPECT_GT(nonbg, pixels / 50) << "canvas is (nearly) blank";
  EXPECT_LT(nonbg, pixels) << "canvas has no background at all";
  EXPECT_GT(red, 0) << "no clash marker drawn";

  // 2. The clash list holds exactly the report's clashes, in order.
  EXPECT_EQ(body_attr(dom, "clash-count"), std::to_string(f.report["clashes"].size()));
  const auto list_begin = dom.find("<ol id=\"clash-list\"");
  const auto list_end = dom.find("</ol>", list_begin);
  ASSERT_NE(list_begin, std::string::npos);
  const std::string list = dom.substr(list_begin, list_end - list_begin);
  std::size_t items = 0;
  for (auto at = list.find("<li"); at != std::string::npos; at = list.find("<li", at + 1)) ++items;
  EXPECT_EQ(items, f.report["clashes"].size());
  for (const auto& c : f.report["clashes"]) {
    const std::string label = c["cable"].get<std::string>() + " × " +
                              (c.contains("part") ? c["part"] : c["other"]).get<std::string>();
    EXPECT_NE(list.find(label), std::string::npos) << label;
  }

  // 3. The click (performed by the #select hook through the list item's click()) selected it
  //    and flew the camera to the report's point.
  EXPECT_EQ(body_attr(dom, "selected"), "clash:1");
  EXPECT_NE(list.find("data-index=\"1\" class=\"selected\""), std::string::npos) << list;
  EXPECT_EQ(body_attr(dom, "camera-target"), "10.00,0.00,2.50");

  // 4. The clamp list holds the clamps that have a point; selecting one flies to it.
  EXPECT_EQ(body_attr(dom, "clamp-count"), "2");
  const std::string clamp_dom = chromium(dir, url + "#select=clamp:1", "--dump-dom");
  EXPECT_EQ(body_attr(clamp_dom, "selected"), "clamp:1");
  EXPECT_EQ(body_attr(clamp_dom, "camera-target"), "30.00,0.00,12.00");
  EXPECT_NE(clamp_dom.find("K8 (no structure within reach)"), std::string::npos);

  // 5. A screenshot, kept beside the test output.
  chromium(dir, url, "--screenshot='" + (dir / "view.png").string() + "'");
  EXPECT_GT(std::filesystem::file_size(dir / "view.png"), 10000u);
}

}  // namespace
}  // namespace loom
