// OutputSet: a command's outputs replace their targets together or not at all.
#include "core/error.hpp"
#include "core/io/atomic_file.hpp"
#include "core/io/output_set.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

fs::path fresh(const std::string& name) {
  const fs::path d = fs::path(LOOM_BINARY_DIR) / "test_output_set" / name;
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

std::string text_of(const fs::path& p) {
  std::ifstream in(p);
  return {std::istreambuf_iterator<char>(in), {}};
}

/// Entries of `dir` whose names start with ".loom-staging".
std::size_t staging_dirs(const fs::path& dir) {
  std::size_t n = 0;
  for (const auto& e : fs::directory_iterator(dir)) n += e.path().filename().string().rfind(".loom-staging", 0) == 0;
  return n;
}

}  // namespace

TEST(OutputSet, CommitReplacesEveryWrittenTargetAndLeavesTheOthers) {
  const fs::path d = fresh("commit");
  loom::write_file_atomic(d / "a.json", "old a");
  loom::write_file_atomic(d / "c.png", "old c");
  loom::OutputSet set(d, {d / "a.json", d / "b.xml", d / "c.png"});
  EXPECT_EQ(staging_dirs(d), 1u);
  loom::write_file_atomic(set.staging() / "a.json", "new a");
  loom::write_file_atomic(set.staging() / "b.xml", "new b");
  // Nothing has reached the targets yet.
  EXPECT_EQ(text_of(d / "a.json"), "old a");
  EXPECT_FALSE(fs::exists(d / "b.xml"));
  const auto replaced = set.commit();
  EXPECT_EQ(replaced, (std::vector<fs::path>{d / "a.json", d / "b.xml"}));
  EXPECT_EQ(text_of(d / "a.json"), "new a");
  EXPECT_EQ(text_of(d / "b.xml"), "new b");
  EXPECT_EQ(text_of(d / "c.png"), "old c");  // not written by this run: left as it was
  EXPECT_EQ(staging_dirs(d), 0u);
}

// A run that fails after writing some outputs (a full disk, a refused render) touches no
// target: the staged files go with the staging directory.
TEST(OutputSet, ARunThatFailsBeforeCommitTouchesNoTarget) {
  const fs::path d = fresh("unwind");
  loom::write_file_atomic(d / "report.json", "old report");
  try {
    loom::OutputSet set(d, {d / "report.json", d / "view.html"});
    loom::write_file_atomic(set.staging() / "view.html", "new view");
    loom::write_file_atomic(set.staging() / "report.json", "new report");
    throw std::runtime_error("the disk is full");
  } catch (const std::runtime_error&) {
  }
  EXPECT_EQ(text_of(d / "report.json"), "old report");
  EXPECT_FALSE(fs::exists(d / "view.html"));
  EXPECT_EQ(staging_dirs(d), 0u);
}

TEST(OutputSet, TargetsAreCheckedAndTheDirectoryMade) {
  const fs::path d = fresh("checks");
  fs::create_directories(d / "report.json");
  EXPECT_THROW(loom::OutputSet(d, {d / "report.json"}), loom::InputError);
  EXPECT_EQ(staging_dirs(d), 0u);
  // A target outside the directory is the caller's error.
  EXPECT_THROW(loom::OutputSet(d, {d / "sub" / "x.json"}), std::logic_error);
  // The output directory is created, with a trailing slash too.
  const fs::path made = d / "new" / "deeper";
  loom::OutputSet set(made.string() + "/", {fs::path(made.string() + "/") / "x.json"});
  EXPECT_TRUE(fs::is_directory(made));
  EXPECT_TRUE(fs::is_directory(set.staging()));
  // Two runs into one directory stage apart.
  loom::OutputSet other(made, {made / "x.json"});
  EXPECT_NE(set.staging(), other.staging());
}
