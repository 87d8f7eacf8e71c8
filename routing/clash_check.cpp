// Clash checking: the seed paper's discrete-point method and the certified variant
// (Lipschitz sphere tracing + exact chord distances). See clash_check.hpp for the contract.
#include "routing/clash_check.hpp"

#include "core/error.hpp"
#include "index/box_pairs.hpp"
#include "index/box_tree.hpp"
#include "index/triangle_distance.hpp"
#include "routing/chord_plan.hpp"
#include "routing/stretch_tracker.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <functional>
#include <limits>
#include <optional>
#include <map>
#include <memory>
#include <mutex>
#include <numeric>
#include <stdexcept>
#include <string>
#include <tuple>
#include <unordered_map>

namespace loom {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
/// Default tolerance as a fraction of the smallest cable radius (DESIGN §7).
constexpr double kDefaultToleranceOfRadius = 0.01;
/// The tolerance reported when there is no cable to derive it from (nothing is checked).
constexpr double kNoCableTolerance = 0.01;
/// Default longest sphere-tracing step, in cable radii.
constexpr double kDefaultMaxStepRadii = 50.0;
/// Share of the tolerance left to the chords' distance from the curve; the rest covers the
/// index's own error (structure: chord + index ≤ tol; cable–cable: 2 · chord ≤ tol).
constexpr double kChordShareOfTolerance = 0.5;
/// Stretches of the sphere trace shorter than this many cable radii that cannot be proven
/// clear are handed to the exact chord measurement.
constexpr double kLeafRadii = 2.0;
/// Longest chord, in cable radii (keeps the self rule |s − t| ≥ πr sharp: the paper's
/// sample spacing 2r).
constexpr double kMaxChordRadii = 2.0;
/// Knot spans shorter than this many cable radii may be merged into one chord with their
/// short neighbours (ChordPlan): routes hold no key points this close on purpose.
constexpr double kShortSpanRadii = 0.25;
/// Most chords the certified audit accepts for one cable's deviation bound. A routed cable
/// (bends of at least a few radii) needs a few thousand at the default tolerance, a
/// 100 m cable at a 1 µm tolerance ~10⁶; beyond this the route wiggles on the scale of the
/// tolerance (e.g. 200,000 key points 1 µm apart) and flattening it would not end.
constexpr double kMaxChordsPerCable = 1e7;
/// Chords per block in the cable–cable narrow phase.
constexpr std::size_t kBlock = 8;
/// Arc-length slack (relative to the cable length) when deciding that two chord or sample
/// intervals touch.
constexpr double kTouchRel = 1e-9;
/// A sphere-tracing query cut short at the distance a decision needs stops this much
/// (relative to the largest query radius) beyond it, so that rounding does not leave the
/// bound a hair short of the decision.
constexpr double kCutMarginRel = 1e-9;
/// With approximate queries, a leaf stretch whose bounds fell short of a proof that its
/// samples' surface points could give is retried with queries this much finer than the
/// request's ε (a lower bound is all a proof needs; exact values cost ~3× more near a
/// finely tessellated surface).
constexpr double kProofErrorShare = 0.125;

std::int64_t as_i64(std::size_t v) { return static_cast<std::int64_t>(v); }

/// Work counters shared by the worker threads.
struct AtomicCounters {
  std::atomic<std::int64_t> distance{0}, inside{0}, pairs{0}, samples{0}, deferred{0}, deferred_measured{0};
  // Written once, by the cable–cable pass.
  std::atomic<std::int64_t> block_overlaps_estimate{0}, block_pairs{0}, pair_contacts{0};
  /// Adds a thread's local counts (one atomic add per counter, not one per query).
  void add(const ClashCounters& c) {
    distance += c.distance_queries;
    inside += c.inside_queries;
    pairs += c.pair_tests;
    samples += c.samples;
    deferred += c.deferred_chords;
    deferred_measured += c.deferred_measured;
  }
  ClashCounters snapshot() const {
    ClashCounters c;
    c.distance_queries = distance.load();
    c.inside_queries = inside.load();
    c.pair_tests = pairs.load();
    c.samples = samples.load();
    c.deferred_chords = deferred.load();
    c.deferred_measured = deferred_measured.load();
    c.block_overlaps_estimate = block_overlaps_estimate.load();
    c.block_pairs = block_pairs.load();
    c.pair_contacts = pair_contacts.load();
    return c;
  }
};

/// Runs body(i), i in [0, n), on `threads` workers (≤ 0: all cores), grain 1.
template <class Body>
void parallel_indices(std::size_t n, int threads, const Body& body) {
  if (n == 0) return;
  tbb::task_arena arena(threads > 0 ? threads : tbb::task_arena::automatic);
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t i = r.begin(); i != r.end(); ++i) body(i);
    });
  });
}

// ---------------------------------------------------------------------------------------
// Shared context.

struct Context {
  const std::vector<CableInput>& cables;
  const std::vector<Part>& parts;
  const ObstacleIndex* index;
  const ClashRequest& req;
  std::vector<PartInfo> info;
  double tol = 0.0;
  double chord_error = 0.0;
  double abs_err = 0.0;
  double band = 0.0;  ///< largest required clearance over parts
  AtomicCounters counters;
  /// BVH over the parts' boxes (info[q].box): the parts near a stretch without a pass over
  /// every part (assemblies have thousands). Built for the certified structure pass only.
  std::unique_ptr<BoxTree> part_tree;
};

/// Segment id of the cable at arc length s (−1 if unknown).
int segment_at(const CableInput& c, double s) {
  const double slack = kTouchRel * (1.0 + std::abs(s));
  for (const auto& r : c.segments)
    if (s >= r.s0 - slack && s <= r.s1 + slack) return r.segment;
  return -1;
}

/// True when a contact between cables a (point p, arc s) and b (point q, arc t) is excused:
/// both run in the same harness segment (a bundle) or both are at a node they share.
bool excused(const CableInput& a, double s, const Vec3& p, const CableInput& b, double t, const Vec3& q) {
  const int sa = segment_at(a, s);
  if (sa >= 0 && sa == segment_at(b, t)) return true;
  for (const auto& ja : a.junctions)
    for (const auto& jb : b.junctions)
      if (ja.node == jb.node) {
        const double rad = std::max(ja.radius, jb.radius);
        if ((p - ja.position).norm() <= rad && (q - ja.position).norm() <= rad) return true;
      }
  return false;
}

// ---------------------------------------------------------------------------------------
// Certified cable–structure.

/// Sphere-traces one cable, measures what cannot be proven clear exactly, tracks stretches.
class StructureTracer {
 public:
  StructureTracer(Context& ctx, int cable)
      : ctx_(ctx),
        cable_(cable),
        in_(ctx.cables[cable]),
        r_(in_.radius),
        tracker_(cable, r_, ctx.info, in_.attachments, [this](PartObservation& o) { measure_deferred(o); }) {
    L_ = in_.curve.length();
    margin_ = ctx.chord_error + ctx.abs_err;
    thr_ = r_ + ctx.band + margin_;
    leaf_ = std::max(kLeafRadii * r_, 4.0 * ctx.tol);
    max_step_ = ctx.req.max_step > 0.0 ? ctx.req.max_step : kDefaultMaxStepRadii * r_;
    max_step_ = std::max(max_step_, leaf_);
    cut_margin_ = ctx.abs_err + kCutMarginRel * (thr_ + max_step_);
    rel_error_ = ctx.req.distance_rel_error;
  }

