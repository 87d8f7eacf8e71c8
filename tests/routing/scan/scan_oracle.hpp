#pragma once
/// Synthetic scans of tubes around closed-form centerlines, and the oracle that measures a
/// recovered centerline against the true one (shared by test_scan_adversarial and the scan
/// regressions). Independent of the scan code: the truth is a dense polyline of the
/// closed-form curve, distances are brute force.

#include "core/centerline.hpp"
#include "core/geometry.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <random>
#include <utility>
#include <vector>

namespace loom::scan_test {

constexpr double kPi = 3.14159265358979323846;

/// The true axis as a dense polyline with arc length and unit tangents.
struct TrueAxis {
  std::vector<Vec3> p;
  std::vector<double> s;
  std::vector<Vec3> tangent;
  /// Total arc length.
  double length() const { return s.back(); }
  /// Index of the last sample with arc length ≤ si.
  std::size_t index_at(double si) const {
    const auto it = std::upper_bound(s.begin(), s.end(), si);
    return static_cast<std::size_t>(std::clamp<std::ptrdiff_t>(it - s.begin() - 1, 0, static_cast<std::ptrdiff_t>(s.size()) - 2));
  }
};

/// Samples curve(u), u ∈ [0, 1], at `n` + 1 points.
inline TrueAxis make_axis(const std::function<Vec3(double)>& curve, int n = 6000) {
  TrueAxis t;
  for (int i = 0; i <= n; ++i) t.p.push_back(curve(static_cast<double>(i) / n));
  t.s.assign(t.p.size(), 0.0);
  for (std::size_t i = 1; i < t.p.size(); ++i) t.s[i] = t.s[i - 1] + (t.p[i] - t.p[i - 1]).norm();
  t.tangent.resize(t.p.size());
  for (std::size_t i = 0; i < t.p.size(); ++i) {
    const std::size_t a = i == 0 ? 0 : i - 1, b = std::min(i + 1, t.p.size() - 1);
    t.tangent[i] = (t.p[b] - t.p[a]).normalized();
  }
  return t;
}

/// How a tube is scanned.
struct ScanSpec {
  double radius = 1.0;
  std::size_t points = 20000;   ///< points on the surface (before outliers)
  double noise = 0.0;           ///< isotropic Gaussian σ, fraction of the diameter
  double outliers = 0.0;        ///< extra uniform points in the inflated box, fraction of `points`
  std::vector<std::pair<double, double>> gaps;  ///< unscanned stretches, fractions of the length
  /// Relative density along the cable (fraction of length → weight in (0, 1]); empty = uniform.
  std::function<double(double)> density;
  Vec3 view = Vec3::Zero();     ///< seen from +view only (surface normals with n·view > 0); 0 = all round
  std::uint64_t seed = 11;
};

/// Points on the tube of `spec.radius` around `axis`.
inline std::vector<Vec3> scan_tube(const TrueAxis& axis, const ScanSpec& spec) {
  std::mt19937_64 rng(spec.seed);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  std::normal_distribution<double> N(0.0, 1.0);
  const double d = 2.0 * spec.radius;
  std::vector<Vec3> pts;
  pts.reserve(spec.points);
  AABB box;
  for (const auto& p : axis.p) box.extend(p);
  while (pts.size() < spec.points) {
    const double f = U(rng), si = f * axis.length();
    if (spec.density && U(rng) > spec.density(f)) continue;
    bool in_gap = false;
    for (const auto& [a, b] : spec.gaps) in_gap = in_gap || (f >= a && f <= b);
    if (in_gap) continue;
    const std::size_t j = axis.index_at(si);
    const double u = (si - axis.s[j]) / std::max(axis.s[j + 1] - axis.s[j], 1e-300);
    const Vec3 c = axis.p[j] + u * (axis.p[j + 1] - axis.p[j]);
    const Vec3 T = (axis.p[j + 1] - axis.p[j]).normalized();
    const Vec3 e1 = T.unitOrthogonal(), e2 = T.cross(e1);
    const double th = 2.0 * kPi * U(rng);
    const Vec3 n = std::cos(th) * e1 + std::sin(th) * e2;
    if (spec.view.squaredNorm() > 0 && n.dot(spec.view) <= 0) continue;
    Vec3 q = c + spec.radius * n;
    if (spec.noise > 0) q += spec.noise * d * Vec3(N(rng), N(rng), N(rng));
    pts.push_back(q);
  }
  const auto n_out = static_cast<std::size_t>(spec.outliers * static_cast<double>(spec.points));
  const AABB big = box.inflated(3.0 * d);
  for (std::size_t i = 0; i < n_out; ++i)
    pts.emplace_back(big.min.x() + U(rng) * (big.max.x() - big.min.x()), big.min.y() + U(rng) * (big.max.y() - big.min.y()),
                     big.min.z() + U(rng) * (big.max.z() - big.min.z()));
  std::shuffle(pts.begin(), pts.end(), rng);
  return pts;
}

/// Distance from p to a polyline, and the arc length of the closest point.
inline std::pair<double, double> to_polyline(const std::vector<Vec3>& poly, const std::vector<double>& s, const Vec3& p) {
  double best = std::numeric_limits<double>::infinity(), bs = 0.0;
  for (std::size_t i = 1; i < poly.size(); ++i) {
    const Vec3 a = poly[i - 1], seg = poly[i] - a;
    const double L2 = seg.squaredNorm();
    const double u = L2 > 0 ? std::clamp((p - a).dot(seg) / L2, 0.0, 1.0) : 0.0;
    const double d2 = (p - a - u * seg).squaredNorm();
    if (d2 < best) {
      best = d2;
      bs = s[i - 1] + u * (s[i] - s[i - 1]);
    }
  }
  if (poly.size() == 1) return {(p - poly[0]).norm(), 0.0};
  return {std::sqrt(best), bs};
}

/// How far a recovered centerline is from the truth.
struct Deviation {
  double to_truth = 0.0;  ///< max distance of the recovered curve from the true axis
  double rms = 0.0;       ///< RMS of the same over the recovered samples
  double to_scan = 0.0;   ///< max distance of the true axis (scanned stretches) from the recovered curve
  double hausdorff() const { return std::max(to_truth, to_scan); }
};

/// Both one-sided Hausdorff distances by dense sampling (spacing `step`). True samples
/// inside a gap (widened by `margin` each side) or within `end_margin` of an end are not
/// required to be covered; recovered samples whose closest true point lies in such a
/// widened gap are not judged either (the curve bridges a gap by a guess).
inline Deviation measure(const TrueAxis& truth, const Centerline& c, double step, double end_margin = 0.0,
                         const std::vector<std::pair<double, double>>& gaps = {}, double margin = 0.0) {
  auto skipped = [&](double si) {
    for (const auto& [a, b] : gaps)
      if (si >= a * truth.length() - margin && si <= b * truth.length() + margin) return true;
    return false;
  };
  Deviation dv;
  std::vector<Vec3> rp;
  std::vector<double> rs;
  for (const auto& [s, p] : c.sample_by_arc_length(step)) {
    rp.push_back(p);
    rs.push_back(s);
  }
  double sq = 0.0;
  std::size_t n = 0;
  for (const auto& p : rp) {
    const auto [dist, ts] = to_polyline(truth.p, truth.s, p);
    if (skipped(ts)) continue;
    dv.to_truth = std::max(dv.to_truth, dist);
    sq += dist * dist;
    ++n;
  }
  dv.rms = n ? std::sqrt(sq / static_cast<double>(n)) : std::numeric_limits<double>::infinity();
  double next = 0.0;
  for (std::size_t i = 0; i < truth.p.size(); ++i) {
    if (truth.s[i] < next) continue;
    next = truth.s[i] + step;
    if (truth.s[i] < end_margin || truth.s[i] > truth.length() - end_margin || skipped(truth.s[i])) continue;
    dv.to_scan = std::max(dv.to_scan, to_polyline(rp, rs, truth.p[i]).first);
  }
  return dv;
}

}  // namespace loom::scan_test
