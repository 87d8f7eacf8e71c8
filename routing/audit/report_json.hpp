#pragma once
/// report.json of `loom audit` exactly as DESIGN §4 lists its fields (plus a few extra
/// fields that say more: keep_out, inside, stretch ends, notes). Never NaN or infinity:
/// unbounded values are omitted and the reason is given beside them.

#include "routing/audit/audit.hpp"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <set>
#include <string>

namespace loom {

/// The report as JSON (numbers in scene units, times in milliseconds).
nlohmann::json audit_report_json(const AuditReport& report);

/// Ids of the cables a report (audit or route) marks `"routed": false` — no curve to draw:
/// a route that failed keeps only its nodes, and a straight line between them is no route.
std::set<std::string> unrouted_cable_ids(const nlohmann::json& report);

/// Writes audit_report_json(report) to `path` atomically (pretty-printed).
void write_audit_report(const AuditReport& report, const std::filesystem::path& path);

}  // namespace loom
