#include "app/option_checks.hpp"

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

}  // namespace loom::app
