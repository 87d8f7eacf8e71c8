// Reproducible routes: `loom route SCENE --seed N --iterations K` writes the same routed.xml
// on every run; --iterations and [routing] iterations are checked as usage / input errors.
// No timing is asserted: the time limit is raised far above what the budget needs, so the
// iteration budget, not the clock, ends every plan.

#include <gtest/gtest.h>

#include "common/run_loom.hpp"

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <unistd.h>

namespace fs = std::filesystem;
using loom::testing::run_loom;

namespace {

const std::string kRouteData = std::string(LOOM_TEST_DATA) + "/route";
/// Iteration budget of the runs compared here: enough for the easy around-the-box scene.
constexpr int kIterations = 200;
/// A time limit that never ends a plan of kIterations on the around-the-box scene, even
/// in a sanitizer build: the budget decides where every plan stops.
constexpr int kGenerousTimeLimit = 60;

/// A fresh, empty-to-be directory under the system temp directory (per process).
fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("loom_repro_" + std::to_string(::getpid()) + "_" + name);
  fs::remove_all(d);
  return d;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

/// `loom route around.toml` with the given extra options into `out`.
loom::testing::LoomRun route_around(const fs::path& out, const std::string& options) {
  return run_loom("route " + kRouteData + "/around.toml --quiet --time-limit " + std::to_string(kGenerousTimeLimit) +
                  " " + options + " --out " + out.string());
}

/// A copy of around.toml in its own directory with `routing` as its [routing] table
/// (absolute paths to the box and the harness); returns the scene path.
fs::path around_scene_with(const std::string& name, const std::string& routing) {
  const fs::path dir = fresh_dir(name);
  fs::create_directories(dir);
  const fs::path scene = dir / "scene.toml";
  std::ofstream(scene) << "[scene]\nname = \"around-the-box\"\nunits = \"mm\"\n\n"
                       << "[[part]]\nname = \"box\"\nfile = \"" << kRouteData << "/box.obj\"\n"
                       << "transform = { translate = [-20, -20, -20], scale = 5.0 }\n\n"
                       << "[harness]\nfile = \"" << kRouteData << "/harness_around.xml\"\n\n"
                       << "[routing]\nclearance = 3.0\nplanner = \"informedrrtstar\"\ntime_limit = "
                       << kGenerousTimeLimit << "\nseed = 7\n"
                       << routing << "\n";
  return scene;
}

}  // namespace

// --- the same seed and budget give the same routes -----------------------------------

TEST(ReproducibleRoute, SameSeedAndIterationsWriteIdenticalRoutedXml) {
  const std::string opts = "--seed 7 --iterations " + std::to_string(kIterations);
  const fs::path a = fresh_dir("run_a"), b = fresh_dir("run_b");
  const auto ra = route_around(a, opts);
  const auto rb = route_around(b, opts);
  ASSERT_EQ(ra.status, 0) << ra.out;
  ASSERT_EQ(rb.status, 0) << rb.out;
  const std::string xa = slurp(a / "routed.xml"), xb = slurp(b / "routed.xml");
  ASSERT_FALSE(xa.empty());
  EXPECT_EQ(xa, xb) << "routed.xml differs between two runs with the same --seed and --iterations";
  // The report says the run is reproducible and names the budget.
  const std::string report = slurp(a / "report.json");
  EXPECT_NE(report.find("\"reproducible\": true"), std::string::npos) << report;
  EXPECT_NE(report.find("\"iterations\": " + std::to_string(kIterations)), std::string::npos) << report;
  fs::remove_all(a);
  fs::remove_all(b);
}

TEST(ReproducibleRoute, AnotherSeedStillRoutesClean) {
  // Another seed may or may not give other routes on this easy scene: only the outcome is
  // asserted, not that it differs.
  const fs::path out = fresh_dir("other_seed");
  const auto r = route_around(out, "--seed 8 --iterations " + std::to_string(kIterations));
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_FALSE(slurp(out / "routed.xml").empty());
  fs::remove_all(out);
}

