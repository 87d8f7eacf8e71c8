#include "core/error.hpp"

#include <cstdio>

namespace loom {
namespace {
std::string compose(const SourceLocation& w, const std::string& reason) {
  std::string s;
  if (!w.file.empty()) {
    s += w.file;
    if (w.line > 0) s += ":" + std::to_string(w.line);
    s += ": ";
  }
  if (!w.element.empty()) s += w.element + ": ";
  return s + reason;
}
}  // namespace

InputError::InputError(SourceLocation where, const std::string& reason)
    : std::runtime_error(compose(where, reason)), where_(std::move(where)), reason_(reason) {}

std::string full_precision(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

}  // namespace loom
