#include "routing/route/bundle_obstacles.hpp"

#include "index/triangle_distance.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace loom {

namespace {

/// Capsules per leaf of the hierarchy.
constexpr int kLeafSize = 4;

/// Squared distance between two boxes (0 when they overlap).
double box_gap2(const AABB& x, const AABB& y) {
  double d2 = 0.0;
  for (int k = 0; k < 3; ++k) {
    const double gap = std::max({0.0, x.min[k] - y.max[k], y.min[k] - x.max[k]});
    d2 += gap * gap;
  }
  return d2;
}

/// Where the line a + t(b − a) enters and leaves the ball (centre c, radius r), as
/// parameters t0 ≤ t1; false if it misses the ball or a == b.
bool ball_interval(const Vec3& a, const Vec3& b, const Vec3& c, double r, double& t0, double& t1) {
  const Vec3 d = b - a, f = a - c;
  const double A = d.squaredNorm();
  if (!(A > 0.0)) return false;
  const double B = f.dot(d), C = f.squaredNorm() - r * r;
  const double disc = B * B - A * C;
  if (disc <= 0.0) return false;
  const double s = std::sqrt(disc);
  t0 = (-B - s) / A;
  t1 = (-B + s) / A;
  return true;
}

double polyline_length(const std::vector<Vec3>& p) {
  double len = 0.0;
  for (std::size_t i = 1; i < p.size(); ++i) len += (p[i] - p[i - 1]).norm();
  return len;
}

}  // namespace

std::vector<std::vector<Vec3>> clip_near_node(const std::vector<Vec3>& points, const Vec3& node, double reach,
                                              double min_length) {
  std::vector<std::vector<Vec3>> runs;
  std::vector<Vec3> cur;
  auto close_run = [&] {
    if (cur.size() >= 2 && polyline_length(cur) >= min_length) runs.push_back(cur);
    cur.clear();
  };
  auto outside = [&](const Vec3& p) { return (p - node).norm() >= reach; };
  for (std::size_t i = 0; i + 1 < points.size(); ++i) {
    const Vec3 a = points[i], b = points[i + 1];
    double t0 = 0.0, t1 = 0.0;
    const bool hits = reach > 0.0 && ball_interval(a, b, node, reach, t0, t1) && t1 > 0.0 && t0 < 1.0;
    if (!hits) {
      if (!outside(a)) continue;  // a degenerate piece inside the ball
      if (cur.empty()) cur.push_back(a);
      cur.push_back(b);
      continue;
    }
    // The piece crosses the ball over [max(t0,0), min(t1,1)]: keep what lies before and after.
    if (t0 > 0.0) {
      if (cur.empty()) cur.push_back(a);
      cur.push_back(a + t0 * (b - a));
    }
    close_run();
    if (t1 < 1.0) {
      cur.push_back(a + t1 * (b - a));
      cur.push_back(b);
    }
  }
  close_run();
  return runs;
}

HarnessAwareIndex::HarnessAwareIndex(const ObstacleIndex& parts, const std::vector<BundleTube>& tubes)
    : parts_(parts) {
  for (const BundleTube& t : tubes) {
    if (t.points.size() < 2) continue;
    const int k = static_cast<int>(tube_segment_.size());
    tube_segment_.push_back(t.segment);
    for (std::size_t i = 0; i + 1 < t.points.size(); ++i)
      caps_.push_back({t.points[i], t.points[i + 1], std::max(0.0, t.radius), k});
  }
  if (!caps_.empty()) build(0, static_cast<int>(caps_.size()));
}

int HarnessAwareIndex::build(int first, int count) {
  const int id = static_cast<int>(nodes_.size());
  nodes_.emplace_back();
  AABB box, centres;
  for (int i = first; i < first + count; ++i) {
    const Capsule& c = caps_[static_cast<std::size_t>(i)];
    AABB cb;
    cb.extend(c.a);
    cb.extend(c.b);
    box.extend(cb.inflated(c.radius));
    centres.extend(0.5 * (c.a + c.b));
  }
  nodes_[static_cast<std::size_t>(id)].box = box;
  if (count <= kLeafSize) {
    nodes_[static_cast<std::size_t>(id)].first = first;
    nodes_[static_cast<std::size_t>(id)].count = count;
    return id;
  }
  int axis = 0;
  centres.size().maxCoeff(&axis);
  const auto begin = caps_.begin() + first;
  std::nth_element(begin, begin + count / 2, begin + count, [axis](const Capsule& x, const Capsule& y) {
    return (x.a[axis] + x.b[axis]) < (y.a[axis] + y.b[axis]);
  });
  const int left = build(first, count / 2);
  const int right = build(first + count / 2, count - count / 2);
  nodes_[static_cast<std::size_t>(id)].left = left;
  nodes_[static_cast<std::size_t>(id)].right = right;
  return id;
}

