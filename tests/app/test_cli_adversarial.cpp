// The command-line contract under hostile use: report.json as DESIGN
// §4 lists it, exit statuses, determinism across thread counts and runs, `--routes` files
// that are not routes, option misuse and output paths. Every test runs the real `loom`
// (LOOM_EXE) on scenes of a few cables around the unit box of tests/data/audit.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "common/run_loom.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <regex>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <unistd.h>

namespace {

namespace fs = std::filesystem;
using loom::testing::run_loom;
using nlohmann::json;

const std::string kAuditData = std::string(LOOM_SOURCE_DIR) + "/tests/data/audit";

/// An empty scratch directory of this test process.
fs::path scratch(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("loom_cli_adv_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

/// A harness of five cables (d = 2, min bend radius 10) around the unit box [0, 10]³, one
/// finding of every kind: C1 runs through the box (cable–structure clash), C2 and C3 cross
/// (cable–cable), C4 loops over itself with polyline corners (self clash, bend radius 0),
/// C5 passes 1 mm above the box (clearance violation: 3 mm required).
const char* kEveryFindingHarness = R"(<?xml version="1.0" encoding="UTF-8"?>
<harness name="k" units="mm">
  <attributes>
    <cable id="C1"><electrical><port id="J1"/><port id="J2"/></electrical><physical diameter="2" min_bend_radius="10"/></cable>
    <cable id="C2"><electrical><port id="J3"/><port id="J4"/></electrical><physical diameter="2" min_bend_radius="10"/></cable>
    <cable id="C3"><electrical><port id="J5"/><port id="J6"/></electrical><physical diameter="2" min_bend_radius="10"/></cable>
    <cable id="C4"><electrical><port id="J7"/><port id="J8"/></electrical><physical diameter="2" min_bend_radius="10"/></cable>
    <cable id="C5"><electrical><port id="J9"/><port id="J10"/></electrical><physical diameter="2" min_bend_radius="10"/></cable>
  </attributes>
  <structure>
    <port id="J1" x="-20" y="5" z="5" dx="1" dy="0" dz="0"/>
    <port id="J2" x="30" y="5" z="5" dx="-1" dy="0" dz="0"/>
    <port id="J3" x="-20" y="30" z="20" dx="1" dy="0" dz="0"/>
    <port id="J4" x="30" y="30" z="20" dx="-1" dy="0" dz="0"/>
    <port id="J5" x="5" y="15" z="20" dx="0" dy="1" dz="0"/>
    <port id="J6" x="5" y="45" z="20" dx="0" dy="-1" dz="0"/>
    <port id="J7" x="-20" y="70" z="20" dx="1" dy="0" dz="0"/>
    <port id="J8" x="10" y="50" z="20" dx="0" dy="1" dz="0"/>
    <port id="J9" x="-20" y="5" z="12" dx="1" dy="0" dz="0"/>
    <port id="J10" x="30" y="5" z="12" dx="-1" dy="0" dz="0"/>
    <segment from="J1" to="J2"><path interp="polyline"></path></segment>
    <segment from="J3" to="J4"><path interp="polyline"></path></segment>
    <segment from="J5" to="J6"><path interp="polyline"></path></segment>
    <segment from="J7" to="J8"><path interp="polyline"><pt x="20" y="70" z="20"/><pt x="20" y="80" z="20"/><pt x="10" y="80" z="20"/></path></segment>
    <segment from="J9" to="J10"><path interp="polyline"></path></segment>
  </structure>
</harness>
)";

/// Writes DIR/box.obj, DIR/harness.xml (`harness`) and DIR/scene.toml (the box, if
/// `with_box`; the harness, if `harness` is not empty; clearance 3) and returns the scene.
fs::path write_scene(const fs::path& dir, const std::string& harness, bool with_box = true) {
  fs::copy_file(kAuditData + "/box.obj", dir / "box.obj", fs::copy_options::overwrite_existing);
  std::string toml = "[scene]\nname = \"kinds\"\nunits = \"mm\"\n";
  if (with_box) toml += "[[part]]\nname = \"box\"\nfile = \"box.obj\"\n";
  if (!harness.empty()) {
    std::ofstream(dir / "harness.xml") << harness;
    toml += "[harness]\nfile = \"harness.xml\"\n";
  }
  toml += "[routing]\nclearance = 3.0\n";
  std::ofstream(dir / "scene.toml") << toml;
  return dir / "scene.toml";
}

/// Every place in `j` that holds null or a non-finite number, as JSON pointers.
void find_non_numbers(const json& j, const std::string& at, std::vector<std::string>& bad) {
  if (j.is_null() || (j.is_number_float() && !std::isfinite(j.get<double>()))) bad.push_back(at);
  if (j.is_object())
    for (auto it = j.begin(); it != j.end(); ++it) find_non_numbers(it.value(), at + "/" + it.key(), bad);
  if (j.is_array())
    for (std::size_t i = 0; i < j.size(); ++i) find_non_numbers(j[i], at + "/" + std::to_string(i), bad);
}

/// report.json without its timing, the one part that may differ between runs.
json without_timing(json j) {
  j.erase("timing_ms");
  return j;
}

/// `key` of `o` is a finite number.
::testing::AssertionResult finite_number(const json& o, const std::string& key) {
  if (!o.contains(key)) return ::testing::AssertionFailure() << "no '" << key << "' in " << o.dump();
  if (!o[key].is_number() || !std::isfinite(o[key].get<double>()))
    return ::testing::AssertionFailure() << "'" << key << "' is not a finite number in " << o.dump();
  return ::testing::AssertionSuccess();
}

/// `key` of `o` is an array of three finite numbers.
::testing::AssertionResult point3(const json& o, const std::string& key) {
  if (!o.contains(key) || !o[key].is_array() || o[key].size() != 3)
    return ::testing::AssertionFailure() << "'" << key << "' is not an array of 3 in " << o.dump();
  for (const auto& v : o[key])
    if (!v.is_number() || !std::isfinite(v.get<double>()))
      return ::testing::AssertionFailure() << "'" << key << "' holds a non-number in " << o.dump();
  return ::testing::AssertionSuccess();
}

TEST(CliAdversarial, AuditReportIsIdenticalAcrossThreadCountsAndRuns) {
  const fs::path dir = scratch("determinism");
  const std::string scene = write_scene(dir, kEveryFindingHarness).string();
  for (const std::string method : {"certified", "discrete"}) {
    std::vector<json> reports;
    for (const char* threads : {"1", "2", "1", "2"}) {
      const fs::path out = dir / ("out_" + method + "_" + std::to_string(reports.size()));
      const auto r = run_loom("audit " + scene + " --method " + method + " --threads " + threads + " --render-size 80x60 --quiet --out " +
                              out.string());
      ASSERT_EQ(r.status, 1) << method << " --threads " << threads << "\n" << r.out;
      reports.push_back(without_timing(json::parse(slurp(out / "report.json"))));
    }
    for (std::size_t k = 1; k < reports.size(); ++k)
      EXPECT_EQ(reports[k], reports[0]) << method << ", run " << k << ":\n"
                                        << json::diff(reports[0], reports[k]).dump(1);
  }
  fs::remove_all(dir);
}

TEST(CliAdversarial, ReportHasEveryDesignFieldAndTheSummaryAgrees) {
  const fs::path dir = scratch("fields");
  const std::string scene = write_scene(dir, kEveryFindingHarness).string();
  const auto r = run_loom("audit " + scene + " --out " + (dir / "out").string());
  ASSERT_EQ(r.status, 1) << r.out;
  const json j = json::parse(slurp(dir / "out" / "report.json"));
  std::vector<std::string> bad;
  find_non_numbers(j, "", bad);
  EXPECT_TRUE(bad.empty()) << bad.front();
  EXPECT_EQ(j["scene"], "kinds");
  EXPECT_EQ(j["units"], "mm");
  EXPECT_EQ(j["method"], "certified");
  EXPECT_TRUE(finite_number(j, "tolerance"));
  EXPECT_DOUBLE_EQ(j["tolerance"].get<double>(), 0.01);  // smallest radius / 100
  for (const char* t : {"load", "index", "route", "check"}) EXPECT_TRUE(finite_number(j["timing_ms"], t)) << t;
  EXPECT_TRUE(j["counters"]["distance_queries"].is_number_integer());
  // One entry per kind here (each stretch once), with the fields of its kind.
  std::multiset<std::string> kinds;
  for (const json& c : j["clashes"]) {
    kinds.insert(c["kind"].get<std::string>());
    EXPECT_TRUE(c["cable"].is_string()) << c;
    EXPECT_TRUE(finite_number(c, "clearance"));
    EXPECT_LT(c["clearance"].get<double>(), 0.0) << c;
    EXPECT_TRUE(point3(c, "point"));
    EXPECT_TRUE(finite_number(c, "s"));
    if (c["kind"] == "cable-structure") {
      EXPECT_EQ(c["cable"], "C1");
      EXPECT_EQ(c["part"], "box");
    } else {
      EXPECT_TRUE(finite_number(c, "s_other"));
      if (c["kind"] == "cable-cable") {
        EXPECT_TRUE(c["other"].is_string()) << c;
      }
    }
  }
  EXPECT_EQ(kinds, (std::multiset<std::string>{"cable-structure", "cable-cable", "self"})) << j["clashes"].dump(1);
  std::multiset<std::string> violations;
  for (const json& v : j["violations"]) {
    violations.insert(v["kind"].get<std::string>());
    EXPECT_TRUE(finite_number(v, "s"));
    if (v["kind"] == "bend-radius") {
      EXPECT_EQ(v["cable"], "C4");
      EXPECT_TRUE(finite_number(v, "radius"));
      EXPECT_DOUBLE_EQ(v["min"].get<double>(), 10.0);
    } else {
      EXPECT_EQ(v["cable"], "C5");
      EXPECT_EQ(v["part"], "box");
      EXPECT_NEAR(v["clearance"].get<double>(), 1.0, 0.01);
      EXPECT_DOUBLE_EQ(v["required"].get<double>(), 3.0);
    }
  }
  // C4's three polyline corners are three bend-radius stretches (one violation each).
  EXPECT_EQ(violations, (std::multiset<std::string>{"bend-radius", "bend-radius", "bend-radius", "clearance"}));
  ASSERT_EQ(j["cables"].size(), 5u);
  for (const json& c : j["cables"]) {
    EXPECT_EQ(c["routed"], true) << c;
    EXPECT_TRUE(finite_number(c, "length"));
    EXPECT_TRUE(finite_number(c, "min_clearance"));  // every cable has the box within reach
  }
  // The terminal summary counts what the report holds.
  std::smatch m;
  ASSERT_TRUE(std::regex_search(r.out, m, std::regex(R"((\d+) clashes, (\d+) violations;)"))) << r.out;
  EXPECT_EQ(std::stoul(m[1]), j["clashes"].size());
  EXPECT_EQ(std::stoul(m[2]), j["violations"].size());
  EXPECT_NE(r.out.find("5 cables (5 checked)"), std::string::npos) << r.out;
  // --json prints the report itself.
  const auto js = run_loom("audit " + scene + " --json --out " + (dir / "out2").string());
  ASSERT_EQ(js.status, 1);
  EXPECT_EQ(without_timing(json::parse(js.out)), without_timing(json::parse(slurp(dir / "out2" / "report.json"))));
  fs::remove_all(dir);
}

TEST(CliAdversarial, DegenerateScenesGiveCompleteReports) {
  const fs::path dir = scratch("degenerate");
  const std::string one = slurp(kAuditData + "/harness_clear.xml");
  std::string tiny = one;  // a cable 1e-7 mm long
  tiny.replace(tiny.find(R"(x="30" y="5" z="30")"), 19, R"(x="-19.9999999" y="5" z="30")");
  tiny.replace(tiny.find(R"(<pt x="5" y="5" z="30"/>)"), 24, "");
  const std::string no_cables = R"(<?xml version="1.0"?>
<harness name="n" units="mm"><attributes/><structure><port id="J1" x="-80" y="5" z="5" dx="1" dy="0" dz="0"/></structure></harness>
)";
  const std::string unplaced = R"(<?xml version="1.0"?>
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
  struct Case {
    std::string name, harness;
    bool with_box;
    std::size_t cables;
    int status;  // 3: cables left unchecked (DESIGN §4, as route says of cables it could not route)
  };
  const std::vector<Case> cases = {{"no parts", one, false, 1, 0},
                                   {"no cables", no_cables, true, 0, 0},
                                   {"no harness", "", true, 0, 0},
                                   {"a cable 1e-7 long", tiny, true, 1, 0},
                                   {"every cable through an unplaced branch point", unplaced, true, 2, 3}};
  for (const auto& c : cases) {
    const fs::path sub = dir / std::to_string(&c - cases.data());
    fs::create_directories(sub);
    const std::string scene = write_scene(sub, c.harness, c.with_box).string();
    for (const std::string method : {"certified", "discrete"}) {
      const auto r = run_loom("audit " + scene + " --method " + method + " --render-size 80x60 --quiet --out " + (sub / "out").string());
      ASSERT_EQ(r.status, c.status) << c.name << ", " << method << "\n" << r.out;
      const json j = json::parse(slurp(sub / "out" / "report.json"));
      std::vector<std::string> bad;
      find_non_numbers(j, "", bad);
      EXPECT_TRUE(bad.empty()) << c.name << ", " << method << ": " << bad.front();
      if (method == "certified") {
        EXPECT_TRUE(finite_number(j, "tolerance")) << c.name;
      }
      EXPECT_TRUE(j["clashes"].empty() && j["violations"].empty()) << c.name << "\n" << j.dump(1);
      ASSERT_EQ(j["cables"].size(), c.cables) << c.name;
      for (const json& cable : j["cables"]) {
        EXPECT_TRUE(cable["id"].is_string());
        if (cable["routed"] == true) {
          EXPECT_TRUE(finite_number(cable, "length")) << c.name;
        } else {
          EXPECT_TRUE(cable["reason"].is_string()) << c.name;  // said, not silently dropped
        }
      }
    }
  }
  fs::remove_all(dir);
}

TEST(CliAdversarial, HostileRoutesFilesAreExitTwoNamingTheFileAndKeepTheLastReport) {
  const fs::path dir = scratch("hostile_routes");
  const std::string scene = kAuditData + "/clean.toml";
  const fs::path out = dir / "out";
  ASSERT_EQ(run_loom("audit " + scene + " --quiet --out " + out.string()).status, 0);
  const std::string last = slurp(out / "report.json");
  const std::string good = slurp(kAuditData + "/harness_clear.xml");
  auto with = [&](const std::string& from, const std::string& to) {
    std::string t = good;
    t.replace(t.find(from), from.size(), to);
    return t;
  };
  const std::string cable = R"(<cable id="C1">)";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {with(R"(<pt x="5")", R"(<pt x="nan")"), "routes.xml:14: <pt>: attribute 'x' is not finite"},
      {with(R"(<pt x="5")", R"(<pt x="1e400")"), "routes.xml:14: <pt>: attribute 'x' is not finite"},
      {"", "routes.xml:1: malformed XML"},
      {"\x01\x02\xff binary", "routes.xml"},
      {"<harness", "routes.xml"},
      {with("</attributes>", good.substr(good.find(cable), good.find("</cable>") + 8 - good.find(cable)) +
                                 "\n  </attributes>"),
       "routes.xml:9: cable 'C1': duplicate cable id"}};
  for (const auto& [text, message] : cases) {
    std::ofstream(dir / "routes.xml") << text;
    const auto r = run_loom("audit " + scene + " --quiet --routes " + (dir / "routes.xml").string() + " --out " +
                            out.string());
    EXPECT_EQ(r.status, 2) << message << "\n" << r.out;
    EXPECT_NE(r.out.find(message), std::string::npos) << message << "\n" << r.out;
    EXPECT_EQ(slurp(out / "report.json"), last) << message;
  }
  fs::create_directories(dir / "routes_dir");
  const auto d = run_loom("audit " + scene + " --quiet --routes " + (dir / "routes_dir").string() + " --out " +
                          out.string());
  EXPECT_EQ(d.status, 2) << d.out;
  EXPECT_NE(d.out.find("routes_dir: not a regular file"), std::string::npos) << d.out;
  EXPECT_EQ(slurp(out / "report.json"), last);
  for (const auto& e : fs::directory_iterator(out))
    EXPECT_NE(e.path().filename().string().rfind(".loom", 0), 0u) << e.path() << " was left behind";
  fs::remove_all(dir);
}

