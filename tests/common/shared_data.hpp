#pragma once
// The shared real test data (LOOM_SHARED_DATA, ../shared/data beside the repository, defined
// for every test by tests/CMakeLists.txt) and one policy for its absence: a test that reads it
// fails under CI (CI=true, where the data is part of the checkout) and is skipped elsewhere,
// so a checkout without the data still runs the rest of the suite.

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>

namespace loom::testing {

/// Absolute path of REL inside the shared real data directory.
inline std::filesystem::path shared_data(const std::filesystem::path& rel) {
  return std::filesystem::path(LOOM_SHARED_DATA) / rel;
}

/// True when the environment variable CI is "true" (missing shared data is then a failure).
inline bool ci_run() {
  const char* ci = std::getenv("CI");
  return ci != nullptr && std::string(ci) == "true";
}

}  // namespace loom::testing

/// Ends the current test (or void helper) when FILE does not exist: FAIL under CI=true,
/// GTEST_SKIP otherwise. A macro because both return from the calling function.
#define LOOM_SHARED_DATA_OR_SKIP(file)                                                          \
  do {                                                                                          \
    const ::std::filesystem::path loom_shared_path_ = (file);                                   \
    if (!::std::filesystem::exists(loom_shared_path_)) {                                        \
      if (::loom::testing::ci_run())                                                            \
        FAIL() << "shared data missing (CI=true): " << loom_shared_path_;                       \
      else                                                                                      \
        GTEST_SKIP() << "shared data not present: " << loom_shared_path_;                       \
    }                                                                                           \
  } while (0)
