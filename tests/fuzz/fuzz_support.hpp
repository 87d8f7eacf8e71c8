#pragma once
/// Shared pieces of the libFuzzer entry points: a private scratch directory for readers
/// that take a path, and the outcome policy (InputError is a normal answer to bad bytes,
/// any other exception is a finding).

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>

namespace loom::fuzz {

/// A directory of this process's own under $TMPDIR (created on first use, removed at exit).
const std::filesystem::path& scratch_dir();

/// Writes `bytes` to `path` (truncating), exactly as given; aborts if the write fails.
void write_bytes(const std::filesystem::path& path, const std::uint8_t* data, std::size_t size);
/// Same for text.
void write_text(const std::filesystem::path& path, const std::string& text);

/// With LOOM_FUZZ_KEEP_RECENT=N (N > 0) and LOOM_FUZZ_KEEP_DIR set: writes the input to
/// KEEP_DIR/recent-<run number, 12 digits>, removing the file of N runs before, so that the
/// last N inputs before a crash can be replayed in order (`fuzz_<target> KEEP_DIR/recent-*`). Why: heap corruption inside an
/// uninstrumented library is noticed at a later free, under another input than the one
/// that corrupted it, and libFuzzer saves only the last one. Otherwise does nothing.
void keep_recent(const std::uint8_t* data, std::size_t size);

/// The bytes of the file `name` of tests/data (`tests/data/<name>`).
std::string read_test_data(const std::string& name);

/// Copies the file `name` of tests/data (`tests/data/<name>`) into the scratch directory as
/// `as` and returns its new path.
std::filesystem::path copy_test_data(const std::string& name, const std::string& as);

/// Runs `body`. An InputError (exit 2 in the command line) returns normally; any other
/// exception escaping prints its type and message and aborts, which libFuzzer records as a
/// crash with the input that caused it.
void expect_only_input_errors(const std::function<void()>& body);

/// Prints `what` and aborts: a property of the reader's output does not hold.
[[noreturn]] void finding(const std::string& what);

}  // namespace loom::fuzz