  void run() {
    const ObstacleIndex& idx = *ctx_.index;
    const double cap = thr_ + max_step_;  // the largest query radius
    // Inside status at the start; it can only change where the trace is not proven clear.
    Sample s0 = sample(0.0, cap, thr_ + 0.5 * max_step_ + cut_margin_);
    inside_part_ = -1;
    ++count_.inside_queries;
    if (!idx.inside(s0.p, &inside_part_)) inside_part_ = -1;
    Sample a = s0;
    double s_prev = 0.0;
    while (s_prev < L_) {
      // A cut-short sample's bound gives the same step and radius once they reach their
      // caps (both grow with d); otherwise a higher bound, or its value, is needed now.
      const double reach_cap = cap - std::min(L_ - s_prev, max_step_);  // a.d that caps the radius
      refresh(a);
      // With approximate queries the bound steps as it is: positions then depend on ε anyway.
      if (rel_error_ == 0.0) {
        tighten(a, std::max(thr_ + 0.5 * max_step_, reach_cap));
        if (a.pending >= 0 && (2.0 * (a.d - thr_) < max_step_ || a.d + std::min(L_ - s_prev, max_step_) < cap))
          resolve(a);
      }
      const double rho = a.d - thr_;
      const double step = std::clamp(2.0 * rho, leaf_, max_step_);
      const double s_next = std::min(L_, s_prev + step);
      // Enough for b: its own step and radius at their caps, and [a, b] proven clear.
      const double enough = std::max(thr_ + 0.5 * max_step_, 2.0 * thr_ + (s_next - s_prev) - a.d) + cut_margin_;
      Sample b = sample(s_next, std::min(a.d + (s_next - s_prev), cap), enough);
      refine(a, b);
      a = b;
      s_prev = s_next;
    }
    flush_free();
    tracker_.flush();
    summary_min_ = std::min(summary_min_, tracker_.min_key);
    settle_pending();
    ctx_.counters.add(count_);
  }

  // The tracker's resolver holds `this`: a tracer is neither copied nor moved.
  StructureTracer(const StructureTracer&) = delete;
  StructureTracer& operator=(const StructureTracer&) = delete;

  StretchTracker& tracker() { return tracker_; }
  double min_clearance() const { return summary_min_; }
  bool min_exact() const { return summary_min_ < ctx_.band; }

 private:
  struct Sample {
    double s = 0.0;
    /// Lower bound on the distance to any part surface (≤ its query radius): the query's
    /// own value, or, while `pending` ≥ 0, a bound on it (the query was cut short).
    double d = 0.0;
    /// Upper bound on that distance: the distance of a surface point the queries found
    /// (infinity when none was found).
    double u = kInf;
    Vec3 p = Vec3::Zero();
    int pending = -1;  ///< index into pending_ while d is only a bound on the query's value
  };

  /// A sample whose closest-point query stopped at `reach` (no surface that close): its
  /// full query (radius `radius`) is run only if a decision needs its value (resolve()).
  struct Pending {
    double s = 0.0;
    Vec3 p = Vec3::Zero();
    double radius = 0.0;  ///< radius of the full query
    double reach = 0.0;   ///< no surface within this distance
    bool resolved = false;
    double d = 0.0;       ///< the sample's d once resolved
    double upper = kInf;  ///< distance of the nearest surface point found so far
    bool sharpened = false;  ///< sharpen() ran: its bound is as good as it gets short of resolve()
  };

  /// Sample at arc length s with a closest-point query of the given radius (the Lipschitz
  /// upper bound). When the caller can go on with any d ≥ `enough` − abs_err, the query
  /// stops at `enough`: far from every surface that costs a few BVH nodes instead of the
  /// leaves around the nearest one, and the value is computed later only if needed. Every
  /// decision taken on a bound is the one the value would give (all grow with d), so the
  /// audit's results do not change; the sample counts as one distance query either way.
  Sample sample(double s, double radius, double enough) {
    Sample x;
    x.s = s;
    x.p = in_.curve.position(in_.curve.parameter_at_length(s));
    ++count_.samples;
    ++count_.distance_queries;
    if (ctx_.req.cut_short_queries && enough < radius) {
      // Found within `enough`: the nearest surface (to within ε), so the full query's answer.
      const ClosestHit h = free_space_query(x.p, enough);
      if (!h.found()) return bounded(x, radius, enough);
      return answered(x, h, radius);
    }
    return answered(x, free_space_query(x.p, radius), radius);
  }

  /// A sphere-tracing query: exact, or (1 + ε)-approximate when the request allows it.
  ClosestHit free_space_query(const Vec3& p, double radius) const {
    return rel_error_ > 0.0 ? ctx_.index->closest_approx(p, radius, rel_error_) : ctx_.index->closest(p, radius);
  }

  /// x as a sample known only to have no surface within `reach` (its full query, radius
  /// `radius`, runs later if a decision needs its value).
  Sample bounded(Sample x, double radius, double reach, double upper = kInf) {
    pending_.push_back({x.s, x.p, radius, reach, false, 0.0, upper});
    x.pending = static_cast<int>(pending_.size()) - 1;
    x.d = std::max(0.0, reach - ctx_.abs_err);
    x.u = upper;
    return x;
  }

  /// x given the answer h of its sphere-tracing query (radius `radius`): the value when the
  /// query was exact or missed, a lower bound when it was approximate and hit.
  Sample answered(Sample x, const ClosestHit& h, double radius) {
    if (rel_error_ > 0.0 && h.found()) {
      note(h, x.s);
      return bounded(x, radius, h.distance / (1.0 + rel_error_), h.distance);
    }
    x.d = take(h, x.s, radius);
    x.u = h.distance;
    return x;
  }

  /// The d of a sample at s whose query of the given radius answered h; counts h towards
  /// the cable's smallest sampled clearance.
  double take(const ClosestHit& h, double s, double radius) {
    note(h, s);
    return h.found() ? std::max(0.0, h.distance - ctx_.abs_err) : std::max(0.0, radius - ctx_.abs_err);
  }

  /// Counts a surface point a query found from arc length s towards the cable's smallest
  /// sampled clearance (its distance is a real clearance there, exact or not).
  void note(const ClosestHit& h, double s) {
    if (h.found() && !is_attached(in_.attachments, h.part, s)) summary_min_ = std::min(summary_min_, h.distance - r_);
  }

  /// Brings a copy of a sample up to date with what is known of its query since.
  void refresh(Sample& x) const {
    if (x.pending < 0) return;
    const Pending& pd = pending_[x.pending];
    x.u = pd.upper;
    if (pd.resolved) {
      x.d = pd.d;
      x.pending = -1;
    } else {
      x.d = std::max(x.d, std::max(0.0, pd.reach - ctx_.abs_err));
    }
  }

  /// Raises a sample's bound to `need` (d units) with a query cut short there, or finds its
  /// value on the way (exact queries: the nearest surface is then within the cut), or, with
  /// approximate queries, a surface point closer than `need` (the decision then fails).
  void tighten(Sample& x, double need) {
    if (x.pending < 0 || x.d >= need) return;
    Pending& pd = pending_[x.pending];
    const double reach = need + cut_margin_;
    if (!(reach < pd.radius)) {
      if (rel_error_ == 0.0) resolve(x);
      return;
    }
    const ClosestHit h = free_space_query(pd.p, reach);
    if (!h.found()) {
      pd.reach = reach;
    } else if (rel_error_ == 0.0) {
      pd.d = take(h, pd.s, pd.radius);
      pd.resolved = true;
      pd.upper = h.distance;
    } else {
      take_approx(pd, h, rel_error_);
    }
    refresh(x);
  }

  /// Replaces a cut-short sample's bound with its query's value (run once per sample).
  void resolve(Sample& x) {
    if (x.pending < 0) return;
    Pending& pd = pending_[x.pending];
    if (!pd.resolved) {
      const ClosestHit h = ctx_.index->closest(pd.p, pd.radius);
      pd.d = take(h, pd.s, pd.radius);
      pd.upper = h.distance;
      pd.resolved = true;
    }
    refresh(x);
  }

  /// With approximate queries: raises a pending sample's bound to within a factor
  /// 1 + kProofErrorShare·ε of its value (one query of its full radius; a miss is the value).
  void sharpen(Sample& x) {
    if (x.pending < 0) return;
    Pending& pd = pending_[x.pending];
    if (pd.resolved || pd.sharpened) return;
    pd.sharpened = true;
    const double e = kProofErrorShare * rel_error_;
    const ClosestHit h = ctx_.index->closest_approx(pd.p, pd.radius, e);
    if (!h.found()) {
      pd.d = take(h, pd.s, pd.radius);
      pd.resolved = true;
    } else {
      take_approx(pd, h, e);
    }
    refresh(x);
  }

  /// Takes a (1 + e)-approximate hit of a pending sample's query: counts its surface point
  /// towards the smallest sampled clearance and narrows the bounds to [D / (1 + e), D].
  void take_approx(Pending& pd, const ClosestHit& h, double e) {
    note(h, pd.s);
    pd.reach = std::max(pd.reach, h.distance / (1.0 + e));
    pd.upper = std::min(pd.upper, h.distance);
  }

