#pragma once
/// Output files that are never half-written: content goes to a temporary file in the
/// same directory, which is renamed over the target only when complete.

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace loom {

/// Writes `path` atomically. Use stream(), then commit(); if commit() is never called
/// (an exception unwinds), the temporary file is removed and `path` is untouched.
class AtomicFile {
 public:
  /// Opens a temporary sibling of `path` (creating parent directories). Throws
  /// std::runtime_error naming the file if it cannot be created.
  explicit AtomicFile(std::filesystem::path path, bool binary = false);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  /// The stream to write to.
  std::ofstream& stream() { return out_; }
  /// Flushes, closes and renames onto the target. Throws std::runtime_error on failure.
  void commit();

 private:
  std::filesystem::path path_, tmp_;
  std::ofstream out_;
  bool committed_ = false;
};

/// Throws InputError naming the first of `paths` that no output file could replace: an
/// existing directory or other non-regular file, or a path below an existing file. Why:
/// each output is atomic, but a command writes several; checked before any work, a target
/// that is bound to fail no longer leaves the outputs before it written and those after it
/// missing.
void check_output_targets(const std::vector<std::filesystem::path>& paths);

/// Writes a whole string to `path` atomically.
void write_file_atomic(const std::filesystem::path& path, const std::string& content);

}  // namespace loom
