// Regressions of the command-line contract: one test per bug in
// `loom audit|route|render` options, `--routes` files and outputs, inputs written out in
// full. Every test runs the real executable (LOOM_EXE) on tiny scenes.
#include <gtest/gtest.h>

#include "common/run_loom.hpp"

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <utility>
#include <vector>

#include <unistd.h>

namespace {

namespace fs = std::filesystem;
using loom::testing::run_loom;

const std::string kAuditData = std::string(LOOM_SOURCE_DIR) + "/tests/data/audit";
const std::string kRouteData = std::string(LOOM_SOURCE_DIR) + "/tests/data/route";

/// An empty scratch directory of this test process.
fs::path scratch(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("loom_cli_reg_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

/// One cable of a test harness: id, its two ports, diameter and minimum bend radius.
struct TestCable {
  std::string id, a, b;
  std::string diameter = "2";
  std::string min_bend = "10";
};

/// A harness XML with `cables` between ports J1, J3, J5 (x = -20) and J2, J4, J6 (x = 30),
/// at y = 5 and z = 30, 50, 70 in pairs, each cable one straight port-to-port segment at
/// least 20 mm above the unit box of tests/data/audit (clean when the cables keep apart).
std::string harness_xml(const std::vector<TestCable>& cables) {
  std::string x = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<harness name=\"h\" units=\"mm\">\n  <attributes>\n";
  for (const auto& c : cables)
    x += "    <cable id=\"" + c.id + "\">\n      <electrical><port id=\"" + c.a + "\"/><port id=\"" + c.b +
         "\"/></electrical>\n      <physical diameter=\"" + c.diameter + "\" min_bend_radius=\"" + c.min_bend +
         "\"/>\n    </cable>\n";
  x += "  </attributes>\n  <structure>\n"
       "    <port id=\"J1\" x=\"-20\" y=\"5\" z=\"30\" dx=\"1\" dy=\"0\" dz=\"0\"/>\n"
       "    <port id=\"J2\" x=\"30\" y=\"5\" z=\"30\" dx=\"-1\" dy=\"0\" dz=\"0\"/>\n"
       "    <port id=\"J3\" x=\"-20\" y=\"5\" z=\"50\" dx=\"1\" dy=\"0\" dz=\"0\"/>\n"
       "    <port id=\"J4\" x=\"30\" y=\"5\" z=\"50\" dx=\"-1\" dy=\"0\" dz=\"0\"/>\n"
       "    <port id=\"J5\" x=\"-20\" y=\"5\" z=\"70\" dx=\"1\" dy=\"0\" dz=\"0\"/>\n"
       "    <port id=\"J6\" x=\"30\" y=\"5\" z=\"70\" dx=\"-1\" dy=\"0\" dz=\"0\"/>\n";
  for (const auto& c : cables)
    x += "    <segment from=\"" + c.a + "\" to=\"" + c.b + "\"><path interp=\"polyline\"/></segment>\n";
  x += "  </structure>\n</harness>\n";
  return x;
}

/// Writes DIR/scene.toml (the unit box, clearance 3) whose harness is DIR/harness.xml.
void write_scene(const fs::path& dir, const std::vector<TestCable>& cables) {
  fs::copy_file(kAuditData + "/box.obj", dir / "box.obj", fs::copy_options::overwrite_existing);
  std::ofstream(dir / "scene.toml") << "[scene]\nname = \"s\"\nunits = \"mm\"\n[[part]]\nname = \"box\"\n"
                                       "file = \"box.obj\"\n[harness]\nfile = \"harness.xml\"\n[routing]\n"
                                       "clearance = 3.0\n";
  std::ofstream(dir / "harness.xml") << harness_xml(cables);
}

// `--threads 100000` (audit and route) made a TBB task arena of 10⁵ slots and the process
// died of a segmentation fault in tbb::task_arena::terminate, leaving a staging directory
// behind in --out. `--threads` takes 1..1024 (exit 2 naming the range, no output).
TEST(CliRegression, HugeThreadCountIsAUsageErrorNotACrash) {
  const fs::path dir = scratch("threads");
  for (const std::string& cmd :
       {"audit " + kAuditData + "/clean.toml", "route " + kRouteData + "/around.toml --time-limit 0.1"}) {
    const auto r = run_loom(cmd + " --threads 100000 --quiet --out " + (dir / "out").string());
    EXPECT_EQ(r.status, 2) << cmd << "\n" << r.out;
    EXPECT_NE(r.out.find("--threads: must be a whole number in 1..1024, got 100000"), std::string::npos) << r.out;
    EXPECT_FALSE(fs::exists(dir / "out")) << cmd;
  }
  fs::remove_all(dir);
}

// `audit --routes FILE` replaced the scene's harness with whatever FILE held: a cable of the
// scene missing from FILE went unchecked (exit 0), a cable the scene does not have was
// audited, and a cable joining other ports or of another diameter was taken as routed.
// Each is exit 2 naming the routes file, the line and the cable (audit and render).
TEST(CliRegression, RoutesFileOfAnotherHarnessIsRefusedNamingFileLineAndCable) {
  const fs::path dir = scratch("routes");
  write_scene(dir, {{"C1", "J1", "J2"}, {"C2", "J3", "J4"}});
  const std::string scene = (dir / "scene.toml").string();
  struct Case {
    std::vector<TestCable> cables;
    std::string message;
  };
  const std::vector<Case> cases = {
      {{{"C1", "J1", "J2"}}, "r.xml: harness 'h': has no cable 'C2' of the scene's harness"},
      {{{"C1", "J1", "J2"}, {"C2", "J3", "J4"}, {"C9", "J5", "J6"}}, "r.xml:12: cable 'C9': not a cable of the scene's harness"},
      {{{"C1", "J1", "J2"}, {"X2", "J3", "J4"}}, "r.xml:8: cable 'X2': not a cable of the scene's harness"},
      {{{"C1", "J1", "J2"}, {"C2", "J3", "J6"}}, "r.xml:8: cable 'C2': joins ports J3 and J6, but J3 and J4 in the scene's harness"},
      {{{"C1", "J1", "J2", "3"}, {"C2", "J3", "J4"}}, "r.xml:4: cable 'C1': diameter 3, but 2 in the scene's harness"},
      {{{"C1", "J1", "J2"}, {"C2", "J3", "J4", "2", "4"}}, "r.xml:8: cable 'C2': min_bend_radius 4, but 10 in the scene's harness"}};
  for (const auto& c : cases) {
    std::ofstream(dir / "r.xml") << harness_xml(c.cables);
    for (const std::string& cmd : {"audit " + scene + " --quiet --out " + (dir / "out").string(),
                                   "render " + scene + " --quiet --out " + (dir / "x.png").string()}) {
      const auto r = run_loom(cmd + " --routes " + (dir / "r.xml").string());
      EXPECT_EQ(r.status, 2) << c.message << "\n" << r.out;
      EXPECT_NE(r.out.find(c.message), std::string::npos) << c.message << "\n" << r.out;
    }
    EXPECT_FALSE(fs::exists(dir / "out" / "report.json")) << c.message;
    EXPECT_FALSE(fs::exists(dir / "x.png")) << c.message;
  }
  // The same cables in another order, one with its ports swapped, a port moved: the same
  // harness, audited.
  std::string same = harness_xml({{"C2", "J4", "J3"}, {"C1", "J1", "J2"}});
  same.replace(same.find("x=\"30\" y=\"5\" z=\"50\""), 19, "x=\"40\" y=\"5\" z=\"50\"");
  std::ofstream(dir / "r.xml") << same;
  const auto ok = run_loom("audit " + scene + " --quiet --routes " + (dir / "r.xml").string() + " --out " +
                           (dir / "out").string());
  EXPECT_EQ(ok.status, 0) << ok.out;
  fs::remove_all(dir);
}

// `audit --method discrete --tolerance T` (or `--no-index --tolerance T`) ignored T, and
// `audit --spacing L` with the certified method ignored L, both without a word: each is
// exit 2 naming the option and the method it belongs to, before any output.
TEST(CliRegression, AccuracyOptionOfTheOtherMethodIsRefused) {
  const fs::path dir = scratch("method_options");
  const std::string scene = kAuditData + "/clean.toml";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"--method discrete --tolerance 0.1", "--tolerance: applies to the certified method only"},
      {"--no-index --tolerance 0.1", "--tolerance: applies to the certified method only"},
      {"--spacing 1", "--spacing: applies to the discrete method only"},
      {"--method certified --spacing 1", "--spacing: applies to the discrete method only"}};
  for (const auto& [flags, message] : cases) {
    const auto r = run_loom("audit " + scene + " " + flags + " --quiet --out " + (dir / "out").string());
    EXPECT_EQ(r.status, 2) << flags << "\n" << r.out;
    EXPECT_NE(r.out.find(message), std::string::npos) << flags << "\n" << r.out;
    EXPECT_FALSE(fs::exists(dir / "out")) << flags;
  }
  for (const char* flags : {"--method discrete --spacing 1", "--no-index --spacing 1", "--tolerance 0.05"})
    EXPECT_EQ(run_loom("audit " + scene + " " + std::string(flags) + " --quiet --out " + (dir / "out").string()).status, 0) << flags;
  fs::remove_all(dir);
}

// `audit --tolerance 1e9` (or anything at or above a cable's radius) ran and reported the
// audit "certified" to a tolerance at which a cable lying on a part's surface may be
// missed. A requested tolerance must lie below the thinnest cable's radius (exit 2).
TEST(CliRegression, ToleranceNotBelowTheThinnestCableRadiusIsRefused) {
  const fs::path dir = scratch("tolerance");
  for (const std::string t : {"1", "1e9"}) {  // clash.toml: one cable of radius 1 through the box
    const auto r = run_loom("audit " + kAuditData + "/clash.toml --tolerance " + t + " --quiet --out " +
                            (dir / "out").string());
    EXPECT_EQ(r.status, 2) << t << "\n" << r.out;
    EXPECT_NE(r.out.find("--tolerance: "), std::string::npos) << r.out;
    EXPECT_NE(r.out.find(" is not below the radius 1 of the thinnest cable 'C1'"), std::string::npos) << r.out;
    EXPECT_FALSE(fs::exists(dir / "out" / "report.json")) << t;
  }
  EXPECT_EQ(run_loom("audit " + kAuditData + "/clash.toml --tolerance 0.5 --quiet --out " + (dir / "out").string()).status,
            1);
  fs::remove_all(dir);
}

// A malformed `--render-size` was refused (exit 2) only after `audit` and `route` had made
// the output directory: a usage error left an empty --out behind.
TEST(CliRegression, BadRenderSizeMakesNoOutputDirectory) {
  const fs::path dir = scratch("render_size");
  for (const std::string& cmd : {"audit " + kAuditData + "/clean.toml", "route " + kRouteData + "/around.toml"}) {
    const auto r = run_loom(cmd + " --render-size 0x0 --quiet --out " + (dir / "out").string());
    EXPECT_EQ(r.status, 2) << cmd << "\n" << r.out;
    EXPECT_NE(r.out.find("--render-size: '0x0'"), std::string::npos) << r.out;
    EXPECT_FALSE(fs::exists(dir / "out")) << cmd;
  }
  fs::remove_all(dir);
}

}  // namespace