  /// The cut-short samples never resolved count towards the smallest sampled clearance only
  /// if they can lower it: their distance exceeds `reach`, and a query bounded by the
  /// current minimum (+ margin, which covers rounding) finds the same nearest surface as
  /// their full query whenever it is below that bound. They are taken nearest bound first,
  /// so that the minimum falls early and stops the rest. With approximate queries the
  /// smallest clearance is the smallest at the surface points found (an upper bound on the
  /// true one, as any sampled value is): samples that found one have counted already.
  void settle_pending() {
    std::vector<const Pending*> open;
    for (const Pending& pd : pending_)
      if (!pd.resolved && pd.reach - r_ < summary_min_ && (rel_error_ == 0.0 || pd.upper == kInf)) open.push_back(&pd);
    std::sort(open.begin(), open.end(), [](const Pending* x, const Pending* y) {
      return x->reach != y->reach ? x->reach < y->reach : x->s < y->s;
    });
    for (const Pending* pd : open) {
      if (pd->reach - r_ >= summary_min_) break;
      const double bound = std::min(pd->radius, summary_min_ + r_ + margin_);
      note(free_space_query(pd->p, bound), pd->s);
    }
    pending_.clear();
  }

  /// Lipschitz bisection of [a, b]: clear, or a leaf handed to the exact measurement.
  void refine(Sample a, Sample b) {
    refresh(a);
    refresh(b);
    const double h = b.s - a.s;
    // Lipschitz lower bound on [a, b]; also when a bound stands for d (the value only adds).
    auto proven_clear = [&] { return 0.5 * (a.d + b.d - h) >= thr_; };
    // The most any values could prove: each distance is at most its surface point's (u), and
    // at most the other's plus h (1-Lipschitz). Beside a surface within the band (a.u < thr_)
    // no query can prove [a, b] clear, so with approximate queries none is spent trying.
    // Exact queries keep them: a value in place of a bound sizes the midpoint's query, and
    // cut-short exact queries promise the report of full ones bit for bit.
    const double ua = std::min(a.u, b.u + h), ub = std::min(b.u, a.u + h);
    const bool provable = rel_error_ == 0.0 || 0.5 * (ua + ub - h) >= thr_;
    // Bounds too low for this decision: raise them to what it needs first, then, if that
    // is not enough, take the values.
    if (!proven_clear() && provable) {
      tighten(a, 2.0 * thr_ + h - b.d);
      tighten(b, 2.0 * thr_ + h - a.d);
    }
    // Values are worth their queries only if the upper bounds could prove it.
    // With approximate bounds a failed proof is cheaper to retry on halves (one approximate
    // query) than to settle with two exact ones, down to the leaves; there two finer
    // approximate queries give bounds close enough to the values.
    if (!proven_clear() && provable && 0.5 * (a.u + b.u - h) >= thr_ && (rel_error_ == 0.0 || h <= leaf_)) {
      if (rel_error_ == 0.0) {
        resolve(a);
        resolve(b);
      } else {
        sharpen(a);
        sharpen(b);
      }
    }
    if (proven_clear()) {
      free_.push_back(a);
      return;
    }
    if (h <= leaf_) {
      near(a.s, b.s);
      return;
    }
    const double sm = 0.5 * (a.s + b.s);
    const double dmin = std::min(a.d, b.d);
    // Enough for m: both halves proven clear at once.
    const Sample m = sample(sm, std::min(dmin + 0.5 * h, thr_ + max_step_), 2.0 * thr_ + 0.5 * h - dmin + cut_margin_);
    refine(a, m);
    refine(m, b);
  }

  /// Records a proven-clear stretch starting at sample a: while inside a closed part it is
  /// a clash stretch with that part (deepest = farthest from its surface).
  void flush_free() {
    // Free samples only matter while the trace is inside a closed part.
    if (inside_part_ >= 0) {
      // The deepest sample is the one farthest from the surface: only samples whose upper
      // bound reaches the largest lower bound can be it, and only they need their values.
      double deepest = 0.0;
      for (Sample& f : free_) {
        refresh(f);
        deepest = std::max(deepest, f.d);
      }
      for (Sample& f : free_)
        if (f.u >= deepest) resolve(f);
      for (Sample& f : free_) {
        PartObservation o;
        o.part = inside_part_;
        o.key = -r_ - f.d;
        o.point = f.p;
        o.s = f.s;
        o.inside = true;
        tracker_.step({o}, f.s, f.s);
      }
    } else if (!free_.empty()) {
      tracker_.flush();  // a proven-clear gap ends every open stretch
    }
    free_.clear();
  }

  /// Exact measurement of [s0, s1] (merged with a directly preceding near stretch).
  void near(double s0, double s1) {
    flush_free();
    Chords ch;
    const Centerline& c = in_.curve;
    flatten(c, c.parameter_at_length(s0), c.parameter_at_length(s1), ctx_.chord_error, kMaxChordRadii * r_,
            kShortSpanRadii * r_, ch);
    count_.samples += as_i64(ch.p.size());
    // Candidate parts for the secondary check: boxes within the band of this stretch.
    AABB box;
    for (const Vec3& p : ch.p) box.extend(p);
    ctx_.part_tree->overlapping(box.inflated(thr_ + cut_margin_), cand_);  // + rounding margin
    const double touch = std::max(4.0 * ctx_.abs_err, ctx_.chord_error);
    std::vector<PartObservation> obs;
    for (std::size_t k = 0; k < ch.size(); ++k) {
      const Vec3& a = ch.p[k];
      const Vec3& b = ch.p[k + 1];
      obs.clear();
      double t = 0.0;
      double lower = 0.0;  // lower bound on the distance from the chord to every part
      const ClosestHit h = chord_query(a, b, touch, &t, &lower);
      const double sk = ch.s[k] + t * (ch.s[k + 1] - ch.s[k]);
      int primary = -1;
      if (h.found() && h.distance <= touch) {
        // The chord touches or crosses a surface: the inside status may change here.
        ++count_.inside_queries;
        int part = -1;
        inside_part_ = ctx_.index->inside(b, &part) ? part : -1;
      }
      if (h.found()) {
        primary = h.part;
        PartObservation o;
        o.part = h.part;
        o.key = h.distance - r_;
        o.key_lower = lower - r_;
        o.point = a + t * (b - a);
        o.s = sk;
        if (o.key < ctx_.info[h.part].required) {
          if (o.key_lower < o.key) {
            o.deferred = DeferredChord{a, b, ch.s[k], ch.s[k + 1]};
            ++count_.deferred_chords;
          }
          obs.push_back(o);
        }
      }
      if (inside_part_ >= 0) {
        // Axis inside a closed part: dist = 0; rank by depth at the chord's end.
        PartObservation o;
        o.part = inside_part_;
        ++count_.distance_queries;
        // Depth only ranks points of the stretch (all have clearance −r): bounded search.
        const ClosestHit hb = ctx_.index->closest_on_part(b, inside_part_, thr_);
        o.key = -r_ - (hb.found() ? hb.distance : thr_);
        o.point = b;
        o.s = ch.s[k + 1];
        o.inside = true;
        obs.erase(std::remove_if(obs.begin(), obs.end(), [&](const PartObservation& x) { return x.part == o.part; }),
                  obs.end());
        obs.push_back(o);
      }
      if (primary >= 0 && cand_.size() > 1) {
        AABB cb;
        cb.extend(a);
        cb.extend(b);
        for (const std::uint32_t cq : cand_) {
          const int q = static_cast<int>(cq);
          if (q == primary || q == inside_part_) continue;
          if (!boxes_overlap(cb.inflated(r_ + ctx_.info[q].required + margin_), ctx_.info[q].box))
            continue;  // the part's box is beyond the band of this chord
          secondary(a, b, ch.s[k], ch.s[k + 1], q, obs);
        }
      }
      tracker_.step(obs, ch.s[k], ch.s[k + 1]);
    }
  }

