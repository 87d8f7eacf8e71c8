#pragma once
/// Exact operations on B-spline curves (Centerline), shared by the harness readers and the
/// cable geometry: knot insertion, clamping, Bézier extraction, splitting, reversal, degree
/// elevation and joining end to start. Every result is the same curve (or the asked-for
/// part of it) up to rounding; world frame, scene units. (Piegl & Tiller, The NURBS Book,
/// A5.1, §5.6, A5.9 for the elevation of a Bézier piece.)

#include "core/centerline.hpp"

#include <vector>

namespace loom {

/// Inserts u once into the knots U of a degree-p curve with control points P, in knot
/// interval k (U[k] ≤ u ≤ U[k+1], U[k] < U[k+1]); the curve is unchanged (Boehm).
void insert_knot(int p, std::size_t k, double u, std::vector<double>& U, std::vector<Vec3>& P);

/// The same curve with a clamped knot vector (end knots of multiplicity degree + 1, so that it
/// starts at its first control point and ends at its last). Any non-decreasing knots are
/// accepted: the domain ends are raised to multiplicity degree by knot insertion and what
/// lies outside the domain dropped.
Centerline clamped(const Centerline& c);

/// The part of the curve over [a, b] (a < b, clamped to the domain) as a clamped curve of the
/// same degree whose parameters run over [a, b]. Throws std::invalid_argument if a ≥ b.
Centerline sub_curve(const Centerline& c, double a, double b);

/// The curve traversed backwards: u ↦ (first knot + last knot) − u.
Centerline reversed(const Centerline& c);

/// The Bézier pieces of the curve, one per non-empty knot span, in order: degree + 1 control
/// points each (the last point of a piece is the first of the next).
std::vector<std::vector<Vec3>> bezier_pieces(const Centerline& c);

/// Bézier pieces of one degree (degree + 1 points each, consecutive pieces sharing their
/// joint) as one clamped curve with knot multiplicity `degree` at the joints; piece k spans
/// [breaks[k], breaks[k + 1]] (breaks.size() == pieces.size() + 1, increasing).
Centerline from_bezier_pieces(int degree, const std::vector<std::vector<Vec3>>& pieces,
                              const std::vector<double>& breaks);

/// The same curve at a higher degree (≤ 7), built piece by piece (C0 joints in the knot
/// vector: the geometric continuity is the curve's own). Returns c itself when the degree is
/// already `degree`; throws std::invalid_argument for a lower one or one beyond 7.
Centerline elevated(const Centerline& c, int degree);

/// How far apart two points that should coincide may lie, given the box of the control
/// points they come from: 1e-9 of the box's extent and of its distance from the origin
/// (coordinates 10⁶ from it round by ~10⁻¹⁰ each when written and read).
double meeting_tolerance(const AABB& box);

/// Joins two curves end to start (C0 at the joint) at the higher of their degrees: both are
/// clamped, the lower one elevated. Throws std::invalid_argument if they do not meet (within
/// meeting_tolerance of their control points' box).
Centerline join(const Centerline& a, const Centerline& b);

}  // namespace loom
