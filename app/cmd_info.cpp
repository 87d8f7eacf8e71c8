// `loom info SCENE [--json]`: what a scene holds and which tolerances were derived.
#include "app/commands.hpp"

#include "core/harness_topology.hpp"
#include "core/io/kbl_read.hpp"
#include "core/io/scene_load.hpp"
#include "app/progress_bar.hpp"
#include "core/io/json_text.hpp"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <cstdio>
#include <iostream>
#include <memory>

namespace loom::app {

namespace {

nlohmann::json setting_json(const Setting& s) { return {{"value", s.value}, {"source", s.source}}; }

nlohmann::json vec_json(const Vec3& v) { return nlohmann::json::array({v.x(), v.y(), v.z()}); }

nlohmann::json info_json(const Scene& scene, const SceneLoadReport& rep) {
  using nlohmann::json;
  json j;
  j["scene"] = scene.name;
  j["units"] = unit_name(scene.units);
  j["file"] = scene.source_file;
  json parts = json::array();
  for (const auto& p : scene.parts) {
    const AABB b = p.mesh.bounds();
    parts.push_back({{"name", p.name},
                     {"file", p.source_file},
                     {"role", role_name(p.role)},
                     {"triangles", p.mesh.triangle_count()},
                     {"brep_faces", p.source_faces},
                     {"closed", p.closed},
                     {"clearance", p.clearance},
                     {"bbox", {{"min", vec_json(b.min)}, {"max", vec_json(b.max)}}}});
  }
  j["parts"] = parts;
  j["triangles"] = scene.triangle_count();
  const Harness& h = scene.harness;
  json harness;
  harness["name"] = h.name;
  harness["file"] = h.source_file;
  json cables = json::array();
  for (const auto& c : h.cables)
    cables.push_back({{"id", c.id},
                      {"ports", {c.ports[0], c.ports[1]}},
                      {"type", c.physical.type},
                      {"color", c.physical.color},
                      {"diameter", c.physical.diameter},
                      {"min_bend_radius", c.physical.min_bend_radius},
                      {"cross_section", c.physical.cross_section},
                      {"cores", c.cores.size()}});
  harness["cables"] = cables;
  json ports = json::array();
  for (const auto& p : h.ports)
    ports.push_back({{"id", p.id}, {"position", vec_json(p.position)}, {"direction", vec_json(p.direction)}});
  harness["ports"] = ports;
  json branches = json::array();
  for (const auto& b : h.branches) {
    json e{{"id", b.id}};
    e["position"] = b.position ? vec_json(*b.position) : json(nullptr);
    branches.push_back(e);
  }
  harness["branch_points"] = branches;
  if (scene.has_harness) {
    HarnessTopology topo(h);
    json segs = json::array();
    for (std::size_t s = 0; s < h.segments.size(); ++s) {
      json cs = json::array();
      for (int c : topo.segment_cables(static_cast<int>(s))) cs.push_back(h.cables[c].id);
      segs.push_back({{"from", h.segments[s].from},
                      {"to", h.segments[s].to},
                      {"cables", cs},
                      {"bundle", topo.is_bundle(static_cast<int>(s))},
                      {"diameter", topo.segment_diameter(static_cast<int>(s))},
                      {"path_points", h.segments[s].path.size()},
                      {"routed", h.segments[s].bspline.has_value()}});
    }
    harness["segments"] = segs;
    json order = json::array();
    for (int s : topo.routing_order()) order.push_back(h.segments[s].from + " -> " + h.segments[s].to);
    harness["routing_order"] = order;
    json degrees = json::object();
    for (const auto& [deg, n] : topo.nodes_by_degree()) degrees[std::to_string(deg)] = n;
    harness["nodes_by_degree"] = degrees;
    harness["notes"] = topo.notes();
    if (h.kbl) {
      json counts = json::object(), ignored = json::object();
      for (const auto& [what, n] : h.kbl->counts) counts[what] = n;
      for (const auto& [what, n] : h.kbl->ignored) ignored[what] = n;
      harness["kbl"] = {{"version", h.kbl->version}, {"counts", counts}, {"not_used", ignored},
                        {"clamps", h.clamps.size()}, {"notes", h.kbl->notes}};
    }
  }
  j["harness"] = harness;
  j["settings"] = {{"routing",
                    {{"clearance", setting_json(scene.routing.clearance)},
                     {"planner", scene.routing.planner},
                     {"time_limit", setting_json(scene.routing.time_limit)},
                     {"seed", scene.routing.seed},
                     {"iterations", setting_json(scene.routing.iterations)}}},
                   {"simplify", {{"dim_pre", setting_json(scene.simplify.dim_pre)}}},
                   {"tessellation",
                    {{"linear_deflection", setting_json(scene.tessellation.linear_deflection)},
                     {"angular_deflection_deg", setting_json(scene.tessellation.angular_deflection_deg)}}}};
  const AABB b = scene.bounds();
  j["bbox"] = {{"min", vec_json(b.min)}, {"max", vec_json(b.max)}};
  j["notes"] = rep.notes;
  j["load_ms"] = rep.load_ms;
  return j;
}

/// What a KBL file held: what loom read from it, what it does not use, what it noticed.
void print_kbl(const KblOrigin& k) {
  std::string read, unused;
  for (const auto& [what, n] : k.counts) read += (read.empty() ? "" : ", ") + std::to_string(n) + " " + what;
  for (const auto& [what, n] : k.ignored) unused += (unused.empty() ? "" : ", ") + what + " " + std::to_string(n);
  std::printf("  KBL %s: %s\n", k.version.c_str(), read.c_str());
  std::printf("  not used by loom: %s\n", unused.empty() ? "nothing" : unused.c_str());
  for (const auto& n : k.notes) std::printf("  kbl: %s\n", n.c_str());
}

void print_text(const Scene& scene, const SceneLoadReport& rep) {
  const char* u = unit_name(scene.units);
  std::printf("scene %s (%s), %zu parts, %zu triangles, loaded in %.0f ms\n", scene.name.c_str(), u,
              scene.parts.size(), scene.triangle_count(), rep.load_ms);
  std::printf("\nparts:\n");
  for (const auto& p : scene.parts) {
    const AABB b = p.mesh.bounds();
    char extra[64] = "";
    if (p.clearance > 0) std::snprintf(extra, sizeof extra, "  +%.4g %s clearance", p.clearance, unit_name(scene.units));
    std::printf("  %-28s %-9s %9zu tris  %-6s  bbox [%.1f %.1f %.1f]..[%.1f %.1f %.1f]%s\n", p.name.c_str(),
                role_name(p.role), p.mesh.triangle_count(), p.closed ? "closed" : "open", b.min.x(), b.min.y(),
                b.min.z(), b.max.x(), b.max.y(), b.max.z(), extra);
  }
  const Harness& h = scene.harness;
  if (scene.has_harness) {
    HarnessTopology topo(h);
    std::printf("\nharness %s: %zu cables, %zu ports, %zu branch points, %zu segments\n", h.name.c_str(),
                h.cables.size(), h.ports.size(), h.branches.size(), h.segments.size());
    for (const auto& c : h.cables)
      std::printf("  cable %-8s %-10s -> %-10s d=%.2f %s  min bend %.1f %s\n", c.id.c_str(), c.ports[0].c_str(),
                  c.ports[1].c_str(), c.physical.diameter, u, c.physical.min_bend_radius, u);
    std::string degrees;
    for (const auto& [deg, n] : topo.nodes_by_degree())
      degrees += (degrees.empty() ? "" : ", ") + std::to_string(n) + " of degree " + std::to_string(deg);
    std::printf("  nodes by degree (segments joined): %s\n", degrees.empty() ? "none" : degrees.c_str());
    if (h.kbl) print_kbl(*h.kbl);
    for (const auto& b : h.branches) {
      if (b.position)
        std::printf("  branch %-8s at [%.1f %.1f %.1f]\n", b.id.c_str(), b.position->x(), b.position->y(),
                    b.position->z());
      else
        std::printf("  branch %-8s unplaced (the router places it)\n", b.id.c_str());
    }
    const auto bundles = topo.bundles();
    std::printf("\nbundles (%zu), in routing order:\n", bundles.size());
    for (int s : topo.routing_order()) {
      const auto& seg = h.segments[s];
      std::printf("  %-10s -> %-10s %2zu cable%s  D=%.2f %s%s\n", seg.from.c_str(), seg.to.c_str(),
                  topo.segment_cables(s).size(), topo.segment_cables(s).size() == 1 ? " " : "s",
                  topo.segment_diameter(s), u, topo.is_bundle(s) ? "  (bundle)" : "");
    }
  } else {
    std::printf("\nno harness\n");
  }
  std::printf("\nsettings (derived where not given):\n");
  auto line = [&](const char* name, const Setting& s) {
    std::printf("  %-30s %-10.4g %s\n", name, s.value, s.source.c_str());
  };
  line("routing.clearance", scene.routing.clearance);
  line("routing.time_limit [s]", scene.routing.time_limit);
  line("routing.iterations", scene.routing.iterations);
  line("simplify.dim_pre", scene.simplify.dim_pre);
  line("tessellation.linear_deflection", scene.tessellation.linear_deflection);
  line("tessellation.angular_deg", scene.tessellation.angular_deflection_deg);
  std::printf("  %-30s %s\n", "routing.planner", scene.routing.planner.c_str());
  for (const auto& n : rep.notes) std::printf("note: %s\n", n.c_str());
  if (scene.has_harness)
    for (const auto& n : HarnessTopology(h).notes()) std::printf("note: %s\n", n.c_str());
}

}  // namespace

void add_info_command(CLI::App& app, int& exit_code) {
  auto* cmd = app.add_subcommand("info", "Load a scene and print its parts, harness, bundles and derived tolerances");
  auto scene_path = std::make_shared<std::string>();
  auto json = std::make_shared<bool>(false);
  auto quiet = std::make_shared<bool>(false);
  cmd->add_option("SCENE", *scene_path, "Scene file (TOML)")->required();
  cmd->add_flag("--json", *json, "Print the summary as JSON");
  cmd->add_flag("--quiet", *quiet, "Print nothing (exit status only)");
  cmd->callback([scene_path, json, quiet, &exit_code]() { exit_code = run_info(*scene_path, *json, *quiet); });
}

int run_info(const std::string& scene_path, bool json, bool quiet) {
  SceneLoadReport rep;
  ProgressBar bar(stderr, quiet || json);
  SceneLoadOptions lo;
  lo.progress = bar.fn();
  Scene scene = load_scene(scene_path, lo, &rep);
  if (quiet) return 0;
  if (json) std::cout << json_text(info_json(scene, rep), 2) << "\n";
  else print_text(scene, rep);
  return 0;
}

}  // namespace loom::app
