// The pair rules' excuses on one chord pair (chord_pair_excuse.hpp).
#include "routing/audit/chord_pair_excuse.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

namespace loom::audit {

namespace {

/// The parameters in [0, 1] of the chord from a (arc length sa) to b (sb) whose arc length
/// lies in [r0, r1], widened by the slack of segment_at(); false if none do.
bool arc_interval(double sa, double sb, double r0, double r1, double& lo, double& hi) {
  const double slack_lo = kTouchRel * (1.0 + std::abs(r0)), slack_hi = kTouchRel * (1.0 + std::abs(r1));
  if (sb + slack_lo < r0 || sa - slack_hi > r1) return false;
  if (!(sb > sa)) {
    lo = 0.0;
    hi = 1.0;
    return true;
  }
  lo = std::clamp((r0 - slack_lo - sa) / (sb - sa), 0.0, 1.0);
  hi = std::clamp((r1 + slack_hi - sa) / (sb - sa), 0.0, 1.0);
  return lo <= hi;
}

/// The parameters in [0, 1] of the chord from a to b within distance `radius` of c; false
/// if none are.
bool ball_interval(const Vec3& a, const Vec3& b, const Vec3& c, double radius, double& lo, double& hi) {
  const Vec3 d = b - a, w = a - c;
  const double dd = d.squaredNorm(), wd = w.dot(d), ww = w.squaredNorm() - radius * radius;
  if (!(dd > 0.0)) {
    lo = 0.0;
    hi = 1.0;
    return ww <= 0.0;
  }
  const double disc = wd * wd - dd * ww;
  if (disc < 0.0) return false;
  const double root = std::sqrt(disc);
  lo = std::max(0.0, (-wd - root) / dd);
  hi = std::min(1.0, (-wd + root) / dd);
  return lo <= hi;
}

}  // namespace

std::optional<SegmentSegmentResult> closest_apart(const Vec3& pa, const Vec3& pb, double sa, double sb, const Vec3& qa,
                                                  const Vec3& qb, double ta, double tb, double gap) {
  std::optional<SegmentSegmentResult> best;
  const double ls = sb - sa, lt = tb - ta;
  if (!(std::max(ls, lt) > 0.0)) return best;  // two points: |s − t| is what it is
  const Vec3 dp = pb - pa, dq = qb - qa;
  for (const double c : {gap, -gap}) {
    // On the edge s − t = c: λ = l0 + l1·x and μ = m0 + m1·x, x the longer chord's parameter.
    double l0 = 0.0, l1 = 1.0, m0 = 0.0, m1 = 1.0;
    if (ls >= lt) {
      l0 = (c + ta - sa) / ls;
      l1 = lt / ls;
    } else {
      m0 = (sa - ta - c) / lt;
      m1 = ls / lt;
    }
    // The x for which both parameters stay within their chords.
    double lo = 0.0, hi = 1.0;
    for (const auto& [v0, v1] : {std::pair{l0, l1}, std::pair{m0, m1}}) {
      if (v1 > 0.0) {
        lo = std::max(lo, -v0 / v1);
        hi = std::min(hi, (1.0 - v0) / v1);
      } else if (v0 < 0.0 || v0 > 1.0) {
        hi = -1.0;
      }
    }
    if (!(lo <= hi)) continue;
    // P − Q = w0 + x·w1 along the edge.
    const Vec3 w0 = pa + l0 * dp - (qa + m0 * dq), w1 = l1 * dp - m1 * dq;
    const double ww = w1.squaredNorm();
    const double x = ww > 0.0 ? std::clamp(-w0.dot(w1) / ww, lo, hi) : lo;
    SegmentSegmentResult r;
    r.s = std::clamp(l0 + l1 * x, 0.0, 1.0);
    r.t = std::clamp(m0 + m1 * x, 0.0, 1.0);
    r.p = pa + r.s * dp;
    r.q = qa + r.t * dq;
    r.dist2 = (r.p - r.q).squaredNorm();
    if (!best || r.dist2 < best->dist2) best = r;
  }
  return best;
}

std::optional<ParamBox> ball_box(const Vec3& pa, const Vec3& pb, const Vec3& qa, const Vec3& qb, const Vec3& center,
                                 double radius) {
  ParamBox x{};
  if (ball_interval(pa, pb, center, radius, x.l0, x.l1) && ball_interval(qa, qb, center, radius, x.m0, x.m1)) return x;
  return std::nullopt;
}

std::vector<ParamBox> excused_boxes(const CableInput& ca, const Vec3& pa, const Vec3& pb, double sa0, double sa1,
                                    const CableInput& cb, const Vec3& qa, const Vec3& qb, double tb0, double tb1) {
  std::vector<ParamBox> out;
  ParamBox x{};
  for (const auto& ra : ca.segments)
    for (const auto& rb : cb.segments)
      if (ra.segment >= 0 && ra.segment == rb.segment && arc_interval(sa0, sa1, ra.s0, ra.s1, x.l0, x.l1) &&
          arc_interval(tb0, tb1, rb.s0, rb.s1, x.m0, x.m1))
        out.push_back(x);
  for (const auto& ja : ca.junctions)
    for (const auto& jb : cb.junctions)
      if (ja.node == jb.node)
        if (const auto b = ball_box(pa, pb, qa, qb, ja.position, std::max(ja.radius, jb.radius))) out.push_back(*b);
  return out;
}

std::optional<SegmentSegmentResult> closest_unexcused(const std::vector<ParamBox>& boxes, const Vec3& pa,
                                                      const Vec3& pb, const Vec3& qa, const Vec3& qb) {
  std::optional<SegmentSegmentResult> best;
  const Vec3 dp = pb - pa, dq = qb - qa;
  // Closest point of P(λ) (λ fixed, on_a) or Q(μ) (μ fixed) to the other chord over [u0, u1].
  auto edge = [&](bool fixed_on_a, double fixed, double u0, double u1) {
    const Vec3 x = fixed_on_a ? Vec3(pa + fixed * dp) : Vec3(qa + fixed * dq);
    const Vec3& o = fixed_on_a ? qa : pa;
    const Vec3& d = fixed_on_a ? dq : dp;
    const double dd = d.squaredNorm();
    const double u = dd > 0.0 ? std::clamp((x - o).dot(d) / dd, u0, u1) : u0;
    SegmentSegmentResult r;
    r.s = fixed_on_a ? fixed : u;
    r.t = fixed_on_a ? u : fixed;
    r.p = pa + r.s * dp;
    r.q = qa + r.t * dq;
    r.dist2 = (r.p - r.q).squaredNorm();
    if (!best || r.dist2 < best->dist2) best = r;
  };
  for (std::size_t k = 0; k < boxes.size(); ++k) {
    const ParamBox& b = boxes[k];
    // Each edge: which chord's parameter is fixed, its value, the outward direction, the
    // other parameter's range. Edges on the square's border have no outside.
    const struct {
      bool on_a;
      double at;
      int out;
      double u0, u1;
    } edges[] = {{true, b.l0, -1, b.m0, b.m1}, {true, b.l1, +1, b.m0, b.m1}, {false, b.m0, -1, b.l0, b.l1},
                 {false, b.m1, +1, b.l0, b.l1}};
    for (const auto& e : edges) {
      if ((e.out < 0 && e.at <= 0.0) || (e.out > 0 && e.at >= 1.0)) continue;
      // The edge minus the parts where another box lies on its outer side.
      std::vector<std::pair<double, double>> free{{e.u0, e.u1}};
      for (std::size_t j = 0; j < boxes.size() && !free.empty(); ++j) {
        if (j == k) continue;
        const ParamBox& o = boxes[j];
        const double f0 = e.on_a ? o.l0 : o.m0, f1 = e.on_a ? o.l1 : o.m1;
        const bool covers = e.out > 0 ? (f0 <= e.at && e.at < f1) : (f0 < e.at && e.at <= f1);
        if (!covers) continue;
        const double c0 = e.on_a ? o.m0 : o.l0, c1 = e.on_a ? o.m1 : o.l1;
        std::vector<std::pair<double, double>> rest;
        for (const auto& [u0, u1] : free) {
          if (c0 > u0) rest.emplace_back(u0, std::min(u1, c0));
          if (c1 < u1) rest.emplace_back(std::max(u0, c1), u1);
        }
        free.swap(rest);
      }
      for (const auto& [u0, u1] : free)
        if (u0 <= u1) edge(e.on_a, e.at, u0, u1);
    }
  }
  return best;
}

std::optional<PairContact> judge_chord_pair(const std::vector<CableInput>& cables, const ChordRef& A, const ChordRef& B,
                                            SegmentSegmentResult r) {
  const CableInput& ca = cables[static_cast<std::size_t>(A.cable)];
  const CableInput& cb = cables[static_cast<std::size_t>(B.cable)];
  const bool self = A.cable == B.cable;
  const double r_sum = ca.radius + cb.radius;
  const double self_gap = M_PI * ca.radius;
  if (!(std::sqrt(r.dist2) < r_sum)) return std::nullopt;
  double s = A.s0 + r.s * (A.s1 - A.s0), t = B.s0 + r.t * (B.s1 - B.s0);
  if (self && std::abs(s - t) < self_gap) {
    // Excused there: the closest points of the two chords at least π r apart instead.
    const auto apart = closest_apart(A.a, A.b, A.s0, A.s1, B.a, B.b, B.s0, B.s1, self_gap);
    if (!apart) return std::nullopt;
    r = *apart;
  }
  if (self && self_excused_at_node(ca, r.p, r.q)) return std::nullopt;  // the node's turn: a bend
  if (!self && excused(ca, s, r.p, cb, t, r.q)) {
    // Excused there: the closest points of the two chords outside the excused region instead.
    const auto boxes = excused_boxes(ca, A.a, A.b, A.s0, A.s1, cb, B.a, B.b, B.s0, B.s1);
    const auto outside = closest_unexcused(boxes, A.a, A.b, B.a, B.b);
    if (!outside) return std::nullopt;
    r = *outside;
  }
  s = A.s0 + r.s * (A.s1 - A.s0);
  t = B.s0 + r.t * (B.s1 - B.s0);
  const double d = std::sqrt(r.dist2);
  if (!(d < r_sum)) return std::nullopt;
  return PairContact::ordered(A.cable, s, A.s0, A.s1, r.p, B.cable, t, B.s0, B.s1, r.q, d);
}

}  // namespace loom::audit
