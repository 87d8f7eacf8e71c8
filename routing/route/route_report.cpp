#include "routing/route/route_report.hpp"

#include "core/harness_topology.hpp"
#include "core/io/atomic_file.hpp"
#include "core/io/harness_xml.hpp"
#include "core/io/kbl_write.hpp"
#include "core/io/mesh_write.hpp"
#include "routing/curve/cable_geometry.hpp"
#include "core/io/json_text.hpp"
#include "routing/audit/report_json.hpp"
#include "routing/curve/sweep.hpp"

#include <cmath>
#include <map>
#include <set>

namespace loom {

namespace {
using nlohmann::json;

double finite_or(double v, double fallback) { return std::isfinite(v) ? v : fallback; }

/// A distinct colour per cable index (golden-angle hue walk).
std::array<std::uint8_t, 3> cable_color(std::size_t i) {
  const double h = std::fmod(static_cast<double>(i) * 137.508, 360.0) / 60.0;
  const double x = 1.0 - std::abs(std::fmod(h, 2.0) - 1.0);
  double r = 0, g = 0, b = 0;
  switch (static_cast<int>(h)) {
    case 0: r = 1, g = x; break;
    case 1: r = x, g = 1; break;
    case 2: g = 1, b = x; break;
    case 3: g = x, b = 1; break;
    case 4: r = x, b = 1; break;
    default: r = 1, b = x; break;
  }
  auto c = [](double v) { return static_cast<std::uint8_t>(std::lround(60 + 195 * v)); };
  return {c(r), c(g), c(b)};
}
}  // namespace

json route_report_json(const RouteReport& rep) {
  json j = audit_report_json(rep.audit);
  j["planner"] = rep.planner;
  j["seed"] = rep.seed;
  j["iterations"] = rep.iterations;  // 0: none
  j["reproducible"] = rep.unreproducible.empty();
  j["clearance"] = rep.clearance;
  if (rep.voxel_resolution > 0.0)
    j["voxel_layer"] = {{"resolution", rep.voxel_resolution}, {"decided", rep.voxel_decided}, {"exact", rep.voxel_exact}};
  if (rep.share_within_reach >= 0.0)
    j["supports"] = {{"clamps_placed", rep.clamps_placed}, {"share_within_reach", rep.share_within_reach}};
  // Per cable: the audit's figures plus how it was routed.
  std::map<std::string, double> plan_ms;
  const HarnessTopology topo(rep.routed);
  for (const auto& info : rep.segments)
    for (int c : topo.segment_cables(info.segment)) plan_ms[rep.routed.cables[c].id] += info.plan.time_ms;
  std::map<std::string, const UnroutedCable*> unrouted;
  for (const auto& u : rep.unrouted) unrouted.emplace(u.cable, &u);
  for (auto& c : j["cables"]) {
    const std::string id = c["id"];
    c["planner"] = rep.planner;
    c["time_ms"] = plan_ms[id];
    if (auto it = unrouted.find(id); it != unrouted.end()) {
      c["routed"] = false;
      c["reason"] = it->second->reason;
      c["blocked_segment"] = it->second->segment;
      c["message"] = it->second->message;
    }
  }
  // Unrouted cables were left out of the audit: list them with the reason.
  for (const auto& u : rep.unrouted) {
    bool listed = false;
    for (const auto& c : j["cables"]) listed = listed || c["id"] == u.cable;
    if (!listed)
      j["cables"].push_back({{"id", u.cable}, {"routed", false}, {"reason", u.reason}, {"blocked_segment", u.segment},
                             {"message", u.message}, {"planner", rep.planner}, {"time_ms", plan_ms[u.cable]}});
  }
  json segs = json::array();
  for (const auto& info : rep.segments) {
    const Segment& s = rep.routed.segments[info.segment];
    json o{{"from", s.from}, {"to", s.to}, {"diameter", topo.segment_diameter(info.segment)}};
    if (info.kept_from_input) {
      o["status"] = "kept from input";
    } else {
      o["status"] = info.plan.solved() ? "routed" : "failed";
      o["reason"] = reason_name(info.plan.reason);
      if (!info.plan.message.empty()) o["message"] = info.plan.message;
      if (info.plan.blocked_at) o["blocked_at"] = {info.plan.blocked_at->x(), info.plan.blocked_at->y(), info.plan.blocked_at->z()};
      o["plan_ms"] = info.plan.time_ms;
      o["iterations"] = info.plan.iterations;
      o["time_limited"] = info.time_limited;
      if (info.portfolio) {
        const PortfolioOutcome& pf = *info.portfolio;
        o["portfolio"] = {{"scale", pf.budget.scale},
                          {"feasibility_seconds", pf.budget.feasibility_seconds},
                          {"feasibility_iterations", pf.budget.feasibility_iterations},
                          {"feasibility_iterations_used", pf.feasibility_iterations_used},
                          {"optimise_seconds", pf.budget.optimise_seconds},
                          {"optimise_iterations", pf.budget.optimise_iterations},
                          {"optimise_iterations_used", pf.optimise_iterations_used},
                          {"corridor_found", pf.corridor_found},
                          {"optimised", pf.optimised}};
        if (pf.corridor_found) o["portfolio"]["corridor_cost"] = pf.feasibility_cost;
      }
      if (info.plan.solved()) {
        o["planned_length"] = info.plan.length;
        o["planned_min_clearance"] = finite_or(info.plan.min_clearance, 0.0);
        o["key_points"] = info.key_points;
        o["repair_rounds"] = info.repair_rounds;
        o["replans"] = info.replans;
        o["support_points"] = info.support_points;
        o["bend_repair"] = info.bend_status;
        if (!info.bend_plan.empty())
          o["bend_plan"] = {{"status", info.bend_plan},
                            {"samples", info.bend_plan_samples},
                            {"ms", info.bend_plan_ms}};
      }
    }
    segs.push_back(o);
  }
  j["segments"] = segs;
  json un = json::array();
  for (const auto& u : rep.unrouted)
    un.push_back({{"cable", u.cable}, {"segment", u.segment}, {"reason", u.reason}, {"message", u.message}});
  j["unrouted"] = un;
  j["timing_ms"] = {{"load", rep.timing.load},     {"index", rep.timing.index + rep.audit.index_ms},
                    {"simplify", rep.timing.simplify}, {"plan", rep.timing.plan},
                    {"spline", rep.timing.spline},  {"audit", rep.timing.audit},
                    {"repair", rep.timing.repair},  {"route", rep.timing.total},
                    {"check", rep.audit.check_ms}};
  for (const auto& n : rep.notes) j["notes"].push_back(n);
  return j;
}

std::vector<std::filesystem::path> route_output_files(const std::filesystem::path& dir) {
  return {dir / "routed.xml", dir / "report.json", dir / "cables.ply", dir / kRoutedKblName};
}

void write_route_outputs(const RouteReport& rep, const std::filesystem::path& dir, double chord_tolerance) {
  // The tubes first: if they are refused (the budget), no file is written.
  const HarnessTopology topo(rep.routed);
  Mesh all;
  std::vector<std::array<std::uint8_t, 3>> colors;
  SweepOptions so;
  so.chord_tolerance = chord_tolerance;
  SegmentCurves curves(topo);
  TubeBudget budget("cables.ply");
  std::set<std::string> unrouted;  // blocked cables are reported, never drawn
  for (const auto& u : rep.unrouted) unrouted.insert(u.cable);
  for (std::size_t c = 0; c < rep.routed.cables.size(); ++c) {
    if (unrouted.count(rep.routed.cables[c].id)) continue;
    auto curve = curves.cable(static_cast<int>(c));
    if (!curve) continue;
    const SweepResult tube = budget.sweep(*curve, rep.routed.cables[c].radius(), so, rep.routed.cables[c].id);
    all.append(tube.mesh);
    colors.insert(colors.end(), tube.mesh.vertices.size(), cable_color(c));
  }
  write_harness_xml(rep.routed, dir / "routed.xml");
  if (rep.routed.kbl) write_harness_kbl(rep.routed, dir / kRoutedKblName);
  write_file_atomic(dir / "report.json", json_text(route_report_json(rep), 2) + "\n");
  write_mesh(dir / "cables.ply", all, colors);
}

}  // namespace loom
