#pragma once
// The cable-motion lines of the `audit` and `route` summaries.
#include "routing/audit/audit.hpp"

#include <cstddef>

namespace loom {

/// Prints up to `max_lines` cable-motion clashes of `rep` (cable, part, clearance, pose),
/// one line each, indented by two blanks; returns how many there are in all.
std::size_t print_motion_clashes(const AuditReport& rep, std::size_t max_lines);

}  // namespace loom
