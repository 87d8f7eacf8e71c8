#include "app/option_checks.hpp"

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <string>

namespace loom::app {

CLI::Validator finite_number(double min, bool min_allowed) {
  const std::string limit = std::string(min_allowed ? ">= " : "> ") + CLI::detail::to_string(min);
  return CLI::Validator(
      [min, min_allowed, limit](std::string& text) -> std::string {
        const char* begin = text.c_str();
        char* end = nullptr;
        const double v = std::strtod(begin, &end);
        const bool whole = end != begin && *end == '\0';
        if (!whole || !std::isfinite(v) || v < min || (!min_allowed && v == min))
          return "must be a finite number " + limit + ", got " + text;
        return {};
      },
      "FINITE " + limit);
}

CLI::Validator whole_number(long long min, long long max) {
  const std::string range = std::to_string(min) + ".." + std::to_string(max);
  return CLI::Validator(
      [min, max, range](std::string& text) -> std::string {
        const char* begin = text.c_str();
        char* end = nullptr;
        errno = 0;
        const long long v = std::strtoll(begin, &end, 10);
        const bool whole = end != begin && *end == '\0' && errno == 0;
        if (!whole || v < min || v > max) return "must be a whole number in " + range + ", got " + text;
        return {};
      },
      "INT in " + range);
}

double byte_size_value(const std::string& text) {
  const char* begin = text.c_str();
  char* end = nullptr;
  const double v = std::strtod(begin, &end);
  if (end == begin || !std::isfinite(v) || !(v > 0.0)) return 0.0;
  std::string unit(end);
  for (char& c : unit) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  double scale = 1.0;
  if (!unit.empty()) {
    const std::string prefixes = "KMGT";
    const auto k = prefixes.find(unit[0]);
    if (k == std::string::npos) return 0.0;
    const std::string rest = unit.substr(1);
    if (!(rest.empty() || rest == "B" || rest == "IB")) return 0.0;
    scale = std::pow(1024.0, static_cast<double>(k + 1));
  }
  const double bytes = v * scale;
  return std::isfinite(bytes) && bytes >= 1.0 ? bytes : 0.0;
}

CLI::Validator byte_size() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        return byte_size_value(text) > 0.0 ? "" : "must be a size such as 24G, 512M or 1.5T, got " + text;
      },
      "SIZE");
}

CLI::Validator non_empty_path() {
  return CLI::Validator(
      [](std::string& text) -> std::string { return text.empty() ? "must name a path, got an empty string" : ""; },
      "PATH");
}

}  // namespace loom::app