TEST(CliAdversarial, OptionMisuseIsExitTwoAndLeavesTheLastOutputs) {
  const fs::path dir = scratch("options");
  const std::string scene = kAuditData + "/clean.toml";
  const fs::path out = dir / "out";
  ASSERT_EQ(run_loom("audit " + scene + " --quiet --out " + out.string()).status, 0);
  const std::string last = slurp(out / "report.json");
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"--bogus", "--bogus"},
      {"--threads 1 --threads 2", "--threads"},
      {"--threads 0", "--threads"},
      {"--threads -1", "--threads"},
      {"--threads 99999999999", "--threads"},
      {"--threads", "--threads"},
      {"--spacing 0", "--spacing"},
      {"--method discrete --spacing -2", "--spacing"},
      {"--method discrete --spacing nan", "--spacing"},
      {"--tolerance -1", "--tolerance"},
      {"--tolerance inf", "--tolerance"},
      {"--method sampled", "--method"},
      {"--method certified --no-index", "--no-index"},
      {"--render-size 0x0", "--render-size"},
      {"--render-size 100000x100000", "--render-size"},
      {"--render-size 12", "--render-size"},
      {"--routes", "--routes"},
      {"extra.toml", "extra.toml"}};
  for (const auto& [flags, named] : cases) {
    const auto r = run_loom("audit " + scene + " --quiet --out " + out.string() + " " + flags);
    EXPECT_EQ(r.status, 2) << flags << "\n" << r.out;
    EXPECT_NE(r.out.find(named), std::string::npos) << flags << "\n" << r.out;
    EXPECT_EQ(slurp(out / "report.json"), last) << flags;
  }
  // --out without its value, and twice.
  for (const std::string& outs : {std::string("--out"), "--out " + out.string() + " --out " + out.string()}) {
    const auto r = run_loom("audit " + scene + " --quiet " + outs);
    EXPECT_EQ(r.status, 2) << outs << "\n" << r.out;
    EXPECT_NE(r.out.find("--out"), std::string::npos) << r.out;
    EXPECT_EQ(slurp(out / "report.json"), last) << outs;
  }
  for (const auto& e : fs::directory_iterator(out))
    EXPECT_NE(e.path().filename().string().rfind(".loom", 0), 0u) << e.path() << " was left behind";
  fs::remove_all(dir);
}

TEST(CliAdversarial, OutputPathsWithSpacesAndUnicodeAndBadTargets) {
  const fs::path dir = scratch("paths");
  const std::string scene = kAuditData + "/clean.toml";
  const fs::path odd = dir / "a b" / "\xc3\xbc \xc3\xb1 \xe2\x9c\x93";
  const auto r = run_loom("audit " + scene + " --quiet --out '" + odd.string() + "'");
  EXPECT_EQ(r.status, 0) << r.out;
  for (const char* f : {"report.json", "view.html", "render.png"}) EXPECT_TRUE(fs::exists(odd / f)) << f;
  std::ofstream(dir / "plain") << "x";
  for (const fs::path& bad : {dir / "plain", fs::path("/dev/null"), fs::path("/proc/loom-no-such/out")}) {
    const auto b = run_loom("audit " + scene + " --quiet --out " + bad.string());
    EXPECT_EQ(b.status, 2) << bad << "\n" << b.out;
    EXPECT_NE(b.out.find(bad.string()), std::string::npos) << b.out;
  }
  EXPECT_EQ(slurp(dir / "plain"), "x");
  fs::remove_all(dir);
}

}  // namespace
