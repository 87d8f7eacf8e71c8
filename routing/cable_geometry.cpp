#include "routing/cable_geometry.hpp"

#include "core/error.hpp"

#include <algorithm>
#include <stdexcept>

namespace loom {

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

Centerline as_cubic(const Centerline& c) {
  if (c.degree() == 3) return c;
  if (c.degree() == 1) return linear_as_cubic(c);
  throw std::invalid_argument("cable_centerline: only degree 1 and 3 segment curves can be joined, got degree " +
                              std::to_string(c.degree()));
}

/// Joins two clamped cubics end to start (C0 at the joint, knot multiplicity 3 there).
Centerline join(const Centerline& a, const Centerline& b) {
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
  if (s.bspline) return Centerline(s.bspline->degree, s.bspline->knots, s.bspline->control_points);
  const auto a = h.node_position(s.from), b = h.node_position(s.to);
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
