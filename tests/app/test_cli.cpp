// The command line as a user meets it: exit codes, help, version, errors naming files.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "common/run_loom.hpp"

#include <array>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <tuple>
#include <iterator>
#include <string>
#include <utility>
#include <vector>

#include <pty.h>
#include <sys/wait.h>
#include <unistd.h>

namespace {

using Run = loom::testing::LoomRun;

/// Runs `loom ARGS` (stderr merged into stdout) and returns exit status and output.
Run loom(const std::string& args) { return loom::testing::run_loom(args); }

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
  for (const char* ex : {"wing-section", "wing-classes", "real-meshes", "building-scan"}) {
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

TEST(CliRoute, PortSealedInACavityIsExitThreeSayingEnclosed) {
  const auto out = fresh_dir("route_sealed");
  auto r = loom("route " + kRouteData + "/unreachable.toml --out " + out.string());
  EXPECT_EQ(r.status, 3) << r.out;
  EXPECT_NE(r.out.find("0/1 cables routed"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("NOT ROUTED C1"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("sealed in a cavity"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("part 'enclosure'"), std::string::npos) << r.out;
  EXPECT_NE(slurp(out / "report.json").find("\"enclosed\""), std::string::npos);
}

TEST(CliRoute, BranchPointInAWallIsExitThreeNamingBranchAndPartOncePerCable) {
  const auto out = fresh_dir("route_branch_wall");
  auto r = loom("route " + kRouteData + "/branch_in_wall.toml --out " + out.string());
  EXPECT_EQ(r.status, 3) << r.out;
  EXPECT_NE(r.out.find("0/2 cables routed"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("branch point B1 at (5, 5, 5) is inside part 'box'"), std::string::npos) << r.out;
  // Each cable is reported once, at the first segment that stopped it.
  std::size_t lines = 0;
  for (std::size_t at = r.out.find("NOT ROUTED"); at != std::string::npos; at = r.out.find("NOT ROUTED", at + 1)) ++lines;
  EXPECT_EQ(lines, 2u) << r.out;
  EXPECT_NE(slurp(out / "report.json").find("\"branch_blocked\""), std::string::npos);
}

TEST(CliDemo, RoutesAndAuditsTheWingSection) {
  const auto out = fresh_dir("demo");
  auto r = loom("demo --out " + out.string());
  // The bundled harness routes clean: no clash and no bend-radius or clearance violation
  // against the exact geometry (exit 0).
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("0 clashes, 0 violations"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("24/24 cables routed"), std::string::npos) << r.out;
  EXPECT_TRUE(std::filesystem::exists(out / "routed.xml"));
  EXPECT_TRUE(std::filesystem::exists(out / "report.json"));
}

TEST(CliRoute, TheWingInThreeClassesRoutesCleanAndSegregated) {
  // Power, data and signal on their own connectors and segments, kept 20/20/10 mm apart:
  // every rule holds — no clash, bend, unsupported span or segregation finding (exit 0).
  const auto out = fresh_dir("wing_classes");
  auto r = loom("route " + kExamples + "/wing-classes/scene.toml --out " + out.string());
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("24/24 cables routed"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("0 clashes, 0 violations"), std::string::npos) << r.out;
  const std::string report = slurp(out / "report.json");
  EXPECT_EQ(report.find("\"segregation\""), std::string::npos) << "a segregation finding";
}

// --- progress bars and --render-size ----------------------------------------

/// Runs `loom ARGS` on a pseudo-terminal (stdin, stdout and stderr are the terminal), as a
/// person at a shell would; returns exit status and everything the terminal received.
Run loom_on_terminal(const std::vector<std::string>& args) {
  Run r;
  std::vector<std::string> words{LOOM_EXE};
  words.insert(words.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& w : words) argv.push_back(w.data());
  argv.push_back(nullptr);
  int master = -1;
  const pid_t pid = forkpty(&master, nullptr, nullptr, nullptr);
  if (pid < 0) return r;
  if (pid == 0) {
    execv(argv[0], argv.data());
    _exit(127);
  }
  std::array<char, 4096> buf{};
  for (;;) {
    const ssize_t n = read(master, buf.data(), buf.size());
    if (n > 0) r.out.append(buf.data(), static_cast<std::size_t>(n));
    else if (n < 0 && errno == EINTR) continue;
    else break;  // EIO once the child has closed the terminal
  }
  close(master);
  int st = 0;
  waitpid(pid, &st, 0);
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  return r;
}

/// Width and height from a PNG's IHDR chunk (bytes 16..23, big-endian), or {-1, -1}.
std::pair<long, long> png_size(const std::filesystem::path& file) {
  const std::string b = slurp(file);
  if (b.size() < 24 || b.compare(1, 3, "PNG") != 0 || b.compare(12, 4, "IHDR") != 0) return {-1, -1};
  auto be32 = [&](std::size_t at) {
    long v = 0;
    for (std::size_t k = 0; k < 4; ++k) v = v * 256 + static_cast<unsigned char>(b[at + k]);
    return v;
  };
  return {be32(16), be32(20)};
}

const std::string kAuditData = std::string(LOOM_SOURCE_DIR) + "/tests/data/audit";

TEST(CliProgress, PipedOutputHasNoProgressText) {
  const auto out = fresh_dir("progress_piped");
  const auto route = loom("route " + kRouteData + "/around.toml --out " + (out / "route").string());
  const auto audit = loom("audit " + kAuditData + "/clash.toml --out " + (out / "audit").string());
  EXPECT_EQ(route.status, 0) << route.out;
  EXPECT_EQ(audit.status, 1) << audit.out;
  for (const auto* r : {&route, &audit}) {
    EXPECT_EQ(r->out.find('\r'), std::string::npos) << r->out;
    EXPECT_EQ(r->out.find("[#"), std::string::npos) << r->out;
    EXPECT_EQ(r->out.find("ETA"), std::string::npos) << r->out;
  }
}

TEST(CliProgress, TerminalShowsBarsAndQuietSilencesThem) {
  const auto out = fresh_dir("progress_tty");
  const auto r = loom_on_terminal({"audit", kAuditData + "/clash.toml", "--out", out.string()});
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_NE(r.out.find('\r'), std::string::npos) << r.out;
  // Loading, indexing, auditing and rendering each end with a completed bar and its count.
  for (const char* line : {"load ", "index ", "audit ", "render "})
    EXPECT_NE(r.out.find(std::string("\r") + line), std::string::npos) << line << "\n" << r.out;
  EXPECT_NE(r.out.find("[########################]  1/1 files"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("1/1 cables"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("1 clashes"), std::string::npos) << "the summary is still printed\n" << r.out;

  const auto q = loom_on_terminal({"audit", kAuditData + "/clash.toml", "--quiet", "--out", out.string()});
  EXPECT_EQ(q.status, 1) << q.out;
  EXPECT_TRUE(q.out.empty()) << q.out;
  const auto j = loom_on_terminal({"audit", kAuditData + "/clash.toml", "--json", "--out", out.string()});
  EXPECT_EQ(j.out.find("[#"), std::string::npos) << "--json prints the report only\n" << j.out;
}

TEST(CliRenderSize, RouteAndAuditWriteTheAskedSize) {
  const auto out = fresh_dir("render_size");
  const auto route = loom("route " + kRouteData + "/around.toml --render-size 320x200 --out " + (out / "route").string());
  EXPECT_EQ(route.status, 0) << route.out;
  EXPECT_EQ(png_size(out / "route" / "render.png"), std::make_pair(320L, 200L));
  const auto audit = loom("audit " + kAuditData + "/clash.toml --render-size 200x320 --out " + (out / "audit").string());
  EXPECT_EQ(audit.status, 1) << audit.out;
  EXPECT_EQ(png_size(out / "audit" / "render.png"), std::make_pair(200L, 320L));
}

TEST(CliRenderSize, BadValueIsExitTwoBeforeAnyWork) {
  const auto out = fresh_dir("render_size_bad");
  for (const char* size : {"0x5", "abc", "320x", "320x200x3", "-5x5"}) {
    const std::string flag = std::string(" --render-size=") + size + " --out " + out.string();
    for (const std::string& cmd :
         {"route " + kRouteData + "/around.toml" + flag, "audit " + kAuditData + "/clash.toml" + flag, "demo" + flag}) {
      const auto r = loom(cmd);
      EXPECT_EQ(r.status, 2) << cmd << "\n" << r.out;
      EXPECT_NE(r.out.find("--render-size"), std::string::npos) << cmd << "\n" << r.out;
      EXPECT_FALSE(std::filesystem::exists(out / "render.png")) << cmd;
    }
  }
}

TEST(CliSimplify, WritesEachPartAndTheReport) {
  const auto out = fresh_dir("simplify");
  const auto r = loom("simplify " + kRouteData + "/around.toml --dim-pre 2 --out " + out.string());
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("containment tolerance"), std::string::npos) << r.out;  // what was used
  EXPECT_NE(r.out.find("12 -> 12 triangles"), std::string::npos) << r.out;     // a box stays a box
  EXPECT_TRUE(std::filesystem::exists(out / "box.stl"));
  const std::string rep = slurp(out / "simplify.json");
  for (const char* key : {"\"dim_pre\": 2.0", "\"dim_pre_source\": \"--dim-pre\"", "\"triangles_before\": 12",
                          "\"triangles_after\": 12", "\"containment\": 1.0", "\"status\": \"ok\"", "\"hausdorff\"",
                          "\"tolerance\"", "\"booleans\": 0", "\"booleans_by\": \"none\"", "\"booleans_note\": \"\""})
    EXPECT_NE(rep.find(key), std::string::npos) << key << "\n" << rep;
  for (const auto& e : std::filesystem::directory_iterator(out))
    EXPECT_TRUE(e.path().extension() == ".json" || e.path().extension() == ".stl") << e.path();  // no temp files
}

/// Writes DIR/scene.toml with one part, DIR/hollow.obj: a cube [0, 40]³ around a sealed
/// cubic cavity [4, 36]³ (the inner shell wound inwards), and `simplify_keys` under [simplify].
std::filesystem::path hollow_box_scene(const std::filesystem::path& dir, const std::string& simplify_keys) {
  std::filesystem::create_directories(dir);
  std::ofstream obj(dir / "hollow.obj");
  for (const double s : {0.0, 4.0})
    for (int k = 0; k < 8; ++k)
      obj << "v " << (k & 1 ? 40 - s : s) << ' ' << (k & 2 ? 40 - s : s) << ' ' << (k & 4 ? 40 - s : s) << '\n';
  const int quads[6][4] = {{1, 3, 4, 2}, {5, 6, 8, 7}, {1, 2, 6, 5}, {3, 7, 8, 4}, {1, 5, 7, 3}, {2, 4, 8, 6}};
  for (const int base : {0, 8})
    for (const auto& q : quads) {
      if (base == 0) obj << "f " << q[0] << ' ' << q[1] << ' ' << q[2] << ' ' << q[3] << '\n';
      else obj << "f " << q[3] + base << ' ' << q[2] + base << ' ' << q[1] + base << ' ' << q[0] + base << '\n';
    }
  std::ofstream toml(dir / "scene.toml");
  toml << "[scene]\nname = \"hollow\"\nunits = \"mm\"\n[[part]]\nname = \"hollow\"\nfile = \"hollow.obj\"\n"
       << "[simplify]\ndim_pre = 2.0\n" << simplify_keys;
  return dir / "scene.toml";
}

TEST(CliSimplify, ABlockedPartIsSplitAndTheTreeReported) {
  const auto dir = fresh_dir("simplify_split");
  const auto out = dir / "out";
  const auto r = loom("simplify " + hollow_box_scene(dir, "").string() + " --out " + out.string());
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("1 parts split, 0 blocked"), std::string::npos) << r.out;
  const nlohmann::json j = nlohmann::json::parse(slurp(out / "simplify.json"));
  EXPECT_EQ(j["parts_split"], 1);
  EXPECT_EQ(j["parts_blocked"], 0);
  EXPECT_GT(j["index_bytes_exact"].get<double>(), 0.0);
  EXPECT_GT(j["index_bytes_simplified"].get<double>(), 0.0);
  const nlohmann::json& part = j["parts"][0];
  EXPECT_NE(part["fallback"], "original") << part["reason"];  // ok, or hull_fallback where a wall piece is torn
  EXPECT_EQ(part["reason"].get<std::string>().rfind("split into ", 0), 0u) << part["reason"];
  ASSERT_TRUE(part.contains("pieces"));
  EXPECT_GE(part["pieces"].size(), 2u);
  for (const auto& p : part["pieces"]) {
    EXPECT_FALSE(p["id"].get<std::string>().empty());
    EXPECT_EQ(p["containment"], 1.0);
  }
  // Off from the scene file: the part is kept whole, blocked, with no tree.
  const auto dir2 = fresh_dir("simplify_nosplit");
  const auto r2 = loom("simplify " + hollow_box_scene(dir2, "split = false\n").string() + " --out " + (dir2 / "out").string());
  ASSERT_EQ(r2.status, 0) << r2.out;
  const nlohmann::json j2 = nlohmann::json::parse(slurp(dir2 / "out" / "simplify.json"));
  EXPECT_EQ(j2["parts_blocked"], 1);
  EXPECT_FALSE(j2["parts"][0].contains("pieces"));
}

TEST(CliSimplify, BadDimPreIsExitTwoAndWritesNothing) {
  const auto out = fresh_dir("simplify_bad");
  for (const char* v : {"0", "-1", "nan", "inf", "abc"}) {
    const auto r = loom("simplify " + kRouteData + "/around.toml --dim-pre " + v + " --out " + out.string());
    EXPECT_EQ(r.status, 2) << v << "\n" << r.out;
    EXPECT_NE(r.out.find("--dim-pre"), std::string::npos) << v << "\n" << r.out;
    EXPECT_FALSE(std::filesystem::exists(out / "simplify.json")) << v;
  }
}

// Regressions: options whose "not given" value was a sentinel inside the
// option (NaN, < 0, 0) took a bad given value for "use the scene's": `simplify --dim-pre
// nan`, `route --time-limit nan|-1`, `route --seed -5`, `audit --spacing 0` and
// `audit --tolerance 0` ran with defaults and exit 0 (`scan --diameter nan` passed CLI11's
// PositiveNumber check and was estimated). Each must be exit 2 naming the option.
TEST(CliRegression, GivenOptionValuesAreCheckedNotTakenForDefaults) {
  const auto out = fresh_dir("sentinels");
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"simplify " + kRouteData + "/around.toml --dim-pre nan", "--dim-pre"},
      {"route " + kRouteData + "/around.toml --time-limit nan", "--time-limit"},
      {"route " + kRouteData + "/around.toml --time-limit -1", "--time-limit"},
      {"route " + kRouteData + "/around.toml --seed -5", "--seed"},
      {"audit " + kAuditData + "/clean.toml --spacing 0", "--spacing"},
      {"audit " + kAuditData + "/clean.toml --tolerance 0", "--tolerance"},
      {"audit " + kAuditData + "/clean.toml --tolerance nan", "--tolerance"},
      {"scan " + std::string(LOOM_SHARED_DATA) + "/pcl/table_scene_mug_stereo_textured.pcd --diameter nan",
       "--diameter"},
      {"scan " + std::string(LOOM_SHARED_DATA) + "/pcl/table_scene_mug_stereo_textured.pcd --diameter 0",
       "--diameter"}};
  for (const auto& [cmd, option] : cases) {
    const auto r = loom(cmd + " --out " + out.string());
    EXPECT_EQ(r.status, 2) << cmd << "\n" << r.out;
    EXPECT_NE(r.out.find(option), std::string::npos) << cmd << "\n" << r.out;
  }
}

// Regressions: numbers far beyond
// any scene (a transform scale or translation of 1e300, a clearance of 1e300, a route's
// control point at x = 1e300) were accepted — the audit of that route ran out of memory —
// and a vertex pushed past single precision's useful range by a transform passed too.
// Each is exit 2 naming the key, element or part.
TEST(CliRegression, NumbersBeyondAnySceneAreRefused) {
  const auto dir = fresh_dir("magnitudes");
  std::filesystem::create_directories(dir);
  std::filesystem::copy_file(kRouteData + "/box.obj", dir / "box.obj");
  const std::string around = slurp(kRouteData + "/around.toml");
  const std::string harness = slurp(kRouteData + "/harness_around.xml");
  auto with = [&](std::string text, const std::string& from, const std::string& to) {
    const auto at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return at == std::string::npos ? text : text.replace(at, from.size(), to);
  };
  std::ofstream(dir / "harness_around.xml") << harness;
  const std::vector<std::pair<std::string, std::string>> scenes = {
      {with(around, "scale = 5.0", "scale = 1e300"), "transform.scale"},
      {with(around, "translate = [-20, -20, -20]", "translate = [-20, 1e18, -20]"), "transform.translate"},
      {with(around, "scale = 5.0", "scale = 1e12"), "a vertex lands at"},
      {with(around, "clearance  = 3.0", "clearance  = 1e300"), "routing.clearance"}};
  for (const auto& [text, key] : scenes) {
    std::ofstream(dir / "scene.toml") << text;
    const auto r = loom("info " + (dir / "scene.toml").string());
    EXPECT_EQ(r.status, 2) << key << "\n" << r.out;
    EXPECT_NE(r.out.find(key), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("scene.toml"), std::string::npos) << r.out;
  }
  std::ofstream(dir / "scene.toml") << around;
  std::ofstream(dir / "harness_around.xml") << with(harness, "diameter=\"2\"", "diameter=\"1e300\"");
  const auto d = loom("info " + (dir / "scene.toml").string());
  EXPECT_EQ(d.status, 2) << d.out;
  EXPECT_NE(d.out.find("harness_around.xml"), std::string::npos) << d.out;
  EXPECT_NE(d.out.find("'diameter'"), std::string::npos) << d.out;
}

// Regression: a tessellation deflection of 1e-9 mm (given, or the
// default r/10 of a cable 1e-300 mm thick) made OpenCASCADE's mesher throw
// Standard_NumericError, which nothing caught: the process aborted. A deflection below 1e-6
// of the file's size is refused before meshing, and OpenCASCADE's own exceptions
// become input errors naming the file.
TEST(CliRegression, TessellationFinerThanTheFileCanHoldIsExitTwo) {
  const auto dir = fresh_dir("deflection");
  std::filesystem::create_directories(dir);
  std::filesystem::copy_file(kExamples + "/wing-section/spar.step", dir / "spar.step");
  std::ofstream(dir / "scene.toml") << "[scene]\nname = \"fine\"\nunits = \"mm\"\n[[part]]\nname = \"spar\"\n"
                                       "file = \"spar.step\"\n[tessellation]\nlinear_deflection = 1e-9\n";
  const auto r = loom("info " + (dir / "scene.toml").string());
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("spar.step"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("below 1e-6 of the file's size"), std::string::npos) << r.out;
}

// Regression: a part named with 100,000 characters made `simplify
// --step` fail to create its files ("File name too long") after other parts' files were
// written, and the exception, thrown inside a TBB task, cancelled the nested loops of the
// parts other threads were simplifying (UBSan: a member call on a null shape). OpenCASCADE's
// STEP writer also printed its statistics on stdout under --quiet, and two parts' STEP
// files written at once by different threads failed now and then ("cannot write STEP
// file": the writer is not thread-safe). Stems are cut to a valid length (with a hash
// of the whole name), exceptions wait until every part is done, one STEP file is written
// at a time, and stdout stays empty.
TEST(CliRegression, LongPartNamesGiveValidFilesAndQuietStaysQuiet) {
  const auto dir = fresh_dir("long_name");
  std::filesystem::create_directories(dir);
  std::filesystem::copy_file(kRouteData + "/box.obj", dir / "box.obj");
  const std::string name(100000, 'x');
  std::ofstream(dir / "scene.toml") << "[scene]\nname = \"long\"\nunits = \"mm\"\n[[part]]\nname = \"" << name
                                    << "\"\nfile = \"box.obj\"\ntransform = { scale = 5.0 }\n[[part]]\nname = \"b\"\n"
                                       "file = \"box.obj\"\ntransform = { translate = [100, 0, 0], scale = 5.0 }\n"
                                       "[simplify]\ndim_pre = 4.0\n";
  const auto out = dir / "out";
  const auto r = loom("simplify " + (dir / "scene.toml").string() + " --step --quiet --out " + out.string());
  EXPECT_EQ(r.status, 0) << r.out.substr(0, 2000);
  EXPECT_TRUE(r.out.empty()) << r.out.substr(0, 2000);
  int stl = 0, step = 0;
  for (const auto& e : std::filesystem::directory_iterator(out)) {
    const std::string f = e.path().filename().string();
    EXPECT_LE(f.size(), 120u) << f;
    stl += e.path().extension() == ".stl";
    step += e.path().extension() == ".step";
  }
  EXPECT_EQ(stl, 2);
  EXPECT_EQ(step, 2);
}

// --- hostile inputs: bad values of every kind ------------------------------------------

// `--threads 0` and `--threads -1` ran with all cores, and `route --seed 5000000000` ran
// with another seed (cut to 32 bits): each is exit 2 naming the option and its range,
// before any work.
TEST(CliOptions, ThreadsAndSeedOutOfRangeAreUsageErrors) {
  const auto out = fresh_dir("threads_seed");
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"audit " + kAuditData + "/clean.toml --threads 0", "--threads: must be a whole number in 1.."},
      {"audit " + kAuditData + "/clean.toml --threads -1", "--threads: must be a whole number in 1.."},
      {"audit " + kAuditData + "/clean.toml --threads 1.5", "--threads"},
      {"route " + kRouteData + "/around.toml --threads 0", "--threads"},
      {"route " + kRouteData + "/around.toml --seed 5000000000", "--seed: must be a whole number in 0..4294967295"},
      {"route " + kRouteData + "/around.toml --seed 1e3", "--seed"}};
  for (const auto& [cmd, message] : cases) {
    const auto r = loom(cmd + " --out " + out.string());
    EXPECT_EQ(r.status, 2) << cmd << "\n" << r.out;
    EXPECT_NE(r.out.find(message), std::string::npos) << cmd << "\n" << r.out;
    EXPECT_FALSE(std::filesystem::exists(out)) << cmd;
  }
  EXPECT_EQ(loom("audit " + kAuditData + "/clean.toml --threads 1 --quiet --out " + out.string()).status, 0);
}

// `--out ""` wrote into the current directory, which nobody named; a tolerance below the
// index's rounding failed as "tolerance 0.000000 is not above twice the index error
// 0.000000", naming neither the option nor the values.
TEST(CliOptions, EmptyOutAndUncertifiableToleranceAreNamed) {
  for (const std::string& cmd : {"audit " + kAuditData + "/clean.toml", "route " + kRouteData + "/around.toml",
                                std::string("demo")}) {
    const auto r = loom(cmd + " --quiet --out ''");
    EXPECT_EQ(r.status, 2) << cmd << "\n" << r.out;
    EXPECT_NE(r.out.find("--out: must name a path, got an empty string"), std::string::npos) << cmd << "\n" << r.out;
  }
  const auto out = fresh_dir("tiny_tolerance");
  const auto r = loom("audit " + kAuditData + "/clean.toml --quiet --tolerance 1e-300 --out " + out.string());
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("clash tolerance 1e-300 (as requested) is not above twice the index's distance rounding"),
            std::string::npos)
      << r.out;
  EXPECT_FALSE(std::filesystem::exists(out / "report.json"));
}

// `--method discrete --spacing 1e-9` failed inside Centerline, naming neither the cable
// nor the option.
TEST(CliOptions, SpacingFarBelowTheCableNamesTheCableAndTheOption) {
  const auto out = fresh_dir("tiny_spacing");
  const auto r = loom("audit " + kAuditData + "/clean.toml --quiet --method discrete --spacing 1e-9 --out " + out.string());
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("cable 'C1': sample spacing 1.0000000000000001e-09 (--spacing) gives"), std::string::npos) << r.out;
  EXPECT_FALSE(std::filesystem::exists(out / "report.json"));
}

