// Clash checking: the entry point (clash_check.hpp) — tolerances derived, the passes run
// (clash_structure.cpp, clash_pairs.cpp, clash_discrete.cpp), results sorted — and the
// bend check.
#include "routing/audit/clash_check.hpp"

#include "routing/audit/bundle_layout.hpp"
#include "routing/audit/chord_plan.hpp"
#include "routing/audit/clash_context.hpp"

#include "core/error.hpp"
#include "routing/curve/cable_limit.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

namespace loom {

using namespace audit;  // the passes' shared context (clash_context.hpp)

namespace {

/// Default tolerance as a fraction of the smallest cable radius (DESIGN §7).
constexpr double kDefaultToleranceOfRadius = 0.01;
/// The tolerance reported when there is no cable to derive it from (nothing is checked).
constexpr double kNoCableTolerance = 0.01;
/// How far (as a share of the chord error) a cable's curve may pass from the ends of its
/// bend pieces for the bundle level to take them as its pieces (rounding only: they are
/// the curve's own pieces).
constexpr double kMeetShareOfChordError = 0.25;
/// Share of the tolerance left to the chords' distance from the curve; the rest covers the
/// index's own error (structure: chord + index ≤ tol; cable–cable: 2 · chord ≤ tol).
constexpr double kChordShareOfTolerance = 0.5;
/// Refuses a certified tolerance at or below twice the index's rounding (it cannot be
/// certified), saying where the tolerance came from (--tolerance, or the thinnest cable,
/// which the refusal then names) at full precision.
[[noreturn]] void refuse_tolerance(const std::vector<CableInput>& cables, const Context& ctx, const std::string& source) {
  const bool requested = source == "request";
  const std::string text = "clash tolerance " + full_precision(ctx.tol) + " (" +
                           (requested ? std::string("as requested") : source) +
                           ") is not above twice the index's distance rounding " + full_precision(ctx.abs_err) +
                           " (scene units): give --tolerance above " + full_precision(2.0 * ctx.abs_err) +
                           " or check the cable diameters and the scene's units";
  if (requested || cables.empty()) throw std::invalid_argument(text);
  const auto thinnest = std::min_element(cables.begin(), cables.end(),
                                         [](const CableInput& a, const CableInput& b) { return a.radius < b.radius; });
  throw CableLimitError(thinnest->id, "cable '" + thinnest->id + "' is the thinnest: " + text);
}

/// A node's breakout is its largest bend radius, so a right-angle turn through it sits
/// exactly at the limit (reach / tan 45°); its tangents come from evaluating the curves,
/// within rounding of the directions the layout gave them, so a node turn within this
/// relative slack of the limit is not tighter than it.
constexpr double kNodeTurnRelSlack = 1e-9;

/// The smallest bend radius of cable c (per bend piece where it has them, and at the nodes
/// it passes) into `sum`, and a bend-radius violation into `out` for every stretch bending
/// tighter than the cable's minimum (Centerline::bend_stretches_below), at its tightest
/// point, and for every node turn tighter than it (NodeTurn).
/// `memo` (may be null) holds the results of curves the cable shares with others.
void check_bend(const Context& ctx, std::size_t c, CableCheckSummary& sum, std::vector<Violation>& out,
                const BendMemo* memo) {
  const CableInput& in = ctx.cables[c];
  // The k-th curve judged (bend piece, or the whole curve): from the memo where it has it.
  auto min_of = [&](std::size_t k, const Centerline& curve) {
    const BendExtremum* m = memo ? memo->min_radius(c, k) : nullptr;
    return m ? *m : curve.min_bend_radius();
  };
  BendExtremum b = in.bend_pieces.empty() ? min_of(0, in.curve) : BendExtremum{};
  if (!in.bend_pieces.empty()) {
    b.radius = std::numeric_limits<double>::infinity();
    for (std::size_t k = 0; k < in.bend_pieces.size(); ++k) {
      const auto& [s0, piece] = in.bend_pieces[k];
      const BendExtremum pb = min_of(k, piece);
      if (pb.radius < b.radius) {
        b = pb;
        b.s += s0;
      }
    }
  }
  for (const NodeTurn& t : in.node_turns)
    if (t.radius < b.radius) b.radius = t.radius, b.s = t.s;
  sum.min_bend_radius = b.radius;
  sum.min_bend_s = b.s;
  if (!(ctx.req.check_bend && in.min_bend_radius > 0.0 && b.radius < in.min_bend_radius)) return;
  // One violation per stretch bending tighter than the minimum, at its tightest point (as
  // one clash per contact stretch): a route with two tight corners needs both mended.
  auto add = [&](const Centerline& curve, double s0, std::size_t k) {
    const std::vector<BendExtremum>* known = memo ? memo->below(c, k) : nullptr;
    for (const BendExtremum& e : known ? *known : curve.bend_stretches_below(in.min_bend_radius)) {
      Violation v;
      v.kind = ViolationKind::BendRadius;
      v.cable = static_cast<int>(c);
      v.value = e.radius;
      v.limit = in.min_bend_radius;
      v.s = s0 + e.s;
      v.s_begin = v.s_end = v.s;
      v.point = curve.position(e.u);
      out.push_back(v);
    }
  };
  if (in.bend_pieces.empty()) add(in.curve, 0.0, 0);
  for (std::size_t k = 0; k < in.bend_pieces.size(); ++k) add(in.bend_pieces[k].second, in.bend_pieces[k].first, k);
  for (const NodeTurn& t : in.node_turns) {
    if (!(t.radius < in.min_bend_radius * (1.0 - kNodeTurnRelSlack))) continue;
    Violation v;
    v.kind = ViolationKind::BendRadius;
    v.cable = static_cast<int>(c);
    v.value = t.radius;
    v.limit = in.min_bend_radius;
    v.s = t.s;
    v.point = t.point;
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

double fewest_certified_chords(double length, double radius) { return length / (kMaxChordRadii * radius); }

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

namespace {

/// Throws CableLimitError for the first cable (in cable order) whose certified check would
/// need more than kMaxCertifiedChords chords, saying which bound asked for them.
void refuse_unbounded_chords(const std::vector<CableInput>& cables, const Context& ctx) {
  // Chords each cable will need, in parallel (a pass over every curve); refused in cable order.
  std::vector<double> chords(cables.size());
  parallel_indices(cables.size(), ctx.req.threads, [&](std::size_t i) {
    const CableInput& c = cables[i];
    chords[i] = planned_chords(c.curve, ctx.chord_error, kMaxChordRadii * c.radius, kShortSpanRadii * c.radius);
  });
  for (std::size_t i = 0; i < cables.size(); ++i) {
    const CableInput& c = cables[i];
    const double hmax = kMaxChordRadii * c.radius;
    const double n = chords[i];
    if (n <= kMaxCertifiedChords) continue;
    // Say which bound asked for the chords: the longest chord (a route thousands of
    // kilometres long is a units or key-point mistake) or the chord error (a wiggle).
    const double by_length = c.curve.length() / hmax;
    const std::string reason =
        by_length >= 0.5 * n
            ? "it is " + full_precision(c.curve.length()) + " long, " + full_precision(std::ceil(by_length)) +
                  " chords of at most 2r = " + full_precision(hmax) + "; check its key points and units"
            : "its curvature reaches the scale of the tolerance; smooth the route or raise --tolerance";
    throw CableLimitError(c.id, "cable '" + c.id + "' would need " + full_precision(n) +
                                    " chords to stay within " + full_precision(ctx.chord_error) +
                                    " of its curve (more than " + full_precision(kMaxCertifiedChords) + "): " + reason);
  }
}

/// check_clashes, inside the audit's arena.
ClashResult check_clashes_in_arena(const std::vector<CableInput>& cables, const std::vector<Part>& parts,
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
    refuse_tolerance(cables, ctx, res.tolerance_source);
  ctx.chord_error = kChordShareOfTolerance * (ctx.tol - ctx.abs_err);
  if (request.method == ClashMethod::Certified) refuse_unbounded_chords(cables, ctx);
  res.cables.resize(cables.size());
  std::vector<std::vector<ClashEntry>> per_clash(cables.size());
  std::vector<std::vector<Violation>> per_viol(cables.size());
  ProgressCounter checked(request.progress, "audit", cables.size(), "cables");
  std::optional<Layout> layout;  // the bundle level's pieces (certified, when cables share some)

  if (request.method == ClashMethod::Certified) {
    res.tolerance = ctx.tol;
    res.chord_error = ctx.chord_error;
    res.distance_rel_error = request.distance_rel_error;
    if (request.check_structure && !parts.empty()) {
      std::vector<AABB> boxes(parts.size());
      for (std::size_t q = 0; q < parts.size(); ++q) boxes[q] = ctx.info[q].box;
      // In the audit's arena: Embree's builder runs on TBB and must not exceed `threads`.
      ctx.part_tree = std::make_unique<BoxTree>(std::move(boxes));
    }
    // The bundle level where cables share pieces: each shared piece checked once for all.
    if (!request.per_cable) {
      layout = make_layout(cables, kMeetShareOfChordError * ctx.chord_error, request.threads);
      if (!layout->shared) layout.reset();
    }
    BundleStructure bundled;
    std::unique_ptr<BendMemo> memo;
    if (layout) {
      res.bundle_level = true;
      if (request.check_structure && !parts.empty()) bundled = bundle_structure(ctx, *layout);
      memo = std::make_unique<BendMemo>(ctx, *layout);
    }
    parallel_indices(cables.size(), request.threads, [&](std::size_t c) {
      CableCheckSummary& sum = res.cables[c];
      sum.length = cables[c].curve.length();
      if (request.check_structure && !parts.empty()) {
        certified_structure(ctx, static_cast<int>(c), sum, per_clash[c], per_viol[c],
                            bundled.cables.empty() ? nullptr : &bundled.cables[c]);
      } else {
        sum.min_clearance = kInf;
      }
      check_bend(ctx, c, sum, per_viol[c], memo.get());
      checked.add();
    });
  } else {
    std::vector<DiscreteSamples> ds(cables.size());
    res.spacing = request.spacing > 0.0 ? request.spacing : 0.0;
    check_discrete_work(ctx);  // before any sampling
    parallel_indices(cables.size(), request.threads, [&](std::size_t c) {
      const double l = discrete_spacing(request, cables[c]);
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
        StretchTracker tr(static_cast<int>(c), cables[c].radius, ctx.info, cables[c].attachments, {}, ctx.tol);
        discrete_structure(ctx, static_cast<int>(c), ds[c], tr);
        per_clash[c] = std::move(tr.clashes);
        per_viol[c] = std::move(tr.violations);
        sum.min_clearance = std::max(tr.min_key, -cables[c].radius);
      }
      check_bend(ctx, c, sum, per_viol[c], nullptr);
      checked.add();
    });
    std::vector<ClashEntry> pair_out;
    discrete_cable_pairs(ctx, ds, pair_out);
    for (const auto& e : pair_out) per_clash[e.cable].push_back(e);
  }
  if (request.method == ClashMethod::Certified) {
    std::vector<ClashEntry> pair_out;
    if (layout)
      bundle_cable_pairs(ctx, *layout, pair_out);
    else
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

}  // namespace

ClashResult check_clashes(const std::vector<CableInput>& cables, const std::vector<Part>& parts,
                          const ObstacleIndex* index, const ClashRequest& request) {
  // Every pass runs in one arena of the requested concurrency (parallel_indices joins it).
  tbb::task_arena arena(request.threads > 0 ? request.threads : tbb::task_arena::automatic);
  return arena.execute([&] { return check_clashes_in_arena(cables, parts, index, request); });
}

}  // namespace loom
