#include "core/harness_topology.hpp"

#include "core/error.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <unordered_map>

namespace loom {

double bundle_diameter(const std::vector<double>& diameters) {
  double s = 0.0;
  for (double d : diameters) s += d * d;
  return 1.2 * std::sqrt(s);
}

namespace {
SourceLocation at(const Harness& h, int line, std::string element) {
  return SourceLocation{h.source_file, line, std::move(element)};
}
}  // namespace

HarnessTopology::HarnessTopology(const Harness& h) : h_(&h) {
  // Node table: ports then branch points, ids unique across both.
  std::unordered_map<std::string, int> node;
  for (const auto& p : h.ports) {
    if (!node.emplace(p.id, static_cast<int>(node.size())).second)
      throw InputError(at(h, p.line, "port '" + p.id + "'"), "duplicate node id");
  }
  for (const auto& b : h.branches) {
    if (!node.emplace(b.id, static_cast<int>(node.size())).second)
      throw InputError(at(h, b.line, "branch '" + b.id + "'"),
                       "duplicate node id (already used by a port or branch)");
  }
  const int n_nodes = static_cast<int>(node.size());
  std::vector<std::vector<std::pair<int, int>>> adj(n_nodes);  // (neighbour, segment)
  std::set<std::pair<int, int>> seen_pairs;
  for (std::size_t s = 0; s < h.segments.size(); ++s) {
    const auto& seg = h.segments[s];
    const std::string name = "segment " + seg.from + " -> " + seg.to;
    auto a = node.find(seg.from), b = node.find(seg.to);
    if (a == node.end())
      throw InputError(at(h, seg.line, name), "unknown node id '" + seg.from + "'");
    if (b == node.end())
      throw InputError(at(h, seg.line, name), "unknown node id '" + seg.to + "'");
    if (a->second == b->second)
      throw InputError(at(h, seg.line, name), "segment joins a node to itself");
    auto key = std::minmax(a->second, b->second);
    if (!seen_pairs.insert({key.first, key.second}).second)
      throw InputError(at(h, seg.line, name), "duplicate segment between the same two nodes (a cycle)");
    adj[a->second].push_back({b->second, static_cast<int>(s)});
    adj[b->second].push_back({a->second, static_cast<int>(s)});
  }
  const int n_ports = static_cast<int>(h.ports.size());
  // Nodes of any degree: a branch point joins as many nodes as the harness needs (the
  // patent's exactly-3 rule is reported by notes(), not enforced); two is a pass-through.
  for (const auto& [id, k] : node) {
    std::vector<int>& inc = incident_[id];
    for (const auto& [v, seg] : adj[k]) inc.push_back(seg);
    std::sort(inc.begin(), inc.end());
  }
  // Cycle check: a forest has (nodes - components) edges. Find components by BFS, and
  // report the first edge that closes a loop.
  std::vector<int> comp(n_nodes, -1), parent_seg(n_nodes, -1), parent(n_nodes, -1), depth(n_nodes, 0);
  for (int start = 0; start < n_nodes; ++start) {
    if (comp[start] >= 0) continue;
    std::vector<int> stack{start};
    comp[start] = start;
    while (!stack.empty()) {
      int u = stack.back();
      stack.pop_back();
      for (auto [v, s] : adj[u]) {
        if (s == parent_seg[u]) continue;
        if (comp[v] >= 0) {
          const auto& seg = h.segments[s];
          throw InputError(at(h, seg.line, "segment " + seg.from + " -> " + seg.to),
                           "the harness structure has a cycle through this segment; a harness must be a tree");
        }
        comp[v] = start;
        parent[v] = u;
        depth[v] = depth[u] + 1;
        parent_seg[v] = s;
        stack.push_back(v);
      }
    }
  }
  // Cables: ports must exist and be connected; chain = tree path.
  std::set<std::string> cable_ids;
  chains_.resize(h.cables.size());
  carried_.assign(h.segments.size(), {});
  for (std::size_t c = 0; c < h.cables.size(); ++c) {
    const auto& cab = h.cables[c];
    const std::string name = "cable '" + cab.id + "'";
    if (!cable_ids.insert(cab.id).second) throw InputError(at(h, cab.line, name), "duplicate cable id");
    int ends[2];
    for (int k = 0; k < 2; ++k) {
      // Through the node table, not Harness::find_port: a linear search per cable end made
      // large harnesses quadratic (40,000 ports: 2 s of 2.1 in `loom info`).
      const auto p = node.find(cab.ports[k]);
      if (p == node.end() || p->second >= n_ports) {
        const bool is_branch = p != node.end();
        throw InputError(at(h, cab.line, name),
                         is_branch ? "'" + cab.ports[k] + "' is a branch point, a cable must end at ports"
                                   : "unknown port id '" + cab.ports[k] + "'");
      }
      ends[k] = p->second;  // ports come first in the node table, in file order
    }
    if (ends[0] == ends[1]) throw InputError(at(h, cab.line, name), "both ends are the same port '" + cab.ports[0] + "'");
    if (comp[ends[0]] != comp[ends[1]])
      throw InputError(at(h, cab.line, name),
                       "ports '" + cab.ports[0] + "' and '" + cab.ports[1] +
                           "' are not connected by the harness structure (no chain of segments joins them)");
    // Path: climb from both ends to their lowest common ancestor in the BFS tree.
    int a = ends[0], b = ends[1];
    int da = depth[a], db = depth[b];
    std::vector<SegmentUse> up, down;
    // Climbing child -> parent along a's side, the cable travels child -> parent:
    // forward iff seg.from == child. Along b's side it travels parent -> child:
    // forward iff seg.from != child.
    auto step = [&](int& v, std::vector<SegmentUse>& out, bool cable_moves_up) {
      const int s = parent_seg[v];
      const bool from_is_child = node.at(h.segments[s].from) == v;
      out.push_back({s, cable_moves_up ? !from_is_child : from_is_child});
      v = parent[v];
    };
    while (da > db) step(a, up, true), --da;
    while (db > da) step(b, down, false), --db;
    while (a != b) {
      step(a, up, true);
      step(b, down, false);
    }
    std::vector<SegmentUse> chain = up;
    chain.insert(chain.end(), down.rbegin(), down.rend());
    chains_[c] = std::move(chain);
    for (const auto& u : chains_[c]) carried_[u.segment].push_back(static_cast<int>(c));
  }
  diameter_.assign(h.segments.size(), 0.0);
  for (std::size_t s = 0; s < h.segments.size(); ++s) {
    const auto& cs = carried_[s];
    if (h.segments[s].diameter) {
      // A given bundle diameter holds its cables: one thinner than a cable it carries is a
      // typo or a unit slip, and would have the router plan too narrow a tube.
      for (int c : cs)
        if (*h.segments[s].diameter < h.cables[c].physical.diameter)
          throw InputError(at(h, h.segments[s].line, "segment " + h.segments[s].from + " -> " + h.segments[s].to),
                           "diameter " + full_precision(*h.segments[s].diameter) + " is less than the diameter " +
                               full_precision(h.cables[c].physical.diameter) + " of cable '" + h.cables[c].id +
                               "', which it carries");
      diameter_[s] = *h.segments[s].diameter;
      continue;
    }
    if (cs.size() == 1) diameter_[s] = h.cables[cs[0]].physical.diameter;
    else if (cs.size() > 1) {
      std::vector<double> d;
      for (int c : cs) d.push_back(h.cables[c].physical.diameter);
      diameter_[s] = bundle_diameter(d);
    }
  }
  std::vector<int> bundle_segs, single_segs;
  for (std::size_t s = 0; s < h.segments.size(); ++s) {
    if (carried_[s].size() > 1) bundle_segs.push_back(static_cast<int>(s));
    else if (carried_[s].size() == 1) single_segs.push_back(static_cast<int>(s));
  }
  std::stable_sort(bundle_segs.begin(), bundle_segs.end(),
                   [&](int x, int y) { return carried_[x].size() > carried_[y].size(); });
  order_ = bundle_segs;
  order_.insert(order_.end(), single_segs.begin(), single_segs.end());
}

std::vector<int> HarnessTopology::bundles() const {
  std::vector<int> out;
  for (std::size_t s = 0; s < carried_.size(); ++s)
    if (carried_[s].size() > 1) out.push_back(static_cast<int>(s));
  return out;
}

const std::vector<int>& HarnessTopology::incident_segments(const std::string& id) const {
  static const std::vector<int> none;
  const auto it = incident_.find(id);
  return it == incident_.end() ? none : it->second;
}

std::vector<std::string> HarnessTopology::notes() const {
  std::vector<std::string> out;
  for (const auto& b : h_->branches) {
    const std::size_t n = incident_segments(b.id).size();
    if (n == 3) continue;
    const std::string where = h_->source_file + (b.line > 0 ? ":" + std::to_string(b.line) : std::string()) +
                              " branch '" + b.id + "' joins " + std::to_string(n) + (n == 1 ? " node" : " nodes");
    if (n == 2) out.push_back(where + ": a pass-through point (the patent's branch points join exactly 3)");
    else if (n < 2) out.push_back(where + ": a dead end, no cable passes it (the patent's branch points join exactly 3)");
    else out.push_back(where + " (the patent's branch points join exactly 3; loom routes and audits nodes of any degree)");
  }
  return out;
}

std::map<int, int> HarnessTopology::nodes_by_degree() const {
  std::map<int, int> out;
  for (const auto& p : h_->ports) ++out[static_cast<int>(incident_segments(p.id).size())];
  for (const auto& b : h_->branches) ++out[static_cast<int>(incident_segments(b.id).size())];
  return out;
}

}  // namespace loom
