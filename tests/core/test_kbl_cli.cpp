// The command line on a KBL scene (examples/kbl-generator): `loom info` says what the file
// held, `loom audit` of the harness alone finds no clash (topology causes none), and
// `loom route --out` / `loom audit --out` write routed.kbl, which loads as the same harness.
#include "common/run_loom.hpp"

#include "core/io/kbl_read.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

namespace loom {
namespace {

using loom::testing::run_loom;
namespace fs = std::filesystem;

const std::string kScene = std::string(LOOM_SOURCE_DIR) + "/examples/kbl-generator/scene.toml";

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("loom_kbl_cli_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  return d;
}

TEST(KblCli, InfoSaysWhatTheFileHeld) {
  const auto r = run_loom("info " + kScene);
  ASSERT_EQ(r.status, 0) << r.out;
  for (const char* s : {"KBL 2.3 SR-1: 3 wires", "1 fixings (clamps)", "nodes by degree (segments joined): 3 of degree 1, 1 of degree 3",
                        "not used by loom:", "Cavity_plug_occurrence 6", "3 protection areas"})
    EXPECT_NE(r.out.find(s), std::string::npos) << s << "\n" << r.out;
  const auto j = run_loom("info " + kScene + " --json");
  ASSERT_EQ(j.status, 0) << j.out;
  const auto info = nlohmann::json::parse(j.out);
  EXPECT_EQ(info["harness"]["kbl"]["counts"]["wires"], 3);
  EXPECT_EQ(info["harness"]["nodes_by_degree"]["3"], 1);
}

TEST(KblCli, AuditOfTheHarnessAloneFindsNoClashAndWritesRoutedKbl) {
  const fs::path out = fresh_dir("audit");
  const auto r = run_loom("audit " + kScene + " --quiet --out " + out.string());
  ASSERT_TRUE(r.status == 0 || r.status == 1) << r.out;
  std::ifstream in(out / "report.json");
  const auto rep = nlohmann::json::parse(in);
  EXPECT_TRUE(rep["clashes"].empty()) << rep["clashes"].dump();
  ASSERT_TRUE(fs::exists(out / "routed.kbl"));
  const Harness a = read_harness_kbl(std::string(LOOM_SOURCE_DIR) + "/examples/kbl-generator/generator.kbl");
  const Harness b = read_harness_kbl(out / "routed.kbl");
  EXPECT_EQ(a.cables.size(), b.cables.size());
  EXPECT_EQ(a.segments.size(), b.segments.size());
  fs::remove_all(out);
}

TEST(KblCli, RouteKeepsTheFilesCurvesAndWritesRoutedKbl) {
  const fs::path out = fresh_dir("route");
  const auto r = run_loom("route " + kScene + " --quiet --iterations 50 --out " + out.string());
  ASSERT_TRUE(r.status == 0 || r.status == 1) << r.out;
  for (const char* f : {"routed.xml", "routed.kbl", "report.json"}) EXPECT_TRUE(fs::exists(out / f)) << f;
  std::ifstream in(out / "report.json");
  const auto rep = nlohmann::json::parse(in);
  for (const auto& s : rep["segments"]) EXPECT_EQ(s["status"], "kept from input");
  const Harness b = read_harness_kbl(out / "routed.kbl");
  EXPECT_EQ(b.cables.size(), 3u);
  fs::remove_all(out);
}

}  // namespace
}  // namespace loom
