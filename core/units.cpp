#include "core/units.hpp"

namespace loom {

std::optional<Unit> parse_unit(const std::string& s) {
  if (s == "mm") return Unit::Millimetre;
  if (s == "cm") return Unit::Centimetre;
  if (s == "m") return Unit::Metre;
  if (s == "in" || s == "inch") return Unit::Inch;
  return std::nullopt;
}

const char* unit_name(Unit u) {
  switch (u) {
    case Unit::Millimetre: return "mm";
    case Unit::Centimetre: return "cm";
    case Unit::Metre: return "m";
    case Unit::Inch: return "in";
  }
  return "mm";
}

double unit_in_mm(Unit u) {
  switch (u) {
    case Unit::Millimetre: return 1.0;
    case Unit::Centimetre: return 10.0;
    case Unit::Metre: return 1000.0;
    case Unit::Inch: return 25.4;
  }
  return 1.0;
}

}  // namespace loom
