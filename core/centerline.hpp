#pragma once
/// The geometry of a cable: a B-spline centerline C(u) in world coordinates, scene units.
/// Cubic and interpolating for routed cables; degree 1 for `interp="polyline"` paths.
/// (Seed: cable-bspline-interpolation-and-fairing; semantics DESIGN §5.)

#include "core/geometry.hpp"

#include <atomic>
#include <cstddef>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
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

namespace detail {
/// A table built on first use, once, also when several threads ask at the same time (a
/// copy takes the table if it is built, else builds its own when asked).
class LazyTable {
 public:
  LazyTable() = default;
  LazyTable(const LazyTable& o) { copy_from(o); }
  LazyTable& operator=(const LazyTable& o) {
    if (this != &o) copy_from(o);
    return *this;
  }
  LazyTable(LazyTable&& o) noexcept { move_from(o); }
  LazyTable& operator=(LazyTable&& o) noexcept {
    if (this != &o) move_from(o);
    return *this;
  }
  /// The table, from build() (returning std::vector<double>) the first time.
  template <class Build>
  const std::vector<double>& get(const Build& build) const {
    if (!ready_.load(std::memory_order_acquire)) {
      const std::lock_guard<std::mutex> lock(mutex_);
      if (!ready_.load(std::memory_order_relaxed)) {
        values_ = build();
        ready_.store(true, std::memory_order_release);
      }
    }
    return values_;
  }
  /// Forgets the table (the next get() builds it again).
  void reset() {
    values_.clear();
    ready_.store(false, std::memory_order_release);
  }

 private:
  void copy_from(const LazyTable& o) {
    const bool ready = o.ready_.load(std::memory_order_acquire);
    values_ = ready ? o.values_ : std::vector<double>{};
    ready_.store(ready, std::memory_order_release);
  }
  void move_from(LazyTable& o) noexcept {
    const bool ready = o.ready_.load(std::memory_order_acquire);
    values_ = ready ? std::move(o.values_) : std::vector<double>{};
    ready_.store(ready, std::memory_order_release);
    o.reset();
  }
  mutable std::vector<double> values_;
  mutable std::atomic<bool> ready_{false};
  mutable std::mutex mutex_;
};
}  // namespace detail

/// A B-spline curve of degree p. Built here its knot vector is clamped; one taken as given
/// may have any non-decreasing knots (the curve lives on [knots[p], knots[n + 1]]).
class Centerline {
 public:
  Centerline() = default;
  /// Takes an existing spline (e.g. read from routed XML). Throws std::invalid_argument if
  /// knots.size() != control_points.size() + degree + 1 or knots decrease.
  Centerline(int degree, std::vector<double> knots, std::vector<Vec3> control_points);

  /// Interpolating cubic through every key point (≥ 2 points, finite). Consecutive
  /// duplicates are merged; throws std::invalid_argument with the reason otherwise.
  /// Parameters run over [0, total chord length] (scene units, so |C'| ≈ 1); a given end
  /// tangent is scaled to that speed. Natural ends have C'' = 0. The tridiagonal system for
  /// the control points is solved with Eigen (dense LU when small, SparseLU otherwise).
  static Centerline interpolate(const std::vector<Vec3>& points, const InterpolationOptions& opt = {});
  /// As above with explicit parameters, one per key point (opt.knots is ignored; consecutive
  /// duplicates take their first point's parameter), increasing across distinct points.
  static Centerline interpolate(const std::vector<Vec3>& points, const std::vector<double>& parameters,
                                const InterpolationOptions& opt);
  /// Degree-1 curve through the points (a polyline exactly as given).
  static Centerline polyline(const std::vector<Vec3>& points);

  int degree() const { return degree_; }
  const std::vector<double>& knots() const { return knots_; }
  const std::vector<Vec3>& control_points() const { return cps_; }
  /// Parameter of each key point it interpolates (empty if built from raw data).
  const std::vector<double>& key_parameters() const { return key_params_; }
  bool empty() const { return cps_.empty(); }
  /// Records the parameters of the key points this curve represents (e.g. after fairing
  /// moved them). Throws std::invalid_argument if one is outside [u_min, u_max] or they decrease.
  void set_key_parameters(std::vector<double> u);

  /// First / last parameter of the curve's domain.
  double u_min() const { return knots_.empty() ? 0.0 : knots_[degree_]; }
  double u_max() const { return knots_.empty() ? 0.0 : knots_[cps_.size()]; }
  /// C(u).
  Vec3 position(double u) const;
  /// k-th derivative C⁽ᵏ⁾(u), k = 0..3.
  Vec3 derivative(double u, int k) const;
  /// Curvature κ(u) = |C'×C''|/|C'|³ (0 where C' = 0 or on straight runs).
  double curvature(double u) const;