  /// The nearest surface to chord ab within thr_, with its parameter on ab in *t and a lower
  /// bound on the chord's distance to every part in *lower. With approximate queries the
  /// answer is (1 + ε)-approximate (*lower = D / (1 + ε)) when that interval decides what
  /// the chord decides — touching (≤ touch), within the hit part's band, in contact — and
  /// exact otherwise; the tracker measures it exactly later only if it can be the deepest.
  ClosestHit chord_query(const Vec3& a, const Vec3& b, double touch, double* t, double* lower) {
    const ObstacleIndex& idx = *ctx_.index;
    ++count_.distance_queries;
    if (rel_error_ > 0.0) {
      const ClosestHit h = idx.segment_closest_approx(a, b, thr_, rel_error_, t);
      if (!h.found()) return h;  // exact: nothing within thr_
      const double lo = h.distance / (1.0 + rel_error_);
      const double band = r_ + ctx_.info[h.part].required;
      const bool decided = (lo <= touch) == (h.distance <= touch) && (lo < band) == (h.distance < band) &&
                           (lo < r_) == (h.distance < r_);
      if (decided) {
        *lower = lo;
        return h;
      }
      ++count_.distance_queries;
    }
    const ClosestHit h = idx.segment_closest(a, b, thr_, t);
    *lower = h.distance;
    return h;
  }

  /// Resolves a deferred chord observation: the chord's exact distance to that part.
  void measure_deferred(PartObservation& o) {
    const DeferredChord& c = *o.deferred;
    double t = 0.0;
    ++count_.distance_queries;
    ++count_.deferred_measured;
    const ClosestHit h = ctx_.index->segment_closest_on_part(c.a, c.b, o.part, thr_, &t);
    // A point of the part lies within key + r ≤ thr_ of the chord: the query finds it.
    if (!h.found())
      throw std::logic_error("clash check: deferred chord " + full_precision(c.a) + " - " + full_precision(c.b) +
                             " lost part " + std::to_string(o.part) + " within " + full_precision(thr_));
    o.key = h.distance - r_;
    o.key_lower = o.key;
    o.point = c.a + t * (c.b - c.a);
    o.s = c.s0 + t * (c.s1 - c.s0);
    o.deferred.reset();
  }

  /// A part other than the nearest (or than the one an approximate query found): the
  /// chord's exact distance to that part alone, an observation if within its band.
  void secondary(const Vec3& a, const Vec3& b, double sa, double sb, int q, std::vector<PartObservation>& obs) {
    const double thr_q = r_ + ctx_.info[q].required + margin_;
    double t = 0.0;
    ++count_.distance_queries;
    const ClosestHit h = ctx_.index->segment_closest_on_part(a, b, q, thr_q, &t);
    if (!h.found()) return;
    PartObservation o;
    o.part = q;
    o.key = h.distance - r_;
    o.point = a + t * (b - a);
    o.s = sa + t * (sb - sa);
    if (o.key < ctx_.info[q].required) obs.push_back(o);
  }

  Context& ctx_;
  int cable_;
  const CableInput& in_;
  double r_;
  StretchTracker tracker_;
  double L_ = 0.0, thr_ = 0.0, leaf_ = 0.0, max_step_ = 0.0, margin_ = 0.0;
  double rel_error_ = 0.0;   ///< ClashRequest::distance_rel_error (0: exact sphere tracing)
  std::vector<std::uint32_t> cand_;  ///< near(): parts whose boxes reach the stretch (reused buffer)
  double cut_margin_ = 0.0;  ///< added to a cut-short query's radius: d = max(0, hit − abs_err) and rounding
  int inside_part_ = -1;
  std::vector<Sample> free_;
  std::vector<Pending> pending_;  ///< cut-short samples of this cable
  double summary_min_ = kInf;
  ClashCounters count_;
};

// ---------------------------------------------------------------------------------------
// Cable–cable and self contacts, grouped into stretches.

/// One measured contact between two cables (or a cable and itself), with the arc-length
/// intervals of the chords/samples that produced it on each.
struct PairContact {
  int a = -1, b = -1;  ///< cables, a ≤ b (self: a == b, s < t)
  double dist = 0.0;   ///< centerline distance
  Vec3 p = Vec3::Zero(), q = Vec3::Zero();
  double s = 0.0, t = 0.0;
  double sa0 = 0.0, sa1 = 0.0, tb0 = 0.0, tb1 = 0.0;

  /// The contact of point p (arc length s, interval [sa0, sa1]) on cable a with q (t,
  /// [tb0, tb1]) on cable b, sides put in the order above (smaller cable first; for a
  /// self contact, smaller arc length first).
  static PairContact ordered(int a, double s, double sa0, double sa1, const Vec3& p, int b, double t, double tb0,
                             double tb1, const Vec3& q, double dist) {
    PairContact pc;
    pc.dist = dist;
    const bool swap = a == b ? s > t : a > b;
    pc.a = swap ? b : a;
    pc.b = swap ? a : b;
    pc.p = swap ? q : p;
    pc.q = swap ? p : q;
    pc.s = swap ? t : s;
    pc.t = swap ? s : t;
    pc.sa0 = swap ? tb0 : sa0;
    pc.sa1 = swap ? tb1 : sa1;
    pc.tb0 = swap ? sa0 : tb0;
    pc.tb1 = swap ? sa1 : tb1;
    return pc;
  }
};

/// One entry per connected group of contacts (intervals touching on both cables).
/// Contacts of one cable pair are taken in cells of equal interval on cable a; within a
/// cell, contacts whose b-intervals touch are chained by a sweep over tb0, giving disjoint
/// b-ranges; cells whose a-intervals touch then join the ranges that overlap, by a merge of
/// the two sorted lists. Why not every pair of contacts: a cable folding back on itself
/// gives each chord thousands of contacts, and comparing them pairwise took a minute.
void group_pair_contacts(std::vector<PairContact>& contacts, const std::vector<CableInput>& cables,
                         std::vector<ClashEntry>& out) {
  std::sort(contacts.begin(), contacts.end(), [](const PairContact& x, const PairContact& y) {
    return std::tie(x.a, x.b, x.sa0, x.sa1, x.tb0) < std::tie(y.a, y.b, y.sa0, y.sa1, y.tb0);
  });
  /// A run of contacts of one cell whose b-intervals touch: their b-range and one member.
  struct Range {
    double lo, hi;
    std::size_t member;
  };
  struct Cell {
    double sa0, sa1;
    std::vector<Range> ranges;  ///< disjoint, by lo
  };
  std::size_t i = 0;
  while (i < contacts.size()) {
    std::size_t j = i;
    while (j < contacts.size() && contacts[j].a == contacts[i].a && contacts[j].b == contacts[i].b) ++j;
    const std::size_t n = j - i;
    std::vector<std::size_t> parent(n);
    std::iota(parent.begin(), parent.end(), 0);
    auto find = [&](std::size_t x) {
      while (parent[x] != x) x = parent[x] = parent[parent[x]];
      return x;
    };
    auto unite = [&](std::size_t x, std::size_t y) { parent[find(x)] = find(y); };
    const double slack_a = kTouchRel * (1.0 + cables[contacts[i].a].curve.length());
    const double slack_b = kTouchRel * (1.0 + cables[contacts[i].b].curve.length());
    std::vector<Cell> cells;
    for (std::size_t x = 0; x < n;) {
      const PairContact& first = contacts[i + x];
      Cell cell{first.sa0, first.sa1, {}};
      std::size_t y = x;
      for (; y < n && contacts[i + y].sa0 == first.sa0 && contacts[i + y].sa1 == first.sa1; ++y) {
        const PairContact& cy = contacts[i + y];  // sorted by tb0 within the cell
        if (!cell.ranges.empty() && cy.tb0 <= cell.ranges.back().hi + slack_b) {
          unite(y, cell.ranges.back().member);
          cell.ranges.back().hi = std::max(cell.ranges.back().hi, cy.tb1);
        } else {
          cell.ranges.push_back({cy.tb0, cy.tb1, y});
        }
      }
      cells.push_back(std::move(cell));
      x = y;
    }
    // Cells are sorted by sa0: the ones touching cell c on a follow it until one starts
    // beyond its end.
    for (std::size_t c = 0; c < cells.size(); ++c)
      for (std::size_t d = c + 1; d < cells.size() && cells[d].sa0 <= cells[c].sa1 + slack_a; ++d) {
        const auto& rc = cells[c].ranges;
        const auto& rd = cells[d].ranges;
        for (std::size_t u = 0, v = 0; u < rc.size() && v < rd.size();) {
          if (rc[u].lo <= rd[v].hi + slack_b && rd[v].lo <= rc[u].hi + slack_b) unite(rc[u].member, rd[v].member);
          (rc[u].hi < rd[v].hi ? u : v) += 1;  // drop the range that ends first
        }
      }
    std::map<std::size_t, std::size_t> best;  // root → index of deepest
    std::map<std::size_t, std::pair<double, double>> range;
    for (std::size_t x = 0; x < n; ++x) {
      const std::size_t root = find(x);
      const PairContact& cx = contacts[i + x];
      auto it = best.find(root);
      if (it == best.end() || cx.dist - 0.0 < contacts[i + it->second].dist) best[root] = x;
      auto rt = range.find(root);
      if (rt == range.end())
        range[root] = {cx.sa0, cx.sa1};
      else
        rt->second = {std::min(rt->second.first, cx.sa0), std::max(rt->second.second, cx.sa1)};
    }
    for (const auto& kv : best) {
      const PairContact& c = contacts[i + kv.second];
      ClashEntry e;
      e.kind = c.a == c.b ? ClashKind::Self : ClashKind::CableCable;
      e.cable = c.a;
      e.other = c.b;
      const double r_sum = cables[c.a].radius + cables[c.b].radius;
      e.clearance = c.dist - r_sum;
      e.point = 0.5 * (c.p + c.q);
      e.s = c.s;
      e.s_other = c.t;
      e.s_begin = range[kv.first].first;
      e.s_end = range[kv.first].second;
      out.push_back(e);
    }
    i = j;
  }
}

