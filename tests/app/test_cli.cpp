// The command line as a user meets it: exit codes, help, version, errors naming files.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

namespace {

struct Run {
  int status = -1;
  std::string out;
};

/// Runs `loom ARGS` (stderr merged into stdout) and returns exit status and output.
Run loom(const std::string& args) {
  Run r;
  const std::string cmd = std::string(LOOM_EXE) + " " + args + " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return r;
  std::array<char, 4096> buf{};
  while (fgets(buf.data(), buf.size(), p)) r.out += buf.data();
  const int st = pclose(p);
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  return r;
}

const std::string kExamples = std::string(LOOM_SOURCE_DIR) + "/examples";

TEST(Cli, HelpAndVersion) {
  auto h = loom("--help");
  EXPECT_EQ(h.status, 0);
  EXPECT_NE(h.out.find("info"), std::string::npos);
  auto v = loom("--version");
  EXPECT_EQ(v.status, 0);
  EXPECT_NE(v.out.find("loom 0."), std::string::npos);
  auto ih = loom("info --help");
  EXPECT_EQ(ih.status, 0);
  EXPECT_NE(ih.out.find("--json"), std::string::npos);
}

TEST(Cli, UsageErrorsExitTwo) {
  EXPECT_EQ(loom("").status, 2);
  EXPECT_EQ(loom("frobnicate").status, 2);
  EXPECT_EQ(loom("info").status, 2);
}

TEST(Cli, MissingSceneNamesTheFile) {
  auto r = loom("info /nonexistent/scene.toml");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.out.find("/nonexistent/scene.toml"), std::string::npos) << r.out;
}

TEST(Cli, BadSceneIsExitTwoWithLine) {
  const auto p = std::filesystem::temp_directory_path() / "loom_cli_bad.toml";
  std::ofstream(p) << "[scene]\nname='x'\nunits='parsec'\n";
  auto r = loom("info " + p.string());
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.out.find("loom_cli_bad.toml:3"), std::string::npos) << r.out;
  std::filesystem::remove(p);
}

TEST(Cli, InfoOnTheBundledExamples) {
  for (const char* ex : {"wing-section", "real-meshes"}) {
    const std::string scene = kExamples + "/" + ex + "/scene.toml";
    auto r = loom("info " + scene);
    EXPECT_EQ(r.status, 0) << ex << "\n" << r.out;
    EXPECT_NE(r.out.find("parts:"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("bundles"), std::string::npos) << r.out;
    auto j = loom("info --json " + scene);
    EXPECT_EQ(j.status, 0) << j.out;
    EXPECT_NE(j.out.find("\"routing_order\""), std::string::npos);
    auto q = loom("info --quiet " + scene);
    EXPECT_EQ(q.status, 0);
    EXPECT_TRUE(q.out.empty()) << q.out;
  }
}

const std::string kRouteData = std::string(LOOM_SOURCE_DIR) + "/tests/data/route";

std::string slurp(const std::filesystem::path& p) {
  std::ifstream f(p);
  return std::string(std::istreambuf_iterator<char>(f), {});
}

std::filesystem::path fresh_dir(const std::string& name) {
  const auto d = std::filesystem::temp_directory_path() / ("loom_cli_" + name);
  std::filesystem::remove_all(d);
  return d;
}

TEST(CliRoute, GoesAroundABoxAndTheRoutesAuditClean) {
  const auto out = fresh_dir("route_around");
  auto r = loom("route " + kRouteData + "/around.toml --out " + out.string());
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("1/1 cables routed"), std::string::npos) << r.out;
  for (const char* f : {"routed.xml", "report.json", "cables.ply", "view.html", "render.png"})
    EXPECT_TRUE(std::filesystem::exists(out / f)) << f;
  const std::string routed = slurp(out / "routed.xml");
  EXPECT_NE(routed.find("<bspline degree=\"3\""), std::string::npos);
  // An independent check: the routed file, audited on its own, is clean.
  auto a = loom("audit " + kRouteData + "/around.toml --routes " + (out / "routed.xml").string() + " --out " +
                (out / "audit").string());
  EXPECT_EQ(a.status, 0) << a.out;
}

TEST(CliRoute, PortInsideAPartIsExitThreeNamingCableAndPart) {
  const auto out = fresh_dir("route_inside");
  auto r = loom("route " + kRouteData + "/inside.toml --out " + out.string());
  EXPECT_EQ(r.status, 3) << r.out;
  EXPECT_NE(r.out.find("NOT ROUTED C1"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("inside part 'box'"), std::string::npos) << r.out;
  const std::string rep = slurp(out / "report.json");
  EXPECT_NE(rep.find("\"start_in_obstacle\""), std::string::npos) << rep;
  EXPECT_EQ(rep.find("\"cable-structure\""), std::string::npos) << "an unrouted cable must not be audited";
}

TEST(CliRoute, ZeroTimeBudgetIsExitThree) {
  const auto out = fresh_dir("route_zero");
  auto r = loom("route " + kRouteData + "/around.toml --time-limit 0 --out " + out.string());
  EXPECT_EQ(r.status, 3) << r.out;
  EXPECT_NE(r.out.find("timeout"), std::string::npos) << r.out;
}

TEST(CliRoute, HarnessWithoutCablesIsNothingToDo) {
  const auto out = fresh_dir("route_none");
  auto r = loom("route " + kRouteData + "/none.toml --out " + out.string());
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("0/0 cables routed"), std::string::npos) << r.out;
}

TEST(CliRoute, UnknownPlannerIsExitTwo) {
  auto r = loom("route " + kRouteData + "/around.toml --planner nosuch --out " + fresh_dir("route_bad").string());
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("rrtstar"), std::string::npos) << "lists the valid planners: " << r.out;
}

TEST(CliDemo, RoutesAndAuditsTheWingSection) {
  const auto out = fresh_dir("demo");
  auto r = loom("demo --out " + out.string());
  // 0 clean, 1 clashes/violations remain (reported); 2 or 3 would be a failure of the demo.
  EXPECT_TRUE(r.status == 0 || r.status == 1) << r.out;
  EXPECT_NE(r.out.find("24/24 cables routed"), std::string::npos) << r.out;
  EXPECT_TRUE(std::filesystem::exists(out / "routed.xml"));
  EXPECT_TRUE(std::filesystem::exists(out / "report.json"));
}

}  // namespace
