#pragma once
/// Scratch files for tests that write inputs and read outputs: a fresh directory per
/// running test, whole-file writes and reads, and the message of an expected InputError.

#include "core/error.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

namespace loom::testing {

/// A fresh, empty directory `<tmp>/<prefix><running test's name>`.
inline std::filesystem::path scratch_dir(const std::string& prefix) {
  const std::filesystem::path d = std::filesystem::temp_directory_path() /
                                  (prefix + ::testing::UnitTest::GetInstance()->current_test_info()->name());
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

/// Writes `bytes` to `p` exactly (truncating).
inline void write_file(const std::filesystem::path& p, const std::string& bytes) {
  std::ofstream(p, std::ios::binary) << bytes;
}

/// The bytes of the file `p` ("" if it cannot be read).
inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream f(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), {});
}

/// The InputError message of `f()`, or "" with a test failure if it throws none.
template <typename F>
std::string input_error(F f) {
  try {
    f();
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& e) {
    return e.what();
  }
  return {};
}

}  // namespace loom::testing
