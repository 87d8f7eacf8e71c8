// Routing a harness that had no 3D geometry: the formboard example (examples/formboard: a
// 2D KBL placed by the scene among three boxes) and a VEC topology. Every cable is routed,
// the router places the branch points, the topology is unchanged in routed.xml and
// routed.kbl, routed.kbl reads back as 3D with the drawing's lengths kept, and the report
// compares each routed length with the nominal one. Bounded by planner iterations.
#include "common/run_loom.hpp"

#include "core/error.hpp"
#include "core/io/harness_xml.hpp"
#include "core/io/kbl_read.hpp"
#include "core/io/kbl_write.hpp"
#include "core/io/scene_load.hpp"
#include "routing/route/route_pipeline.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

namespace loom {
namespace {

namespace fs = std::filesystem;
using loom::testing::run_loom;

const std::string kScene = std::string(LOOM_SOURCE_DIR) + "/examples/formboard/scene.toml";

Centerline curve_of(const Segment& s) { return Centerline(s.bspline->degree, s.bspline->knots, s.bspline->control_points); }

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("loom_formboard_route_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  return d;
}

/// The same nodes, segments (between the same nodes, in order) and cables (same ports).
void expect_same_topology(const Harness& a, const Harness& b) {
  ASSERT_EQ(a.ports.size(), b.ports.size());
  for (const auto& p : a.ports) {
    const int q = b.find_port(p.id);
    ASSERT_GE(q, 0) << p.id;
    EXPECT_LT((b.ports[static_cast<std::size_t>(q)].position - p.position).norm(), 1e-9) << p.id;
  }
  ASSERT_EQ(a.branches.size(), b.branches.size());
  for (const auto& br : a.branches) EXPECT_GE(b.find_branch(br.id), 0) << br.id;
  ASSERT_EQ(a.segments.size(), b.segments.size());
  for (std::size_t k = 0; k < a.segments.size(); ++k) {
    EXPECT_EQ(a.segments[k].from, b.segments[k].from) << k;
    EXPECT_EQ(a.segments[k].to, b.segments[k].to) << k;
  }
  ASSERT_EQ(a.cables.size(), b.cables.size());
  for (std::size_t c = 0; c < a.cables.size(); ++c) {
    EXPECT_EQ(a.cables[c].id, b.cables[c].id);
    EXPECT_EQ(a.cables[c].ports[0], b.cables[c].ports[0]);
    EXPECT_EQ(a.cables[c].ports[1], b.cables[c].ports[1]);
  }
}

std::string fixed1(double v) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.1f", v);
  return buf;
}

class FormboardRoute : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    scene_ = new Scene(load_scene(kScene));
    RouteOptions opt;
    opt.threads = 1;
    report_ = new RouteReport(route_scene(*scene_, opt));
  }
  static void TearDownTestSuite() {
    delete report_;
    delete scene_;
  }
  static Scene* scene_;
  static RouteReport* report_;
};
Scene* FormboardRoute::scene_ = nullptr;
RouteReport* FormboardRoute::report_ = nullptr;

TEST_F(FormboardRoute, EveryCableIsRoutedAndTheNodeIsPlaced) {
  const Harness& r = report_->routed;
  EXPECT_TRUE(report_->unrouted.empty());
  EXPECT_EQ(report_->iterations, 4000u);  // the scene's budget bounds every plan
  ASSERT_TRUE(r.branches[0].position);
  for (const auto& s : r.segments) {
    ASSERT_TRUE(s.bspline) << s.from << " -> " << s.to;
    const Centerline c = curve_of(s);
    EXPECT_LT((c.position(c.u_min()) - *r.node_position(s.from)).norm(), 1e-6) << s.from;
    EXPECT_LT((c.position(c.u_max()) - *r.node_position(s.to)).norm(), 1e-6) << s.to;
  }
  expect_same_topology(scene_->harness, r);
  // The ports are where the scene put them, leaving along its directions.
  const Port& x1 = r.ports[static_cast<std::size_t>(r.find_port("X1"))];
  EXPECT_EQ(x1.position, Vec3(0, 0, 50));
  const Centerline s1 = curve_of(r.segments[0]);
  Vec3 d[2];
  s1.evaluate(s1.u_min(), 1, d);
  EXPECT_GT(d[1].normalized().dot(x1.direction), 0.999);
}

TEST_F(FormboardRoute, TheReportComparesRoutedWithNominalLengths) {
  // The oracle: lengths of the routed curves, against the drawing's 200, 260, 260 mm.
  double routed = 0.0, nominal = 0.0;
  std::string notes;
  for (const auto& n : report_->notes) notes += n + "\n";
  for (const auto& s : report_->routed.segments) {
    const double len = curve_of(s).length();
    routed += len;
    nominal += *s.nominal_length;
    const bool over = len > 1.05 * *s.nominal_length;
    const std::string said = "segment " + s.from + " -> " + s.to + ": routed " + fixed1(len) + " mm, nominal " +
                             fixed1(*s.nominal_length) + " mm";
    EXPECT_EQ(notes.find(said) != std::string::npos, over) << said << "\n" << notes;
  }
  EXPECT_DOUBLE_EQ(nominal, 720.0);
  EXPECT_NE(notes.find("nominal lengths: 3 segments routed " + fixed1(routed) + " mm in total against 720.0 mm nominal"),
            std::string::npos)
      << notes;
}

