#include "routing/route/class_separation.hpp"

#include "core/error.hpp"

#include <algorithm>
#include <utility>

namespace loom {

std::vector<std::set<std::string>> segment_classes(const HarnessTopology& topo) {
  const Harness& h = topo.harness();
  std::vector<std::set<std::string>> out(h.segments.size());
  for (std::size_t s = 0; s < h.segments.size(); ++s)
    for (int c : topo.segment_cables(static_cast<int>(s))) {
      const std::string& cls = h.cables[static_cast<std::size_t>(c)].physical.cable_class;
      if (!cls.empty()) out[s].insert(cls);
    }
  return out;
}

double class_gap(const RoutingSettings& routing, const std::set<std::string>& a, const std::set<std::string>& b) {
  double gap = 0.0;
  for (const std::string& x : a)
    for (const std::string& y : b)
      if (x != y) gap = std::max(gap, routing.separation_between(x, y));
  return gap;
}

namespace {

/// The first pair of classes from `a` × `b` with the largest separation (empty names: none).
std::pair<std::string, std::string> widest_pair(const RoutingSettings& routing, const std::set<std::string>& a,
                                                const std::set<std::string>& b, double& gap) {
  std::pair<std::string, std::string> best;
  gap = 0.0;
  for (const std::string& x : a)
    for (const std::string& y : b)
      if (x != y && routing.separation_between(x, y) > gap) {
        gap = routing.separation_between(x, y);
        best = {std::min(x, y), std::max(x, y)};
      }
  return best;
}

std::string keeps_apart(const std::pair<std::string, std::string>& p, double gap) {
  return "classes " + p.first + " and " + p.second + ", which [routing.separation] keeps " + full_precision(gap) +
         " apart";
}

/// Node ids of the harness: ports, then branch points.
std::vector<std::string> node_ids(const Harness& h) {
  std::vector<std::string> ids;
  for (const Port& p : h.ports) ids.push_back(p.id);
  for (const BranchPoint& b : h.branches) ids.push_back(b.id);
  return ids;
}

}  // namespace

std::vector<std::string> separation_conflicts(const HarnessTopology& topo, const RoutingSettings& routing,
                                              const std::vector<std::set<std::string>>& classes) {
  const Harness& h = topo.harness();
  std::vector<std::string> out;
  double gap = 0.0;
  for (std::size_t s = 0; s < h.segments.size(); ++s) {
    const auto pair = widest_pair(routing, classes[s], classes[s], gap);
    if (gap > 0.0)
      out.push_back("segment " + h.segments[s].from + " -> " + h.segments[s].to + " carries " + keeps_apart(pair, gap) +
                    ": the audit reports segregation along it (give each class its own segments)");
  }
  for (const std::string& node : node_ids(h)) {
    // Pairs of different segments only: a segment's own mix is named above.
    const std::vector<int>& inc = topo.incident_segments(node);
    double widest = 0.0;
    std::pair<std::string, std::string> which;
    for (std::size_t i = 0; i < inc.size(); ++i)
      for (std::size_t j = i + 1; j < inc.size(); ++j) {
        const auto pair = widest_pair(routing, classes[static_cast<std::size_t>(inc[i])],
                                      classes[static_cast<std::size_t>(inc[j])], gap);
        if (gap > widest) {
          widest = gap;
          which = pair;
        }
      }
    if (widest > 0.0)
      out.push_back("node " + node + " joins segments of " + keeps_apart(which, widest) +
                    ": the audit reports segregation where they meet");
  }
  return out;
}

}  // namespace loom