TEST(ReproducibleRoute, SummaryNamesTheBudget) {
  const fs::path out = fresh_dir("summary");
  const auto r = run_loom("route " + kRouteData + "/around.toml --iterations " + std::to_string(kIterations) +
                          " --time-limit " + std::to_string(kGenerousTimeLimit) + " --out " + out.string());
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find(std::to_string(kIterations) + " iterations"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("not reproducible"), std::string::npos) << r.out;
  fs::remove_all(out);
}

TEST(ReproducibleRoute, WithoutABudgetTheReportSaysSo) {
  const fs::path out = fresh_dir("no_budget");
  const auto r = run_loom("route " + kRouteData + "/around.toml --quiet --out " + out.string());
  EXPECT_EQ(r.status, 0) << r.out;
  const std::string report = slurp(out / "report.json");
  EXPECT_NE(report.find("\"reproducible\": false"), std::string::npos) << report;
  EXPECT_NE(report.find("no iteration budget"), std::string::npos) << report;
  fs::remove_all(out);
}

// --- --iterations is a usage error unless a whole number in range ---------------------

TEST(CliIterationsOption, RejectsBadValuesNamingTheOption) {
  for (const char* bad : {"0", "-1", "ten", "1.5", "1e3", "", "100000001", "99999999999999999999999"}) {
    const fs::path out = fresh_dir("bad_iterations");
    const auto r = run_loom("route " + kRouteData + "/around.toml --iterations '" + std::string(bad) + "' --out " +
                            out.string());
    EXPECT_EQ(r.status, 2) << "--iterations '" << bad << "': " << r.out;
    EXPECT_NE(r.out.find("--iterations"), std::string::npos) << r.out;
    EXPECT_FALSE(fs::exists(out / "routed.xml")) << "a usage error must do no work";
    fs::remove_all(out);
  }
}

TEST(CliIterationsOption, DemoTakesItAndChecksIt) {
  const auto r = run_loom("demo --iterations 0 --out " + fresh_dir("demo_bad").string());
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("--iterations"), std::string::npos) << r.out;
  const auto help = run_loom("demo --help");
  EXPECT_EQ(help.status, 0) << help.out;
  EXPECT_NE(help.out.find("--iterations"), std::string::npos) << help.out;
}

TEST(CliIterationsOption, HelpSaysPrmIsNotReproducible) {
  const auto r = run_loom("route --help");
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("--iterations"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("prmstar"), std::string::npos) << r.out;
}

// --- [routing] iterations ---------------------------------------------------------------

TEST(SceneIterationsKey, RejectsBadValuesNamingTheKey) {
  for (const char* bad : {"0", "-3", "2.5", "\"ten\"", "1e9", "true"}) {
    const fs::path scene = around_scene_with("scene_bad", std::string("iterations = ") + bad);
    const auto r = run_loom("route " + scene.string() + " --out " + (scene.parent_path() / "out").string());
    EXPECT_EQ(r.status, 2) << "iterations = " << bad << ": " << r.out;
    EXPECT_NE(r.out.find("routing.iterations"), std::string::npos) << r.out;
    fs::remove_all(scene.parent_path());
  }
}

TEST(SceneIterationsKey, MisspelledKeyIsRefusedListingIterations) {
  const fs::path scene = around_scene_with("scene_typo", "iteration = 50");
  const auto r = run_loom("route " + scene.string() + " --out " + (scene.parent_path() / "out").string());
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("unknown key"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("iterations"), std::string::npos) << r.out;
  fs::remove_all(scene.parent_path());
}

TEST(SceneIterationsKey, SceneValueIsUsedAndTheOptionOverridesIt) {
  const fs::path scene = around_scene_with("scene_ok", "iterations = 150");
  const fs::path out = scene.parent_path() / "out";
  auto r = run_loom("route " + scene.string() + " --quiet --out " + out.string());
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(slurp(out / "report.json").find("\"iterations\": 150"), std::string::npos);
  r = run_loom("route " + scene.string() + " --quiet --iterations 160 --out " + out.string());
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(slurp(out / "report.json").find("\"iterations\": 160"), std::string::npos);
  // `loom info` reports the value and its source.
  r = run_loom("info " + scene.string());
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("routing.iterations"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("scene file"), std::string::npos) << r.out;
  fs::remove_all(scene.parent_path());
}
