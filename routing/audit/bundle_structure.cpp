// Bundle-level structure work: each piece that carries more than one cable is sphere-traced
// once as a tube of its largest cable radius; the stretches it proves clear (and outside
// every closed part) are clear for every cable along it, the rest is measured chord by
// chord once for all of them; each cable's own structure pass then reads those stretches
// instead of tracing them (bundle_layout.hpp, clash_structure.cpp).
#include "routing/audit/bundle_layout.hpp"
#include "routing/audit/chord_plan.hpp"

#include <algorithm>
#include <cmath>
#include <map>

namespace loom::audit {

namespace {

/// One sample of the piece trace: a lower bound on the distance to every part surface, and
/// the surface point a query found (upper bound), if any.
struct PieceSample {
  double sigma = 0.0;
  Vec3 p = Vec3::Zero();
  double d = 0.0;      ///< lower bound on the distance to any part surface
  int part = -1;       ///< part of the surface point found (−1: none within the query)
  double upper = kInf; ///< its distance
};

/// A proven-clear run of the piece: [s0, s1] in σ, and the nearest surface sampled per part.
struct ClearRun {
  double s0 = 0.0, s1 = 0.0;
  Vec3 start = Vec3::Zero();
  std::map<int, double> nearest;
};

/// Sphere-traces one piece as a tube of radius r_max (Lipschitz bisection, as the cable
/// pass; its leaves are left to the cables): the proven-clear runs.
class PieceTracer {
 public:
  PieceTracer(Context& ctx, const Piece& p) : ctx_(ctx), piece_(p) {
    thr_ = p.r_max + ctx.band + ctx.chord_error + ctx.abs_err;
    leaf_ = std::max(kLeafRadii * p.r_max, 4.0 * ctx.tol);
    max_step_ = std::max(ctx.req.max_step > 0.0 ? ctx.req.max_step : kDefaultMaxStepRadii * p.r_max, leaf_);
    eps_ = ctx.req.distance_rel_error;
  }

  std::vector<ClearRun> run() {
    const double L = piece_.length, cap = thr_ + max_step_;
    PieceSample a = sample(0.0, cap);
    while (a.sigma < L) {
      const double step = std::clamp(2.0 * (a.d - thr_), leaf_, max_step_);
      const double next = std::min(L, a.sigma + step);
      const PieceSample b = sample(next, std::min(a.d + (next - a.sigma), cap));
      refine(a, b);
      a = b;
    }
    ctx_.counters.add(count_);
    return std::move(runs_);
  }

 private:
  PieceSample sample(double sigma, double radius) {
    PieceSample x;
    x.sigma = sigma;
    x.p = piece_.curve->position(piece_.curve->parameter_at_length(sigma));
    ++count_.samples;
    ++count_.distance_queries;
    const ClosestHit h = eps_ > 0.0 ? ctx_.index->closest_approx(x.p, radius, eps_) : ctx_.index->closest(x.p, radius);
    if (h.found()) {
      x.d = std::max(0.0, h.distance / (1.0 + eps_) - ctx_.abs_err);
      x.part = h.part;
      x.upper = h.distance;
    } else {
      x.d = std::max(0.0, radius - ctx_.abs_err);
    }
    return x;
  }

  void refine(const PieceSample& a, const PieceSample& b) {
    const double h = b.sigma - a.sigma;
    if (0.5 * (a.d + b.d - h) >= thr_) {
      clear(a, b);
      return;
    }
    if (h <= leaf_) return;  // left to the cables
    const PieceSample m = sample(0.5 * (a.sigma + b.sigma), std::min(std::min(a.d, b.d) + 0.5 * h, thr_ + max_step_));
    refine(a, m);
    refine(m, b);
  }

