// The command line as a user meets it: exit codes, help, version, errors naming files.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
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

}  // namespace
