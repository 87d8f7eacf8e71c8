#pragma once
/// Where the parts of a sharded audit go (docs/audit.md "Sharding"): a k-d split of space
/// into K regions of about equal work, and each part owned by the region holding its box's
/// centre. The work is half the triangles (loading and indexing them, the memory) and half
/// the cable length (the checks, which step along the cables and slow down near parts):
/// each part counts its share of the triangles, each cable chord its share of the length.
/// Deterministic: every rank computes the same plan from the same input.

#include "core/geometry.hpp"
#include "routing/audit/clash_check.hpp"

#include <cstddef>
#include <vector>

namespace loom {

/// A part as the plan sees it: its world-frame box (scene units) and triangle count.
struct ShardPartBox {
  AABB box;
  std::size_t triangles = 0;
  bool pinned = false;  ///< owned by region 0 whatever its place (moving parts: see audit_shard.hpp)
};

/// The outcome of plan_shards().
struct ShardPlan {
  std::vector<int> owner;            ///< region (rank) of each part
  std::vector<AABB> regions;         ///< the K boxes of the split (they tile the items' box)
  std::vector<double> region_work;   ///< each region's share of the work (sums to 1)
  std::vector<std::size_t> region_triangles;  ///< triangles each region owns
};

/// Each cable's centreline as a polyline of `chords` + 1 points evenly spaced in its
/// parameter: the cable length plan_shards weighs (a plan needs no finer).
std::vector<std::vector<Vec3>> cable_polylines(const std::vector<CableInput>& cables, int chords = 64);

/// Splits the parts and the cable chords (`cables`: polylines, world frame) into `regions`
/// ≥ 1 regions by recursive bisection across the widest extent, at the weighted median
/// that gives each side work in proportion to its number of regions.
ShardPlan plan_shards(const std::vector<ShardPartBox>& parts, const std::vector<std::vector<Vec3>>& cables,
                      int regions);

}  // namespace loom
