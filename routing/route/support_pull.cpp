#include "routing/route/support_pull.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace loom {

namespace {

/// A point of the polyline at arc length s, on segment `seg` (points[seg] → points[seg+1]),
/// with its nearest supporting part: distance d (capped) and the closest surface point q.
struct Sample {
  double s = 0.0;
  Vec3 p = Vec3::Zero();
  std::size_t seg = 0;
  bool at_vertex = false;  ///< a key point itself (not moved: only new points are inserted)
  double d = std::numeric_limits<double>::infinity();
  Vec3 q = Vec3::Zero();
};

/// A stretch between two supports (arc lengths; the ends may be virtual, beyond the polyline).
struct Gap {
  double a = 0.0, b = 0.0;
};

class Puller {
 public:
  Puller(const ObstacleIndex& index, const SupportPullSettings& set) : index_(index), set_(set) {
    for (int i = 0; i < index.part_count(); ++i) {
      const auto k = static_cast<std::size_t>(i);
      const bool supports = set.part_supports.empty() || (k < set.part_supports.size() && set.part_supports[k]);
      (supports ? supporting_ : others_).push_back(i);
    }
    // Samples close enough that a support between two of them is not missed by much.
    step_ = std::min(set.spacing / 32.0, set.reach);
    target_ = set.target > 0.0 ? set.target : 0.5 * (set.required + set.reach);
    firm_ = 0.5 * (target_ + set.reach);
  }

  bool any_support() const { return !supporting_.empty(); }

  /// Nearest supporting part to p, searched up to 4 × reach (farther is "unsupported" alike).
  ClosestHit support_hit(const Vec3& p) const {
    const double cap = 4.0 * set_.reach;
    const ClosestHit hit = index_.closest(p, cap);
    if (!hit.found() || others_.empty() || std::find(others_.begin(), others_.end(), hit.part) == others_.end())
      return hit;
    ClosestHit best;
    for (int part : supporting_) {
      const ClosestHit h = index_.closest_on_part(p, part, std::min(cap, best.distance));
      if (h.found() && h.distance < best.distance) best = h;
    }
    return best;
  }

  std::vector<Sample> sample(const std::vector<Vec3>& pts) const {
    std::vector<Sample> out;
    double s0 = 0.0;
    for (std::size_t i = 0; i + 1 < pts.size(); ++i) {
      const double len = (pts[i + 1] - pts[i]).norm();
      const int n = std::max(1, static_cast<int>(std::ceil(len / step_)));
      for (int k = (i == 0 ? 0 : 1); k <= n; ++k) {
        Sample sm;
        const double t = static_cast<double>(k) / n;
        sm.s = s0 + t * len;
        sm.p = pts[i] + t * (pts[i + 1] - pts[i]);
        sm.seg = i;
        sm.at_vertex = k == 0 || k == n;
        const ClosestHit h = support_hit(sm.p);
        if (h.found()) {
          sm.d = h.distance;
          sm.q = h.point;
        }
        out.push_back(sm);
      }
      s0 += len;
    }
    return out;
  }

  /// Stretches between consecutive supports longer than the spacing. A port end is a
  /// support at its end; a branch-point end a virtual one spacing / 2 beyond it.
  std::vector<Gap> gaps(const std::vector<Sample>& sm, double length, double& longest) const {
    std::vector<double> at;
    at.push_back(set_.start_is_port ? 0.0 : -0.5 * set_.spacing);
    for (const Sample& x : sm)
      if (x.d <= firm_) at.push_back(x.s);
    at.push_back(set_.end_is_port ? length : length + 0.5 * set_.spacing);
    std::vector<Gap> out;
    longest = 0.0;
    for (std::size_t i = 1; i < at.size(); ++i) {
      longest = std::max(longest, std::min(at[i], length) - std::max(at[i - 1], 0.0));
      if (at[i] - at[i - 1] > set_.spacing) out.push_back({at[i - 1], at[i]});
    }
    return out;
  }

