#pragma once
/// report.json, routed.xml and cables.ply of `loom route` (DESIGN §4): the audit report of
/// the routed cables, extended with per-cable routing results, per-segment planning
/// results, unroutable cables with reasons, and the time split of the run.

#include "routing/route/route_pipeline.hpp"

#include <filesystem>
#include <nlohmann/json.hpp>

namespace loom {

/// The report as JSON (no NaN/inf anywhere).
nlohmann::json route_report_json(const RouteReport& report);

/// Writes DIR/routed.xml, DIR/report.json and DIR/cables.ply (one swept tube per routed
/// cable, coloured per cable), each atomically, and DIR/routed.kbl when the harness was read
/// from KBL (kbl_write.hpp). `chord_tolerance` sets the tube resolution.
/// The tubes are swept first, within kHarnessTubeTriangleBudget triangles together; past
/// it throws std::invalid_argument naming the cable, and writes nothing.
void write_route_outputs(const RouteReport& report, const std::filesystem::path& dir, double chord_tolerance);

/// The files write_route_outputs() may write into `dir` (routed.xml, report.json, cables.ply,
/// routed.kbl).
std::vector<std::filesystem::path> route_output_files(const std::filesystem::path& dir);

}  // namespace loom