  /// Total arc length (Gauss–Legendre per knot span, accurate to ~1e-12 relative). The
  /// per-span lengths behind this and the arc-length functions below are computed on the
  /// first call to any of them (thread-safe), not by the constructor.
  double length() const;
  /// Arc length from u_min() to u.
  double arc_length_at(double u) const;
  /// Inverse of arc_length_at: the u where the arc length from the start is s (clamped).
  double parameter_at_length(double s) const;
  /// Bounds on C over [a, b] (clamped to the domain) from the convex hulls of its pieces'
  /// Bézier points (hull_points), relative to the chord from C(a) to C(b).
  struct HullBounds {
    double deviation = 0.0;  ///< upper bound on the distance of C(u) from the chord, scene units
    /// Upper bound on the sine of the angle between C'(u) and the chord; 1 if C' may vanish
    /// or turn against it (the hodograph's Bézier points, differences of those above).
    double turn_sine = 1.0;
  };
  /// Both bounds of HullBounds, from one pass over the pieces' Bézier points.
  HullBounds hull_bounds(double a, double b) const;
  /// Most points sample_by_arc_length() returns (it throws beyond: ~2.4 GB of samples).
  static constexpr double kMaxArcSamples = 1e8;
  /// Points at equal arc spacing ≤ `spacing`, first and last included; with their s.
  /// Throws std::invalid_argument for a spacing that is not positive and finite, or that
  /// asks for more than kMaxArcSamples points.
  std::vector<std::pair<double, Vec3>> sample_by_arc_length(double spacing) const;
  /// Smallest bend radius and where it occurs (dense search + local refinement); 0 at a
  /// kink (tangent jump at a knot, e.g. polyline corners) or a fold (C' = 0 with the
  /// tangent reversing); infinity for a straight curve.
  BendExtremum min_bend_radius() const;
  /// Every contiguous stretch of the curve bending tighter than `limit` (bend radius <
  /// limit, scene units), each at its tightest point, in order along the curve: a cable
  /// with two tight corners has two. Stretches are told apart by the dense samples of the
  /// search (kBendSamplesPerSpan per knot span): two peaks whose dip above the limit no
  /// sample catches are one stretch, at the tighter. Kinks and folds are stretches of
  /// radius 0. Empty if limit ≤ 0 or nothing bends that tightly.
  std::vector<BendExtremum> bend_stretches_below(double limit) const;

  /// Writes C⁽ᵏ⁾(u) for k = 0..nder (nder ≤ 3) into out[0..nder]; u is clamped to the
  /// domain. With left_limit, at an interior knot the span to the left is used (one-sided
  /// derivatives: tangent kinks, third-derivative jumps).
  void evaluate(double u, int nder, Vec3* out, bool left_limit = false) const;
  /// As evaluate(), for a caller that knows the breakpoint interval: u must lie in
  /// [breakpoints()[k], breakpoints()[k + 1]] (not clamped: outside, the interval's
  /// polynomial is extended). Inside the interval (or at its left end) the result equals
  /// evaluate(u, nder, out) exactly; it skips the interval search. nder ≤ 3. Throws
  /// std::out_of_range if k is not an interval of the curve.
  void evaluate_in_interval(std::size_t k, double u, int nder, Vec3* out) const {
    if (k + 1 >= span_u_.size())
      throw std::out_of_range("Centerline::evaluate_in_interval: no interval " + std::to_string(k));
    evaluate_on_span(static_cast<int>(k), u, nder < 0 ? 0 : (nder > 3 ? 3 : nder), out);
  }
  /// Distinct knot values u_min = v_0 < v_1 < ... < v_K = u_max (span boundaries).
  const std::vector<double>& breakpoints() const { return span_u_; }

 private:
  int degree_ = 3;
  std::vector<double> knots_;
  std::vector<Vec3> cps_;
  std::vector<double> key_params_;
  detail::LazyTable span_len_;    ///< cumulative arc length at each distinct knot (built on first use)
  /// The cumulative arc lengths, built on first use.
  const std::vector<double>& lengths() const;
  std::vector<double> build_lengths() const;
  std::vector<double> span_u_;    ///< the distinct knot values (span boundaries)
  std::vector<int> span_index_;   ///< knot-span index of each non-empty span
  double typical_speed_ = 1.0;    ///< control-polygon length / parameter range
  double scale_length_ = 1.0;     ///< control-polygon length
  void build_length_table();
  /// degree + 1 points per breakpoint interval meeting [a, b] (clamped), in order: the
  /// Bézier points of the curve's piece in it (degree ≤ 3; above, the span's control
  /// points), whose convex hull holds that piece.
  std::vector<Vec3> hull_points(double a, double b) const;
  int find_span(double u) const;
  std::vector<Vec3> poly_;        ///< Taylor coefficients of each piece about its start
  std::size_t piece_of(double u, bool left_limit) const;
  void evaluate_on_span(int piece, double u, int nder, Vec3* out) const;
  double curvature_from(const Vec3& d1, const Vec3& d2) const;
  double locate_fold(double a, double b) const;
  /// One point of the bend search: curvature κ at u (infinity at a kink or fold).
  struct BendPoint {
    double u = 0.0;
    double kappa = 0.0;
    enum Kind { Sample, Peak, Kink, Fold } kind = Sample;
  };
  /// The bend search in u order: every dense sample, the golden-section refinement of each
  /// sampled local maximum, tangent kinks at interior knots and folds.
  std::vector<BendPoint> bend_profile() const;
  double span_length(int span, double a, double b) const;
  double solve_length_in_span(std::size_t k, double u0, double s0, double target) const;
};

/// Nonzero B-spline basis functions of `degree` over `knots` at u and their derivatives:
/// returns the index i0 of the first nonzero function and writes
/// ders[k * (degree + 1) + j] = N⁽ᵏ⁾_{i0+j}(u) for k = 0..nder, j = 0..degree (nder ≤ degree
/// is not required: higher orders are 0). u is clamped to [knots[degree], knots[n+1]] where
/// n + 1 = knots.size() − degree − 1 basis functions exist. Throws std::invalid_argument on
/// an invalid knot vector or degree outside 1..7.
int bspline_basis(const std::vector<double>& knots, int degree, double u, int nder, double* ders);

}  // namespace loom
