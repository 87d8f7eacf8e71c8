#include "routing/curve/cable_geometry.hpp"

#include "core/error.hpp"

#include <algorithm>
#include <cstddef>
#include <stdexcept>
#include <tuple>
#include <utility>
#include <vector>

namespace loom {

double derived_stub_length(double radius, double min_bend_radius) {
  return std::max(min_bend_radius, 2.0 * radius);
}

namespace {

/// The curve traversed backwards: u ↦ (a + b) − u.
Centerline reversed(const Centerline& c) {
  const auto& k = c.knots();
  const double a = k.front(), b = k.back();
  std::vector<double> knots(k.size());
  for (std::size_t i = 0; i < k.size(); ++i) knots[i] = a + b - k[k.size() - 1 - i];
  std::vector<Vec3> cps(c.control_points().rbegin(), c.control_points().rend());
  return Centerline(c.degree(), std::move(knots), std::move(cps));
}

/// A degree-1 curve as an exact cubic: each linear piece becomes a cubic Bézier with
/// control points at thirds; interior knots get multiplicity 3 (the corners stay corners).
Centerline linear_as_cubic(const Centerline& c) {
  const auto& k = c.knots();
  const auto& p = c.control_points();
  std::vector<double> knots;
  std::vector<Vec3> cps{p.front()};
  knots.insert(knots.end(), 4, k[1]);
  for (std::size_t i = 0; i + 1 < p.size(); ++i) {
    const Vec3 d = p[i + 1] - p[i];
    cps.push_back(p[i] + d / 3.0);
    cps.push_back(p[i] + 2.0 * d / 3.0);
    cps.push_back(p[i + 1]);
    const double t = k[i + 2];
    knots.insert(knots.end(), i + 2 < p.size() ? 3 : 4, t);
  }
  return Centerline(3, std::move(knots), std::move(cps));
}

/// Inserts u once into the knots U of a degree-p curve with control points P, in knot
/// interval k (U[k] ≤ u ≤ U[k+1], U[k] < U[k+1]); the curve is unchanged (Boehm; Piegl &
/// Tiller A5.1).
void insert_knot(int p, std::size_t k, double u, std::vector<double>& U, std::vector<Vec3>& P) {
  const std::size_t q = static_cast<std::size_t>(p);
  std::vector<Vec3> Q(P.size() + 1);
  for (std::size_t i = 0; i + q <= k; ++i) Q[i] = P[i];
  for (std::size_t i = k - q + 1; i <= k; ++i) {
    const double a = (u - U[i]) / (U[i + q] - U[i]);
    Q[i] = a * P[i] + (1.0 - a) * P[i - 1];
  }
  for (std::size_t i = k + 1; i < Q.size(); ++i) Q[i] = P[i - 1];
  U.insert(U.begin() + static_cast<std::ptrdiff_t>(k) + 1, u);
  P = std::move(Q);
}

/// The same curve with a clamped knot vector (end knots of multiplicity degree + 1, so that
/// it starts at its first control point and ends at its last, as join() needs). An exact
/// <bspline> may have any non-decreasing knots: its domain ends are raised to multiplicity
/// degree by knot insertion, and the control points and knots outside the domain dropped
/// (the curve split at its ends, Piegl & Tiller §5.6).
Centerline clamped(const Centerline& c) {
  const int p = c.degree();
  const std::size_t q = static_cast<std::size_t>(p);
  std::vector<double> U = c.knots();
  std::vector<Vec3> P = c.control_points();
  auto run = [&U](double u) { return std::equal_range(U.begin(), U.end(), u); };
  // Start: after insertion u_min fills U[j, j + m) with m ≥ p, and the curve starts at
  // control point j + m − p − 1.
  const double a = U[q];
  for (auto r = run(a); r.second - r.first < p; r = run(a))
    insert_knot(p, static_cast<std::size_t>(r.second - U.begin()) - 1, a, U, P);
  {
    const auto r = run(a);
    const std::size_t j = static_cast<std::size_t>(r.first - U.begin()), m = static_cast<std::size_t>(r.second - r.first);
    std::vector<double> V(q + 1, a);
    V.insert(V.end(), U.begin() + static_cast<std::ptrdiff_t>(j + m), U.end());
    P.erase(P.begin(), P.begin() + static_cast<std::ptrdiff_t>(j + m - q - 1));
    U = std::move(V);
  }
  // End: u_max fills U[f, f + m) with m ≥ p, and the curve ends at control point f − 1.
  const double b = U[P.size()];
  for (auto r = run(b); r.second - r.first < p; r = run(b))
    insert_knot(p, static_cast<std::size_t>(r.first - U.begin()) - 1, b, U, P);
  const std::size_t f = static_cast<std::size_t>(run(b).first - U.begin());
  U.resize(f);
  U.insert(U.end(), q + 1, b);
  P.resize(f);
  return Centerline(p, std::move(U), std::move(P));
}

Centerline as_cubic(const Centerline& c) {
  if (c.degree() == 3) return clamped(c);
  if (c.degree() == 1) return linear_as_cubic(c);
  throw std::invalid_argument("cable_centerline: only degree 1 and 3 segment curves can be joined, got degree " +
                              std::to_string(c.degree()));
}

/// Largest gap between the end of one piece and the start of the next that join() closes,
/// relative to the pieces' extent (control-point bounding box): rounding of coordinates
/// written out and read back. Pieces built here meet exactly (both ends are the node's
/// position); an exact <bspline> that stops short of its node does not make a curve.
constexpr double kJoinGapRel = 1e-9;

/// How far apart two points that should coincide may lie, given the box of the control
/// points they come from: kJoinGapRel of the box's extent and of its distance from the
/// origin (coordinates 10⁶ from it round by ~10⁻¹⁰ each when written and read).
double meeting_tolerance(const AABB& box) {
  return kJoinGapRel * (box.diagonal() + std::max(box.min.cwiseAbs().maxCoeff(), box.max.cwiseAbs().maxCoeff()));
}

/// Joins two clamped cubics end to start (C0 at the joint, knot multiplicity 3 there).
/// Throws std::invalid_argument if they do not meet (within meeting_tolerance).
Centerline join(const Centerline& a, const Centerline& b) {
  const Vec3 end = a.control_points().back(), start = b.control_points().front();
  AABB box;
  for (const Centerline* c : {&a, &b})
    for (const Vec3& q : c->control_points()) box.extend(q);
  if ((end - start).norm() > meeting_tolerance(box))
    throw std::invalid_argument("consecutive segments do not meet: one ends at " + full_precision(end) +
                                ", the next starts at " + full_precision(start) + " (gap " +
                                full_precision((end - start).norm()) + ")");
  const auto& ka = a.knots();
  const auto& kb = b.knots();
  const double shift = ka.back() - kb.front();
  std::vector<double> knots(ka.begin(), ka.end() - 1);  // a's knots with its end knot thrice
  for (std::size_t i = 4; i < kb.size(); ++i) knots.push_back(kb[i] + shift);
  std::vector<Vec3> cps = a.control_points();
  cps.insert(cps.end(), b.control_points().begin() + 1, b.control_points().end());
  return Centerline(3, std::move(knots), std::move(cps));
}

/// A cable whose segments do not make a curve (coincident key points, an empty knot
/// domain, a degree that cannot be joined, ...) is a fault of the harness file: every user
/// of the curves (audit, render, view, scan --compare) reports it naming the file, the
/// cable's line and the reason.
[[noreturn]] void not_a_curve(const Harness& h, int cable, const std::invalid_argument& e) {
  const Cable& c = h.cables.at(static_cast<std::size_t>(cable));
  throw InputError({h.source_file, c.line, "cable " + c.id}, std::string("its route does not make a curve: ") + e.what());
}

}  // namespace

std::optional<Centerline> segment_centerline(const Harness& h, int segment) {
  const Segment& s = h.segments.at(static_cast<std::size_t>(segment));
  const auto a = h.node_position(s.from), b = h.node_position(s.to);
  if (s.bspline) {
    Centerline c(s.bspline->degree, s.bspline->knots, s.bspline->control_points);
    // The exact curve is the segment: it must leave its from-node and reach its to-node
    // where the file puts them (an unplaced branch point takes the curve's end). A curve
    // that stops short would be audited as if it were connected.
    AABB box;
    for (const Vec3& q : c.control_points()) box.extend(q);
    for (const auto& [node, at, u] : {std::tuple(s.from, a, c.u_min()), std::tuple(s.to, b, c.u_max())}) {
      if (!at) continue;
      box.extend(*at);
      const Vec3 end = c.position(u);
      if ((end - *at).norm() > meeting_tolerance(box))
        throw std::invalid_argument("the <bspline> of segment " + s.from + " -> " + s.to + " " +
                                    (u == c.u_min() ? "starts" : "ends") + " at " + full_precision(end) +
                                    ", not at " + node + " " + full_precision(*at) + " (gap " +
                                    full_precision((end - *at).norm()) + ")");
    }
    return c;
  }
  if (!a || !b) return std::nullopt;
  std::vector<Vec3> pts{*a};
  pts.insert(pts.end(), s.path.begin(), s.path.end());
  pts.push_back(*b);
  if (s.interp == Interp::Polyline) return Centerline::polyline(pts);
  InterpolationOptions opt;
  // A cable leaves a port along its exit direction and arrives against it.
  if (int p = h.find_port(s.from); p >= 0) opt.start_tangent = h.ports[p].direction;
  if (int p = h.find_port(s.to); p >= 0) opt.end_tangent = -h.ports[p].direction;
  return Centerline::interpolate(pts, opt);
}

double breakout_length(const HarnessTopology& topo, const std::string& node) {
  const Harness& h = topo.harness();
  double len = 0.0;
  for (int s : topo.incident_segments(node)) {
    if (topo.segment_cables(s).empty()) continue;
    double bend = 0.0;
    for (int c : topo.segment_cables(s)) bend = std::max(bend, h.cables[c].physical.min_bend_radius);
    len = std::max({len, bend, topo.segment_diameter(s)});
  }
  return len;
}

SegmentCurves::SegmentCurves(const HarnessTopology& topo)
    : topo_(topo), built_(topo.harness().segments.size(), {false, false}),
      curves_(topo.harness().segments.size()) {}

const std::optional<Centerline>& SegmentCurves::segment(int s, bool backwards) {
  const std::size_t i = static_cast<std::size_t>(s);
  const int b = backwards ? 1 : 0;
  if (!built_.at(i)[b]) {
    const std::optional<Centerline>& fwd = backwards ? segment(s, false) : curves_[i][0];
    std::optional<Centerline> c = backwards ? (fwd ? std::optional<Centerline>(reversed(*fwd)) : std::nullopt)
                                            : segment_centerline(topo_.harness(), s);
    if (c) c->length();  // the arc-length table, built once here, travels with every copy
    curves_[i][b] = std::move(c);
    built_[i][b] = true;
  }
  return curves_[i][b];
}

std::vector<CablePiece> SegmentCurves::pieces(int cable) {
  std::vector<CablePiece> out;
  double s0 = 0.0;
  for (const SegmentUse& u : topo_.cable_chain(cable)) {
    const std::optional<Centerline>* c = nullptr;
    try {
      c = &segment(u.segment, u.reversed);
    } catch (const std::invalid_argument& e) {
      not_a_curve(topo_.harness(), cable, e);
    }
    if (!*c) return {};
    out.push_back(CablePiece{u.segment, s0, **c});
    s0 += out.back().curve.length();
  }
  return out;
}

std::optional<Centerline> SegmentCurves::cable(int cable) {
  std::optional<Centerline> out;
  const auto pieces = this->pieces(cable);
  if (pieces.empty()) return std::nullopt;
  try {
    for (const CablePiece& p : pieces) {
      Centerline cubic = as_cubic(p.curve);
      out = out ? join(*out, cubic) : cubic;
    }
  } catch (const std::invalid_argument& e) {
    not_a_curve(topo_.harness(), cable, e);
  }
  return out;
}

std::vector<CablePiece> cable_pieces(const HarnessTopology& topo, int cable) {
  return SegmentCurves(topo).pieces(cable);
}

std::optional<Centerline> cable_centerline(const HarnessTopology& topo, int cable) {
  return SegmentCurves(topo).cable(cable);
}

}  // namespace loom