/// One cable flattened to chords, with a box per block of kBlock chords (inflated by the
/// cable radius + chord error: two blocks whose boxes do not meet hold no pair of chords
/// closer than the radii sum).
struct CableChords {
  int cable = -1;
  Chords ch;
  std::vector<AABB> blocks;  ///< box of chords [k·kBlock, (k+1)·kBlock)
};

/// Every cable, flattened (cables in parallel).
std::vector<CableChords> flatten_cables(Context& ctx) {
  std::vector<CableChords> out(ctx.cables.size());
  parallel_indices(ctx.cables.size(), ctx.req.threads, [&](std::size_t k) {
    const CableInput& c = ctx.cables[k];
    CableChords& cc = out[k];
    cc.cable = static_cast<int>(k);
    flatten(c.curve, c.curve.u_min(), c.curve.u_max(), ctx.chord_error, kMaxChordRadii * c.radius,
            kShortSpanRadii * c.radius, cc.ch);
    ctx.counters.samples += as_i64(cc.ch.p.size());
    const double infl = c.radius + ctx.chord_error;
    for (std::size_t b = 0; b * kBlock < cc.ch.size(); ++b) {
      AABB box;
      for (std::size_t v = b * kBlock; v <= std::min(cc.ch.size(), (b + 1) * kBlock); ++v) box.extend(cc.ch.p[v]);
      cc.blocks.push_back(box.inflated(infl));
    }
  });
  return out;
}

/// Exact chord–chord narrow phase of block ba of span A against block bb of span B (a block
/// against itself when A and B are one span and ba == bb). Returns the segment tests made.
std::int64_t narrow_phase(const Context& ctx, const CableChords& A, std::size_t ba, const CableChords& B, std::size_t bb,
                          std::vector<PairContact>& out) {
  const CableInput& ca = ctx.cables[A.cable];
  const CableInput& cb = ctx.cables[B.cable];
  const bool self = A.cable == B.cable;
  const bool same_block = &A == &B && ba == bb;
  const double r_sum = ca.radius + cb.radius;
  const double self_gap = M_PI * ca.radius;
  const std::size_t ka1 = std::min(A.ch.size(), (ba + 1) * kBlock);
  const std::size_t kb1 = std::min(B.ch.size(), (bb + 1) * kBlock);
  if (self) {  // whole block pair closer in s than π r: excused
    const double gap_max =
        std::max(std::abs(B.ch.s[kb1] - A.ch.s[ba * kBlock]), std::abs(A.ch.s[ka1] - B.ch.s[bb * kBlock]));
    if (gap_max < self_gap) return 0;
  }
  std::int64_t tests = 0;
  for (std::size_t ka = ba * kBlock; ka < ka1; ++ka) {
    for (std::size_t kb = same_block ? ka : bb * kBlock; kb < kb1; ++kb) {
      const double sa0 = A.ch.s[ka], sa1 = A.ch.s[ka + 1];
      const double tb0 = B.ch.s[kb], tb1 = B.ch.s[kb + 1];
      if (self && std::max(std::abs(tb1 - sa0), std::abs(sa1 - tb0)) < self_gap) continue;
      // Midpoint bound: chords whose midpoints are farther apart than their half
      // lengths plus the radii cannot touch.
      const Vec3 ma = 0.5 * (A.ch.p[ka] + A.ch.p[ka + 1]), mb = 0.5 * (B.ch.p[kb] + B.ch.p[kb + 1]);
      const double reach = r_sum + 0.5 * ((A.ch.p[ka + 1] - A.ch.p[ka]).norm() + (B.ch.p[kb + 1] - B.ch.p[kb]).norm());
      if ((ma - mb).squaredNorm() >= reach * reach) continue;
      ++tests;
      const SegmentSegmentResult r = closest_segment_segment(A.ch.p[ka], A.ch.p[ka + 1], B.ch.p[kb], B.ch.p[kb + 1]);
      const double d = std::sqrt(r.dist2);
      if (!(d < r_sum)) continue;
      double s = sa0 + r.s * (sa1 - sa0), t = tb0 + r.t * (tb1 - tb0);
      if (self && std::abs(s - t) < self_gap) continue;
      if (!self && excused(ca, s, r.p, cb, t, r.q)) continue;
      out.push_back(PairContact::ordered(A.cable, s, sa0, sa1, r.p, B.cable, t, tb0, tb1, r.q, d));
    }
  }
  return tests;
}

/// Why the pair passes refuse an audit that reaches a ClashLimits limit.
const char* const kFoldBack = "a route folds back on itself or runs over another along great lengths";

/// Refuses the audit: more pairs of `what` (chords, samples) in contact than
/// ClashLimits::max_pair_contacts. The message names the cable pair with the most of the
/// `found` contacts (lowest ids on a tie): which contacts were stored when the limit was
/// passed depends on thread timing, the pair that dominates them hardly does.
[[noreturn]] void refuse_contacts(const Context& ctx, const std::vector<PairContact>& found, const char* what) {
  std::map<std::pair<int, int>, std::size_t> per_pair;
  for (const PairContact& c : found) ++per_pair[{c.a, c.b}];
  std::pair<int, int> top{0, 0};
  std::size_t most = 0;
  for (const auto& [ab, n] : per_pair)
    if (n > most) {
      most = n;
      top = ab;
    }
  const std::string among = top.first == top.second
                                ? "cable '" + ctx.cables[top.first].id + "' with itself"
                                : "cables '" + ctx.cables[top.first].id + "' and '" + ctx.cables[top.second].id + "'";
  throw std::invalid_argument("check_clashes: more than " +
                              full_precision(static_cast<double>(ctx.req.limits.max_pair_contacts)) + " pairs of " +
                              what + " are in contact (" + among + " the most of them): " + kFoldBack);
}

/// Block pairs handed to one narrow-phase task (amortises task and lock overhead).
constexpr std::size_t kPairsPerTask = 256;

