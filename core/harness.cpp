#include "core/harness.hpp"

#include <algorithm>
#include <limits>

namespace loom {

int Harness::find_port(const std::string& id) const {
  for (std::size_t i = 0; i < ports.size(); ++i)
    if (ports[i].id == id) return static_cast<int>(i);
  return -1;
}

int Harness::find_branch(const std::string& id) const {
  for (std::size_t i = 0; i < branches.size(); ++i)
    if (branches[i].id == id) return static_cast<int>(i);
  return -1;
}

std::optional<Vec3> Harness::node_position(const std::string& id) const {
  if (int p = find_port(id); p >= 0) return ports[p].position;
  if (int b = find_branch(id); b >= 0) return branches[b].position;
  return std::nullopt;
}

int Harness::find_cable(const std::string& id) const {
  for (std::size_t i = 0; i < cables.size(); ++i)
    if (cables[i].id == id) return static_cast<int>(i);
  return -1;
}

double Harness::smallest_diameter() const {
  if (cables.empty()) return 0.0;
  double d = std::numeric_limits<double>::infinity();
  for (const auto& c : cables) d = std::min(d, c.physical.diameter);
  return d;
}

}  // namespace loom
