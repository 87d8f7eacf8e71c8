#pragma once
// A test-only oracle for routed harnesses, independent of loom's audit: each segment's
// <bspline> as read back from routed.xml is evaluated here (de Boor, derivatives from the
// hodograph's control points), sampled densely, and measured by brute force against every
// triangle of every part (exact point–triangle distance written here, Ericson's regions);
// a point inside a closed box part is at distance 0 (the scenes' parts are boxes).
// Curvature is the closed form |C′ × C″| / |C′|³. Sampled values are exact values at real
// curve points, so a violation the oracle finds is real; a true minimum may hide between
// samples by at most half the sample spacing (distance is 1-Lipschitz).

#include "core/harness.hpp"
#include "core/harness_topology.hpp"
#include "core/part.hpp"
#include "common/brute_geometry.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace loom::route_oracle {

/// A clamped B-spline as stored in the file.
struct Spline {
  int degree = 3;
  std::vector<double> knots;
  std::vector<Vec3> cps;
};

inline Spline spline_of(const BSplineData& b) { return Spline{b.degree, b.knots, b.control_points}; }

/// The knot span holding u (clamped to the last non-empty span at the domain's end).
inline int find_span(const Spline& s, double u) {
  const int n = static_cast<int>(s.cps.size());
  int lo = s.degree, hi = n;
  if (u >= s.knots[static_cast<std::size_t>(n)]) {
    int i = n - 1;
    while (i > s.degree && s.knots[static_cast<std::size_t>(i)] == s.knots[static_cast<std::size_t>(i) + 1]) --i;
    return i;
  }
  while (hi - lo > 1) {
    const int m = (lo + hi) / 2;
    if (s.knots[static_cast<std::size_t>(m)] <= u) lo = m;
    else hi = m;
  }
  return lo;
}

/// C(u) by de Boor.
inline Vec3 eval(const Spline& s, double u) {
  if (s.degree == 0) return s.cps[static_cast<std::size_t>(std::min<int>(find_span(s, u), int(s.cps.size()) - 1))];
  const int p = s.degree, i = find_span(s, u);
  std::vector<Vec3> d;
  for (int j = 0; j <= p; ++j) d.push_back(s.cps[static_cast<std::size_t>(j + i - p)]);
  for (int r = 1; r <= p; ++r)
    for (int j = p; j >= r; --j) {
      const double den = s.knots[static_cast<std::size_t>(j + 1 + i - r)] - s.knots[static_cast<std::size_t>(j + i - p)];
      const double a = den == 0.0 ? 0.0 : (u - s.knots[static_cast<std::size_t>(j + i - p)]) / den;
      d[static_cast<std::size_t>(j)] = (1.0 - a) * d[static_cast<std::size_t>(j) - 1] + a * d[static_cast<std::size_t>(j)];
    }
  return d[static_cast<std::size_t>(p)];
}

/// The derivative curve (degree − 1).
inline Spline derivative(const Spline& s) {
  Spline d;
  d.degree = s.degree - 1;
  d.knots.assign(s.knots.begin() + 1, s.knots.end() - 1);
  for (std::size_t i = 0; i + 1 < s.cps.size(); ++i) {
    const double den = s.knots[i + static_cast<std::size_t>(s.degree) + 1] - s.knots[i + 1];
    d.cps.push_back(den == 0.0 ? Vec3::Zero() : Vec3(s.degree * (s.cps[i + 1] - s.cps[i]) / den));
  }
  return d;
}

using loom::test_oracle::point_triangle_distance;

/// Distance from p to a part: 0 inside a closed box part (its vertex box), else the
/// smallest exact triangle distance.
inline double part_distance(const Part& part, const Vec3& p) {
  if (part.closed) {
    AABB box;
    for (const auto& v : part.mesh.vertices) box.extend(v);
    if (box.contains(p)) return 0.0;
  }
  double best = std::numeric_limits<double>::infinity();
  for (const auto& t : part.mesh.triangles)
    best = std::min(best, point_triangle_distance(p, part.mesh.vertices[t[0]], part.mesh.vertices[t[1]],
                                                  part.mesh.vertices[t[2]]));
  return best;
}

/// What the oracle measured along one cable (scene units).
struct CableFindings {
  std::string cable;
  bool has_curve = false;
  double length = 0.0;
  double worst_clearance_shortfall = -std::numeric_limits<double>::infinity();  ///< max(required − clearance)
  std::string worst_part;
  Vec3 worst_point = Vec3::Zero();
  double min_bend_radius = std::numeric_limits<double>::infinity();  ///< over the samples, within pieces
  double start_gap = 0.0, end_gap = 0.0;     ///< |C(0) − first port|, |C(L) − second port|
  double start_turn = 0.0, end_turn = 0.0;   ///< angle (rad) between the end tangent and the exit direction
  double joint_gap = 0.0;                    ///< largest gap between consecutive pieces
};

