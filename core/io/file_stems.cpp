#include "core/io/file_stems.hpp"

#include <cctype>
#include <cstdint>
#include <cstdio>
#include <set>

namespace loom {

namespace {
/// FNV-1a, 64 bits: enough to tell apart long names that share their first bytes.
std::uint64_t fnv1a(const std::string& s) {
  std::uint64_t h = 1469598103934665603ull;
  for (unsigned char c : s) h = (h ^ c) * 1099511628211ull;
  return h;
}

std::string sanitized(const std::string& name) {
  std::string s = name.empty() ? "part" : name;
  for (auto& ch : s)
    if (!(std::isalnum(static_cast<unsigned char>(ch)) || ch == '-' || ch == '_' || ch == '.')) ch = '_';
  if (s[0] == '.') s.insert(s.begin(), '_');
  if (s.size() > kMaxFileStemLength) {
    char tail[18];
    std::snprintf(tail, sizeof tail, "-%016llx", static_cast<unsigned long long>(fnv1a(name)));
    s.resize(kMaxFileStemLength - 17);
    s += tail;
  }
  return s;
}
}  // namespace

std::vector<std::string> output_file_stems(const std::vector<std::string>& names) {
  std::vector<std::string> out;
  out.reserve(names.size());
  std::set<std::string> used;
  for (const auto& name : names) {
    const std::string s = sanitized(name);
    std::string stem = s;
    // The suffix may take a long stem past the limit by a few bytes: still far below 255.
    for (int k = 2; used.count(stem); ++k) stem = s + "_" + std::to_string(k);
    used.insert(stem);
    out.push_back(stem);
  }
  return out;
}

}  // namespace loom