// An output path that is a directory failed only when its turn came: `audit` had written
// nothing of use, `route` had left routed.xml, report.json and cables.ply beside a missing
// view. Every target is checked before any work, and nothing is written.
TEST(CliOutputs, ATargetThatIsADirectoryStopsTheCommandBeforeAnyOutput) {
  namespace fs = std::filesystem;
  const std::vector<std::tuple<std::string, std::string, std::vector<std::string>>> cases = {
      {"audit " + kAuditData + "/clean.toml", "render.png", {"report.json", "view.html"}},
      {"route " + kRouteData + "/around.toml", "view.html", {"routed.xml", "report.json", "cables.ply", "render.png"}},
      {"route " + kRouteData + "/around.toml", "cables.ply", {"routed.xml", "report.json", "view.html"}}};
  for (const auto& [cmd, blocked, others] : cases) {
    const auto out = fresh_dir("blocked_target");
    fs::create_directories(out / blocked);
    const auto r = loom(cmd + " --quiet --out " + out.string());
    EXPECT_EQ(r.status, 2) << cmd << "\n" << r.out;
    EXPECT_NE(r.out.find((out / blocked).string() + ": is a directory"), std::string::npos) << cmd << "\n" << r.out;
    for (const auto& f : others) EXPECT_FALSE(fs::exists(out / f)) << cmd << ": " << f << " was written";
  }
  // A path below a file.
  const auto out = fresh_dir("below_file");
  fs::create_directories(out);
  std::ofstream(out / "plain") << "x";
  const auto r = loom("audit " + kAuditData + "/clean.toml --quiet --out " + (out / "plain" / "sub").string());
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("which is not a directory"), std::string::npos) << r.out;
}

