// Grouping the pair passes' contacts into stretches, and their refusal past the limits
// (pair_contacts.hpp).
#include "routing/audit/pair_contacts.hpp"

#include "routing/curve/cable_limit.hpp"

#include <algorithm>
#include <map>
#include <numeric>
#include <stdexcept>
#include <string>
#include <tuple>

namespace loom::audit {

void group_pair_contacts(std::vector<PairContact>& contacts, const std::vector<CableInput>& cables,
                         std::vector<ClashEntry>& out) {
  std::sort(contacts.begin(), contacts.end(), [](const PairContact& x, const PairContact& y) {
    return std::tie(x.a, x.b, x.sa0, x.sa1, x.tb0) < std::tie(y.a, y.b, y.sa0, y.sa1, y.tb0);
  });
  /// A run of contacts of one cell whose b-intervals touch: their b-range and one member.
  struct Range {
    double lo, hi;
    std::size_t member;
  };
  struct Cell {
    double sa0, sa1;
    std::vector<Range> ranges;  ///< disjoint, by lo
  };
  std::size_t i = 0;
  while (i < contacts.size()) {
    std::size_t j = i;
    while (j < contacts.size() && contacts[j].a == contacts[i].a && contacts[j].b == contacts[i].b) ++j;
    const std::size_t n = j - i;
    std::vector<std::size_t> parent(n);
    std::iota(parent.begin(), parent.end(), 0);
    auto find = [&](std::size_t x) {
      while (parent[x] != x) x = parent[x] = parent[parent[x]];
      return x;
    };
    auto unite = [&](std::size_t x, std::size_t y) { parent[find(x)] = find(y); };
    const double slack_a = kTouchRel * (1.0 + cables[contacts[i].a].curve.length());
    const double slack_b = kTouchRel * (1.0 + cables[contacts[i].b].curve.length());
    std::vector<Cell> cells;
    for (std::size_t x = 0; x < n;) {
      const PairContact& first = contacts[i + x];
      Cell cell{first.sa0, first.sa1, {}};
      std::size_t y = x;
      for (; y < n && contacts[i + y].sa0 == first.sa0 && contacts[i + y].sa1 == first.sa1; ++y) {
        const PairContact& cy = contacts[i + y];  // sorted by tb0 within the cell
        if (!cell.ranges.empty() && cy.tb0 <= cell.ranges.back().hi + slack_b) {
          unite(y, cell.ranges.back().member);
          cell.ranges.back().hi = std::max(cell.ranges.back().hi, cy.tb1);
        } else {
          cell.ranges.push_back({cy.tb0, cy.tb1, y});
        }
      }
      cells.push_back(std::move(cell));
      x = y;
    }
    // Cells are sorted by sa0: the ones touching cell c on a follow it until one starts
    // beyond its end.
    for (std::size_t c = 0; c < cells.size(); ++c)
      for (std::size_t d = c + 1; d < cells.size() && cells[d].sa0 <= cells[c].sa1 + slack_a; ++d) {
        const auto& rc = cells[c].ranges;
        const auto& rd = cells[d].ranges;
        for (std::size_t u = 0, v = 0; u < rc.size() && v < rd.size();) {
          if (rc[u].lo <= rd[v].hi + slack_b && rd[v].lo <= rc[u].hi + slack_b) unite(rc[u].member, rd[v].member);
          (rc[u].hi < rd[v].hi ? u : v) += 1;  // drop the range that ends first
        }
      }
    std::map<std::size_t, std::size_t> best;  // root → index of deepest
    std::map<std::size_t, std::pair<double, double>> range;
    for (std::size_t x = 0; x < n; ++x) {
      const std::size_t root = find(x);
      const PairContact& cx = contacts[i + x];
      auto it = best.find(root);
      if (it == best.end() || cx.dist - 0.0 < contacts[i + it->second].dist) best[root] = x;
      auto rt = range.find(root);
      if (rt == range.end())
        range[root] = {cx.sa0, cx.sa1};
      else
        rt->second = {std::min(rt->second.first, cx.sa0), std::max(rt->second.second, cx.sa1)};
    }
    for (const auto& kv : best) {
      const PairContact& c = contacts[i + kv.second];
      ClashEntry e;
      e.kind = c.a == c.b ? ClashKind::Self : ClashKind::CableCable;
      e.cable = c.a;
      e.other = c.b;
      const double r_sum = cables[c.a].radius + cables[c.b].radius;
      e.clearance = c.dist - r_sum;
      e.point = 0.5 * (c.p + c.q);
      e.s = c.s;
      e.s_other = c.t;
      e.s_begin = range[kv.first].first;
      e.s_end = range[kv.first].second;
      out.push_back(e);
    }
    i = j;
  }
}

void refuse_contacts(const Context& ctx, const std::vector<PairContact>& found, const char* what) {
  std::map<std::pair<int, int>, std::size_t> per_pair;
  for (const PairContact& c : found) ++per_pair[{c.a, c.b}];
  std::pair<int, int> top{0, 0};
  std::size_t most = 0;
  for (const auto& [ab, n] : per_pair)
    if (n > most) {
      most = n;
      top = ab;
    }
  const std::string among = top.first == top.second
                                ? "cable '" + ctx.cables[top.first].id + "' with itself"
                                : "cables '" + ctx.cables[top.first].id + "' and '" + ctx.cables[top.second].id + "'";
  throw CableLimitError(ctx.cables[top.first].id,
                        "more than " + full_precision(static_cast<double>(ctx.req.limits.max_pair_contacts)) +
                            " pairs of " + what + " are in contact (" + among + " the most of them): " + kFoldBack);
}

}  // namespace loom::audit
