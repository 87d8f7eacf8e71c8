#include "routing/curve/cable_geometry.hpp"

#include "core/bspline_ops.hpp"
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
    // Joined at the highest degree of the chain (routed pieces are cubic, pieces read from a
    // file may be of any degree the readers accept, polylines are degree 1).
    int degree = 3;
    for (const CablePiece& p : pieces) degree = std::max(degree, p.curve.degree());
    for (const CablePiece& p : pieces) {
      Centerline piece = elevated(clamped(p.curve), degree);
      out = out ? join(*out, piece) : piece;
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
