#include "index/brute_force_index.hpp"

#include "core/error.hpp"
#include "index/triangle_distance.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace loom {

namespace {

/// Ulps of the largest coordinate that the double closest-point kernel may be off by.
constexpr double kRoundingUlps = 16.0;

void check_part(int part, std::size_t n) {
  if (part < 0 || static_cast<std::size_t>(part) >= n)
    throw std::out_of_range("obstacle index: part id " + std::to_string(part) + " out of range [0, " +
                            std::to_string(n) + ")");
}

/// Unit direction of dir; throws std::invalid_argument for a zero or non-finite vector.
Vec3 unit_direction(const Vec3& dir) {
  const double n = dir.norm();
  if (!(n > 0.0) || !std::isfinite(n)) throw std::invalid_argument("obstacle index: ray direction is zero or not finite");
  return dir / n;
}

}  // namespace

std::vector<PartTriangles> extract_part_triangles(const std::vector<Part>& parts) {
  std::vector<PartTriangles> out(parts.size());
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const Mesh& m = parts[i].mesh;
    out[i].closed = parts[i].closed;
    out[i].triangles.reserve(m.triangle_count());
    for (std::size_t t = 0; t < m.triangle_count(); ++t) {
      const auto c = m.corners(t);
      out[i].triangles.push_back(c);
      for (const Vec3& v : c) out[i].bounds.extend(v);
    }
  }
  return out;
}

double winding_number(const PartTriangles& part, const Vec3& p) {
  return triangles_winding_number(p, part.triangles.size(), [&](std::size_t t) { return part.triangles[t]; });
}

BruteForceIndex::BruteForceIndex(const std::vector<Part>& parts) : parts_(extract_part_triangles(parts)) {}

IndexAccuracy BruteForceIndex::accuracy() const {
  IndexAccuracy a;
  a.exact = true;
  double extent = 0.0;
  for (const auto& p : parts_)
    if (!p.bounds.empty()) extent = std::max(extent, p.bounds.min.cwiseAbs().cwiseMax(p.bounds.max.cwiseAbs()).maxCoeff());
  // Double rounding in the closest-point kernel: a few ulps of the largest coordinate.
  a.abs_error = kRoundingUlps * std::numeric_limits<double>::epsilon() * extent;
  a.description = "brute force over every triangle, double precision: <= " + full_precision(a.abs_error) +
                  " scene units";
  return a;
}

void BruteForceIndex::scan_part(int part, const Vec3& p, ClosestHit& best) const {
  const PartTriangles& pt = parts_[part];
  // No bounding-box culling: this is the O(n) baseline of the seed's brute force.
  double cur2 = best.distance * best.distance;
  for (std::size_t t = 0; t < pt.triangles.size(); ++t) {
    const auto& c = pt.triangles[t];
    const TrianglePointResult r = closest_point_on_triangle(p, c[0], c[1], c[2]);
    if (r.dist2 <= cur2) {
      if (r.dist2 == cur2 && best.part >= 0) continue;  // keep the first of equals
      cur2 = r.dist2;
      best.distance = std::sqrt(r.dist2);
      best.point = r.point;
      best.part = part;
      best.triangle = static_cast<std::int64_t>(t);
    }
  }
}

ClosestHit BruteForceIndex::closest(const Vec3& p, double max_radius) const {
  ClosestHit best;
  best.distance = max_radius;
  for (int i = 0; i < part_count(); ++i) scan_part(i, p, best);
  if (!best.found()) best.distance = std::numeric_limits<double>::infinity();
  return best;
}

ClosestHit BruteForceIndex::closest_on_part(const Vec3& p, int part, double max_radius) const {
  check_part(part, parts_.size());
  ClosestHit best;
  best.distance = max_radius;
  scan_part(part, p, best);
  if (!best.found()) best.distance = std::numeric_limits<double>::infinity();
  return best;
}

double BruteForceIndex::part_winding_number(int part, const Vec3& p) const {
  check_part(part, parts_.size());
  return winding_number(parts_[part], p);
}

double surface_rounding(const AABB& bounds) {
  if (bounds.empty()) return 0.0;
  const double extent = bounds.min.cwiseAbs().cwiseMax(bounds.max.cwiseAbs()).maxCoeff();
  return kRoundingUlps * std::numeric_limits<double>::epsilon() * extent;
}

