#pragma once
/// A command's output files, replaced together or not at all. Each file is already written
/// atomically (atomic_file.hpp), but a command writes several: a run that failed between two
/// of them (a full disk, a refused render) left a mixed set, new report beside old view.
/// The outputs are written into a staging directory inside the output directory instead,
/// and moved onto their targets only when all are complete (renames within one file system
/// take no space, so a full disk fails the run before any target is touched).

#include <filesystem>
#include <vector>

namespace loom {

/// Stages the outputs of one command run for one output directory.
class OutputSet {
 public:
  /// Checks every target (check_output_targets: InputError naming a target no file could
  /// replace) and creates the output directory and, inside it, a hidden staging directory.
  /// `targets` are the files the run may write, each directly inside `dir`. Throws
  /// std::runtime_error naming `dir` if the staging directory cannot be created.
  OutputSet(std::filesystem::path dir, std::vector<std::filesystem::path> targets);
  /// Removes the staging directory and what is still in it: every output, if commit() did
  /// not run (an exception unwound the command), so that no target was touched.
  ~OutputSet();
  OutputSet(const OutputSet&) = delete;
  OutputSet& operator=(const OutputSet&) = delete;

  /// The directory to write the outputs to, under their own file names; they reach `dir`
  /// at commit().
  const std::filesystem::path& staging() const { return stage_; }
  /// Moves every staged target onto its place in the output directory (targets the run did
  /// not write are left as they were) and removes the staging directory. Returns the targets
  /// replaced. Throws std::runtime_error naming a target that could not be replaced.
  std::vector<std::filesystem::path> commit();

 private:
  std::filesystem::path dir_, stage_;
  std::vector<std::filesystem::path> targets_;
};

}  // namespace loom