TEST_F(FormboardRoute, RoutedKblReadsBackAs3DWithTheSameTopologyAndLengths) {
  const Harness& r = report_->routed;
  const Harness back = parse_harness_kbl(harness_to_kbl(r), "routed.kbl");
  expect_same_topology(r, back);
  for (const auto& p : back.ports) EXPECT_TRUE(p.placed) << p.id;
  ASSERT_TRUE(back.branches[0].position);
  EXPECT_LT((*back.branches[0].position - *r.branches[0].position).norm(), 1e-9);
  const double nominal[3] = {200, 260, 260};
  for (std::size_t k = 0; k < r.segments.size(); ++k) {
    ASSERT_TRUE(back.segments[k].bspline) << k;
    EXPECT_NEAR(curve_of(back.segments[k]).length(), curve_of(r.segments[k]).length(), 1e-6) << k;
    ASSERT_TRUE(back.segments[k].nominal_length) << k;  // the drawing's length, now its Physical_length
    EXPECT_DOUBLE_EQ(*back.segments[k].nominal_length, nominal[k]);
  }
  // The clip the drawing placed in 2D now sits at its location on the routed segment.
  ASSERT_EQ(back.clamps.size(), 1u);
  const Centerline s1 = curve_of(back.segments[0]);
  EXPECT_LT((back.clamps[0].position - s1.position(s1.parameter_at_length(0.5 * s1.length()))).norm(), 1e-6);
}

TEST_F(FormboardRoute, RoutedXmlHasTheSameTopology) {
  const Harness back = parse_harness_xml(harness_to_xml(report_->routed), "routed.xml");
  expect_same_topology(report_->routed, back);
  for (const auto& s : back.segments) EXPECT_TRUE(s.bspline);
}

TEST(FormboardCli, TheExampleRoutesCleanlyAndWritesRoutedKbl) {
  const fs::path out = fresh_dir("cli");
  const auto r = run_loom("route " + kScene + " --quiet --threads 1 --out " + out.string());
  EXPECT_EQ(r.status, 0) << r.out;
  ASSERT_TRUE(fs::exists(out / "routed.kbl")) << r.out;
  ASSERT_TRUE(fs::exists(out / "routed.xml"));
  std::ifstream in(out / "report.json");
  const auto rep = nlohmann::json::parse(in);
  EXPECT_TRUE(rep["clashes"].empty()) << rep["clashes"].dump();
  std::string notes;
  for (const auto& n : rep["notes"]) notes += n.get<std::string>() + "\n";
  EXPECT_NE(notes.find("no 3D geometry: topology only, 3 nodes to be placed by the scene, 1 by the router"), std::string::npos)
      << notes;
  const Harness back = read_harness_kbl(out / "routed.kbl");
  EXPECT_EQ(back.segments.size(), 3u);
  for (const auto& s : back.segments) EXPECT_TRUE(s.bspline);
  fs::remove_all(out);
}

TEST(FormboardCli, InfoSaysTopologyOnlyAndAMissingPlacementIsExit2) {
  const auto info = run_loom("info " + kScene);
  ASSERT_EQ(info.status, 0) << info.out;
  EXPECT_NE(info.out.find("no 3D geometry: topology only, 3 nodes to be placed by the scene, 1 by the router"),
            std::string::npos)
      << info.out;
  // The example without X3's placement: refused before anything is written.
  const fs::path dir = fresh_dir("missing");
  fs::create_directories(dir);
  for (const char* f : {"harness.kbl", "floor.obj", "pillar.obj", "wall.obj"})
    fs::copy_file(fs::path(kScene).parent_path() / f, dir / f);
  std::ifstream in(kScene);
  std::ofstream toml(dir / "scene.toml");
  for (std::string line; std::getline(in, line);)
    if (line.rfind("X3 =", 0) != 0) toml << line << "\n";
  toml.close();
  const auto r = run_loom("route " + (dir / "scene.toml").string() + " --quiet --out " + (dir / "out").string());
  EXPECT_EQ(r.status, 2) << r.out;
  for (const char* s : {"harness.kbl:", "1 port has no position: X3 (line", "[harness.place]", "scene.toml"})
    EXPECT_NE(r.out.find(s), std::string::npos) << s << "\n" << r.out;
  EXPECT_FALSE(fs::exists(dir / "out" / "routed.xml"));
  fs::remove_all(dir);
}

TEST(VecRoute, APlacedVecTopologyRoutesWithItsBranchPointsPlaced) {
  const fs::path dir = fresh_dir("vec");
  fs::create_directories(dir);
  std::ofstream(dir / "scene.toml") << "[scene]\nname = \"vec\"\nunits = \"mm\"\n\n[routing]\niterations = 500\n"
                                       "time_limit = 10.0\n\n[harness]\nfile = \""
                                    << LOOM_TEST_DATA << "/formboard/routing-examples-rl.vec\"\n\n[harness.place]\n"
                                    << "A1 = { at = [0.0, 0.0, 0.0], dir = [1.0, 0.0, 0.0] }\n"
                                    << "A2 = { at = [150.0, 150.0, 0.0], dir = [0.0, -1.0, 0.0] }\n"
                                    << "A3 = { at = [600.0, 0.0, 0.0], dir = [-1.0, 0.0, 0.0] }\n";
  const Scene scene = load_scene(dir / "scene.toml");
  RouteOptions opt;
  opt.threads = 1;
  const RouteReport rep = route_scene(scene, opt);
  EXPECT_TRUE(rep.unrouted.empty());
  for (const auto& b : rep.routed.branches) EXPECT_TRUE(b.position) << b.id;
  for (const auto& s : rep.routed.segments) EXPECT_TRUE(s.bspline) << s.from << " -> " << s.to;
  expect_same_topology(scene.harness, rep.routed);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace loom