void certified_cable_pairs(Context& ctx, std::vector<ClashEntry>& out) {
  if (!ctx.req.check_cable_cable && !ctx.req.check_self) return;
  const std::vector<CableChords> cc = flatten_cables(ctx);
  // Broad phase over the block boxes of all cables together (a BVH, Embree's rtcCollide):
  // the candidates are local chord groups, not whole cables, so their number follows the
  // chords that really come near each other as cables are added.
  struct BlockRef {
    std::uint32_t cable, block;
  };
  std::vector<BlockRef> blocks;
  std::vector<AABB> boxes;
  for (std::size_t i = 0; i < cc.size(); ++i)
    for (std::size_t b = 0; b < cc[i].blocks.size(); ++b) {
      blocks.push_back({static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(b)});
      boxes.push_back(cc[i].blocks[b]);
    }
  // Arc-length range of a block and the one harness segment it lies in (−1: several).
  auto block_s = [&](const BlockRef& r) {
    const Chords& ch = cc[r.cable].ch;
    return std::make_pair(ch.s[r.block * kBlock], ch.s[std::min(ch.size(), (r.block + 1) * kBlock)]);
  };
  std::vector<int> block_segment(blocks.size());
  for (std::size_t k = 0; k < blocks.size(); ++k) {
    const auto [s0, s1] = block_s(blocks[k]);
    const CableInput& c = ctx.cables[blocks[k].cable];
    const int seg = segment_at(c, s0);
    block_segment[k] = seg >= 0 && seg == segment_at(c, s1) ? seg : -1;
  }
  // Keep the kinds asked for, and only pairs with a contact that could count: not two
  // cables' blocks both inside one harness segment (bundled there on purpose: every
  // contact is excused), not a cable's blocks closer in s than π r. Why here: a large
  // bundle puts every block beside the blocks of every other cable in it.
  const ClashLimits& lim = ctx.req.limits;
  BoxPairRequest bp;
  bp.filter.keep = [&](std::uint32_t i, std::uint32_t j) {
    const BlockRef& x = blocks[i];
    const BlockRef& y = blocks[j];
    if (x.cable == y.cable) {
      if (!ctx.req.check_self) return false;
      const auto [a0, a1] = block_s(x);
      const auto [b0, b1] = block_s(y);
      return std::max(std::abs(b1 - a0), std::abs(a1 - b0)) >= M_PI * ctx.cables[x.cable].radius;
    }
    return ctx.req.check_cable_cable && !(block_segment[i] >= 0 && block_segment[i] == block_segment[j]);
  };
  bp.filter.max_pairs = lim.max_block_pairs;
  bp.max_overlaps = lim.max_block_overlaps;
  bp.threads = ctx.req.threads;
  BoxPairResult found = overlapping_box_pairs(boxes, bp);
  ctx.counters.block_overlaps_estimate =
      static_cast<std::int64_t>(std::llround(std::min(found.estimated_overlaps, 9e18)));
  if (found.status == BoxPairStatus::TooManyOverlaps)
    throw std::invalid_argument("check_clashes: about " + full_precision(std::round(found.estimated_overlaps)) +
                                " pairs of chord blocks come within reach of each other (limit " +
                                full_precision(static_cast<double>(lim.max_block_overlaps)) + "; cable '" +
                                ctx.cables[blocks[found.busiest].cable].id + "' among them): " + kFoldBack);
  if (found.status == BoxPairStatus::TooManyKept)
    throw std::invalid_argument("check_clashes: more than " + full_precision(static_cast<double>(lim.max_block_pairs)) +
                                " pairs of chord blocks of different cables, or of one cable πr apart, come within "
                                "reach of each other: " + kFoldBack);
  std::vector<BoxPair>& pairs = found.pairs;
  ctx.counters.block_pairs = as_i64(pairs.size());
  if (ctx.req.check_self)
    for (std::uint32_t i = 0; i < blocks.size(); ++i) pairs.emplace_back(i, i);
  std::mutex mu;
  std::vector<PairContact> contacts;
  const std::size_t tasks = (pairs.size() + kPairsPerTask - 1) / kPairsPerTask;
  parallel_indices(tasks, ctx.req.threads, [&](std::size_t t) {
    std::vector<PairContact> local;
    std::int64_t tests = 0;
    for (std::size_t k = t * kPairsPerTask; k < std::min(pairs.size(), (t + 1) * kPairsPerTask); ++k) {
      const BlockRef& x = blocks[pairs[k].first];
      const BlockRef& y = blocks[pairs[k].second];
      tests += narrow_phase(ctx, cc[x.cable], x.block, cc[y.cable], y.block, local);
    }
    ctx.counters.pairs += tests;
    if (!local.empty()) {
      std::lock_guard<std::mutex> lock(mu);
      contacts.insert(contacts.end(), local.begin(), local.end());
      if (contacts.size() > lim.max_pair_contacts) refuse_contacts(ctx, contacts, "chords");
    }
  });
  ctx.counters.pair_contacts = as_i64(contacts.size());
  group_pair_contacts(contacts, ctx.cables, out);
}

// ---------------------------------------------------------------------------------------
// Discrete method (the seed paper).

/// Nearest part to p by brute force over every triangle; inside via winding numbers.
struct BruteHit {
  int part = -1;
  double dist = kInf;
  bool inside = false;
};

BruteHit brute_point(const Context& ctx, const Vec3& p) {
  BruteHit best;
  for (std::size_t q = 0; q < ctx.parts.size(); ++q) {
    const Mesh& m = ctx.parts[q].mesh;
    double d2 = kInf;
    double wind = 0.0;
    const bool closed = ctx.info[q].closed;
    for (std::size_t t = 0; t < m.triangles.size(); ++t) {
      const auto c = m.corners(t);
      d2 = std::min(d2, closest_point_on_triangle(p, c[0], c[1], c[2]).dist2);
      if (closed) wind += triangle_solid_angle(p, c[0], c[1], c[2]);
    }
    if (closed && std::abs(wind) > 2.0 * M_PI) {  // winding number > 1/2
      best.inside = true;
      best.part = static_cast<int>(q);
      best.dist = 0.0;
      return best;
    }
    const double d = std::sqrt(d2);
    if (d < best.dist) {
      best.dist = d;
      best.part = static_cast<int>(q);
    }
  }
  return best;
}

/// Samples of every cable for the discrete method.
struct DiscreteSamples {
  std::vector<double> s;
  std::vector<Vec3> p;
  double spacing = 0.0;
};

void discrete_structure(Context& ctx, int cable, const DiscreteSamples& ds, StretchTracker& tr) {
  const double r = ctx.cables[cable].radius;
  ClashCounters count;
  for (std::size_t k = 0; k < ds.p.size(); ++k) {
    const Vec3& p = ds.p[k];
    const double s0 = k == 0 ? 0.0 : 0.5 * (ds.s[k - 1] + ds.s[k]);
    const double s1 = k + 1 == ds.p.size() ? ds.s[k] : 0.5 * (ds.s[k] + ds.s[k + 1]);
    PartObservation o;
    o.point = p;
    o.s = ds.s[k];
    if (ctx.req.use_index) {
      int part = -1;
      ++count.inside_queries;
      if (ctx.index->inside(p, &part)) {
        o.part = part;
        o.key = -r;
        o.inside = true;
      } else {
        ++count.distance_queries;
        const ClosestHit h = ctx.index->closest(p, r + ctx.band);
        if (h.found()) {
          o.part = h.part;
          o.key = h.distance - r;
        }
      }
    } else {
      ++count.distance_queries;
      ++count.inside_queries;
      const BruteHit h = brute_point(ctx, p);
      if (h.part >= 0) {
        o.part = h.part;
        o.key = h.inside ? -r : h.dist - r;
        o.inside = h.inside;
      }
    }
    if (o.part >= 0 && o.key < ctx.info[o.part].required)
      tr.step({o}, s0, s1);
    else
      tr.step({}, s0, s1);
  }
  tr.flush();
  ctx.counters.add(count);
}

