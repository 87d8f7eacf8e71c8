// Certified cable–structure pass: Lipschitz sphere tracing along each cable, exact chord
// measurement near contact (clash_context.hpp, clash_check.hpp for the contract).
#include "routing/audit/clash_context.hpp"

#include "core/error.hpp"
#include "routing/audit/chord_plan.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>

namespace loom::audit {

namespace {

/// A sphere-tracing query cut short at the distance a decision needs stops this much
/// (relative to the largest query radius) beyond it, so that rounding does not leave the
/// bound a hair short of the decision.
constexpr double kCutMarginRel = 1e-9;
/// With approximate queries, a leaf stretch whose bounds fell short of a proof that its
/// samples' surface points could give is retried with queries this much finer than the
/// request's ε (a lower bound is all a proof needs; exact values cost ~3× more near a
/// finely tessellated surface).
constexpr double kProofErrorShare = 0.125;

/// Sphere-traces one cable, measures what cannot be proven clear exactly, tracks stretches.
class StructureTracer {
 public:
  StructureTracer(Context& ctx, int cable, const StructureHints* hints)
      : ctx_(ctx),
        in_(ctx.cables[cable]),
        r_(in_.radius),
        hints_(hints),
        // Attachments are excused here, chord by chord (excuse_attached), not by the tracker.
        tracker_(cable, r_, ctx.info, no_attachments(), [this](PartObservation& o) { measure_deferred(o); }) {
    L_ = in_.curve.length();
    margin_ = ctx.chord_error + ctx.abs_err;
    thr_ = r_ + ctx.band + margin_;
    leaf_ = std::max(kLeafRadii * r_, 4.0 * ctx.tol);
    max_step_ = ctx.req.max_step > 0.0 ? ctx.req.max_step : kDefaultMaxStepRadii * r_;
    max_step_ = std::max(max_step_, leaf_);
    cut_margin_ = ctx.abs_err + kCutMarginRel * (thr_ + max_step_);
    rel_error_ = ctx.req.distance_rel_error;
    if (hints_) summary_min_ = hints_->sampled_min;
  }

