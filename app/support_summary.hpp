#pragma once
// The supports and segregation lines of the `audit` and `route` summaries.
#include "routing/audit/audit.hpp"

#include <cstddef>

namespace loom {

/// Prints up to `max_lines` unsupported spans and segregation findings of `rep`, one line
/// each, indented by two blanks; returns how many findings there are in all.
std::size_t print_support_findings(const AuditReport& rep, std::size_t max_lines);

}  // namespace loom
