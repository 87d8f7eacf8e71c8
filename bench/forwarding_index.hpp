#pragma once
/// An ObstacleIndex that forwards every query to another one: the base of the benchmarks'
/// decorators (timing each method, logging the calls a planner makes), which override only
/// what they observe. The batch methods are not forwarded: ObstacleIndex's own batches call
/// the per-point methods, so a decorator sees each point.

#include "index/obstacle_index.hpp"

namespace loom {

class ForwardingIndex : public ObstacleIndex {
 public:
  /// `inner` must outlive this index.
  explicit ForwardingIndex(const ObstacleIndex& inner) : inner_(inner) {}
  std::string name() const override { return inner_.name(); }
  IndexAccuracy accuracy() const override { return inner_.accuracy(); }
  int part_count() const override { return inner_.part_count(); }
  std::optional<AABB> part_bounds(int part) const override { return inner_.part_bounds(part); }
  ClosestHit closest(const Vec3& p, double r) const override { return inner_.closest(p, r); }
  ClosestHit closest_approx(const Vec3& p, double r, double e) const override { return inner_.closest_approx(p, r, e); }
  ClosestHit closest_on_part(const Vec3& p, int part, double r) const override {
    return inner_.closest_on_part(p, part, r);
  }
  bool inside(const Vec3& p, int* part) const override { return inner_.inside(p, part); }
  void inside_parts(const Vec3& p, std::vector<int>& out) const override { inner_.inside_parts(p, out); }
  RayHit ray(const Vec3& o, const Vec3& d, double t) const override { return inner_.ray(o, d, t); }
  bool any_within(const Vec3& p, double r) const override { return inner_.any_within(p, r); }
  bool segment_within(const Vec3& a, const Vec3& b, double r) const override { return inner_.segment_within(a, b, r); }
  ClosestHit segment_closest(const Vec3& a, const Vec3& b, double r, double* t) const override {
    return inner_.segment_closest(a, b, r, t);
  }
  ClosestHit segment_closest_approx(const Vec3& a, const Vec3& b, double r, double e, double* t) const override {
    return inner_.segment_closest_approx(a, b, r, e, t);
  }
  ClosestHit segment_closest_on_part(const Vec3& a, const Vec3& b, int part, double r, double* t) const override {
    return inner_.segment_closest_on_part(a, b, part, r, t);
  }

 protected:
  const ObstacleIndex& inner_;
};

}  // namespace loom