int HarnessAwareIndex::bundle_segment(int part) const {
  const int k = part - parts_.part_count();
  if (k < 0 || k >= static_cast<int>(tube_segment_.size())) return -1;
  return tube_segment_[static_cast<std::size_t>(k)];
}

ClosestHit HarnessAwareIndex::nearest_capsule(const Vec3& a, const Vec3& b, double max_radius, int only_tube,
                                              double* param) const {
  ClosestHit best;
  if (nodes_.empty()) return best;
  double limit = max_radius;
  AABB q;
  q.extend(a);
  q.extend(b);
  std::vector<int> stack{0};
  while (!stack.empty()) {
    const Node& n = nodes_[static_cast<std::size_t>(stack.back())];
    stack.pop_back();
    // Boxes are inflated by the radii: a capsule surface within `limit` of ab lies in a node
    // whose box comes within `limit` of ab's box.
    if (std::isfinite(limit) && box_gap2(n.box, q) > limit * limit) continue;
    if (n.left >= 0) {
      stack.push_back(n.left);
      stack.push_back(n.right);
      continue;
    }
    for (int i = n.first; i < n.first + n.count; ++i) {
      const Capsule& c = caps_[static_cast<std::size_t>(i)];
      if (only_tube >= 0 && c.tube != only_tube) continue;
      const SegmentSegmentResult r = closest_segment_segment(a, b, c.a, c.b);
      const double centre = std::sqrt(r.dist2);
      const double d = std::max(0.0, centre - c.radius);
      if (d > limit || (best.found() && d >= best.distance)) continue;
      best.distance = d;
      best.point = centre > 0.0 ? Vec3(r.q + (c.radius / centre) * (r.p - r.q)) : r.q;
      best.part = parts_.part_count() + c.tube;
      best.triangle = -1;
      limit = d;
      if (param) *param = r.s;
    }
  }
  return best;
}

std::optional<AABB> HarnessAwareIndex::part_bounds(int part) const {
  if (part < parts_.part_count()) return parts_.part_bounds(part);
  const int k = part - parts_.part_count();
  if (k >= static_cast<int>(tube_segment_.size())) throw std::out_of_range("HarnessAwareIndex: bad part id");
  AABB box;
  for (const Capsule& c : caps_)
    if (c.tube == k) {
      AABB cb;
      cb.extend(c.a);
      cb.extend(c.b);
      box.extend(cb.inflated(c.radius));
    }
  return box;
}

ClosestHit HarnessAwareIndex::closest(const Vec3& p, double max_radius) const {
  ClosestHit hit = parts_.closest(p, max_radius);
  const ClosestHit cap = nearest_capsule(p, p, hit.found() ? hit.distance : max_radius, -1, nullptr);
  return cap.found() && (!hit.found() || cap.distance < hit.distance) ? cap : hit;
}

ClosestHit HarnessAwareIndex::closest_on_part(const Vec3& p, int part, double max_radius) const {
  if (part < parts_.part_count()) return parts_.closest_on_part(p, part, max_radius);
  return nearest_capsule(p, p, max_radius, part - parts_.part_count(), nullptr);
}

bool HarnessAwareIndex::any_within(const Vec3& p, double r) const {
  return parts_.any_within(p, r) || nearest_capsule(p, p, r, -1, nullptr).found();
}

double HarnessAwareIndex::distance_lower_bound(const Vec3& p) const {
  const double parts = parts_.distance_lower_bound(p);
  if (!(parts > 0.0)) return parts;
  const ClosestHit cap = nearest_capsule(p, p, parts, -1, nullptr);
  return cap.found() ? cap.distance : parts;
}

bool HarnessAwareIndex::segment_within(const Vec3& a, const Vec3& b, double r) const {
  return parts_.segment_within(a, b, r) || nearest_capsule(a, b, r, -1, nullptr).found();
}

ClosestHit HarnessAwareIndex::segment_closest(const Vec3& a, const Vec3& b, double max_radius,
                                              double* segment_param) const {
  double t_part = 0.0, t_cap = 0.0;
  const ClosestHit hit = parts_.segment_closest(a, b, max_radius, &t_part);
  const ClosestHit cap = nearest_capsule(a, b, hit.found() ? hit.distance : max_radius, -1, &t_cap);
  const bool use_cap = cap.found() && (!hit.found() || cap.distance < hit.distance);
  if (segment_param) *segment_param = use_cap ? t_cap : t_part;
  return use_cap ? cap : hit;
}

ClosestHit HarnessAwareIndex::segment_closest_on_part(const Vec3& a, const Vec3& b, int part, double max_radius,
                                                      double* segment_param) const {
  if (part < parts_.part_count()) return parts_.segment_closest_on_part(a, b, part, max_radius, segment_param);
  if (part - parts_.part_count() >= static_cast<int>(tube_segment_.size()))
    throw std::out_of_range("HarnessAwareIndex: bad part id");
  return nearest_capsule(a, b, max_radius, part - parts_.part_count(), segment_param);
}

}  // namespace loom