/// Cable–cable (min sample distance < r₁ + r₂) and self (non-adjacent samples < 2r, then
/// the midpoint test) contacts, through a uniform grid or all pairs (no index).
void discrete_cable_pairs(Context& ctx, const std::vector<DiscreteSamples>& ds, std::vector<ClashEntry>& out) {
  if (!ctx.req.check_cable_cable && !ctx.req.check_self) return;
  const auto& cables = ctx.cables;
  std::vector<PairContact> contacts;
  std::mutex mu;
  // Test point k of cable a (or the midpoint of k, k+1 when mid) against sample m of b.
  auto test = [&](int a, std::size_t k, bool mid, int b, std::size_t m, std::vector<PairContact>& local,
                  std::int64_t& tests) {
    const bool self = a == b;
    if (self) {
      // Non-adjacent samples (|k − m| ≥ 2, the paper at l = 2r) and midpoints of pairs away
      // from the judged point; at a finer spacing also |s − t| ≥ π r (DESIGN §5), else
      // every pair of neighbours closer than 2r would count.
      const long dk = static_cast<long>(m) - static_cast<long>(k);
      if (!mid && dk < 2) return;  // each unordered pair once
      if (mid && dk >= -1 && dk <= 2) return;
      const double sk = mid ? 0.5 * (ds[a].s[k] + ds[a].s[k + 1]) : ds[a].s[k];
      if (std::abs(ds[b].s[m] - sk) < M_PI * cables[a].radius) return;
    } else if (a > b) {
      return;
    }
    const Vec3 p = mid ? Vec3(0.5 * (ds[a].p[k] + ds[a].p[k + 1])) : ds[a].p[k];
    const Vec3& q = ds[b].p[m];
    ++tests;
    const double d = (p - q).norm();
    const double limit = cables[a].radius + cables[b].radius;
    if (!(d < limit)) return;
    const double s = mid ? 0.5 * (ds[a].s[k] + ds[a].s[k + 1]) : ds[a].s[k];
    const double t = ds[b].s[m];
    if (!self && excused(cables[a], s, p, cables[b], t, q)) return;
    const double ha = ds[a].spacing, hb = ds[b].spacing;
    local.push_back(PairContact::ordered(a, s, s - ha, s + ha, p, b, t, t - hb, t + hb, q, d));
    if (local.size() > ctx.req.limits.max_pair_contacts) refuse_contacts(ctx, local, "samples");
  };
  auto merge = [&](std::vector<PairContact>& local) {
    std::lock_guard<std::mutex> lock(mu);
    contacts.insert(contacts.end(), local.begin(), local.end());
    if (contacts.size() > ctx.req.limits.max_pair_contacts) refuse_contacts(ctx, contacts, "samples");
  };
  auto want = [&](int a, int b) { return a == b ? ctx.req.check_self : ctx.req.check_cable_cable; };
  if (!ctx.req.use_index) {
    // The paper: every sample pair of every cable pair.
    parallel_indices(cables.size(), ctx.req.threads, [&](std::size_t ai) {
      const int a = static_cast<int>(ai);
      std::vector<PairContact> local;
      std::int64_t tests = 0;
      for (int b = a; b < static_cast<int>(cables.size()); ++b) {
        if (!want(a, b)) continue;
        for (std::size_t k = 0; k < ds[a].p.size(); ++k) {
          for (std::size_t m = 0; m < ds[b].p.size(); ++m) {
            test(a, k, false, b, m, local, tests);
            if (a == b && k + 1 < ds[a].p.size()) test(a, k, true, b, m, local, tests);
          }
        }
      }
      ctx.counters.pairs += tests;
      if (!local.empty()) merge(local);
    });
  } else {
    // Uniform grid of samples, cell = the largest contact distance.
    double rmax = 0.0;
    for (const auto& c : cables) rmax = std::max(rmax, c.radius);
    const double cell = std::max(2.0 * rmax, 1e-12);
    auto key = [&](const Vec3& p) {
      const std::int64_t x = static_cast<std::int64_t>(std::floor(p.x() / cell));
      const std::int64_t y = static_cast<std::int64_t>(std::floor(p.y() / cell));
      const std::int64_t z = static_cast<std::int64_t>(std::floor(p.z() / cell));
      return std::array<std::int64_t, 3>{x, y, z};
    };
    struct KeyHash {
      std::size_t operator()(const std::array<std::int64_t, 3>& k) const {
        return static_cast<std::size_t>(k[0] * 73856093LL ^ k[1] * 19349663LL ^ k[2] * 83492791LL);
      }
    };
    std::unordered_map<std::array<std::int64_t, 3>, std::vector<std::pair<int, std::size_t>>, KeyHash> grid;
    for (std::size_t c = 0; c < cables.size(); ++c)
      for (std::size_t k = 0; k < ds[c].p.size(); ++k) grid[key(ds[c].p[k])].emplace_back(static_cast<int>(c), k);
    // Bound the work before doing it: every sample (and midpoint) meets the samples of the
    // 27 cells around its own. Routes stay far below the limit; one folding back on itself
    // thousands of times packs its samples into a few cells.
    double candidates = 0.0, worst = -1.0;
    int worst_cable = 0;  // a cable in the most crowded neighbourhood, for the message
    for (const auto& [k, members] : grid) {
      double near = 0.0;
      for (int dx = -1; dx <= 1; ++dx)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dz = -1; dz <= 1; ++dz) {
            const auto it = grid.find({k[0] + dx, k[1] + dy, k[2] + dz});
            if (it != grid.end()) near += static_cast<double>(it->second.size());
          }
      candidates += 2.0 * static_cast<double>(members.size()) * near;
      if (near > worst) {
        worst = near;
        worst_cable = members.front().first;
      }
    }
    if (candidates > static_cast<double>(ctx.req.limits.max_sample_pairs))
      throw std::invalid_argument("check_clashes: the discrete method would compare about " +
                                  full_precision(std::round(candidates)) + " pairs of samples (limit " +
                                  full_precision(static_cast<double>(ctx.req.limits.max_sample_pairs)) + "; cable '" +
                                  cables[worst_cable].id + "' among them): " + kFoldBack);
    parallel_indices(cables.size(), ctx.req.threads, [&](std::size_t ai) {
      const int a = static_cast<int>(ai);
      std::vector<PairContact> local;
      std::int64_t tests = 0;
      for (std::size_t k = 0; k < ds[a].p.size(); ++k) {
        for (int mid = 0; mid < 2; ++mid) {
          if (mid && k + 1 >= ds[a].p.size()) continue;
          const Vec3 p = mid ? Vec3(0.5 * (ds[a].p[k] + ds[a].p[k + 1])) : ds[a].p[k];
          const auto kk = key(p);
          for (int dx = -1; dx <= 1; ++dx)
            for (int dy = -1; dy <= 1; ++dy)
              for (int dz = -1; dz <= 1; ++dz) {
                auto it = grid.find({kk[0] + dx, kk[1] + dy, kk[2] + dz});
                if (it == grid.end()) continue;
                for (const auto& e : it->second) {
                  if (mid && e.first != a) continue;  // the midpoint test is for self only
                  if (!want(a, e.first)) continue;
                  test(a, k, mid != 0, e.first, e.second, local, tests);
                }
              }
        }
      }
      ctx.counters.pairs += tests;
      if (!local.empty()) merge(local);
    });
  }
  ctx.counters.pair_contacts = as_i64(contacts.size());
  group_pair_contacts(contacts, cables, out);
}

void check_bend(const Context& ctx, std::size_t c, CableCheckSummary& sum, std::vector<Violation>& out) {
  const CableInput& in = ctx.cables[c];
  BendExtremum b = in.bend_pieces.empty() ? in.curve.min_bend_radius() : BendExtremum{};
  Vec3 where = in.bend_pieces.empty() ? in.curve.position(b.u) : Vec3::Zero();
  if (!in.bend_pieces.empty()) {
    b.radius = std::numeric_limits<double>::infinity();
    for (const auto& [s0, piece] : in.bend_pieces) {
      const BendExtremum pb = piece.min_bend_radius();
      if (pb.radius < b.radius) {
        b = pb;
        b.s += s0;
        where = piece.position(pb.u);
      }
    }
  }
  sum.min_bend_radius = b.radius;
  sum.min_bend_s = b.s;
  if (ctx.req.check_bend && in.min_bend_radius > 0.0 && b.radius < in.min_bend_radius) {
    Violation v;
    v.kind = ViolationKind::BendRadius;
    v.cable = static_cast<int>(c);
    v.value = b.radius;
    v.limit = in.min_bend_radius;
    v.s = b.s;
    v.point = where;
    out.push_back(v);
  }
}

}  // namespace

const char* clash_method_name(ClashMethod m) { return m == ClashMethod::Certified ? "certified" : "discrete"; }

const char* clash_kind_name(ClashKind k) {
  switch (k) {
    case ClashKind::CableStructure: return "cable-structure";
    case ClashKind::CableCable: return "cable-cable";
    case ClashKind::Self: return "self";
  }
  return "?";
}

const char* violation_kind_name(ViolationKind k) {
  return k == ViolationKind::BendRadius ? "bend-radius" : "clearance";
}