/// One cable measured from its segments' <bspline>s. `routing_clearance` is the scene's;
/// parts add their own. A non-keep-out part within radius + required clearance of a port
/// (the port's connector) is not measured over the port's straight exit of length
/// max(min bend radius, 2r), at most half the cable (DESIGN / README "Attached parts").
/// `samples_per_segment` evaluations per segment (uniform in the parameter).
inline CableFindings measure_cable(const Harness& h, const std::vector<Part>& parts, int cable,
                                   double routing_clearance, int samples_per_segment) {
  CableFindings f;
  const Cable& cab = h.cables[static_cast<std::size_t>(cable)];
  f.cable = cab.id;
  const HarnessTopology topo(h);
  const double r = cab.radius();
  struct Sample {
    Vec3 p;
    double s;
  };
  std::vector<Sample> samples;
  double s_acc = 0.0;
  Vec3 prev_end = Vec3::Zero();
  bool first_piece = true;
  Vec3 start_tangent = Vec3::Zero(), end_tangent = Vec3::Zero();
  for (const SegmentUse& use : topo.cable_chain(cable)) {
    const Segment& sg = h.segments[static_cast<std::size_t>(use.segment)];
    if (!sg.bspline) return f;  // not routed
    const Spline c = spline_of(*sg.bspline);
    const Spline d1 = derivative(c), d2 = derivative(d1);
    const double u0 = c.knots[static_cast<std::size_t>(c.degree)], u1 = c.knots[c.knots.size() - 1 - static_cast<std::size_t>(c.degree)];
    std::vector<Sample> piece;
    for (int i = 0; i <= samples_per_segment; ++i) {
      const double t = static_cast<double>(use.reversed ? samples_per_segment - i : i) / samples_per_segment;
      const double u = u0 + (u1 - u0) * t;
      const Vec3 p = eval(c, u);
      if (!piece.empty()) s_acc += (p - piece.back().p).norm();
      piece.push_back({p, s_acc});
      const Vec3 v = eval(d1, u), a = eval(d2, u);
      const double speed = v.norm();
      if (speed > 0.0) {
        const double kappa = v.cross(a).norm() / (speed * speed * speed);
        if (kappa > 0.0) f.min_bend_radius = std::min(f.min_bend_radius, 1.0 / kappa);
      }
      if (first_piece && i == 0) start_tangent = use.reversed ? Vec3(-v) : v;
      if (i == samples_per_segment) end_tangent = use.reversed ? Vec3(-v) : v;
    }
    if (!first_piece) f.joint_gap = std::max(f.joint_gap, (piece.front().p - prev_end).norm());
    prev_end = piece.back().p;
    first_piece = false;
    samples.insert(samples.end(), piece.begin(), piece.end());
  }
  if (samples.empty()) return f;
  f.has_curve = true;
  f.length = s_acc;
  const Port& p0 = h.ports[static_cast<std::size_t>(h.find_port(cab.ports[0]))];
  const Port& p1 = h.ports[static_cast<std::size_t>(h.find_port(cab.ports[1]))];
  f.start_gap = (samples.front().p - p0.position).norm();
  f.end_gap = (samples.back().p - p1.position).norm();
  auto angle = [](const Vec3& a, const Vec3& b) { return std::atan2(a.cross(b).norm(), a.dot(b)); };
  f.start_turn = angle(start_tangent, p0.direction);
  f.end_turn = angle(-end_tangent, p1.direction);  // the cable arrives against the exit direction
  const double exit = std::min(std::max(cab.physical.min_bend_radius, 2.0 * r), 0.5 * f.length);
  for (std::size_t q = 0; q < parts.size(); ++q) {
    const Part& part = parts[q];
    const double required = routing_clearance + part.clearance;
    const bool keep_out = part.role == PartRole::KeepOut;
    const bool on0 = !keep_out && part_distance(part, p0.position) <= r + required;
    const bool on1 = !keep_out && part_distance(part, p1.position) <= r + required;
    for (const Sample& smp : samples) {
      if ((on0 && smp.s <= exit) || (on1 && smp.s >= f.length - exit)) continue;
      const double shortfall = required - (part_distance(part, smp.p) - r);
      if (shortfall > f.worst_clearance_shortfall) {
        f.worst_clearance_shortfall = shortfall;
        f.worst_part = part.name;
        f.worst_point = smp.p;
      }
    }
  }
  return f;
}

}  // namespace loom::route_oracle