// The outputs of a run replace the last run's together or not at all: they are staged in
// the output directory and moved into place at the end (core/io/output_set). A run that
// fails after the stage is made leaves the last run's set as it was and no stage behind.
TEST(CliOutputs, AFailedRunLeavesTheLastRunsOutputsWhole) {
  namespace fs = std::filesystem;
  const auto out = fresh_dir("output_set");
  const std::string cmd = "audit " + kAuditData + "/clash.toml --quiet --out " + out.string();
  ASSERT_EQ(loom(cmd).status, 1);
  auto read = [](const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  const std::string report = read(out / "report.json"), view = read(out / "view.html");
  ASSERT_FALSE(report.empty());
  const auto r = loom(cmd + " --routes " + (out / "no-such-routes.xml").string());
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_EQ(read(out / "report.json"), report);
  EXPECT_EQ(read(out / "view.html"), view);
  for (const auto& e : fs::directory_iterator(out))
    EXPECT_NE(e.path().filename().string().rfind(".loom", 0), 0u) << e.path() << " was left behind";
  // A clean run replaces the set and leaves no stage either.
  ASSERT_EQ(loom("audit " + kAuditData + "/clean.toml --quiet --out " + out.string()).status, 0);
  EXPECT_NE(read(out / "report.json"), report);
  for (const auto& e : fs::directory_iterator(out))
    EXPECT_NE(e.path().filename().string().rfind(".loom", 0), 0u) << e.path() << " was left behind";
}

// `render --report` took a report of the wrong shape silently (`"clashes": 5`: no markers)
// or failed naming nothing (`"kind": 5`: nlohmann's type_error 302).
TEST(CliRender, ReportOfTheWrongShapeIsExitTwoNamingTheEntry) {
  const auto dir = fresh_dir("render_report");
  std::filesystem::create_directories(dir);
  const std::vector<std::pair<std::string, std::string>> cases = {
      {R"({"clashes": 5})", "r.json: clashes: expected an array"},
      {R"({"clashes": [{"kind": 5, "point": [0, 0, 0]}]})", "r.json: clashes[0].kind: expected a string"},
      {R"({"violations": [{"point": [0, "a", 0]}]})", "r.json: violations[0].point: expected an array of 3 finite"},
      {R"({"violations": [7]})", "r.json: violations[0]: expected an object"},
      {"[1, 2]", "r.json: expected a JSON object"}};
  for (const auto& [json, message] : cases) {
    std::ofstream(dir / "r.json") << json;
    const auto r = loom("render " + kAuditData + "/clash.toml --report " + (dir / "r.json").string() + " --out " +
                        (dir / "x.png").string());
    EXPECT_EQ(r.status, 2) << json << "\n" << r.out;
    EXPECT_NE(r.out.find(message), std::string::npos) << json << "\n" << r.out;
    EXPECT_FALSE(std::filesystem::exists(dir / "x.png")) << json;
  }
}

/// Points on a tube of radius 1 around the x axis from x = 0 to 60, as XYZ text.
std::string tube_cloud() {
  std::string s;
  for (int i = 0; i < 600; ++i)
    for (int k = 0; k < 12; ++k) {
      const double a = 2.0 * M_PI * k / 12.0 + 0.37 * i;
      s += std::to_string(0.1 * i) + " " + std::to_string(std::cos(a)) + " " + std::to_string(std::sin(a)) + "\n";
    }
  return s;
}

// A route that does not make a curve (two ports at one place) named its harness file and
// cable in `audit`, but `render --routes` and `scan --compare` said only
// "Centerline::interpolate: need at least 2 distinct key points".
TEST(CliRoutes, RouteThatIsNoCurveNamesFileAndCableInEveryCommand) {
  const auto dir = fresh_dir("no_curve");
  std::filesystem::create_directories(dir);
  std::string h = slurp(kAuditData + "/harness_clear.xml");
  h.replace(h.find(R"(x="30" y="5" z="30")"), 19, R"(x="-20" y="5" z="30")");
  h.replace(h.find(R"(<pt x="5" y="5" z="30"/>)"), 24, "");
  std::ofstream(dir / "r.xml") << h;
  std::ofstream(dir / "c.xyz") << tube_cloud();
  const std::string routes = (dir / "r.xml").string();
  for (const std::string& cmd :
       {"audit " + kAuditData + "/clean.toml --routes " + routes + " --out " + (dir / "a").string(),
        "render " + kAuditData + "/clean.toml --routes " + routes + " --out " + (dir / "x.png").string(),
        "scan " + (dir / "c.xyz").string() + " --compare " + routes + " --cable C1 --out " + (dir / "s").string()}) {
    const auto r = loom(cmd);
    EXPECT_EQ(r.status, 2) << cmd << "\n" << r.out;
    EXPECT_NE(r.out.find("r.xml:5: cable C1: its route does not make a curve"), std::string::npos) << cmd << "\n" << r.out;
  }
}

/// A routed harness of one straight cable C1 (d = 2) from `a` to `b` through their midpoint.
using Point = std::array<double, 3>;
std::string straight_route(const Point& a, const Point& b) {
  auto xyz = [](const Point& p) {
    return "x=\"" + std::to_string(p[0]) + "\" y=\"" + std::to_string(p[1]) + "\" z=\"" + std::to_string(p[2]) + "\"";
  };
  const Point m{0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1]), 0.5 * (a[2] + b[2])};
  return "<?xml version=\"1.0\"?>\n<harness name=\"s\" units=\"mm\">\n<attributes>\n<cable id=\"C1\">"
         "<electrical><port id=\"J1\"/><port id=\"J2\"/></electrical>"
         "<physical diameter=\"2\" min_bend_radius=\"10\"/></cable>\n</attributes>\n<structure>\n"
         "<port id=\"J1\" " + xyz(a) + " dx=\"1\" dy=\"0\" dz=\"0\"/>\n<port id=\"J2\" " + xyz(b) +
         " dx=\"-1\" dy=\"0\" dz=\"0\"/>\n<segment from=\"J1\" to=\"J2\"><path interp=\"polyline\"><pt " + xyz(m) +
         "/></path></segment>\n</structure>\n</harness>\n";
}

