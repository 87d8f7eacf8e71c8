// k-d split of a sharded audit's work into regions (shard_plan.hpp).
#include "routing/audit/shard_plan.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>

namespace loom {

namespace {

/// Something to place: a point, its work, and the part it is (−1 for a cable chord).
struct Item {
  Vec3 at;
  double work = 0.0;
  int part = -1;
};

/// Assigns items[first, last) to regions [region0, region0 + k) inside `box`.
void bisect(std::vector<Item>& items, std::size_t first, std::size_t last, int region0, int k, const AABB& box,
            ShardPlan& plan, std::vector<int>& region_of_item) {
  if (k == 1 || last - first < 2) {
    // One region, or nothing left to divide: the others of this branch stay empty.
    for (std::size_t i = first; i < last; ++i) region_of_item[i] = region0;
    plan.regions[static_cast<std::size_t>(region0)] = box;
    for (int r = 1; r < k; ++r) {
      AABB none;  // an empty region owns nothing
      plan.regions[static_cast<std::size_t>(region0 + r)] = none;
    }
    return;
  }
  AABB spread;
  for (std::size_t i = first; i < last; ++i) spread.extend(items[i].at);
  int axis = 0;
  spread.size().maxCoeff(&axis);
  // Ties in the coordinate keep the input order: the plan is the same on every rank.
  std::stable_sort(items.begin() + static_cast<std::ptrdiff_t>(first), items.begin() + static_cast<std::ptrdiff_t>(last),
                   [axis](const Item& a, const Item& b) { return a.at[axis] < b.at[axis]; });
  const int k_low = k / 2;
  double total = 0.0;
  for (std::size_t i = first; i < last; ++i) total += items[i].work;
  const double want = total * k_low / k;
  // The cut after the item whose running sum comes nearest the low side's share, keeping
  // at least one item on each side.
  std::size_t cut = first + 1;
  double run = items[first].work, best = std::abs(run - want);
  for (std::size_t i = first + 1; i + 1 < last; ++i) {
    const double next = run + items[i].work;
    if (std::abs(next - want) < best) best = std::abs(next - want), cut = i + 1;
    run = next;
  }
  const double plane = 0.5 * (items[cut - 1].at[axis] + items[cut].at[axis]);
  AABB low = box, high = box;
  low.max[axis] = plane;
  high.min[axis] = plane;
  bisect(items, first, cut, region0, k_low, low, plan, region_of_item);
  bisect(items, cut, last, region0 + k_low, k - k_low, high, plan, region_of_item);
}

}  // namespace

std::vector<std::vector<Vec3>> cable_polylines(const std::vector<CableInput>& cables, int chords) {
  std::vector<std::vector<Vec3>> out;
  for (const CableInput& c : cables) {
    auto& line = out.emplace_back();
    const double u0 = c.curve.u_min(), du = c.curve.u_max() - u0;
    for (int i = 0; i <= chords; ++i) line.push_back(c.curve.position(u0 + du * i / chords));
  }
  return out;
}

ShardPlan plan_shards(const std::vector<ShardPartBox>& parts, const std::vector<std::vector<Vec3>>& cables,
                      int regions) {
  if (regions < 1) throw std::invalid_argument("plan_shards: " + std::to_string(regions) + " regions");
  double triangles = 0.0, length = 0.0;
  for (const ShardPartBox& p : parts) triangles += static_cast<double>(p.triangles);
  for (const auto& c : cables)
    for (std::size_t i = 0; i + 1 < c.size(); ++i) length += (c[i + 1] - c[i]).norm();
  // Half the work each, or all of it where the other is absent.
  const double tri_share = length > 0.0 ? (triangles > 0.0 ? 0.5 : 0.0) : 1.0;
  const double len_share = 1.0 - tri_share;
  std::vector<Item> items;
  double pinned_work = 0.0;
  for (std::size_t k = 0; k < parts.size(); ++k) {
    const double w = triangles > 0.0 ? tri_share * static_cast<double>(parts[k].triangles) / triangles : 0.0;
    if (parts[k].pinned) pinned_work += w;
    else items.push_back({parts[k].box.center(), w, static_cast<int>(k)});
  }
  for (const auto& c : cables)
    for (std::size_t i = 0; i + 1 < c.size(); ++i)
      items.push_back({0.5 * (c[i] + c[i + 1]), len_share * (c[i + 1] - c[i]).norm() / length, -1});
  ShardPlan plan;
  plan.owner.assign(parts.size(), 0);
  plan.regions.resize(static_cast<std::size_t>(regions));
  plan.region_work.assign(static_cast<std::size_t>(regions), 0.0);
  plan.region_triangles.assign(static_cast<std::size_t>(regions), 0);
  AABB all;
  for (const Item& it : items) all.extend(it.at);
  std::vector<int> region_of_item(items.size(), 0);
  bisect(items, 0, items.size(), 0, regions, all, plan, region_of_item);
  for (std::size_t i = 0; i < items.size(); ++i) {
    const auto r = static_cast<std::size_t>(region_of_item[i]);
    plan.region_work[r] += items[i].work;
    if (items[i].part >= 0) plan.owner[static_cast<std::size_t>(items[i].part)] = region_of_item[i];
  }
  plan.region_work[0] += pinned_work;
  for (std::size_t k = 0; k < parts.size(); ++k)
    plan.region_triangles[static_cast<std::size_t>(plan.owner[k])] += parts[k].triangles;
  return plan;
}

}  // namespace loom