double default_clash_tolerance(const std::vector<CableInput>& cables, std::string* source) {
  double rmin = kInf;
  for (const auto& c : cables) rmin = std::min(rmin, c.radius);
  if (!std::isfinite(rmin)) {
    if (source) *source = "no cables to derive it from";
    return kNoCableTolerance;
  }
  if (source) *source = "smallest cable radius / 100";
  return kDefaultToleranceOfRadius * rmin;
}

ClashResult check_clashes(const std::vector<CableInput>& cables, const std::vector<Part>& parts,
                          const ObstacleIndex* index, const ClashRequest& request) {
  for (const auto& c : cables) {
    if (c.curve.empty()) throw std::invalid_argument("check_clashes: cable '" + c.id + "' has no centerline");
    if (!(c.radius > 0.0) || !std::isfinite(c.radius))
      throw std::invalid_argument("check_clashes: cable '" + c.id + "' has a non-positive radius");
  }
  const bool need_index = request.use_index || request.method == ClashMethod::Certified;
  if (need_index && index == nullptr) throw std::invalid_argument("check_clashes: an index is required");
  if (index != nullptr && index->part_count() != static_cast<int>(parts.size()))
    throw std::invalid_argument("check_clashes: the index does not index the given parts");
  if (!(request.distance_rel_error >= 0.0) || !std::isfinite(request.distance_rel_error))
    throw std::invalid_argument("check_clashes: distance_rel_error must be finite and >= 0, got " +
                                full_precision(request.distance_rel_error));

  Context ctx{cables, parts, index, request, {}, 0.0, 0.0, 0.0, 0.0, {}, nullptr};
  ClashResult res;
  ctx.info.resize(parts.size());
  for (std::size_t q = 0; q < parts.size(); ++q) {
    // The index keeps each part's box: no pass over every triangle per audit.
    const std::optional<AABB> kept = index ? index->part_bounds(static_cast<int>(q)) : std::nullopt;
    ctx.info[q].box = kept ? *kept : parts[q].mesh.bounds();
    ctx.info[q].required = std::max(0.0, request.routing_clearance + parts[q].clearance);
    ctx.info[q].keep_out = parts[q].role == PartRole::KeepOut;
    ctx.info[q].closed = parts[q].closed;
    ctx.band = std::max(ctx.band, ctx.info[q].required);
    if (!parts[q].closed) res.notes.push_back("part '" + parts[q].name + "' is open: surface checks only");
  }
  if (request.tolerance > 0.0) {
    ctx.tol = request.tolerance;
    res.tolerance_source = "request";
  } else {
    ctx.tol = default_clash_tolerance(cables, &res.tolerance_source);
  }
  if (index) ctx.abs_err = index->accuracy().abs_error;
  if (request.method == ClashMethod::Certified && !(ctx.abs_err < 0.5 * ctx.tol))
    throw std::invalid_argument("check_clashes: tolerance " + std::to_string(ctx.tol) +
                                " is not above twice the index error " + std::to_string(ctx.abs_err));
  ctx.chord_error = kChordShareOfTolerance * (ctx.tol - ctx.abs_err);
  if (request.method == ClashMethod::Certified)
    for (const auto& c : cables) {
      const double hmax = kMaxChordRadii * c.radius;
      const double n = planned_chords(c.curve, ctx.chord_error, hmax, kShortSpanRadii * c.radius);
      if (n <= kMaxChordsPerCable) continue;
      // Say which bound asked for the chords: the longest chord (a route thousands of
      // kilometres long is a units or key-point mistake) or the chord error (a wiggle).
      const double by_length = c.curve.length() / hmax;
      const std::string reason =
          by_length >= 0.5 * n
              ? "it is " + full_precision(c.curve.length()) + " long, " + full_precision(std::ceil(by_length)) +
                    " chords of at most 2r = " + full_precision(hmax) + "; check its key points and units"
              : "its curvature reaches the scale of the tolerance; smooth the route or raise --tolerance";
      throw std::invalid_argument("check_clashes: cable '" + c.id + "' would need " + full_precision(n) +
                                  " chords to stay within " + full_precision(ctx.chord_error) +
                                  " of its curve (more than " + full_precision(kMaxChordsPerCable) + "): " + reason);
    }
  res.cables.resize(cables.size());
  std::vector<std::vector<ClashEntry>> per_clash(cables.size());
  std::vector<std::vector<Violation>> per_viol(cables.size());
  ProgressCounter checked(request.progress, "audit", cables.size(), "cables");

  if (request.method == ClashMethod::Certified) {
    res.tolerance = ctx.tol;
    res.chord_error = ctx.chord_error;
    res.distance_rel_error = request.distance_rel_error;
    if (request.check_structure && !parts.empty()) {
      std::vector<AABB> boxes(parts.size());
      for (std::size_t q = 0; q < parts.size(); ++q) boxes[q] = ctx.info[q].box;
      // In the audit's arena: Embree's builder runs on TBB and must not exceed `threads`.
      tbb::task_arena arena(request.threads > 0 ? request.threads : tbb::task_arena::automatic);
      arena.execute([&] { ctx.part_tree = std::make_unique<BoxTree>(std::move(boxes)); });
    }
    parallel_indices(cables.size(), request.threads, [&](std::size_t c) {
      CableCheckSummary& sum = res.cables[c];
      sum.length = cables[c].curve.length();
      if (request.check_structure && !parts.empty()) {
        StructureTracer tr(ctx, static_cast<int>(c));
        tr.run();
        per_clash[c] = std::move(tr.tracker().clashes);
        per_viol[c] = std::move(tr.tracker().violations);
        sum.min_clearance = std::max(tr.min_clearance(), -cables[c].radius);
        sum.min_clearance_exact = tr.min_exact();
      } else {
        sum.min_clearance = kInf;
      }
      check_bend(ctx, c, sum, per_viol[c]);
      checked.add();
    });
  } else {
    std::vector<DiscreteSamples> ds(cables.size());
    res.spacing = request.spacing > 0.0 ? request.spacing : 0.0;
    parallel_indices(cables.size(), request.threads, [&](std::size_t c) {
      const double l = request.spacing > 0.0 ? request.spacing : 2.0 * cables[c].radius;
      const auto samples = cables[c].curve.sample_by_arc_length(l);
      ds[c].spacing = samples.size() > 1 ? samples[1].first - samples[0].first : l;
      for (const auto& sp : samples) {
        ds[c].s.push_back(sp.first);
        ds[c].p.push_back(sp.second);
      }
      ctx.counters.samples += as_i64(samples.size());
      CableCheckSummary& sum = res.cables[c];
      sum.length = cables[c].curve.length();
      sum.min_clearance = kInf;
      if (request.check_structure && !parts.empty()) {
        StretchTracker tr(static_cast<int>(c), cables[c].radius, ctx.info, cables[c].attachments);
        discrete_structure(ctx, static_cast<int>(c), ds[c], tr);
        per_clash[c] = std::move(tr.clashes);
        per_viol[c] = std::move(tr.violations);
        sum.min_clearance = std::max(tr.min_key, -cables[c].radius);
      }
      check_bend(ctx, c, sum, per_viol[c]);
      checked.add();
    });
    std::vector<ClashEntry> pair_out;
    discrete_cable_pairs(ctx, ds, pair_out);
    for (const auto& e : pair_out) per_clash[e.cable].push_back(e);
  }
  if (request.method == ClashMethod::Certified) {
    std::vector<ClashEntry> pair_out;
    certified_cable_pairs(ctx, pair_out);
    for (const auto& e : pair_out) per_clash[e.cable].push_back(e);
  }
  for (std::size_t c = 0; c < cables.size(); ++c) {
    std::sort(per_clash[c].begin(), per_clash[c].end(), [](const ClashEntry& a, const ClashEntry& b) { return a.s < b.s; });
    std::sort(per_viol[c].begin(), per_viol[c].end(), [](const Violation& a, const Violation& b) { return a.s < b.s; });
    res.clashes.insert(res.clashes.end(), per_clash[c].begin(), per_clash[c].end());
    res.violations.insert(res.violations.end(), per_viol[c].begin(), per_viol[c].end());
  }
  res.counters = ctx.counters.snapshot();
  checked.finish();
  return res;
}

}  // namespace loom
