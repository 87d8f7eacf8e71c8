#pragma once
/// What the audit's passes share (internal to routing/clash_check*.cpp): the checked
/// cables and parts, the tolerances derived for them, work counters, and the passes'
/// entry points — certified cable–structure (clash_structure.cpp), certified cable–cable
/// and self (clash_pairs.cpp), the seed paper's discrete method (clash_discrete.cpp).
/// World frame, scene units; s is arc length along a cable.

#include "index/box_tree.hpp"
#include "routing/audit/clash_check.hpp"
#include "routing/audit/stretch_tracker.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <atomic>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <utility>
#include <vector>

namespace loom::audit {

constexpr double kInf = std::numeric_limits<double>::infinity();
/// Longest chord, in cable radii (keeps the self rule |s − t| ≥ πr sharp: the paper's
/// sample spacing 2r).
constexpr double kMaxChordRadii = 2.0;
/// Knot spans shorter than this many cable radii may be merged into one chord with their
/// short neighbours (ChordPlan): routes hold no key points this close on purpose.
constexpr double kShortSpanRadii = 0.25;
/// Arc-length slack (relative to the cable length) when deciding that two chord or sample
/// intervals touch.
constexpr double kTouchRel = 1e-9;
/// Default longest sphere-tracing step of the certified structure pass, in tube radii.
constexpr double kDefaultMaxStepRadii = 50.0;
/// Stretches of the sphere trace shorter than this many tube radii that cannot be proven
/// clear are handed to the exact chord measurement.
constexpr double kLeafRadii = 2.0;

inline std::int64_t as_i64(std::size_t v) { return static_cast<std::int64_t>(v); }

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

/// Runs body(i), i in [0, n), on `threads` workers (≤ 0: all cores), grain 1. Called from
/// inside an arena of that concurrency (check_clashes runs in one), it runs there: a new
/// arena per pass makes the workers join again each time, which on a harness checked in
/// milliseconds costs more than a pass's work.
template <class Body>
void parallel_indices(std::size_t n, int threads, const Body& body) {
  if (n == 0) return;
  auto loop = [&] {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t i = r.begin(); i != r.end(); ++i) body(i);
    });
  };
  if (threads > 0 && tbb::this_task_arena::max_concurrency() == threads) {
    loop();
    return;
  }
  tbb::task_arena arena(threads > 0 ? threads : tbb::task_arena::automatic);
  arena.execute(loop);
}

/// The checked scene and the audit's derived tolerances, shared by every pass and thread.
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
inline int segment_at(const CableInput& c, double s) {
  const double slack = kTouchRel * (1.0 + std::abs(s));
  for (const auto& r : c.segments)
    if (s >= r.s0 - slack && s <= r.s1 + slack) return r.segment;
  return -1;
}

/// True when a contact between cables a (point p, arc s) and b (point q, arc t) is excused:
/// both run in the same harness segment (a bundle) or both are at a node they share.
inline bool excused(const CableInput& a, double s, const Vec3& p, const CableInput& b, double t, const Vec3& q) {
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

/// True when a self contact of cable c between points p and q lies within the radius of a
/// node it passes through: its turn at the node, judged as a bend (NodeTurn), not a clash.
inline bool self_excused_at_node(const CableInput& c, const Vec3& p, const Vec3& q) {
  for (const auto& j : c.junctions)
    if (j.passes && (p - j.position).norm() <= j.radius && (q - j.position).norm() <= j.radius) return true;
  return false;
}

/// A part within reach of a chord the bundle level measured: its exact distance from the
/// chord and where.
struct ChordPartDistance {
  int part = -1;
  double dist = 0.0;  ///< exact distance from the chord to the part's surface
  double t = 0.0;     ///< parameter of the closest point on the chord, from its start
  Vec3 point = Vec3::Zero();  ///< that point of the chord
};

/// A chord of a shared piece measured once for all its cables: every part within the
/// largest radius + the part's required clearance + the measuring margin (nothing touches
/// the centerline, which lies outside every closed part).
struct MeasuredChord {
  Vec3 a = Vec3::Zero(), b = Vec3::Zero();
  double sigma0 = 0.0, sigma1 = 0.0;  ///< arc lengths along the piece at a and b
  std::vector<ChordPartDistance> parts;
};

/// A stretch of a cable the bundle level has decided: proven clear (`chords` null: farther
/// than the cable's radius + the band + the measuring margin from every part, outside every
/// closed part), or measured (`chords`: the piece's chords over it, in the piece's
/// direction, the cable running them backwards when `reversed`).
struct HintStretch {
  double s0 = 0.0, s1 = 0.0;  ///< on the cable, s0 < s1
  const std::vector<MeasuredChord>* chords = nullptr;
  double piece_s0 = 0.0;      ///< the cable's arc length at σ = 0 of the piece
  double piece_length = 0.0;  ///< the piece's length on the cable
  bool reversed = false;
  /// Cable arc length at piece arc length σ.
  double s_at(double sigma) const { return reversed ? piece_s0 + (piece_length - sigma) : piece_s0 + sigma; }
};

/// What the bundle level decided of one cable before its structure pass (bundle_layout.hpp).
struct StructureHints {
  std::vector<HintStretch> stretches;  ///< sorted, disjoint
  /// Smallest clearance seen there, to parts the cable is not attached to (an upper bound
  /// on the cable's smallest clearance).
  double sampled_min = kInf;
};

/// Certified cable–structure pass of one cable (sphere tracing + exact chords): its clashes
/// and clearance violations appended, its smallest clearance written into `sum`. The
/// stretches `hints` proves clear are not traced again (null: none).
void certified_structure(Context& ctx, int cable, CableCheckSummary& sum, std::vector<ClashEntry>& clashes,
                         std::vector<Violation>& violations, const StructureHints* hints = nullptr);

/// Certified cable–cable and self pass over all cables (chord blocks in one BVH, exact
/// segment distances): one entry per contact stretch, appended to `out`.
void certified_cable_pairs(Context& ctx, std::vector<ClashEntry>& out);

/// Samples of every cable for the discrete method.
struct DiscreteSamples {
  std::vector<double> s;
  std::vector<Vec3> p;
  double spacing = 0.0;
};

/// The discrete method's sample spacing of a cable: --spacing, else the paper's 2r.
inline double discrete_spacing(const ClashRequest& req, const CableInput& c) {
  return req.spacing > 0.0 ? req.spacing : 2.0 * c.radius;
}

/// Refuses, before any sample is taken, a discrete audit whose samples or sample pairs
/// would pass its limits (Centerline::kMaxArcSamples per cable; with an index, a lower
/// bound on the pairs its grid hands to the distance test against max_sample_pairs):
/// CableLimitError naming the cable and the figure.
void check_discrete_work(const Context& ctx);

/// The discrete method's cable–structure checks of one cable's samples, into `tr`.
void discrete_structure(Context& ctx, int cable, const DiscreteSamples& ds, StretchTracker& tr);

/// The discrete method's cable–cable and self checks over all cables' samples.
void discrete_cable_pairs(Context& ctx, const std::vector<DiscreteSamples>& ds, std::vector<ClashEntry>& out);

}  // namespace loom::audit
