#include "routing/view/motion_view.hpp"

#include "core/error.hpp"

#include <cmath>

namespace loom {

namespace {

PosedPartView posed(const Part& p, double q, const std::string& role, const std::string& units) {
  return {p.name + " @ " + full_precision(q) + " " + p.motion->pose_unit(units), role, posed_mesh(p.mesh, *p.motion, q)};
}

}  // namespace

std::vector<PosedPartView> motion_view_meshes(const Scene& scene, const nlohmann::json& report) {
  std::vector<PosedPartView> out;
  const std::string units = unit_name(scene.units);
  for (const Part& p : scene.parts) {
    if (!p.motion) continue;
    out.push_back(posed(p, p.motion->from, "swept", units));
    if (p.motion->to != p.motion->from) out.push_back(posed(p, p.motion->to, "swept", units));
  }
  if (!report.contains("clashes") || !report["clashes"].is_array()) return out;
  for (const auto& c : report["clashes"]) {
    if (!c.is_object() || c.value("kind", "") != "cable-motion" || !c.contains("part") || !c["part"].is_string() ||
        !c.contains("pose") || !c["pose"].is_number())
      continue;
    const int k = scene.find_part(c["part"].get<std::string>());
    const double q = c["pose"].get<double>();
    if (k < 0 || !scene.parts[static_cast<std::size_t>(k)].motion || !std::isfinite(q)) continue;
    out.push_back(posed(scene.parts[static_cast<std::size_t>(k)], q, "clash-pose", units));
  }
  return out;
}

}  // namespace loom