  /// Adds [a, b] to the proven-clear runs (continuing the last one where it ends at a).
  void clear(const PieceSample& a, const PieceSample& b) {
    if (runs_.empty() || runs_.back().s1 != a.sigma) {
      runs_.emplace_back();
      runs_.back().s0 = a.sigma;
      runs_.back().start = a.p;
    }
    ClearRun& r = runs_.back();
    r.s1 = b.sigma;
    for (const PieceSample* x : {&a, &b})
      if (x->part >= 0) {
        auto [it, fresh] = r.nearest.emplace(x->part, x->upper);
        if (!fresh) it->second = std::min(it->second, x->upper);
      }
  }

  Context& ctx_;
  const Piece& piece_;
  double thr_ = 0.0, leaf_ = 0.0, max_step_ = 0.0, eps_ = 0.0;
  std::vector<ClearRun> runs_;
  ClashCounters count_;
};

/// Measures [s0, s1] of piece p chord by chord against every part within reach (see
/// bundle_structure); false, with nothing kept, where a chord touches a surface or the
/// stretch starts inside a closed part.
bool measure(Context& ctx, const Piece& p, double s0, double s1, MeasuredRun& run, ClashCounters& count) {
  const Centerline& c = *p.curve;
  Chords ch;
  flatten(c, c.parameter_at_length(s0), c.parameter_at_length(s1), ctx.chord_error, kMaxChordRadii * p.r_min,
          kShortSpanRadii * p.r_min, ch);
  count.samples += as_i64(ch.p.size());
  std::vector<int> inside;
  ++count.inside_queries;
  ctx.index->inside_parts(ch.p.front(), inside);
  if (!inside.empty()) return false;
  const double margin = ctx.chord_error + ctx.abs_err;
  const double touch = std::max(4.0 * ctx.abs_err, ctx.chord_error);  // as the cable pass
  AABB box;
  for (const Vec3& q : ch.p) box.extend(q);
  std::vector<std::uint32_t> cand;
  ctx.part_tree->overlapping(box.inflated((p.r_max + ctx.band + margin) * (1.0 + 1e-9)), cand);
  run.sigma0 = s0;
  run.sigma1 = s1;
  std::map<int, double> nearest;
  for (std::size_t k = 0; k < ch.size(); ++k) {
    MeasuredChord mc{ch.p[k], ch.p[k + 1], ch.s[k], ch.s[k + 1], {}};
    AABB cb;
    cb.extend(mc.a);
    cb.extend(mc.b);
    for (const std::uint32_t cq : cand) {
      const int q = static_cast<int>(cq);
      const double reach = p.r_max + ctx.info[static_cast<std::size_t>(q)].required + margin;
      if (!boxes_overlap(cb.inflated(reach), ctx.info[static_cast<std::size_t>(q)].box)) continue;
      double t = 0.0;
      ++count.distance_queries;
      const ClosestHit h = ctx.index->segment_closest_on_part(mc.a, mc.b, q, reach, &t);
      if (!h.found()) continue;
      if (h.distance <= touch) return false;  // the inside may change here: each cable traces it
      mc.parts.push_back({q, h.distance, t, mc.a + t * (mc.b - mc.a)});
      auto [it, fresh] = nearest.emplace(q, h.distance);
      if (!fresh) it->second = std::min(it->second, h.distance);
    }
    run.chords.push_back(std::move(mc));
  }
  run.nearest.assign(nearest.begin(), nearest.end());
  return true;
}

/// A cable's hints from its pieces' clear and measured runs (see bundle_structure).
void cable_hints(const Context& ctx, const Layout& lay, std::size_t c, const std::vector<std::vector<ClearRun>>& clear,
                 const std::vector<std::vector<MeasuredRun>>& measured, StructureHints& h) {
  const CableInput& in = ctx.cables[c];
  const double L = in.curve.length();
  const double slack = kTouchRel * (1.0 + L);
  auto attached = [&](int part) {
    return std::any_of(in.attachments.begin(), in.attachments.end(), [&](const PartAttachment& at) { return at.part == part; });
  };
  for (const auto& [k, u] : lay.of_cable[c]) {
    const PieceUse& use = lay.pieces[static_cast<std::size_t>(k)].uses[static_cast<std::size_t>(u)];
    auto add = [&](double sigma0, double sigma1, const std::vector<MeasuredChord>* chords) {
      const double a = use.s_at(sigma0), b = use.s_at(sigma1);
      h.stretches.push_back({std::min(a, b), std::max(a, b), chords, use.s0, use.length, use.reversed});
    };
    for (const ClearRun& r : clear[static_cast<std::size_t>(k)]) {
      add(r.s0, r.s1, nullptr);
      // A part the cable is attached to is not a clearance of the cable's (is_attached).
      for (const auto& [part, dist] : r.nearest)
        if (!attached(part)) h.sampled_min = std::min(h.sampled_min, dist - in.radius);
    }
    for (const MeasuredRun& r : measured[static_cast<std::size_t>(k)]) {
      const double a = use.s_at(r.sigma0), b = use.s_at(r.sigma1);
      // Attached parts are excused chord by chord, cut at the attachment's ends: the cable's
      // own pass measures a stretch its attachments reach.
      const bool reached = std::any_of(in.attachments.begin(), in.attachments.end(), [&](const PartAttachment& at) {
        return at.s_begin < std::max(a, b) + slack && at.s_end > std::min(a, b) - slack;
      });
      if (reached) continue;
      add(r.sigma0, r.sigma1, &r.chords);
      for (const auto& [part, dist] : r.nearest) h.sampled_min = std::min(h.sampled_min, dist - in.radius);
    }
  }
  // In order along the cable; clear stretches that meet merged (the runs of consecutive
  // pieces meet at their common end), and ends within rounding of each other made one.
  std::sort(h.stretches.begin(), h.stretches.end(),
            [](const HintStretch& x, const HintStretch& y) { return x.s0 < y.s0; });
  std::vector<HintStretch> merged;
  for (HintStretch hs : h.stretches) {
    if (!merged.empty() && hs.s0 <= merged.back().s1 + slack) {
      hs.s0 = merged.back().s1;
      if (!hs.chords && !merged.back().chords) {
        merged.back().s1 = std::max(merged.back().s1, hs.s1);
        continue;
      }
    }
    if (hs.s0 <= slack) hs.s0 = 0.0;
    if (hs.s1 >= L - slack) hs.s1 = L;
    merged.push_back(hs);
  }
  h.stretches = std::move(merged);
}

}  // namespace

BundleStructure bundle_structure(Context& ctx, const Layout& lay) {
  BundleStructure out;
  out.cables.resize(ctx.cables.size());
  out.measured.resize(lay.pieces.size());
  std::vector<std::vector<ClearRun>> clear(lay.pieces.size());
  parallel_indices(lay.pieces.size(), ctx.req.threads, [&](std::size_t k) {
    const Piece& p = lay.pieces[k];
    if (p.uses.size() < 2) return;  // a piece of one cable: its own pass traces it
    std::vector<ClearRun> found = PieceTracer(ctx, p).run();
    // A run lies at least thr_ from every surface, so it is inside a closed part all along
    // or nowhere: one inside test at its start tells.
    std::vector<int> inside;
    ClashCounters count;
    for (ClearRun& r : found) {
      ++count.inside_queries;
      ctx.index->inside_parts(r.start, inside);
      if (inside.empty()) clear[k].push_back(std::move(r));
    }
    // The gaps between the clear runs, measured.
    double at = 0.0;
    for (std::size_t i = 0; i <= clear[k].size(); ++i) {
      const double end = i < clear[k].size() ? clear[k][i].s0 : p.length;
      if (end > at) {
        MeasuredRun run;
        if (measure(ctx, p, at, end, run, count)) out.measured[k].push_back(std::move(run));
      }
      if (i < clear[k].size()) at = clear[k][i].s1;
    }
    ctx.counters.add(count);
  });
  parallel_indices(ctx.cables.size(), ctx.req.threads,
                   [&](std::size_t c) { cable_hints(ctx, lay, c, clear, out.measured, out.cables[c]); });
  return out;
}

}  // namespace loom::audit
