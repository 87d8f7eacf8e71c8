#include "routing/route/arc_line.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace loom {

namespace {

/// Turns smaller than this (radians) are straight: no arc, no tangent.
constexpr double kStraight = 1e-9;
/// Chords of a checked arc span at most this angle (radians): sagitta ≤ R·(1 − cos 7.5°) ≈ 0.009 R.
constexpr double kCheckStep = M_PI / 12.0;
/// Relative rounding allowed when a leg holds exactly its tangents (a planner steering to the
/// largest turn a run allows makes the two equal).
constexpr double kLegTolerance = 1e-9;
/// A stub's straight run shorter than this (in radii) is none: the arc starts at its node.
constexpr double kSameRun = 1e-3;
/// Fewest pieces of a rounded arc (fewer leave a small turn's cubic further from its arc).
constexpr int kMinArcPieces = 4;
/// Points placed on each leg next to an arc, as far apart as the arc's points.
constexpr int kLeadPoints = 2;

double turn(const Vec3& a, const Vec3& b) { return std::atan2(a.cross(b).norm(), a.dot(b)); }

/// Point of the arc rounding a corner (tangent point p1, unit normal n towards the centre,
/// unit incoming direction u) at angle phi from p1.
Vec3 arc_point(const Vec3& p1, const Vec3& n, const Vec3& u, double radius, double phi) {
  const Vec3 c = p1 + radius * n;
  return c + radius * (-std::cos(phi) * n + std::sin(phi) * u);
}

/// Unit normal of a corner's plane towards the centre of its arc.
Vec3 towards_centre(const Vec3& in, const Vec3& out) { return (out - in.dot(out) * in).normalized(); }

}  // namespace

Vec3 arc_line_in(const std::vector<Vec3>& v, const ArcLineEnds& ends, std::size_t k) {
  return k == 0 ? Vec3(ends.start_heading.normalized()) : Vec3((v[k] - v[k - 1]).normalized());
}

Vec3 arc_line_out(const std::vector<Vec3>& v, const ArcLineEnds& ends, std::size_t k) {
  return k + 1 == v.size() ? Vec3(ends.end_heading.normalized()) : Vec3((v[k + 1] - v[k]).normalized());
}

Vec3 corner_normal(const Vec3& in, const Vec3& out) {
  if (turn(in, out) < kStraight) return Vec3::Zero();
  return in.cross(out).normalized();
}

double leg_slack(const Vec3& n1, const Vec3& n2, double radius) {
  if (n1.isZero(0.0) || n2.isZero(0.0)) return 0.0;
  return kInnerLegSlack * radius * std::min(1.0, (n1 - n2).norm());
}

double corner_tangent(const Vec3& in, const Vec3& out, double radius) {
  const double th = turn(in, out);
  if (th < kStraight) return 0.0;
  if (M_PI - th < kStraight) return std::numeric_limits<double>::infinity();
  return radius * std::tan(0.5 * th);
}

std::vector<double> arc_line_tangents(const std::vector<Vec3>& v, const ArcLineEnds& ends, double radius) {
  std::vector<double> t(v.size());
  for (std::size_t k = 0; k < v.size(); ++k) t[k] = corner_tangent(arc_line_in(v, ends, k), arc_line_out(v, ends, k), radius);
  return t;
}

ShortLeg arc_line_short_leg(const std::vector<Vec3>& v, const ArcLineEnds& ends, double radius) {
  const std::vector<double> t = arc_line_tangents(v, ends, radius);
  const std::size_t n = v.size();
  auto normal = [&](std::size_t k) { return corner_normal(arc_line_in(v, ends, k), arc_line_out(v, ends, k)); };
  for (std::size_t k = 0; k <= n; ++k) {
    const double before = k == 0 ? 0.0 : t[k - 1];
    const double after = k == n ? 0.0 : t[k];
    const bool inner = k > 0 && k < n;
    const double length = k == 0 ? ends.start_run : k == n ? ends.end_run : (v[k] - v[k - 1]).norm();
    const double needed = before + after + (inner ? leg_slack(normal(k - 1), normal(k), radius) : 0.0);
    if (needed > length * (1.0 + kLegTolerance)) {
      ShortLeg s;
      s.leg = static_cast<int>(k);
      s.at = (k == n || (k > 0 && before >= after)) ? v[k - 1] : v[k];
      s.needed = needed;
      s.length = length;
      return s;
    }
  }
  return {};
}

