// Sphere-moving sweep (seed: cable-scan-centerline-and-sphere-sweep §4, eqs. 7–9): each
// ring is the circle where the moving sphere S(s) of radius r(s) touches its envelope,
// centre M = C − r·r'·T and radius R = r·√(1 − r'²) (r' = dr/ds, T the unit tangent).
// The ring's in-plane axes come from a rotation-minimising frame (double reflection, Wang
// et al. 2008), not from the seed's Frenet frame (undefined on straight runs, flips at
// inflections).
#include "routing/curve/sweep.hpp"

#include "core/error.hpp"
#include "routing/curve/cable_limit.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

namespace loom {

namespace {

/// Share of the chord tolerance given to the spacing of the rings along the tube: the
/// outer-fibre sagitta between neighbouring rings stays within it.
constexpr double kAxialShare = 0.5;
/// Share given to the ring polygons (sagitta across the tube). Odd rings are rotated by
/// half a vertex step, so the facets are near-equilateral triangles rather than halves of
/// quads. Locally the tube is the quadratic ½(x²/r + b·y²) (x across, y along, |b| ≤ the
/// outer fibre's κ(1 + rκ) per unit centerline length); scaled to isotropy (X = x/√r,
/// Y = y·√b) a facet is an isosceles triangle of base H (ring sagitta H²/8 = s_c) and
/// height K (axial sagitta K²/8 = s_a), and linear interpolation of ½|P|² on it errs by at
/// most ρ²/2, ρ its circumradius (K ≥ H/2), or H²/8 (obtuse, K < H/2). With s_a ≤ ½·tol,
/// s_c ≤ ¾·tol: ρ = (K² + H²/4)/(2K) ≤ 1.375·√tol, error ≤ 0.945·tol. The aligned quad
/// layout errs by s_a + s_c and needed s_c ≤ ½·tol: this share needs √(½/¾) ≈ 0.82 times
/// the vertices per ring at the same rings and tolerance.
constexpr double kRingPolygonShare = 0.75;
/// Fewest vertices per ring (a triangle) and most (beyond this the tolerance is absurd for
/// the radius).
constexpr int kMinCircumferential = 3;
constexpr int kMaxCircumferential = 1 << 16;
/// Most rings a sweep may produce before it reports the tolerance as unreasonable.
constexpr std::size_t kMaxRings = 1u << 22;
/// A step never exceeds this fraction of its knot span, so that curvature sampled at the
/// step's ends and middle sees every feature of the (cubic) span.
constexpr double kMaxSpanFraction = 0.25;
/// Knot intervals shorter than this many tube radii may be crossed several at a time (see
/// the hull jump in sections()).
constexpr double kShortIntervalRadii = 1.0;
/// Attempts to shrink one step until the curvature inside it is consistent with its length.
constexpr int kStepShrinkIterations = 4;
/// Newton iterations of the step prediction (from above: each brings it closer to the step
/// the extrapolated curvature allows).
constexpr int kStepGuessNewtonIterations = 2;
/// The predicted step is shortened by this fraction, so that the curvature's second-order
/// change over a step (which the linear prediction leaves out) rarely makes the march retry.
constexpr double kStepGuessMargin = 0.01;
/// Smallest step as a fraction of the parameter range (a cusp's unbounded curvature must
/// not stall the march; the ring limit below reports absurd tolerances instead).
constexpr double kMinStepRel = 1e-9;
/// |C'| below this fraction of the average speed: the tangent is taken from C'' instead.
constexpr double kStationaryRelSpeed = 1e-12;


/// C, C', C'', C''' at one parameter with |C'| and the curvature, each computed once
/// (C''' only where a step may start: the march leaves it unset at a step's middle).
struct Sample {
  Vec3 d[4];
  Vec3 bend;           ///< C' × C'' (|bend| = κ|C'|³)
  double speed = 0.0;  ///< |C'|
  double kappa = 0.0;  ///< curvature (0 where |C'| ≤ the stationary threshold)
  /// Fills bend, speed and kappa from d.
  void finish(double min_speed) {
    speed = d[1].norm();
    bend = d[1].cross(d[2]);
    kappa = speed > min_speed ? bend.norm() / (speed * speed * speed) : 0.0;
  }
  /// Unit tangent from the first (or, at a stationary point, second) derivative.
  Vec3 tangent(double min_speed, const Vec3& fallback) const {
    if (speed > min_speed) return d[1] / speed;
    const double a = d[2].norm();
    if (a > 0.0) return d[2] / a;
    return fallback;
  }
};

/// Largest axial step Δs whose outer-fibre sagitta κ(1 + rκ)Δs²/8 stays within tol.
double axial_step(double kappa, double r, double tol) {
  const double k = kappa * (1.0 + r * kappa);
  if (!(k > 0.0)) return std::numeric_limits<double>::infinity();
  return std::sqrt(8.0 * tol / k);
}

/// Parameter step from the sample `d` (with C''') whose outer-fibre sagitta is predicted to
/// stay within tol, at most du_max. The march accepts a step when κ(1 + rκ)·(|C'|Δu)²/8 ≤ tol
/// with κ and |C'| the largest of their values at the step's start, middle and end; here
/// both are extrapolated linearly from their derivatives at the start (only increases
/// count, as in that maximum): κ' = (a·a')/(|a||C'|³) − 3κ|C'|'/|C'| with a = C'×C'',
/// a' = C'×C''', and |C'|' = C'·C''/|C'|. F(Δu) = Δu²·v(Δu)²·k(Δu) is then a polynomial with
/// non-negative coefficients (increasing, convex), so Newton from the constant-curvature
/// step (too long) approaches its root F = 8·tol from above; the result is shortened by
/// kStepGuessMargin for the second-order terms the extrapolation leaves out.
double predicted_step(const Sample& d, double r, double tol, double du_max, double min_speed) {
  const double v0 = d.speed;
  if (!(v0 > min_speed)) return du_max;  // stationary point: no direction to extrapolate
  const double dv = std::max(0.0, d.d[1].dot(d.d[2]) / v0);
  const double v3 = v0 * v0 * v0;
  const double bend_norm = d.kappa * v3;
  const Vec3 bend_rate = d.d[1].cross(d.d[3]);
  const double dk = std::max(0.0, bend_norm > 0.0 ? d.bend.dot(bend_rate) / (bend_norm * v3) - 3.0 * d.kappa * dv / v0
                                                  : bend_rate.norm() / v3);
  const double target = 8.0 * tol;
  // F and dF/dΔu at du, with k(κ) = κ(1 + rκ), dk/dκ = 1 + 2rκ.
  auto F = [&](double du, double& slope) {
    const double v = v0 + dv * du, kap = d.kappa + dk * du;
    const double k = kap * (1.0 + r * kap);
    slope = 2.0 * du * v * v * k + 2.0 * du * du * v * dv * k + du * du * v * v * dk * (1.0 + 2.0 * r * kap);
    return du * du * v * v * k;
  };
  double du = std::min(axial_step(d.kappa, r, tol) / v0, du_max);
  double slope = 0.0;
  double f = F(du, slope);
  if (f <= target) return du;  // even the extrapolated curvature allows the longest step
  for (int it = 0; it < kStepGuessNewtonIterations && slope > 0.0; ++it) {
    du -= (f - target) / slope;
    f = F(du, slope);
  }
  return (1.0 - kStepGuessMargin) * du;
}

/// Any unit vector perpendicular to unit t.
Vec3 any_perpendicular(const Vec3& t) {
  const Vec3 a = std::abs(t.x()) <= std::abs(t.y()) && std::abs(t.x()) <= std::abs(t.z()) ? Vec3::UnitX()
                 : std::abs(t.y()) <= std::abs(t.z())                                      ? Vec3::UnitY()
                                                                                           : Vec3::UnitZ();
  return (a - a.dot(t) * t).normalized();
}

/// Rotation angle θ ∈ [0, π] between two frames as the pair (sin θ, cos θ), both scaled by
/// the same positive factor (atan2 of it is θ; comparing two needs no atan2).
struct TurnAngle {
  double sin = 0.0;
  double cos = 1.0;
  /// True if this angle exceeds `o` (sin(θ − θo) > 0 for θ, θo ∈ [0, π]).
  bool exceeds(const TurnAngle& o) const { return sin * o.cos - cos * o.sin > 0.0; }
  /// The angle in radians.
  double radians() const { return std::atan2(sin, cos); }
};

/// Rotation taking the orthonormal frame (t0, b0, t0×b0) to (t1, b1, t1×b1): with
/// R = Σ f1 f0ᵀ, sin θ = |axial(R)| / 2 and cos θ = (tr R − 1) / 2 (stable near 0 and π),
/// where axial(R) = Σ f0 × f1 and tr R = Σ f0 · f1 (no matrix needed).
TurnAngle frame_turn(const Vec3& t0, const Vec3& b0, const Vec3& t1, const Vec3& b1) {
  const Vec3 c0 = t0.cross(b0), c1 = t1.cross(b1);
  const Vec3 axial = t0.cross(t1) + b0.cross(b1) + c0.cross(c1);
  const double trace = t0.dot(t1) + b0.dot(b1) + c0.dot(c1);
  return {0.5 * axial.norm(), 0.5 * (trace - 1.0)};
}

/// Cross-sections with rotation-minimising frames for any radius law (RadiusFn(s) returns
/// {r, dr/ds}), written over `rings` (its storage reused); returns the largest frame
/// rotation between neighbours (radians).
template <class RadiusFn>
double sections(const Centerline& c, const RadiusFn& radius_at, bool variable_radius, const SweepOptions& opt,
                const char* who, std::vector<SweepSection>& rings) {
  if (c.empty()) throw std::invalid_argument(std::string(who) + ": empty centerline");
  if (!(opt.chord_tolerance > 0.0) || !std::isfinite(opt.chord_tolerance))
    throw std::invalid_argument(std::string(who) + ": chord_tolerance must be positive and finite");
  const double tol_axial = kAxialShare * opt.chord_tolerance;
  const double u0 = c.u_min(), u1 = c.u_max();
  const double L = c.length();
  const double min_speed = kStationaryRelSpeed * std::max(L, 1e-300) / (u1 - u0);
  const std::vector<double>& bp = c.breakpoints();

  auto check_radius = [&](double s, double r, double rs) {
    if (!(r > 0.0) || !std::isfinite(r))
      throw std::invalid_argument(std::string(who) + ": radius " + full_precision(r) + " at s = " +
                                  full_precision(s) + " is not positive and finite");
    if (!(std::abs(rs) < 1.0))
      throw std::invalid_argument(std::string(who) + ": |dr/ds| = " + full_precision(std::abs(rs)) +
                                  " ≥ 1 at s = " + full_precision(s) +
                                  ": the moving sphere swallows its neighbours, no envelope surface");
  };

  // --- rings along the curve ---------------------------------------------------------
  rings.clear();
  auto make_ring = [&](double u, double s, const Sample& d, const Vec3& fallback) {
    SweepSection g;
    g.u = u;
    g.s = s;
    g.point = d.d[0];
    g.tangent = d.tangent(min_speed, fallback);
    const auto [r, rs] = radius_at(s);
    check_radius(s, r, rs);
    g.centre = variable_radius ? Vec3(d.d[0] - r * rs * g.tangent) : d.d[0];  // eq. 7
    g.radius = variable_radius ? r * std::sqrt(1.0 - rs * rs) : r;           // eq. 8
    return g;
  };

  // --- rotation-minimising frame, carried along as rings are placed (its dependency chain
  // then overlaps the march's) ---------------------------------------------------------------
  Vec3 b1;          // frame normal at the last ring
  TurnAngle worst;  // largest frame rotation between neighbours (one atan2 at the end)
  auto frame_next = [&]() {
    const std::size_t i = rings.size() - 1;
    SweepSection& g = rings[i];
    if (i == 0) {
      b1 = any_perpendicular(g.tangent);
      g.normal = b1;
      return;
    }
    const SweepSection& prev = rings[i - 1];
    // Double reflection: reflect (b1, t) in the bisector plane of x_i → x_{i+1}, then in
    // the plane that maps the reflected tangent onto the new one.
    const Vec3 v1 = g.point - prev.point;
    const double c1 = v1.squaredNorm();
    Vec3 rL = b1, tL = prev.tangent;
    if (c1 > 0.0) {
      rL = b1 - (2.0 / c1) * v1.dot(b1) * v1;
      tL = tL - (2.0 / c1) * v1.dot(tL) * v1;
    }
    const Vec3 v2 = g.tangent - tL;
    const double c2 = v2.squaredNorm();
    Vec3 bn = c2 > 0.0 ? Vec3(rL - (2.0 / c2) * v2.dot(rL) * v2) : rL;
    bn -= bn.dot(g.tangent) * g.tangent;  // remove rounding drift
    const double len = bn.norm();
    bn = len > 0.0 ? Vec3(bn / len) : any_perpendicular(g.tangent);
    // Two reflections in planes with normals v1, v2 compose to a rotation by twice the angle
    // α ∈ [0, π/2] between the planes: with X = |v1·v2|, Y = |v1×v2| (both scaled by
    // |v1||v2|), sin 2α ∝ 2XY and cos 2α ∝ X² − Y². Otherwise (a reflection skipped, or the
    // normal replaced) the frames themselves are compared.
    TurnAngle turn;
    if (c1 > 0.0 && c2 > 0.0 && len > 0.0) {
      const double X = std::abs(v1.dot(v2)), Y = v1.cross(v2).norm();
      turn = {2.0 * X * Y, X * X - Y * Y};
    } else {
      turn = frame_turn(prev.tangent, b1, g.tangent, bn);
    }
    if (turn.exceeds(worst)) worst = turn;
    b1 = bn;
    g.normal = b1;
  };

  Sample d;  // at the current ring
  c.evaluate(u0, 3, d.d);
  d.finish(min_speed);
  {
    Vec3 fb = Vec3::UnitX();
    if (c.length() > 0.0) fb = (c.position(u1) - d.d[0]).normalized();
    if (!is_finite(fb)) fb = Vec3::UnitX();
    rings.push_back(make_ring(u0, 0.0, d, fb));
    frame_next();
  }
  double u = u0, s = 0.0;
  std::size_t bpi = 0;  // breakpoint interval holding u
  // The sample at x ∈ [u, u1] from the breakpoint interval evaluate() would use there (the
  // march knows where it is: no search).
  auto sample_ahead = [&](double x, Sample& out, int nder) {
    std::size_t k = bpi;
    while (k + 2 < bp.size() && x >= bp[k + 1]) ++k;
    c.evaluate_in_interval(k, x, nder, out.d);
    out.finish(min_speed);
  };
  Sample dm, de;  // at the middle and the end of a step
  // The ring at (u, s) from the sample d, its frame carried on.
  auto add_ring = [&]() {
    rings.push_back(make_ring(u, std::min(s, L), d, rings.back().tangent));
    frame_next();
    if (rings.size() > kMaxRings)
      throw std::invalid_argument("the tube at chord tolerance " + full_precision(opt.chord_tolerance) +
                                  " needs more than " + std::to_string(kMaxRings) + " rings along its " +
                                  full_precision(L) + " of centerline");
  };
  while (u < u1) {
    while (bpi + 2 < bp.size() && u >= bp[bpi + 1]) ++bpi;
    const double span_w = bp[bpi + 1] - bp[bpi];
    const double speed0 = std::max(d.speed, min_speed);
    const double k0 = d.kappa;
    const double r0 = rings.back().radius;
    double du = predicted_step(d, r0, tol_axial, kMaxSpanFraction * span_w, min_speed);
    if (variable_radius) {
      // Keep the linear interpolation of r between rings within tolerance too: |r''|Δs²/8.
      const double h = 1e-3 * std::max(std::min(axial_step(k0, r0, tol_axial), L), 1e-12);
      const double rpp = std::abs(radius_at(std::min(s + h, L)).first - 2.0 * radius_at(s).first +
                                  radius_at(std::max(s - h, 0.0)).first) /
                         (h * h);
      if (rpp > 0.0) du = std::min(du, std::sqrt(8.0 * tol_axial / rpp) / speed0);
    }
    du = std::max(du, kMinStepRel * (u1 - u0));
    for (int it = 0;; ++it) {
      du = std::min(du, u1 - u);
      sample_ahead(u + 0.5 * du, dm, 2);
      sample_ahead(u + du, de, 3);
      const double vmax = std::max({d.speed, dm.speed, de.speed, min_speed});
      const double kmax = std::max({k0, dm.kappa, de.kappa});
      const double allowed = axial_step(kmax, r0, tol_axial) / vmax;
      if (du <= allowed * 1.0000001 || it >= kStepShrinkIterations) break;
      du = std::max(allowed, kMinStepRel * (u1 - u0));
    }
    // Hull jump. Why: key points far closer together than the tube is thick (a dense export)
    // make knot intervals so short that a quarter of one is a needless ring, millions of
    // them per cable. Where such intervals lie within half the axial tolerance of the chord
    // to a breakpoint ahead and every tangent there leans from the chord by less than that
    // much at the tube's radius (Centerline::hull_bounds), the canal surface over them
    // is within the axial tolerance of a straight tube: one step crosses them all.
    if (!variable_radius && bpi + 2 < bp.size() && span_w * speed0 < kShortIntervalRadii * r0) {
      auto straight_to = [&](std::size_t j) {
        if (!(bp[j] > u + du)) return false;
        const Centerline::HullBounds hb = c.hull_bounds(u, bp[j]);
        return hb.deviation <= 0.5 * tol_axial && r0 * hb.turn_sine <= 0.5 * tol_axial;
      };
      // Doubling from the second breakpoint ahead while the test passes (no bisection after
      // the first failure: the next step starts there); `ok` is the farthest passed, 0: none.
      std::size_t ok = 0;
      for (std::size_t off = 1;; off *= 2) {
        const std::size_t j = std::min(bpi + 1 + off, bp.size() - 1);
        if (!straight_to(j)) break;
        ok = j;
        if (j + 1 == bp.size()) break;
      }
      if (ok != 0) {
        const double un = bp[ok];
        sample_ahead(un, de, 3);
        s = un == u1 ? L : std::min(c.arc_length_at(un) - c.arc_length_at(u0), L);
        u = un;
        d = de;
        add_ring();
        continue;
      }
    }
    // Simpson on |C'| (the three derivatives we have) advances s for the radius law.
    const double un = (u1 - (u + du) <= 1e-12 * (u1 - u0)) ? u1 : u + du;
    if (un == u1 && un != u + du) sample_ahead(un, de, 3);
    s += (un - u) / 6.0 * (d.speed + 4.0 * dm.speed + de.speed);
    if (un == u1) s = L;
    u = un;
    d = de;
    add_ring();
  }

  return worst.radians();
}

}  // namespace

int circumferential_resolution(double radius, double tolerance) {
  if (!(radius > 0.0) || !(tolerance > 0.0) || !std::isfinite(radius) || !std::isfinite(tolerance))
    throw std::invalid_argument("circumferential_resolution: radius and tolerance must be positive and finite");
  if (tolerance >= radius) return kMinCircumferential;
  const double half_angle = std::acos(1.0 - tolerance / radius);  // sagitta R(1 − cos(π/n)) ≤ tol
  const double need = std::ceil(M_PI / half_angle);
  if (need > kMaxCircumferential)
    throw std::invalid_argument("chord tolerance " + full_precision(tolerance) + " is too small for radius " +
                                full_precision(radius));
  return std::max(kMinCircumferential, static_cast<int>(need));
}

namespace {

using Tri = std::array<std::uint32_t, 3>;

/// True if the tube folds between neighbouring rings a → b: some point of one ring lies
/// behind the plane of the other (the facets between them cross). Over each ring the
/// signed distance from the other's plane is smallest at radius·sin(turn) below its centre's,
/// so for a step Δs around a bend of radius R this is R < r, whatever Δs; a kink or a
/// reversal of the centerline folds at any radius.
bool rings_fold(const SweepSection& a, const SweepSection& b) {
  const Vec3 step = b.centre - a.centre;
  const double sine = a.tangent.cross(b.tangent).norm();
  return step.dot(a.tangent) < b.radius * sine || step.dot(b.tangent) < a.radius * sine;
}

/// Triangle mesh of out.sections' rings (n vertices each, odd rings rotated by π/n) with
/// fan end caps, written over out.mesh (its storage reused). Sizes are known up front:
/// vertices and triangles are written in place, indices by formula.
void mesh_sections(const SweepOptions& opt, double max_turn, SweepResult& out) {
  const std::vector<SweepSection>& rings = out.sections;
  double rmax = 0.0;
  for (const SweepSection& g : rings) rmax = std::max(rmax, g.radius);
  const int n = circumferential_resolution(rmax, kRingPolygonShare * opt.chord_tolerance);
  out.circumferential = n;
  out.rings = static_cast<int>(rings.size());
  out.max_frame_turn = max_turn;
  out.folded = false;
  out.fold_s = 0.0;
  for (std::size_t i = 0; i + 1 < rings.size(); ++i)
    if (rings_fold(rings[i], rings[i + 1])) {
      out.folded = true;
      out.fold_s = rings[i].s;
      break;
    }
  Mesh& m = out.mesh;
  const std::size_t nr = rings.size();
  const std::size_t un = static_cast<std::size_t>(n);
  const std::size_t ring_vertices = nr * un;
  if (ring_vertices + 2 > std::numeric_limits<std::uint32_t>::max())
    throw std::invalid_argument("the tube's " + std::to_string(ring_vertices) + " vertices exceed 32-bit indices");
  // The mesh's size is known before any of it is allocated: refuse it here if it is over
  // the caller's budget (e.g. a route folding back on itself thousands of times).
  const std::size_t planned_triangles = (nr > 0 ? nr - 1 : 0) * 2 * un + (opt.end_caps ? 2 * un : 0);
  if (planned_triangles > opt.max_triangles)
    throw std::invalid_argument("the tube would have " + std::to_string(planned_triangles) + " triangles (" +
                                std::to_string(nr) + " rings of " + std::to_string(n) + " vertices), more than the " +
                                std::to_string(opt.max_triangles) + " allowed");
  // Unit circle (cos, sin) at the even rings' angles 2πj/n, then at the odd rings' 2π(j + ½)/n.
  std::vector<Eigen::Vector2d> circle(2 * un);
  for (std::size_t j = 0; j < un; ++j)
    for (std::size_t odd = 0; odd < 2; ++odd) {
      const double a = M_PI * static_cast<double>(2 * j + odd) / n;
      circle[odd * un + j] = Eigen::Vector2d(std::cos(a), std::sin(a));
    }
  // Every element is written below: a reused array is resized in place (Vec3's default
  // constructor writes nothing), one too small is emptied first (nothing stale is copied).
  const std::size_t vertex_count = ring_vertices + (opt.end_caps ? 2 : 0);
  if (m.vertices.capacity() < vertex_count) m.vertices.clear();
  m.vertices.resize(vertex_count);
  Vec3* v = m.vertices.data();
  for (std::size_t i = 0; i < nr; ++i) {
    const SweepSection& g = rings[i];
    Eigen::Matrix<double, 3, 2> E;  // radius × (normal, tangent × normal)
    E.col(0) = g.radius * g.normal;
    E.col(1) = g.radius * g.tangent.cross(g.normal);
    const Vec3 o = g.centre;
    const Eigen::Vector2d* cs = circle.data() + (i % 2) * un;
    for (std::size_t j = 0; j < un; ++j) *v++ = o + E * cs[j];  // eq. 9
  }
  if (opt.end_caps) {
    m.vertices[ring_vertices] = rings.front().centre;
    m.vertices[ring_vertices + 1] = rings.back().centre;
  }
  // --- triangles: strips between rings, fans for the caps (outward, counter-clockwise) ---
  // Between ring i and i + 1 each vertex j contributes two triangles. Ring i is rotated by
  // (i mod 2)·π/n, so an even ring's vertex j + ½ step sits between the odd ring's j and
  // j + 1, and vice versa. A strip is its parity's index pattern (relative to ring i's
  // first vertex) plus i·n (the offset loop vectorises). Into reused storage the strips are
  // written in place; otherwise each is built in a small buffer and appended, so that the
  // new array is written once (resizing would zero-fill it first).
  static_assert(sizeof(Tri) == 3 * sizeof(std::uint32_t), "Tri is three packed indices (as Embree reads it)");
  const auto N = static_cast<std::uint32_t>(n);
  std::vector<Tri> pattern(4 * un);  // even strip, then odd strip
  for (std::uint32_t j = 0; j < N; ++j) {
    const std::uint32_t j1 = j + 1 == N ? 0 : j + 1;
    pattern[2 * j] = Tri{j, j1, N + j};
    pattern[2 * j + 1] = Tri{j1, N + j1, N + j};
    pattern[2 * un + 2 * j] = Tri{j, j1, N + j1};
    pattern[2 * un + 2 * j + 1] = Tri{j, N + j1, N + j};
  }
  const std::size_t strip_triangles = 2 * un;
  const std::size_t strips = nr - 1;
  const std::size_t strip_total = strips * strip_triangles;
  const std::size_t triangle_count = strip_total + (opt.end_caps ? 2 * un : 0);
  const bool in_place = m.triangles.capacity() >= triangle_count;
  std::vector<Tri> buffer;
  if (in_place) {
    m.triangles.resize(strip_total);
  } else {
    m.triangles.clear();
    m.triangles.reserve(triangle_count);
    buffer.resize(strip_triangles);
  }
  const std::size_t strip_indices = 3 * strip_triangles;
  for (std::size_t i = 0; i < strips; ++i) {
    const std::uint32_t* pat = pattern.data()->data() + (i % 2) * strip_indices;
    const auto a = static_cast<std::uint32_t>(i * un);
    // Flat views of the packed indices.
    std::uint32_t* dst = in_place ? m.triangles.data()->data() + i * strip_indices : buffer.data()->data();
    for (std::size_t q = 0; q < strip_indices; ++q) dst[q] = pat[q] + a;
    if (!in_place) m.triangles.insert(m.triangles.end(), buffer.begin(), buffer.end());
  }
  m.triangles.resize(triangle_count);  // the caps, written next
  if (opt.end_caps) {
    const auto c0 = static_cast<std::uint32_t>(ring_vertices), c1 = c0 + 1;
    const auto last = static_cast<std::uint32_t>((nr - 1) * un);
    Tri* cap = m.triangles.data() + strips * strip_triangles;
    for (std::uint32_t j = 0; j < N; ++j) {
      const std::uint32_t j1 = j + 1 == N ? 0 : j + 1;
      *cap++ = Tri{c0, j1, j};
      *cap++ = Tri{c1, last + j, last + j1};
    }
  }
}

/// Tube sections of constant radius, written over `rings`; returns the largest frame turn.
double tube_section_list(const Centerline& c, double radius, const SweepOptions& opt,
                         std::vector<SweepSection>& rings) {
  if (!(radius > 0.0) || !std::isfinite(radius))
    throw std::invalid_argument("sweep_tube: radius must be positive and finite");
  return sections(
      c, [radius](double) { return std::pair<double, double>(radius, 0.0); }, false, opt, "sweep_tube", rings);
}

/// Canal sections of radius r(s), written over `rings`; returns the largest frame turn.
double canal_section_list(const Centerline& c, const std::function<double(double)>& radius_of_s,
                          const SweepOptions& opt, std::vector<SweepSection>& rings) {
  if (!radius_of_s) throw std::invalid_argument("sweep_canal: no radius function");
  const double L = c.empty() ? 0.0 : c.length();
  // Central difference for r'(s); one-sided at the ends.
  const double h = 6e-6 * std::max(L, 1e-300);
  auto law = [&](double s) {
    const double r = radius_of_s(s);
    const double a = std::max(0.0, s - h), b = std::min(L, s + h);
    const double rs = b > a ? (radius_of_s(b) - radius_of_s(a)) / (b - a) : 0.0;
    return std::pair<double, double>(r, rs);
  };
  return sections(c, law, true, opt, "sweep_canal", rings);
}

/// True for a centerline of zero length (all its points one point, e.g. an exact <bspline>
/// whose control points coincide). Its cable is the ball of radius r there (DESIGN §5), which
/// sweep_junction meshes; rings along it would all coincide in a flat, zero-volume disc.
bool zero_length(const Centerline& c) { return !c.empty() && c.length() == 0.0; }

/// The ball of a zero-length cable, within the caller's triangle budget.
void sweep_ball(const Centerline& c, double radius, const SweepOptions& opt, SweepResult& out) {
  out = sweep_junction(c.position(c.u_min()), radius, opt);
  if (out.mesh.triangles.size() > opt.max_triangles)
    throw std::invalid_argument("the ball of a zero-length centerline would have " +
                                std::to_string(out.mesh.triangles.size()) + " triangles, more than the " +
                                std::to_string(opt.max_triangles) + " allowed");
}

}  // namespace

void sweep_tube(const Centerline& c, double radius, const SweepOptions& opt, SweepResult& out) {
  if (zero_length(c)) {
    sweep_ball(c, radius, opt, out);
    return;
  }
  const double turn = tube_section_list(c, radius, opt, out.sections);
  mesh_sections(opt, turn, out);
}

void sweep_canal(const Centerline& c, const std::function<double(double)>& radius_of_s, const SweepOptions& opt,
                 SweepResult& out) {
  if (zero_length(c) && radius_of_s) {
    sweep_ball(c, radius_of_s(0.0), opt, out);
    return;
  }
  const double turn = canal_section_list(c, radius_of_s, opt, out.sections);
  mesh_sections(opt, turn, out);
}

SweepResult sweep_tube(const Centerline& c, double radius, const SweepOptions& opt) {
  SweepResult out;
  sweep_tube(c, radius, opt, out);
  return out;
}

SweepResult sweep_canal(const Centerline& c, const std::function<double(double)>& radius_of_s,
                        const SweepOptions& opt) {
  SweepResult out;
  sweep_canal(c, radius_of_s, opt, out);
  return out;
}

TubeBudget::TubeBudget(std::string owner, std::size_t total) : owner_(std::move(owner)), total_(total) {}

SweepResult TubeBudget::sweep(const Centerline& c, double radius, SweepOptions opt, const std::string& cable) {
  opt.max_triangles = std::min(opt.max_triangles, total_ - std::min(total_, used_));
  SweepResult tube;
  try {
    tube = sweep_tube(c, radius, opt);
  } catch (const std::invalid_argument& e) {
    // What the cables before it took of the budget matters only when they took some.
    const std::string taken = used_ == 0 ? std::string()
                                         : " (the tubes of " + std::to_string(cables_) + " cables before it have " +
                                               std::to_string(used_) + " of " + std::to_string(total_) +
                                               " triangles; a route folding back on itself thousands of times?)";
    throw CableLimitError(cable, owner_ + ": cable '" + cable + "': " + e.what() + taken);
  }
  used_ += tube.mesh.triangles.size();
  ++cables_;
  return tube;
}

std::vector<SweepSection> tube_sections(const Centerline& c, double radius, const SweepOptions& opt) {
  std::vector<SweepSection> rings;
  tube_section_list(c, radius, opt, rings);
  return rings;
}

std::vector<SweepSection> canal_sections(const Centerline& c, const std::function<double(double)>& radius_of_s,
                                         const SweepOptions& opt) {
  std::vector<SweepSection> rings;
  canal_section_list(c, radius_of_s, opt, rings);
  return rings;
}

SweepResult sweep_junction(const Vec3& centre, double radius, const SweepOptions& opt) {
  if (!is_finite(centre)) throw std::invalid_argument("sweep_junction: centre is not finite");
  if (!(radius > 0.0) || !std::isfinite(radius))
    throw std::invalid_argument("sweep_junction: radius must be positive and finite");
  if (!(opt.chord_tolerance > 0.0) || !std::isfinite(opt.chord_tolerance))
    throw std::invalid_argument("sweep_junction: chord_tolerance must be positive and finite");
  // UV sphere with n longitudes and n/2 latitude bands, vertices on a sphere of radius
  // Rv = r / cos ρ, ρ ≥ the angular circumradius of every triangle (half a longitude step
  // plus half a latitude step): every facet plane is at least r from the centre, so the
  // mesh contains the ball; Rv − r ≤ tol fixes the resolution.
  int n = 4;
  for (;; n += 2) {
    const double rho = 0.5 * (2.0 * M_PI / n + M_PI / (n / 2));
    if (radius * (1.0 / std::cos(rho) - 1.0) <= opt.chord_tolerance) break;
    if (n > kMaxCircumferential)
      throw std::invalid_argument("sweep_junction: chord tolerance too small for the radius");
  }
  const int bands = n / 2;
  const double rho = 0.5 * (2.0 * M_PI / n + M_PI / bands);
  const double Rv = radius / std::cos(rho);
  SweepResult out;
  out.circumferential = n;
  out.rings = bands - 1;
  Mesh& m = out.mesh;
  using Tri = std::array<std::uint32_t, 3>;
  m.vertices.push_back(centre + Vec3(0, 0, -Rv));  // south pole
  for (int b = 1; b < bands; ++b) {
    const double th = -0.5 * M_PI + M_PI * b / bands;
    for (int j = 0; j < n; ++j) {
      const double ph = 2.0 * M_PI * j / n;
      m.vertices.push_back(centre + Rv * Vec3(std::cos(th) * std::cos(ph), std::cos(th) * std::sin(ph), std::sin(th)));
    }
  }
  m.vertices.push_back(centre + Vec3(0, 0, Rv));  // north pole
  const auto north = static_cast<std::uint32_t>(m.vertices.size() - 1);
  auto ring = [n](int b, int j) { return static_cast<std::uint32_t>(1 + (b - 1) * n + (j % n)); };
  for (int j = 0; j < n; ++j) m.triangles.push_back(Tri{0, ring(1, j + 1), ring(1, j)});
  for (int b = 1; b + 1 < bands; ++b)
    for (int j = 0; j < n; ++j) {
      m.triangles.push_back(Tri{ring(b, j), ring(b, j + 1), ring(b + 1, j + 1)});
      m.triangles.push_back(Tri{ring(b, j), ring(b + 1, j + 1), ring(b + 1, j)});
    }
  for (int j = 0; j < n; ++j) m.triangles.push_back(Tri{north, ring(bands - 1, j), ring(bands - 1, j + 1)});
  return out;
}

}  // namespace loom
