// Flattening a centerline into chords with a proven deviation bound (chord_plan.hpp).
#include "routing/audit/chord_plan.hpp"

#include <algorithm>
#include <cmath>

namespace loom {

double deviation_chords(const Centerline& c, double a, double b, double eps) {
  if (c.degree() < 2) return 1.0;
  const double inset = 1e-9 * (b - a);
  double m = std::max(c.derivative(a + inset, 2).norm(), c.derivative(b - inset, 2).norm());
  if (c.degree() > 3) {  // C'' not affine: sample densely and keep a safety factor
    for (int k = 1; k < 16; ++k) m = std::max(m, c.derivative(a + (b - a) * k / 16.0, 2).norm());
    m *= 1.5;
  }
  return std::max(1.0, (b - a) * std::sqrt(m / (8.0 * eps)));
}

double length_chords(const Centerline& c, double a, double b, double hmax) {
  // On a span of a degree ≤ 3 spline C' is a quadratic Bézier curve (the hodograph) with
  // control points C'(a), C'(a) + h·C''(a)/2 and C'(b): |C'| stays within the largest of
  // their norms (convex hull). Above degree 3, as in deviation_chords, dense samples with
  // a margin.
  const double h = b - a, inset = 1e-9 * h;
  const Vec3 d0 = c.derivative(a + inset, 1);
  double v = std::max(d0.norm(), c.derivative(b - inset, 1).norm());
  if (c.degree() <= 3) {
    v = std::max(v, (d0 + 0.5 * h * c.derivative(a + inset, 2)).norm());
  } else {
    for (int k = 1; k < 16; ++k) v = std::max(v, c.derivative(a + h * k / 16.0, 1).norm());
    v *= 1.5;
  }
  return std::max(1.0, h * v / hmax);
}

namespace {

/// The chords of a stretch [u0, u1] of a centerline, piece by piece: each piece [a, b] is
/// cut uniformly in u into n chords that deviate at most eps from the curve and are no
/// longer than hmax. A piece is one knot span, cut by the deviation bound above, or a run
/// of consecutive short spans (each shorter than short_len) taken as one chord: the convex
/// hull property puts each piece inside the hull of its Bézier points, so the run lies
/// within their largest distance from the chord (Centerline::hull_bounds), and where that
/// is ≤ eps the one chord is certified. Why: key points far closer together than the cable
/// is thick (a dense export, a scan) give thousands of spans within a few radii, one chord
/// each at least, and every chord pair among them a broad-phase candidate; their hull shows
/// how little the curve moves there.
class ChordPlan {
 public:
  ChordPlan(const Centerline& c, double u0, double u1, double eps, double hmax, double short_len)
      : c_(c), eps_(eps), hmax_(hmax), short_len_(short_len) {
    br_.push_back(u0);
    for (double k : c.knots())
      if (k > br_.back() && k < u1) br_.push_back(k);
    br_.push_back(u1);
    s_.assign(br_.size(), -1.0);
  }

  /// Calls piece(a, b, sa, sb, n) for each piece in order (sa, sb: exact arc lengths at
  /// its ends, n ≥ 1 chords).
  template <class F>
  void visit(F&& piece) {
    for (std::size_t i = 0; i + 1 < br_.size();) {
      if (!(br_[i + 1] > br_[i])) {
        ++i;
        continue;
      }
      const std::size_t j = merged_end(i);
      if (j > i) {  // a run of short spans (perhaps one) that is one chord
        piece(br_[i], br_[j], s(i), s(j), std::size_t(1));
        i = j;
        continue;
      }
      const double a = br_[i], b = br_[i + 1];
      const double n_dev = deviation_chords(c_, a, b, eps_);
      const double n_len = length_chords(c_, a, b, hmax_);
      piece(a, b, s(i), s(i + 1), static_cast<std::size_t>(std::ceil(std::max(n_dev, n_len))));
      ++i;
    }
  }

 private:
  /// Exact arc length at break i (cached).
  double s(std::size_t i) {
    if (s_[i] < 0.0) s_[i] = c_.arc_length_at(br_[i]);
    return s_[i];
  }
  bool short_span(std::size_t i) { return s(i + 1) - s(i) < short_len_; }

  /// True if the pieces i..j−1 are short, no longer than hmax together, and their control
  /// points lie within eps of the chord from br_[i] to br_[j].
  bool one_chord(std::size_t i, std::size_t j) {
    if (!(s(j) - s(i) <= hmax_)) return false;
    for (std::size_t k = i; k < j; ++k)
      if (!short_span(k)) return false;
    return c_.hull_bounds(br_[i], br_[j]).deviation <= eps_;
  }

  /// A j > i with one_chord(i, j), by doubling the run from i + 1 while the test passes
  /// (every answer checked, so it is certified even where the test is not monotone in j;
  /// no bisection after the first failure: the next run starts there), or i if not even
  /// the piece i alone passes. Work: about twice the pieces merged.
  std::size_t merged_end(std::size_t i) {
    const std::size_t last = br_.size() - 1;
    if (!short_span(i) || !one_chord(i, i + 1)) return i;
    std::size_t ok = i + 1;
    for (std::size_t step = 1; ok < last; step *= 2) {
      const std::size_t t = std::min(last, ok + step);
      if (!one_chord(i, t)) break;
      ok = t;
    }
    return ok;
  }

  const Centerline& c_;
  double eps_, hmax_, short_len_;
  std::vector<double> br_;
  std::vector<double> s_;
};

}  // namespace

double planned_chords(const Centerline& c, double eps, double hmax, double short_len) {
  double n = 0.0;
  ChordPlan(c, c.u_min(), c.u_max(), eps, hmax, short_len)
      .visit([&](double, double, double, double, std::size_t k) { n += static_cast<double>(k); });
  return n;
}

void flatten(const Centerline& c, double u0, double u1, double eps, double hmax, double short_len, Chords& out) {
  if (out.p.empty()) {
    out.p.push_back(c.position(u0));
    out.s.push_back(c.arc_length_at(u0));
  }
  std::vector<double> lens;
  ChordPlan(c, u0, u1, eps, hmax, short_len).visit([&](double a, double b, double, double sb, std::size_t n) {
    const double sa = out.s.back();
    double acc = 0.0;
    lens.clear();
    for (std::size_t k = 1; k <= n; ++k) {
      const double u = k == n ? b : a + (b - a) * static_cast<double>(k) / static_cast<double>(n);
      out.p.push_back(c.position(u));
      acc += (out.p.back() - out.p[out.p.size() - 2]).norm();
      lens.push_back(acc);
    }
    for (std::size_t k = 0; k < n; ++k)
      out.s.push_back(acc > 0.0 ? sa + (sb - sa) * lens[k] / acc : sa + (sb - sa) * (k + 1.0) / n);
  });
}

}  // namespace loom
