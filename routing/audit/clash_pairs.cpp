// Certified cable–cable and self pass: chords of every cable boxed in blocks, one BVH broad
// phase over the blocks, exact segment–segment distances, contacts grouped into stretches
// (clash_context.hpp, clash_check.hpp for the contract).
#include "routing/audit/clash_context.hpp"
#include "routing/audit/chord_pair_excuse.hpp"
#include "routing/audit/pair_contacts.hpp"

#include "core/error.hpp"
#include "index/box_pairs.hpp"
#include "index/triangle_distance.hpp"
#include "routing/audit/chord_plan.hpp"
#include "routing/curve/cable_limit.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <mutex>
#include <stdexcept>
#include <string>

namespace loom::audit {

namespace {

/// Chords per block in the cable–cable narrow phase.
constexpr std::size_t kBlock = 8;

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
      if (auto c = judge_chord_pair(ctx.cables, {A.cable, A.ch.p[ka], A.ch.p[ka + 1], sa0, sa1},
                                    {B.cable, B.ch.p[kb], B.ch.p[kb + 1], tb0, tb1}, r))
        out.push_back(*c);
    }
  }
  return tests;
}

/// Block pairs handed to one narrow-phase task (amortises task and lock overhead).
constexpr std::size_t kPairsPerTask = 256;

}  // namespace

std::vector<BoxPair> bounded_block_pairs(Context& ctx, const std::vector<AABB>& boxes,
                                         std::function<bool(std::uint32_t, std::uint32_t)> keep,
                                         const std::function<int(std::uint32_t)>& cable_of) {
  const ClashLimits& lim = ctx.req.limits;
  BoxPairRequest bp;
  bp.filter.keep = std::move(keep);
  bp.filter.max_pairs = lim.max_block_pairs;
  bp.max_overlaps = lim.max_block_overlaps;
  bp.threads = ctx.req.threads;
  BoxPairResult found = overlapping_box_pairs(boxes, bp);
  ctx.counters.block_overlaps_estimate =
      static_cast<std::int64_t>(std::llround(std::min(found.estimated_overlaps, 9e18)));
  // A cable with the most overlapping blocks, named by the refusals (which need blocks).
  const std::string busiest =
      found.status == BoxPairStatus::Done ? "" : ctx.cables[static_cast<std::size_t>(cable_of(found.busiest))].id;
  if (found.status == BoxPairStatus::TooManyOverlaps)
    throw CableLimitError(busiest, "about " + full_precision(std::round(found.estimated_overlaps)) +
                                       " pairs of chord blocks come within reach of each other (limit " +
                                       full_precision(static_cast<double>(lim.max_block_overlaps)) + "; cable '" +
                                       busiest + "' among them): " + kFoldBack);
  if (found.status == BoxPairStatus::TooManyKept)
    throw CableLimitError(busiest, "more than " + full_precision(static_cast<double>(lim.max_block_pairs)) +
                                       " pairs of chord blocks of different cables, or of one cable πr apart, come "
                                       "within reach of each other (about " +
                                       full_precision(std::round(found.estimated_kept)) + " estimated; cable '" +
                                       busiest + "' among them): " + kFoldBack);
  ctx.counters.block_pairs = as_i64(found.pairs.size());
  return std::move(found.pairs);
}

std::vector<PairContact> gather_contacts(Context& ctx, std::size_t n,
                                         const std::function<std::int64_t(std::size_t, std::vector<PairContact>&)>& narrow) {
  std::mutex mu;
  std::vector<PairContact> contacts;
  const std::size_t tasks = (n + kPairsPerTask - 1) / kPairsPerTask;
  parallel_indices(tasks, ctx.req.threads, [&](std::size_t t) {
    std::vector<PairContact> local;
    std::int64_t tests = 0;
    for (std::size_t k = t * kPairsPerTask; k < std::min(n, (t + 1) * kPairsPerTask); ++k) tests += narrow(k, local);
    ctx.counters.pairs += tests;
    if (!local.empty()) {
      std::lock_guard<std::mutex> lock(mu);
      contacts.insert(contacts.end(), local.begin(), local.end());
      if (contacts.size() > ctx.req.limits.max_pair_contacts) refuse_contacts(ctx, contacts, "chords");
    }
  });
  ctx.counters.pair_contacts = as_i64(contacts.size());
  return contacts;
}

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
  auto keep = [&](std::uint32_t i, std::uint32_t j) {
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
  std::vector<BoxPair> pairs =
      bounded_block_pairs(ctx, boxes, keep, [&](std::uint32_t k) { return static_cast<int>(blocks[k].cable); });
  if (ctx.req.check_self)
    for (std::uint32_t i = 0; i < blocks.size(); ++i) pairs.emplace_back(i, i);
  std::vector<PairContact> contacts = gather_contacts(ctx, pairs.size(), [&](std::size_t k, std::vector<PairContact>& local) {
    const BlockRef& x = blocks[pairs[k].first];
    const BlockRef& y = blocks[pairs[k].second];
    return narrow_phase(ctx, cc[x.cable], x.block, cc[y.cable], y.block, local);
  });
  group_pair_contacts(contacts, ctx.cables, out);
}

}  // namespace loom::audit