double arc_line_length(const std::vector<Vec3>& v, const ArcLineEnds& ends, double radius) {
  const std::vector<double> t = arc_line_tangents(v, ends, radius);
  double len = 0.0;
  for (std::size_t k = 0; k + 1 < v.size(); ++k) len += (v[k + 1] - v[k]).norm();
  for (std::size_t k = 0; k < v.size(); ++k) {
    if (!(t[k] > 0.0)) continue;
    len += radius * turn(arc_line_in(v, ends, k), arc_line_out(v, ends, k)) - 2.0 * t[k];
  }
  // The end vertices' arcs reach into the stubs: count the rounded route from the first
  // tangent point to the last one.
  return len + t.front() + t.back();
}

std::vector<Vec3> arc_line_points(const std::vector<Vec3>& v, const ArcLineEnds& ends, double radius,
                                  double max_step) {
  const double step = max_step > 0.0 ? max_step : kCheckStep;
  const std::vector<double> t = arc_line_tangents(v, ends, radius);
  const std::size_t n = v.size();
  // Straight run between the arcs of vertex k − 1 and k (k = 0: the start stub's, k = n: the end's).
  auto gap = [&](std::size_t k) {
    const double len = k == 0 ? ends.start_run : k == n ? ends.end_run : (v[k] - v[k - 1]).norm();
    return std::max(0.0, len - (k > 0 ? t[k - 1] : 0.0) - (k < n ? t[k] : 0.0));
  };
  std::vector<Vec3> out;
  for (std::size_t k = 0; k < n; ++k) {
    const Vec3 in = arc_line_in(v, ends, k), o = arc_line_out(v, ends, k);
    const double th = turn(in, o);
    if (!(t[k] > 0.0) || !std::isfinite(t[k])) {
      out.push_back(v[k]);
      continue;
    }
    const Vec3 p1 = v[k] - t[k] * in, p2 = v[k] + t[k] * o, nc = towards_centre(in, o);
    const int pieces = std::max(kMinArcPieces, static_cast<int>(std::ceil(th / step)));
    // Lead points on the legs, spaced as the arc points, within half of each straight run:
    // the interpolating cubic then meets the arc with even spacing.
    const double chord = radius * th / pieces;
    const int before = std::min(kLeadPoints, static_cast<int>(0.5 * gap(k) / chord));
    const int after = std::min(kLeadPoints, static_cast<int>(0.5 * gap(k + 1) / chord));
    // An arc that uses (nearly) all of a stub starts at the stub's far end, the caller's
    // node: its tangent point would be a near-duplicate point, a cusp of the cubic.
    const bool at_start = k == 0 && gap(0) < kSameRun * radius, at_end = k + 1 == n && gap(n) < kSameRun * radius;
    for (int i = before; i >= 1; --i) out.push_back(p1 - (i * chord) * in);
    for (int i = at_start ? 1 : 0; i < pieces; ++i) out.push_back(arc_point(p1, nc, in, radius, th * i / pieces));
    if (!at_end) out.push_back(p2);
    for (int i = 1; i <= after; ++i) out.push_back(p2 + (i * chord) * o);
  }
  return out;
}

bool corner_arc_clear(const ObstacleIndex& index, const Vec3& vertex, const Vec3& in, const Vec3& out, double radius,
                      double required) {
  const double th = turn(in, out);
  const double t = corner_tangent(in, out, radius);
  if (!(t > 0.0)) return true;
  if (!std::isfinite(t)) return false;
  const Vec3 p1 = vertex - t * in, n = towards_centre(in, out);
  const int pieces = std::max(1, static_cast<int>(std::ceil(th / kCheckStep)));
  const double dphi = th / pieces;
  const double sag = radius * (1.0 - std::cos(0.5 * dphi));
  Vec3 a = p1;
  for (int i = 1; i <= pieces; ++i) {
    const Vec3 b = i == pieces ? Vec3(vertex + t * out) : arc_point(p1, n, in, radius, dphi * i);
    if (index.segment_within(a, b, required + sag)) return false;
    a = b;
  }
  return true;
}

}  // namespace loom
