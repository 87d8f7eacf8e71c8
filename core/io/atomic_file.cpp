#include "core/io/atomic_file.hpp"

#include "core/error.hpp"

#include <atomic>
#include <stdexcept>
#include <system_error>
#include <unistd.h>

namespace loom {

namespace {
std::filesystem::path temp_sibling(const std::filesystem::path& p) {
  static std::atomic<unsigned> counter{0};
  auto name = "." + p.filename().string() + ".tmp." + std::to_string(::getpid()) + "." +
              std::to_string(counter++);
  return p.parent_path() / name;
}
}  // namespace

AtomicFile::AtomicFile(std::filesystem::path path, bool binary) : path_(std::move(path)) {
  std::error_code ec;
  if (path_.has_parent_path()) std::filesystem::create_directories(path_.parent_path(), ec);
  tmp_ = temp_sibling(path_);
  out_.open(tmp_, binary ? std::ios::binary | std::ios::trunc : std::ios::trunc);
  if (!out_) throw std::runtime_error(path_.string() + ": cannot create output file");
}

AtomicFile::~AtomicFile() {
  if (!committed_) {
    out_.close();
    std::error_code ec;
    std::filesystem::remove(tmp_, ec);
  }
}

void AtomicFile::commit() {
  out_.flush();
  const bool ok = static_cast<bool>(out_);
  out_.close();
  if (!ok) throw std::runtime_error(path_.string() + ": write failed");
  std::error_code ec;
  std::filesystem::rename(tmp_, path_, ec);
  if (ec) throw std::runtime_error(path_.string() + ": cannot rename temporary file: " + ec.message());
  committed_ = true;
}

void write_file_atomic(const std::filesystem::path& path, const std::string& content) {
  AtomicFile f(path, true);
  f.stream().write(content.data(), static_cast<std::streamsize>(content.size()));
  f.commit();
}

void check_output_targets(const std::vector<std::filesystem::path>& paths) {
  namespace fs = std::filesystem;
  for (const fs::path& p : paths) {
    std::error_code ec;
    const fs::file_status st = fs::status(p, ec);
    if (fs::exists(st) && !fs::is_regular_file(st))
      throw InputError({p.string(), 0, ""}, fs::is_directory(st) ? "is a directory: the output file cannot replace it"
                                                                  : "is not a regular file: the output cannot replace it");
    // The nearest existing ancestor must be a directory (the rest is created).
    fs::path a = p.parent_path();
    while (!a.empty() && !fs::exists(a, ec) && a != a.parent_path()) a = a.parent_path();
    if (!a.empty() && fs::exists(a, ec) && !fs::is_directory(a, ec))
      throw InputError({p.string(), 0, ""}, "lies below " + a.string() + ", which is not a directory");
  }
}

}  // namespace loom