  /// Tries to support gap g: at its samples nearest to structure (inside the window that
  /// splits it), moves a point towards structure and inserts it. True if one was inserted.
  bool fix(const Gap& g, const std::vector<Sample>& sm, std::vector<Vec3>& pts) const {
    // A support in (b − spacing, a + spacing) splits a gap of up to 2·spacing in two good
    // ones; a longer gap is cut from its start. 0.9: the move lengthens the way a little.
    const double lo = std::max(g.a, g.b - 0.9 * set_.spacing), hi = std::min(g.b, g.a + 0.9 * set_.spacing);
    const bool split = lo < hi;
    // Candidates: the window's samples nearest to structure first, then the rest of the
    // gap's (a support anywhere in it shortens it; the next round supports what is left).
    std::vector<const Sample*> in_window, rest;
    for (const Sample& x : sm) {
      if (x.at_vertex || !(x.s > g.a && x.s < g.b) || !std::isfinite(x.d)) continue;
      const bool in = split ? (x.s >= lo && x.s <= hi) : x.s <= g.a + 0.9 * set_.spacing;
      (in ? in_window : rest).push_back(&x);
    }
    auto nearest_first = [](const Sample* u, const Sample* v) { return u->d < v->d || (u->d == v->d && u->s < v->s); };
    std::sort(in_window.begin(), in_window.end(), nearest_first);
    std::sort(rest.begin(), rest.end(), nearest_first);
    if (in_window.size() > kCandidates) in_window.resize(kCandidates);
    if (rest.size() > kCandidates) rest.resize(kCandidates);
    std::vector<const Sample*> cand = in_window;
    cand.insert(cand.end(), rest.begin(), rest.end());
    for (const Sample* x : cand) {
      const Vec3 away = x->p - x->q;
      const double d = away.norm();
      if (!(d > target_)) continue;
      const Vec3 goal = x->q + away * (target_ / d);
      for (double f : {1.0, 0.75, 0.5, 0.25}) {
        const Vec3 np = x->p + f * (goal - x->p);
        if ((np - x->q).norm() > firm_) break;  // shorter moves reach even less
        const Vec3 &a = pts[x->seg], &b = pts[x->seg + 1];
        if (index_.segment_within(a, np, set_.required) || index_.segment_within(np, b, set_.required)) continue;
        pts.insert(pts.begin() + static_cast<std::ptrdiff_t>(x->seg + 1), np);
        return true;
      }
    }
    return false;
  }

 private:
  static constexpr std::size_t kCandidates = 6;  ///< samples tried per gap, nearest first
  const ObstacleIndex& index_;
  const SupportPullSettings& set_;
  std::vector<int> supporting_, others_;
  double step_ = 0.0, target_ = 0.0;
  /// A sample this near structure counts as a support: the spline through the key points
  /// strays from them, so a point just within reach may not be on the curve.
  double firm_ = 0.0;
};

double polyline_length(const std::vector<Vec3>& p) {
  double l = 0.0;
  for (std::size_t i = 1; i < p.size(); ++i) l += (p[i] - p[i - 1]).norm();
  return l;
}

}  // namespace

SupportPullResult pull_to_structure(const ObstacleIndex& index, const std::vector<Vec3>& points,
                                    const SupportPullSettings& settings) {
  if (!(settings.spacing > 0.0) || !std::isfinite(settings.spacing))
    throw std::invalid_argument("pull_to_structure: spacing must be finite and > 0");
  if (!(settings.reach > settings.required) || !std::isfinite(settings.reach))
    throw std::invalid_argument("pull_to_structure: reach must be finite and beyond the required distance");
  SupportPullResult r;
  r.points = points;
  if (points.size() < 2) return r;
  const Puller puller(index, settings);
  std::vector<Sample> sm = puller.sample(r.points);
  std::vector<Gap> open = puller.gaps(sm, polyline_length(r.points), r.longest_span_before);
  // Forward over the gaps: one that cannot be supported is passed (cursor), and since
  // points are only inserted after the cursor, the arc lengths before it never change.
  double cursor = -std::numeric_limits<double>::infinity();
  while (puller.any_support() && r.inserted < settings.max_insertions) {
    const auto g = std::find_if(open.begin(), open.end(), [&](const Gap& x) { return x.a >= cursor; });
    if (g == open.end()) break;
    if (puller.fix(*g, sm, r.points)) {
      ++r.inserted;
      sm = puller.sample(r.points);
    } else {
      cursor = std::nextafter(g->a, std::numeric_limits<double>::infinity());
    }
    open = puller.gaps(sm, polyline_length(r.points), r.longest_span_after);
  }
  open = puller.gaps(sm, polyline_length(r.points), r.longest_span_after);
  r.unfixed_spans = static_cast<int>(open.size());
  return r;
}

}  // namespace loom

