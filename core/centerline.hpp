#pragma once
/// The geometry of a cable: a B-spline centerline C(u) in world coordinates, scene units.
/// Cubic and interpolating for routed cables; degree 1 for `interp="polyline"` paths.
/// (Seed: cable-bspline-interpolation-and-fairing; semantics DESIGN §5.)

#include "core/geometry.hpp"

#include <optional>
#include <vector>

namespace loom {

/// How interpolation parameters (knots) are assigned to key points.
enum class KnotMethod {
  ChordLength,  ///< parameters proportional to cumulative chord length
  HartleyJudd,  ///< Hartley–Judd knots (seed eq. 1–2)
};

/// End conditions of an interpolating cubic.
struct InterpolationOptions {
  KnotMethod knots = KnotMethod::ChordLength;
  /// Unit tangent at the first / last key point (a cable leaves its connector along the
  /// port's exit direction). Absent = natural end condition (C'' = 0).
  std::optional<Vec3> start_tangent;
  std::optional<Vec3> end_tangent;
};

/// Where a centerline bends most tightly.
struct BendExtremum {
  double radius = 0.0;  ///< smallest 1/κ found (infinity for a straight line)
  double u = 0.0;       ///< curve parameter where it occurs
  double s = 0.0;       ///< arc length from the start where it occurs
};

/// A B-spline curve of degree p with a clamped knot vector.
class Centerline {
 public:
  Centerline() = default;
  /// Takes an existing spline (e.g. read from routed XML). Throws std::invalid_argument if
  /// knots.size() != control_points.size() + degree + 1 or knots decrease.
  Centerline(int degree, std::vector<double> knots, std::vector<Vec3> control_points);

  /// Interpolating cubic through every key point (≥ 2 points, finite). Consecutive
  /// duplicates are merged; throws std::invalid_argument with the reason otherwise.
  static Centerline interpolate(const std::vector<Vec3>& points, const InterpolationOptions& opt = {});
  /// Degree-1 curve through the points (a polyline exactly as given).
  static Centerline polyline(const std::vector<Vec3>& points);

  int degree() const { return degree_; }
  const std::vector<double>& knots() const { return knots_; }
  const std::vector<Vec3>& control_points() const { return cps_; }
  /// Parameter of each key point it interpolates (empty if built from raw data).
  const std::vector<double>& key_parameters() const { return key_params_; }
  bool empty() const { return cps_.empty(); }

  double u_min() const;
  double u_max() const;
  /// C(u).
  Vec3 position(double u) const;
  /// k-th derivative C⁽ᵏ⁾(u), k = 0..3.
  Vec3 derivative(double u, int k) const;
  /// Curvature κ(u) = |C'×C''|/|C'|³ (0 where C' = 0 or on straight runs).
  double curvature(double u) const;

  /// Total arc length (Gauss–Legendre per knot span, accurate to ~1e-12 relative).
  double length() const;
  /// Arc length from u_min() to u.
  double arc_length_at(double u) const;
  /// Inverse of arc_length_at: the u where the arc length from the start is s (clamped).
  double parameter_at_length(double s) const;
  /// Points at equal arc spacing ≤ `spacing`, first and last included; with their s.
  std::vector<std::pair<double, Vec3>> sample_by_arc_length(double spacing) const;
  /// Smallest bend radius and where it occurs (dense search + local refinement).
  BendExtremum min_bend_radius() const;

 private:
  int degree_ = 3;
  std::vector<double> knots_;
  std::vector<Vec3> cps_;
  std::vector<double> key_params_;
  std::vector<double> span_len_;  ///< cumulative arc length at each distinct knot
  void build_length_table();
  int find_span(double u) const;
};

}  // namespace loom
