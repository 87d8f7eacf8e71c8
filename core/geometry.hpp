#pragma once
/// Basic geometric types shared by every loom module. All coordinates are in scene
/// units (see Scene::units) and in the scene's world frame unless a name says otherwise.

#include "core/error.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace loom {

/// Largest magnitude loom accepts for a coordinate, length or other number read from a
/// scene, harness or route file (scene units): Embree's BVH is single precision and squares
/// distances, and (1e12)² stays far inside float range; 1e12 mm is a million kilometres.
constexpr double kMaxInputMagnitude = 1e12;

/// A point or vector in world coordinates, scene units.
using Vec3 = Eigen::Vector3d;

/// "(x, y, z)" with every coordinate at full precision (17 significant digits): messages
/// that must let a failure be replayed.
inline std::string full_precision(const Vec3& p) {
  return "(" + full_precision(p.x()) + ", " + full_precision(p.y()) + ", " + full_precision(p.z()) + ")";
}

/// Axis-aligned bounding box; empty() until the first point is added.
struct AABB {
  Vec3 min = Vec3::Constant(std::numeric_limits<double>::infinity());
  Vec3 max = Vec3::Constant(-std::numeric_limits<double>::infinity());

  /// True while no point has been added.
  bool empty() const { return !(min.x() <= max.x()); }
  /// Grows the box to contain p.
  void extend(const Vec3& p) {
    min = min.cwiseMin(p);
    max = max.cwiseMax(p);
  }
  /// Grows the box to contain another box.
  void extend(const AABB& b) {
    if (b.empty()) return;
    extend(b.min);
    extend(b.max);
  }
  /// Edge lengths (zero vector when empty).
  Vec3 size() const { return empty() ? Vec3::Zero() : Vec3(max - min); }
  /// Centre point (zero when empty).
  Vec3 center() const { return empty() ? Vec3::Zero() : Vec3(0.5 * (min + max)); }
  /// Length of the diagonal, 0 when empty.
  double diagonal() const { return size().norm(); }
  /// The box grown by r on every side (scene units; r ≥ 0). An empty box stays empty.
  AABB inflated(double r) const {
    AABB b = *this;
    b.min.array() -= r;
    b.max.array() += r;
    return b;
  }
  /// True if p lies in the closed box.
  bool contains(const Vec3& p) const {
    return (p.array() >= min.array()).all() && (p.array() <= max.array()).all();
  }
};

/// True if every component is finite (no NaN, no inf).
inline bool is_finite(const Vec3& v) { return v.allFinite(); }

/// The unit vector along d (finite, not zero): d itself when its length is 1 within
/// rounding, so that a direction written at full precision reads back bit for bit (one
/// normalised again moves in its last bits); else d scaled by its largest component first
/// (the squared length of (1e-200, 0, 0) underflows) and normalised.
inline Vec3 stable_unit_direction(const Vec3& d) {
  if (std::abs(d.norm() - 1.0) <= 8.0 * std::numeric_limits<double>::epsilon()) return d;
  return (d / d.cwiseAbs().maxCoeff()).normalized();
}

/// Squared distance from p to the closed segment ab (scene units²; a point if a == b).
inline double point_segment_dist2(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 0.0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return (a + t * ab - p).squaredNorm();
}

}  // namespace loom
