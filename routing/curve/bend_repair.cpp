// Bend-radius repair: fairing first (least change), then corner rounding with inserted
// key points on a circular arc of the required radius.
#include "routing/curve/bend_repair.hpp"

#include "routing/curve/fairing.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>

namespace loom {

namespace {

/// The rounding arc is made this much tighter-proof than required (the interpolating cubic
/// through arc points bends slightly more than the arc near its ends); grows per round.
constexpr double kArcMarginFirst = 1.1;
constexpr double kArcMarginStep = 0.15;
/// An arc may use at most this fraction of a leg it shares with another corner.
constexpr double kMaxLegShare = 0.5;
/// Arc points inserted between the two tangent points (plus the two tangent points).
constexpr int kArcInteriorPoints = 3;
/// Key points turning less than this (radians) lie on a straight leg.
constexpr double kStraightTurn = 1e-3;
/// A turn below this (radians) at a key point is no corner to round.
constexpr double kMinCornerTurn = 1e-6;

double turn_angle(const Vec3& a, const Vec3& b) { return std::atan2(a.cross(b).norm(), a.dot(b)); }

std::string num(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

/// Unique key points of an interpolant, in order.
std::vector<Vec3> unique_points(const Centerline& c) {
  std::vector<Vec3> out;
  double last = -std::numeric_limits<double>::infinity();
  for (double u : c.key_parameters())
    if (u > last) {
      out.push_back(c.position(u));
      last = u;
    }
  return out;
}

}  // namespace

BendRepairResult repair_bend_radius(const std::vector<Vec3>& points, const BendRepairOptions& opt) {
  if (!(opt.min_bend_radius > 0.0) || !std::isfinite(opt.min_bend_radius))
    throw std::invalid_argument("repair_bend_radius: min_bend_radius must be positive and finite");
  if (!(opt.max_deviation > 0.0) || !std::isfinite(opt.max_deviation))
    throw std::invalid_argument("repair_bend_radius: max_deviation must be positive and finite");
  const double R = opt.min_bend_radius;
  BendRepairResult res;
  Centerline c = Centerline::interpolate(points, opt.interpolation);
  std::vector<Vec3> pts = unique_points(c);
  res.worst = c.min_bend_radius();
  res.curve = c;
  res.points = pts;
  if (res.worst.radius >= R) {
    res.status = BendRepairStatus::AlreadySatisfied;
    return res;
  }
  double spent = 0.0;  // largest corner displacement so far
  std::vector<bool> on_arc(pts.size(), false);  // key points placed by corner rounding
  const int steps = std::max(opt.fairing_steps, 1);
  for (int round = 0;; ++round) {
    // 1. Fairing within what is left of the deviation budget, smallest budget first.
    const double budget = opt.max_deviation - spent;
    if (budget > 0.0) {
      for (int k = 0; k < steps; ++k) {
        FairingOptions f;
        f.tolerance = budget * std::ldexp(1.0, k - steps + 1);
        const FairingResult fr = fair_energy(c, f);
        if (fr.status != FairingStatus::Faired) continue;
        const BendExtremum w = fr.curve.min_bend_radius();
        if (w.radius >= R) {
          res.curve = fr.curve;
          res.worst = w;
          res.deviation_used = f.tolerance;
          res.points = unique_points(fr.curve);
          res.status = round == 0 ? BendRepairStatus::Faired : BendRepairStatus::PointsInserted;
          return res;
        }
      }
    }
    if (round >= opt.max_iterations) {
      res.reason = "no repair within " + std::to_string(opt.max_iterations) + " rounds of corner rounding";
      break;
    }
    // 2. Round the corner nearest to the tightest bend.
    const BendExtremum w = c.min_bend_radius();
    const std::vector<double> ku = [&] {
      std::vector<double> u;
      for (double v : c.key_parameters())
        if (u.empty() || v > u.back()) u.push_back(v);
      return u;
    }();
    const int n = static_cast<int>(pts.size());
    int i = -1;
    double best = std::numeric_limits<double>::infinity();
    for (int k = 1; k + 1 < n; ++k)
      if (std::abs(ku[k] - w.u) < best) {
        best = std::abs(ku[k] - w.u);
        i = k;
      }
    if (i < 0) {
      res.reason = "the tightest bend (radius " + num(w.radius) + " at s = " + num(w.s) +
                   ") lies between the end points: the end tangents force it";
      break;
    }
    // The legs run to the next real corner: key points on a straight leg may be dropped.
    auto turn_at = [&](int k) { return turn_angle(pts[k] - pts[k - 1], pts[k + 1] - pts[k]); };
    int jl = i - 1, jr = i + 1;
    while (jl > 0 && turn_at(jl) < kStraightTurn) --jl;
    while (jr + 1 < n && turn_at(jr) < kStraightTurn) ++jr;
    const Vec3 a = pts[i] - pts[i - 1], b = pts[i + 1] - pts[i];
    const double theta = turn_angle(a, b);
    if (theta < kMinCornerTurn) {
      res.reason = "the tightest bend (radius " + num(w.radius) + " at s = " + num(w.s) +
                   ") is not at a corner of the key points";
      break;
    }
    const double margin = kArcMarginFirst + kArcMarginStep * round;
    double Rr = margin * R;
    double d = Rr * std::tan(0.5 * theta);
    // A leg ending at another corner is shared with it; one ending at an arc already placed
    // (or at an end of the curve) is ours alone.
    const double share_l = (on_arc[jl] || jl == 0) ? 1.0 : kMaxLegShare;
    const double share_r = (on_arc[jr] || jr == n - 1) ? 1.0 : kMaxLegShare;
    const double dmax = std::min(share_l * (pts[i] - pts[jl]).norm(), share_r * (pts[jr] - pts[i]).norm());
    if (d > dmax) {
      d = dmax;
      Rr = d / std::tan(0.5 * theta);
    }
    const double dev = Rr * (1.0 / std::cos(0.5 * theta) - 1.0);
    if (Rr < R) {
      res.reason = "the corner at key point " + std::to_string(i) + " turns " + num(theta * 180.0 / M_PI) +
                   "° between legs too short for radius " + num(R) + " (at most " + num(Rr) + ")";
      break;
    }
    if (std::max(spent, dev) > opt.max_deviation) {
      res.reason = "rounding the corner at key point " + std::to_string(i) + " to radius " + num(Rr) +
                   " moves the path by " + num(dev) + " > max_deviation " + num(opt.max_deviation);
      break;
    }
    spent = std::max(spent, dev);
    const Vec3 ah = a.normalized(), bh = b.normalized();
    const Vec3 A = pts[i] - d * ah, B = pts[i] + d * bh;
    const Vec3 inward = (bh - ah).normalized();
    const Vec3 O = pts[i] + inward * (Rr / std::cos(0.5 * theta));
    const Vec3 axis = (A - O).cross(B - O).normalized();
    std::vector<Vec3> arc{A};
    for (int k = 1; k <= kArcInteriorPoints; ++k) {
      const double phi = theta * k / (kArcInteriorPoints + 1);  // the arc subtends the turn angle
      arc.push_back(O + Eigen::AngleAxisd(phi, axis) * (A - O));
    }
    arc.push_back(B);
    // Drop the key points of the legs that the arc replaces (those closer to the corner
    // than its tangent points), then put the arc in the corner's place.
    int first = i, last = i;
    while (first - 1 > jl && (pts[first - 1] - pts[i]).norm() <= d) --first;
    while (last + 1 < jr && (pts[last + 1] - pts[i]).norm() <= d) ++last;
    pts.erase(pts.begin() + first, pts.begin() + last + 1);
    pts.insert(pts.begin() + first, arc.begin(), arc.end());
    on_arc.erase(on_arc.begin() + first, on_arc.begin() + last + 1);
    on_arc.insert(on_arc.begin() + first, arc.size(), true);
    res.points_inserted += static_cast<int>(arc.size()) - 1;
    res.iterations = round + 1;
    c = Centerline::interpolate(pts, opt.interpolation);
    res.curve = c;
    res.points = pts;
    res.worst = c.min_bend_radius();
    if (res.worst.radius >= R) {
      res.status = BendRepairStatus::PointsInserted;
      return res;
    }
  }
  res.status = BendRepairStatus::Failed;
  res.worst = res.curve.min_bend_radius();
  return res;
}

}  // namespace loom