// An audit of a harness whose branch point has no position yet checked none of its cables,
// said so in report.json ("routed": false, a reason) and exited 0, "ran and found nothing":
// a CI gate on the exit status passed a harness nobody had checked. Cables left unchecked
// give exit 3, as `route` gives for cables it could not route (DESIGN §4).
TEST(CliRegression, AnAuditThatLeftCablesUncheckedWasExitZero) {
  const fs::path dir = scratch("unchecked");
  write_scene(dir, {});
  std::ofstream(dir / "harness.xml") << R"(<?xml version="1.0"?>
<harness name="u" units="mm">
  <attributes>
    <cable id="A"><electrical><port id="J1"/><port id="J2"/></electrical><physical diameter="2" min_bend_radius="10"/></cable>
    <cable id="B"><electrical><port id="J1"/><port id="J3"/></electrical><physical diameter="2" min_bend_radius="10"/></cable>
  </attributes>
  <structure>
    <port id="J1" x="-20" y="5" z="30" dx="1" dy="0" dz="0"/>
    <port id="J2" x="30" y="5" z="30" dx="-1" dy="0" dz="0"/>
    <port id="J3" x="30" y="5" z="60" dx="-1" dy="0" dz="0"/>
    <branch id="B1"><segment to="J1"/><segment to="J2"/><segment to="J3"/></branch>
  </structure>
</harness>
)";
  for (const std::string method : {"certified", "discrete"}) {
    const auto r = run_loom("audit " + (dir / "scene.toml").string() + " --method " + method +
                            " --render-size 80x60 --quiet --out " + (dir / "out").string());
    EXPECT_EQ(r.status, 3) << method << "\n" << r.out;
    std::ifstream in(dir / "out" / "report.json");
    const std::string report((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_NE(report.find("\"routed\": false"), std::string::npos) << report;
  }
  fs::remove_all(dir);
}
