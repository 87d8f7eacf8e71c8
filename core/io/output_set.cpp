#include "core/io/output_set.hpp"

#include "core/error.hpp"
#include "core/io/atomic_file.hpp"

#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <string>
#include <system_error>
#include <unistd.h>

namespace loom {

OutputSet::OutputSet(std::filesystem::path dir, std::vector<std::filesystem::path> targets)
    : dir_(std::move(dir)), targets_(std::move(targets)) {
  namespace fs = std::filesystem;
  for (const fs::path& t : targets_)
    if (dir_ / t.filename() != t)  // a broken precondition of the caller, not of the input
      throw std::logic_error("OutputSet: " + t.string() + " is not directly inside " + dir_.string());
  check_output_targets(targets_);
  std::error_code ec;
  if (!dir_.empty()) fs::create_directories(dir_, ec);
  if (ec) throw InputError({dir_.string(), 0, ""}, "cannot create the output directory: " + ec.message());
  // mkdtemp: a fresh name even when two runs share the directory.
  std::string pattern = ((dir_.empty() ? fs::path(".") : dir_) / ".loom-staging-XXXXXX").string();
  if (::mkdtemp(pattern.data()) == nullptr)
    throw std::runtime_error(dir_.string() + ": cannot create a staging directory for the outputs: " +
                             std::strerror(errno));
  stage_ = pattern;
}

OutputSet::~OutputSet() {
  std::error_code ec;
  if (!stage_.empty()) std::filesystem::remove_all(stage_, ec);
}

std::vector<std::filesystem::path> OutputSet::commit() {
  namespace fs = std::filesystem;
  std::vector<fs::path> replaced;
  for (const fs::path& t : targets_) {
    const fs::path staged = stage_ / t.filename();
    std::error_code ec;
    if (!fs::exists(staged, ec)) continue;
    fs::rename(staged, t, ec);
    if (ec) throw std::runtime_error(t.string() + ": cannot move the finished output into place: " + ec.message());
    replaced.push_back(t);
  }
  std::error_code ec;
  std::filesystem::remove_all(stage_, ec);  // empty now, but for files the run wrote beside its targets
  stage_.clear();
  return replaced;
}

}  // namespace loom