void parts_holding(const std::vector<PartTriangles>& parts, const Vec3& p, bool first_only, std::vector<int>& out) {
  out.clear();
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const PartTriangles& pt = parts[i];
    if (!pt.closed || pt.triangles.empty() || !pt.bounds.contains(p)) continue;
    if (winding_number(pt, p) > 0.5) {
      const double on = surface_rounding(pt.bounds);
      const bool on_surface = std::any_of(pt.triangles.begin(), pt.triangles.end(), [&](const auto& c) {
        return closest_point_on_triangle(p, c[0], c[1], c[2]).dist2 <= on * on;
      });
      if (on_surface) continue;
      out.push_back(static_cast<int>(i));
      if (first_only) return;
    }
  }
}

bool BruteForceIndex::inside(const Vec3& p, int* part) const {
  std::vector<int> held;
  parts_holding(parts_, p, true, held);
  if (held.empty()) return false;
  if (part) *part = held.front();
  return true;
}

void BruteForceIndex::inside_parts(const Vec3& p, std::vector<int>& out) const { parts_holding(parts_, p, false, out); }

RayHit BruteForceIndex::ray(const Vec3& origin, const Vec3& dir, double t_max) const {
  const Vec3 u = unit_direction(dir);
  RayHit best;
  best.t = t_max;
  for (int i = 0; i < part_count(); ++i) {
    const PartTriangles& pt = parts_[i];
    for (std::size_t t = 0; t < pt.triangles.size(); ++t) {
      const auto& c = pt.triangles[t];
      const RayTriangleResult r = intersect_ray_triangle(origin, u, c[0], c[1], c[2]);
      if (r.hit && r.t <= best.t && !(r.t == best.t && best.part >= 0)) {
        best.t = r.t;
        best.part = i;
        best.triangle = static_cast<std::int64_t>(t);
        best.normal = (c[1] - c[0]).cross(c[2] - c[0]).normalized();
      }
    }
  }
  if (!best.found()) best.t = std::numeric_limits<double>::infinity();
  return best;
}

bool BruteForceIndex::any_within(const Vec3& p, double r) const {
  if (!(r >= 0.0)) return false;
  const double r2 = r * r;
  for (const PartTriangles& pt : parts_) {
    for (const auto& c : pt.triangles)
      if (closest_point_on_triangle(p, c[0], c[1], c[2]).dist2 <= r2) return true;
  }
  return false;
}

bool BruteForceIndex::segment_within(const Vec3& a, const Vec3& b, double r) const {
  if (!(r >= 0.0)) return false;
  const double r2 = r * r;
  for (const PartTriangles& pt : parts_) {
    for (const auto& c : pt.triangles)
      if (closest_segment_triangle(a, b, c[0], c[1], c[2]).dist2 <= r2) return true;
  }
  return false;
}

ClosestHit BruteForceIndex::segment_closest(const Vec3& a, const Vec3& b, double max_radius,
                                            double* segment_param) const {
  return segment_scan(a, b, -1, max_radius, segment_param);
}

ClosestHit BruteForceIndex::segment_closest_on_part(const Vec3& a, const Vec3& b, int part, double max_radius,
                                                    double* segment_param) const {
  check_part(part, parts_.size());
  return segment_scan(a, b, part, max_radius, segment_param);
}

ClosestHit BruteForceIndex::segment_scan(const Vec3& a, const Vec3& b, int only_part, double max_radius,
                                         double* segment_param) const {
  ClosestHit best;
  double best2 = max_radius * max_radius;
  double best_s = 0.0;
  const int first = only_part >= 0 ? only_part : 0, last = only_part >= 0 ? only_part + 1 : part_count();
  for (int i = first; i < last; ++i) {
    const PartTriangles& pt = parts_[i];
    for (std::size_t t = 0; t < pt.triangles.size(); ++t) {
      const auto& c = pt.triangles[t];
      const SegmentTriangleResult r = closest_segment_triangle(a, b, c[0], c[1], c[2]);
      if (r.dist2 < best2 || (r.dist2 == best2 && best.part < 0)) {
        best2 = r.dist2;
        best.point = r.triangle_point;
        best.part = i;
        best.triangle = static_cast<std::int64_t>(t);
        best_s = r.s;
      }
    }
  }
  if (best.found()) {
    best.distance = std::sqrt(best2);
    if (segment_param) *segment_param = best_s;
  }
  return best;
}

}  // namespace loom
