#pragma once
/// Length units a scene can be written in.

#include <optional>
#include <string>

namespace loom {

/// Length unit of a scene or harness. Every length in a scene is in its unit.
enum class Unit { Millimetre, Centimetre, Metre, Inch };

/// Parses "mm", "cm", "m", "in" (also "inch"); nullopt for anything else.
std::optional<Unit> parse_unit(const std::string& s);
/// The canonical short name ("mm", "cm", "m", "in").
const char* unit_name(Unit u);
/// Millimetres in one unit (1 for mm, 1000 for m, 25.4 for in).
double unit_in_mm(Unit u);

}  // namespace loom
