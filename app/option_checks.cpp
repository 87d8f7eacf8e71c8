#include "app/option_checks.hpp"

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

CLI::Validator non_empty_path() {
  return CLI::Validator(
      [](std::string& text) -> std::string { return text.empty() ? "must name a path, got an empty string" : ""; },
      "PATH");
}

}  // namespace loom::app
