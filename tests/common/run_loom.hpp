#pragma once
// Runs the loom executable (LOOM_EXE, defined for every test by tests/CMakeLists.txt) as a
// user types it, for the tests of the command line.

#include <array>
#include <cstdio>
#include <string>
#include <sys/wait.h>

namespace loom::testing {

/// What a run of the command line gave.
struct LoomRun {
  int status = -1;  ///< exit status; −1 if it could not run or did not exit
  std::string out;  ///< stdout and stderr, merged
};

/// Runs a shell command line and returns its exit status and output (stderr merged).
inline LoomRun run_command(const std::string& command) {
  LoomRun r;
  const std::string cmd = command + " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return r;
  std::array<char, 4096> buf{};
  while (fgets(buf.data(), buf.size(), p)) r.out += buf.data();
  const int st = pclose(p);
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  return r;
}

/// Runs `loom ARGS` through the shell (so ARGS may quote) and returns its exit status and
/// output.
inline LoomRun run_loom(const std::string& args) { return run_command(std::string(LOOM_EXE) + " " + args); }

}  // namespace loom::testing