// `scan --compare` measured the design from the scan only: cable laid beyond the design
// (a longer run, a slack loop) was never counted. The scan from the design is reported
// too, and the Hausdorff distance of the two. Closed forms: the cloud is a tube of d = 2
// along x from 0 to 59.9 (tube_cloud).
TEST(CliScan, CompareMeasuresBothWays) {
  const auto dir = fresh_dir("scan_compare");
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "c.xyz") << tube_cloud();
  struct Case {
    Point a, b;
    double design_from_scan, scan_from_design;  // the two maxima, closed form
  };
  const std::vector<Case> cases{{{0, 0, 0}, {40, 0, 0}, 0.0, 19.9},  // 19.9 laid beyond the design
                                {{0, 0.5, 0}, {59.9, 0.5, 0}, 0.5, 0.5}};
  // The scan's own error (RMS ~0.001 d) and its ends (short by up to ~0.07 d) allow:
  const double slack = 0.2;
  for (const Case& c : cases) {
    std::ofstream(dir / "r.xml") << straight_route(c.a, c.b);
    const auto r = loom("scan " + (dir / "c.xyz").string() + " --quiet --compare " + (dir / "r.xml").string() +
                        " --cable C1 --out " + (dir / "s").string());
    ASSERT_EQ(r.status, 0) << r.out;
    const auto j = nlohmann::json::parse(slurp(dir / "s" / "report.json"));
    const auto& dev = j.at("deviation");
    EXPECT_NEAR(dev.at("max").get<double>(), c.design_from_scan, slack) << dev.dump();
    EXPECT_NEAR(dev.at("max_scan_to_design").get<double>(), c.scan_from_design, slack) << dev.dump();
    EXPECT_DOUBLE_EQ(dev.at("hausdorff").get<double>(),
                     std::max(dev.at("max").get<double>(), dev.at("max_scan_to_design").get<double>()));
  }
}