  void run() {
    const double cap = thr_ + max_step_;  // the largest query radius
    // Inside status at the start; it can only change where the trace is not proven clear.
    Sample s0 = sample(0.0, cap, thr_ + 0.5 * max_step_ + cut_margin_);
    update_inside(s0.p);
    Sample a = s0;
    double s_prev = 0.0;
    std::size_t next_hint = 0;  // the first stretch the bundle level decided that is not passed yet
    const std::size_t n_hint = hints_ ? hints_->stretches.size() : 0;
    while (s_prev < L_) {
      // A stretch the bundle level proved clear is a proven-clear gap; one it measured gives
      // its chords' observations. Either is sampled again at its end only.
      while (next_hint < n_hint && hints_->stretches[next_hint].s1 <= s_prev) ++next_hint;
      if (next_hint < n_hint && hints_->stretches[next_hint].s0 <= s_prev) {
        const HintStretch& hs = hints_->stretches[next_hint];
        const double s_end = std::min(L_, hs.s1);
        if (hs.chords) {
          flush_free();
          measured(hs);
        } else {
          free_.push_back({a, s_end});
        }
        a = sample(s_end, cap, thr_ + 0.5 * max_step_ + cut_margin_);
        s_prev = s_end;
        continue;
      }
      const double clear_start = next_hint < n_hint ? hints_->stretches[next_hint].s0 : L_;
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
      const double s_next = std::min({L_, s_prev + step, clear_start});
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
      free_.push_back({a, b.s});
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

  /// Records the proven-clear stretches: while inside closed parts each is a clash stretch
  /// with each of them, over its whole length (deepest = farthest from any surface).
  void flush_free() {
    // Free samples only matter while the trace is inside a closed part.
    if (!inside_parts_.empty()) {
      // The deepest sample is the one farthest from the surface: only samples whose upper
      // bound reaches the largest lower bound can be it, and only they need their values.
      double deepest = 0.0;
      for (FreeStretch& f : free_) {
        refresh(f.a);
        deepest = std::max(deepest, f.a.d);
      }
      for (FreeStretch& f : free_)
        if (f.a.u >= deepest) resolve(f.a);
      std::vector<PartObservation> obs;
      for (const FreeStretch& f : free_) {
        obs.clear();
        for (const int q : inside_parts_) {
          PartObservation o;
          o.part = q;
          o.key = -r_ - f.a.d;
          o.point = f.a.p;
          o.s = f.a.s;
          o.inside = true;
          obs.push_back(o);
        }
        excuse_attached(obs, f.a.s, f.s_end, 0.0);
        tracker_.step(obs, f.a.s, f.s_end);
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
    // Chords end where an attachment's range does, and where its lift off a port on a face
    // does (exit_lifted): each lies within the range or outside it, and within the lift or
    // past it.
    std::vector<double> cuts{s0};
    for (const PartAttachment& at : in_.attachments)
      for (const double x : {at.s_begin, at.s_end, lift_end(at)})
        if (x > s0 && x < s1) cuts.push_back(x);
    std::sort(cuts.begin(), cuts.end());
    cuts.push_back(s1);
    for (std::size_t i = 0; i + 1 < cuts.size(); ++i)
      if (cuts[i + 1] > cuts[i])
        flatten(c, c.parameter_at_length(cuts[i]), c.parameter_at_length(cuts[i + 1]), ctx_.chord_error,
                kMaxChordRadii * r_, kShortSpanRadii * r_, ch);
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
      // The chord touches or crosses a surface: the inside status may change here.
      if (h.found() && h.distance <= touch) update_inside(b);
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
      for (const int q : inside_parts_) {
        // Axis inside a closed part: dist = 0; rank by depth at the chord's end.
        PartObservation o;
        o.part = q;
        ++count_.distance_queries;
        // Depth only ranks points of the stretch (all have clearance −r): bounded search.
        const ClosestHit hb = ctx_.index->closest_on_part(b, q, thr_);
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
          if (q == primary || is_inside(q)) continue;
          if (!boxes_overlap(cb.inflated(r_ + ctx_.info[q].required + margin_), ctx_.info[q].box))
            continue;  // the part's box is beyond the band of this chord
          secondary(a, b, ch.s[k], ch.s[k + 1], q, obs);
        }
      }
      excuse_attached(obs, ch.s[k], ch.s[k + 1], touch);
      tracker_.step(obs, ch.s[k], ch.s[k + 1]);
    }
  }

  /// The observations of a stretch the bundle level measured, chord by chord in the
  /// cable's direction: each part closer than r + its required clearance (what near()
  /// observes on a chord outside every part, with exact distances).
  void measured(const HintStretch& hs) {
    const std::vector<MeasuredChord>& chords = *hs.chords;
    std::vector<PartObservation> obs;
    for (std::size_t i = 0; i < chords.size(); ++i) {
      const MeasuredChord& mc = chords[hs.reversed ? chords.size() - 1 - i : i];
      obs.clear();
      for (const ChordPartDistance& d : mc.parts) {
        if (!(d.dist - r_ < ctx_.info[d.part].required)) continue;
        PartObservation o;
        o.part = d.part;
        o.key = d.dist - r_;
        o.point = d.point;
        o.s = hs.s_at(mc.sigma0 + d.t * (mc.sigma1 - mc.sigma0));
        obs.push_back(o);
      }
      const double sa = hs.s_at(mc.sigma0), sb = hs.s_at(mc.sigma1);
      tracker_.step(obs, std::min(sa, sb), std::max(sa, sb));
    }
  }

  /// Sets the closed parts holding p strictly inside (the index's answer: all of them, so
  /// a keep-out zone drawn around a box clashes as well as the box).
  void update_inside(const Vec3& p) {
    ++count_.inside_queries;
    ctx_.index->inside_parts(p, inside_parts_);
  }

  /// No attachments: what this pass's tracker is given (it excuses them itself).
  static const std::vector<PartAttachment>& no_attachments() {
    static const std::vector<PartAttachment> none;
    return none;
  }

  /// Drops the observations of parts the cable is attached to over the whole step [sa, sb]
  /// (a chord, which near() ends at every attachment's ends, or a proven-clear stretch).
  /// Why by the step and not by the observation's point: the closest point of the first
  /// chord past a port's exit is often the exit's end itself, which the attachment holds,
  /// while the rest of the chord is not excused and may fall short of the clearance (a
  /// violation of 2.0 for 3.0 required, 3 r from a connector, went unreported).
  /// The centerline inside the part, or with its axis within `touch` of it past the lift
  /// (exit_lifted), is excused only where the port lies inside the part: a port on a face
  /// whose exit runs into the part, or through a plate, goes through it (a clash).
  void excuse_attached(std::vector<PartObservation>& obs, double sa, double sb, double touch) const {
    const double slack = kTouchRel * (1.0 + L_);
    auto excused = [&](const PartObservation& o, const PartAttachment& at) {
      if (at.part != o.part || sa < at.s_begin - slack || sb > at.s_end + slack) return false;
      if (holds_port(at, ctx_.tol)) return true;
      if (o.inside) return false;
      return !(o.key + r_ <= touch && exit_lifted(at, sa, sb));
    };
    obs.erase(std::remove_if(obs.begin(), obs.end(),
                             [&](const PartObservation& o) {
                               return std::any_of(in_.attachments.begin(), in_.attachments.end(),
                                                  [&](const PartAttachment& at) { return excused(o, at); });
                             }),
              obs.end());
  }

  /// True if the attachment's port is the cable's first (its range starts at s = 0), false
  /// for its last.
  static bool port_at_start(const PartAttachment& at) { return at.s_begin <= 0.0; }

  /// Where the lift off a port on a face ends: the first tolerance of the exit, over which
  /// the axis may touch the part it leaves (the port is on its surface, up to rounding and
  /// the tolerance). NaN for a part holding its port (no lift: the exit leaves the part).
  double lift_end(const PartAttachment& at) const {
    if (holds_port(at, ctx_.tol)) return std::numeric_limits<double>::quiet_NaN();
    return port_at_start(at) ? at.s_begin + ctx_.tol : at.s_end - ctx_.tol;
  }

  /// True if the step [sa, sb] lies past the lift off the attachment's port.
  bool exit_lifted(const PartAttachment& at, double sa, double sb) const {
    const double slack = kTouchRel * (1.0 + L_);
    return port_at_start(at) ? sa >= lift_end(at) - slack : sb <= lift_end(at) + slack;
  }

  bool is_inside(int part) const {
    return std::find(inside_parts_.begin(), inside_parts_.end(), part) != inside_parts_.end();
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
  const CableInput& in_;
  double r_;
  const StructureHints* hints_;  ///< stretches proven clear beforehand (may be null)
  StretchTracker tracker_;
  double L_ = 0.0, thr_ = 0.0, leaf_ = 0.0, max_step_ = 0.0, margin_ = 0.0;
  double rel_error_ = 0.0;   ///< ClashRequest::distance_rel_error (0: exact sphere tracing)
  std::vector<std::uint32_t> cand_;  ///< near(): parts whose boxes reach the stretch (reused buffer)
  double cut_margin_ = 0.0;  ///< added to a cut-short query's radius: d = max(0, hit − abs_err) and rounding
  /// Closed parts the trace is inside (ascending; usually none or one).
  std::vector<int> inside_parts_;
  /// A proven-clear stretch from sample `a` to arc length `s_end`.
  struct FreeStretch {
    Sample a;
    double s_end = 0.0;
  };
  std::vector<FreeStretch> free_;
  std::vector<Pending> pending_;  ///< cut-short samples of this cable
  double summary_min_ = kInf;
  ClashCounters count_;
};

}  // namespace

void certified_structure(Context& ctx, int cable, CableCheckSummary& sum, std::vector<ClashEntry>& clashes,
                         std::vector<Violation>& violations, const StructureHints* hints) {
  StructureTracer tr(ctx, cable, hints);
  tr.run();
  clashes = std::move(tr.tracker().clashes);
  violations = std::move(tr.tracker().violations);
  sum.min_clearance = std::max(tr.min_clearance(), -ctx.cables[static_cast<std::size_t>(cable)].radius);
  sum.min_clearance_exact = tr.min_exact();
}

}  // namespace loom::audit
