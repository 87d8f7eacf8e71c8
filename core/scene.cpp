#include "core/scene.hpp"

#include <utility>

namespace loom {

const std::vector<std::string>& routing_planner_names() {
  static const std::vector<std::string> names = {
      "abitstar", "bfmt", "bitstar", "fmt", "informedrrtstar", "lazyprm", "lazyprmstar", "portfolio",
      "prm", "prmstar", "rrt", "rrtconnect", "rrtsharp", "rrtstar", "sorrtstar"};
  return names;
}

AABB Scene::bounds() const {
  AABB box;
  for (const auto& p : parts) box.extend(p.mesh.bounds());
  for (const auto& p : harness.ports) box.extend(p.position);
  return box;
}

std::size_t Scene::triangle_count() const {
  std::size_t n = 0;
  for (const auto& p : parts) n += p.mesh.triangle_count();
  return n;
}

int Scene::find_part(const std::string& name) const {
  for (std::size_t i = 0; i < parts.size(); ++i)
    if (parts[i].name == name) return static_cast<int>(i);
  return -1;
}

double RoutingSettings::separation_between(const std::string& a, const std::string& b) const {
  if (a.empty() || b.empty()) return 0.0;
  const auto it = separation.find(a < b ? std::make_pair(a, b) : std::make_pair(b, a));
  return it == separation.end() ? 0.0 : it->second;
}

}  // namespace loom