// File names are bytes: one that is not UTF-8 (a Latin-1 name) made nlohmann's dump()
// throw type_error 316 — `scan` had then written centerline.xml and tube.ply but no
// report, `audit` nothing, both exit 2 naming nothing. Reports carry U+FFFD for the
// bad bytes.
TEST(CliNames, NonUtf8FileNamesGiveCompleteReports) {
  const auto dir = fresh_dir("latin1");
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "c\xff.xyz") << tube_cloud();
  const auto scan = loom("scan '" + (dir / "c\xff.xyz").string() + "' --quiet --out " + (dir / "s").string());
  EXPECT_EQ(scan.status, 0) << scan.out;
  EXPECT_NE(slurp(dir / "s" / "report.json").find("c\xef\xbf\xbd.xyz"), std::string::npos);
  for (const char* f : {"box.obj", "harness_clash.xml"}) std::filesystem::copy_file(kAuditData + "/" + f, dir / f);
  std::ofstream(dir / "sc\xe9ne.toml") << "[scene]\nunits = 'mm'\n[[part]]\nname = 'box'\nfile = 'box.obj'\n"
                                          "[harness]\nfile = 'harness_clash.xml'\n";
  const auto audit = loom("audit '" + (dir / "sc\xe9ne.toml").string() + "' --quiet --out " + (dir / "a").string());
  EXPECT_EQ(audit.status, 1) << audit.out;
  EXPECT_NE(slurp(dir / "a" / "report.json").find("\"scene\": \"sc\xef\xbf\xbdne\""), std::string::npos);
  EXPECT_TRUE(std::filesystem::exists(dir / "a" / "view.html"));
}

}  // namespace
