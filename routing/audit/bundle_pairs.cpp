// Bundle-level certified cable–cable and self pass: the pieces flattened to chords once, one
// broad phase over their blocks, one exact segment distance per pair of piece chords, then
// the pair rules (judge_chord_pair) per cable pair only where some pair's radii reach past
// what every cable of both pieces is excused (bundle_layout.hpp, clash_pairs.cpp).
#include "routing/audit/bundle_layout.hpp"
#include "routing/audit/chord_pair_excuse.hpp"
#include "routing/audit/chord_plan.hpp"
#include "routing/audit/pair_contacts.hpp"

#include "index/triangle_distance.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <tuple>
#include <unordered_map>

namespace loom::audit {

namespace {

/// Chords per block in the broad phase (as the per-cable pass).
constexpr std::size_t kPieceBlock = 8;
/// Cables whose arc-length offsets between two pieces differ by at most this (relative)
/// are one self class: the same |s − t| on every chord pair, up to rounding.
constexpr double kOffsetRel = 1e-9;

/// A block lies within `reach` of a junction node of its piece, whose radius there is
/// `radius` (the smallest its cables give it).
struct BallRef {
  int node = -1;
  double reach = 0.0, radius = 0.0;
};

/// One piece flattened: chords (arc lengths σ along the piece), a box per block of
/// kPieceBlock chords inflated by r_max + chord error, the junction balls holding each
/// block, and per chord its unit direction and its arc length over its length (≥ 1; 0 for
/// a chord of length 0).
struct PieceChords {
  Chords ch;
  std::vector<AABB> blocks;
  std::vector<std::vector<BallRef>> in_ball;
  std::vector<Vec3> dir;
  std::vector<double> stretch;
};

/// Most chords apart for which straight_between() is tried (beyond, the self rule is
/// applied: a route coming back to itself).
constexpr std::size_t kStraightChords = 32;

/// True if no cable of any radius r along the piece has a self contact between chords ka
/// and kb (ka < kb) and the chords between: their directions all lie within an angle α of
/// the direction from the first point to the last with cos α ≥ (2/π)·k, k the largest arc
/// length per chord length among them. Why: two points of the polyline an arc length G
/// apart (along the chords, G/k at least) are then at least cos α · G/k apart, ≥ 2r when
/// G ≥ π r — the self rule finds nothing there, whatever r. Most chord pairs of a routed
/// piece (straight or gently bent over a few radii) are decided so, without a distance.
bool straight_between(const PieceChords& pc, std::size_t ka, std::size_t kb) {
  if (kb - ka > kStraightChords) return false;
  const Vec3 span = pc.ch.p[kb + 1] - pc.ch.p[ka];
  const double n = span.norm();
  if (!(n > 0.0)) return false;
  const Vec3 d = span / n;
  double cos_min = 1.0, k_max = 1.0;
  for (std::size_t i = ka; i <= kb; ++i) {
    if (!(pc.stretch[i] > 0.0)) return false;
    cos_min = std::min(cos_min, pc.dir[i].dot(d));
    k_max = std::max(k_max, pc.stretch[i]);
  }
  return cos_min >= (2.0 / M_PI) * k_max * (1.0 + 1e-9);
}

std::vector<PieceChords> flatten_pieces(Context& ctx, const Layout& lay) {
  std::vector<PieceChords> out(lay.pieces.size());
  parallel_indices(lay.pieces.size(), ctx.req.threads, [&](std::size_t k) {
    const Piece& p = lay.pieces[k];
    PieceChords& pc = out[k];
    flatten(*p.curve, p.curve->u_min(), p.curve->u_max(), ctx.chord_error, kMaxChordRadii * p.r_min,
            kShortSpanRadii * p.r_min, pc.ch);
    ctx.counters.samples += as_i64(pc.ch.p.size());
    for (std::size_t i = 0; i < pc.ch.size(); ++i) {
      const Vec3 e = pc.ch.p[i + 1] - pc.ch.p[i];
      const double len = e.norm();
      pc.dir.push_back(len > 0.0 ? Vec3(e / len) : Vec3::Zero());
      pc.stretch.push_back(len > 0.0 ? std::max(1.0, (pc.ch.s[i + 1] - pc.ch.s[i]) / len) : 0.0);
    }
    for (std::size_t b = 0; b * kPieceBlock < pc.ch.size(); ++b) {
      AABB box;
      const std::size_t v1 = std::min(pc.ch.size(), (b + 1) * kPieceBlock);
      for (std::size_t v = b * kPieceBlock; v <= v1; ++v) box.extend(pc.ch.p[v]);
      pc.blocks.push_back(box.inflated(p.r_max + ctx.chord_error));
      pc.in_ball.emplace_back();
      for (const PieceJunction& j : p.junctions) {
        if (!box.inflated(j.radius).contains(j.position)) continue;  // the block reaches beyond the ball
        double reach = 0.0;
        for (std::size_t v = b * kPieceBlock; v <= v1; ++v) reach = std::max(reach, (pc.ch.p[v] - j.position).norm());
        if (reach <= j.radius) pc.in_ball.back().push_back({j.node, reach, j.radius});
      }
    }
  });
  return out;
}

/// True if two blocks lie within one junction ball that every cable of both pieces shares
/// (radius: the smaller of the two pieces'): every contact between their cables there is
/// excused, whatever the cables.
bool in_common_ball(const std::vector<BallRef>& x, const std::vector<BallRef>& y) {
  for (const BallRef& a : x)
    for (const BallRef& b : y)
      if (a.node == b.node && std::max(a.reach, b.reach) <= std::min(a.radius, b.radius)) return true;
  return false;
}

/// Cables along both pieces of a pair with one radius and one arc-length offset between
/// the pieces: the self rule gives them the same answer on every chord pair.
struct SelfClass {
  double radius = 0.0;
  std::vector<std::pair<int, int>> members;  ///< (use in the first piece, use in the second)
};

/// What the pair rules need to know of a pair of pieces (P ≤ Q).
struct PairPlan {
  bool cc = false;                     ///< some two different cables, one on each piece, may clash
  std::vector<PieceJunction> common;   ///< junctions of every cable of both, the smaller radius
  std::vector<SelfClass> self;         ///< by radius, largest first
  double self_r_max = 0.0, self_r_min = kInf;
};

PairPlan plan_pair(const Context& ctx, const Layout& lay, std::size_t pi, std::size_t qi) {
  const Piece& P = lay.pieces[pi];
  const Piece& Q = lay.pieces[qi];
  auto radius = [&](const PieceUse& u) { return ctx.cables[static_cast<std::size_t>(u.cable)].radius; };
  PairPlan plan;
  if (ctx.req.check_cable_cable)
    plan.cc = pi == qi ? P.bundle_segment < 0 && P.uses.size() > 1
                       : !(P.uses.size() == 1 && Q.uses.size() == 1 && P.uses[0].cable == Q.uses[0].cable);
  for (const PieceJunction& a : P.junctions)
    for (const PieceJunction& b : Q.junctions)
      if (a.node == b.node && a.position == b.position)
        plan.common.push_back({a.node, a.position, std::min(a.radius, b.radius)});
  if (!ctx.req.check_self) return plan;
  // Members: the cables along both pieces; on one piece, every cable with itself.
  struct Member {
    double radius, offset;
    bool rev_p, rev_q;
    int i, j;
  };
  std::vector<Member> members;
  if (pi == qi) {
    for (std::size_t i = 0; i < P.uses.size(); ++i)
      members.push_back({radius(P.uses[i]), 0.0, false, false, static_cast<int>(i), static_cast<int>(i)});
  } else {
    std::vector<std::pair<int, int>> q_of;  // (cable, use in Q)
    for (std::size_t j = 0; j < Q.uses.size(); ++j) q_of.emplace_back(Q.uses[j].cable, static_cast<int>(j));
    std::sort(q_of.begin(), q_of.end());
    for (std::size_t i = 0; i < P.uses.size(); ++i) {
      const PieceUse& u = P.uses[i];
      auto it = std::lower_bound(q_of.begin(), q_of.end(), std::make_pair(u.cable, -1));
      for (; it != q_of.end() && it->first == u.cable; ++it) {
        const PieceUse& v = Q.uses[static_cast<std::size_t>(it->second)];
        members.push_back({radius(u), u.s_at(0.0) - v.s_at(0.0), u.reversed, v.reversed, static_cast<int>(i), it->second});
      }
    }
  }
  std::sort(members.begin(), members.end(), [](const Member& a, const Member& b) {
    return std::make_tuple(-a.radius, a.rev_p, a.rev_q, a.offset) < std::make_tuple(-b.radius, b.rev_p, b.rev_q, b.offset);
  });
  double rep_offset = 0.0;  // the current class's first member's offset
  for (std::size_t k = 0; k < members.size(); ++k) {
    const Member& m = members[k];
    const Member* prev = k > 0 ? &members[k - 1] : nullptr;
    if (prev && m.radius == prev->radius && m.rev_p == prev->rev_p && m.rev_q == prev->rev_q &&
        std::abs(m.offset - rep_offset) <= kOffsetRel * (1.0 + std::abs(rep_offset))) {
      plan.self.back().members.emplace_back(m.i, m.j);
      continue;
    }
    rep_offset = m.offset;
    plan.self.push_back({m.radius, {{m.i, m.j}}});
    plan.self_r_max = std::max(plan.self_r_max, m.radius);
    plan.self_r_min = std::min(plan.self_r_min, m.radius);
  }
  return plan;
}

/// Chord k of a piece as cable `u` runs it (in its direction of travel).
ChordRef oriented(const PieceUse& u, const Chords& ch, std::size_t k) {
  const double s0 = u.s_at(ch.s[k]), s1 = u.s_at(ch.s[k + 1]);
  return u.reversed ? ChordRef{u.cable, ch.p[k + 1], ch.p[k], s1, s0} : ChordRef{u.cable, ch.p[k], ch.p[k + 1], s0, s1};
}

/// Closest points r of two piece chords, as parameters on the chords oriented for cables
/// running them backwards or not.
SegmentSegmentResult oriented(SegmentSegmentResult r, bool rev_a, bool rev_b) {
  if (rev_a) r.s = 1.0 - r.s;
  if (rev_b) r.t = 1.0 - r.t;
  return r;
}

/// Largest |s − t| over s in [a0, a1] and t in [b0, b1] (either order).
double max_gap(double a0, double a1, double b0, double b1) {
  return std::max(std::abs(std::max(b0, b1) - std::min(a0, a1)), std::abs(std::max(a0, a1) - std::min(b0, b1)));
}

/// The narrow phase of one block pair of pieces P ≤ Q.
class BlockPairJudge {
 public:
  BlockPairJudge(const Context& ctx, const Layout& lay, const std::vector<PieceChords>& pcs)
      : ctx_(ctx), lay_(lay), pcs_(pcs), boxes_(buffer()) {}

  /// Block bx of piece pi against block by of piece qi (pi ≤ qi); returns the segment tests.
  std::int64_t run(std::size_t pi, std::size_t bx, std::size_t qi, std::size_t by, const PairPlan& plan,
                   std::vector<PairContact>& out) {
    const Piece& P = lay_.pieces[pi];
    const Piece& Q = lay_.pieces[qi];
    const Chords& A = pcs_[pi].ch;
    const Chords& B = pcs_[qi].ch;
    const bool same_piece = pi == qi, same_block = same_piece && bx == by;
    // Cable pairs are all excused where both blocks lie in a ball every cable shares.
    const bool block_cc = plan.cc && !in_common_ball(pcs_[pi].in_ball[bx], pcs_[qi].in_ball[by]);
    const std::size_t ka1 = std::min(A.size(), (bx + 1) * kPieceBlock);
    const std::size_t kb1 = std::min(B.size(), (by + 1) * kPieceBlock);
    std::int64_t tests = 0;
    for (std::size_t ka = bx * kPieceBlock; ka < ka1; ++ka)
      for (std::size_t kb = same_block ? ka : by * kPieceBlock; kb < kb1; ++kb) {
        const Vec3 &pa = A.p[ka], &pb = A.p[ka + 1], &qa = B.p[kb], &qb = B.p[kb + 1];
        boxes_.clear();  // (a thread's buffer: one allocation per thread, not per chord pair)
        bool cc = block_cc;
        for (std::size_t n = 0; cc && n < plan.common.size(); ++n)
          if (const auto bx2 = ball_box(pa, pb, qa, qb, plan.common[n].position, plan.common[n].radius)) {
            boxes_.push_back(*bx2);
            if (bx2->l0 <= 0.0 && bx2->l1 >= 1.0 && bx2->m0 <= 0.0 && bx2->m1 >= 1.0) cc = false;  // all excused
          }
        const bool self = !plan.self.empty() && !(same_block && ka == kb) && self_reachable(P, Q, A, B, ka, kb, plan) &&
                          !(same_piece && straight_between(pcs_[pi], std::min(ka, kb), std::max(ka, kb)));
        if (!cc && !self) continue;
        // Midpoint bound: chords whose midpoints are farther apart than their half lengths
        // plus the largest radii sum that matters cannot touch.
        const double r_sum = std::max(cc ? P.r_max + Q.r_max : 0.0, self ? 2.0 * plan.self_r_max : 0.0);
        const double reach = r_sum + 0.5 * ((pb - pa).norm() + (qb - qa).norm());
        if ((0.5 * (pa + pb) - 0.5 * (qa + qb)).squaredNorm() >= reach * reach) continue;
        ++tests;
        const SegmentSegmentResult r = closest_segment_segment(pa, pb, qa, qb);
        const double d = std::sqrt(r.dist2);
        if (cc && d < P.r_max + Q.r_max) cable_pairs(P, Q, A, B, ka, kb, same_block && ka == kb, r, out);
        if (self && d < 2.0 * plan.self_r_max) self_pairs(P, Q, A, B, ka, kb, r, d, plan, out);
      }
    return tests;
  }

 private:
  static std::vector<ParamBox>& buffer() {
    thread_local std::vector<ParamBox> b;
    return b;
  }
  double radius(const PieceUse& u) const { return ctx_.cables[static_cast<std::size_t>(u.cable)].radius; }

  /// True if some self class's cables are π r apart somewhere on the chord pair.
  bool self_reachable(const Piece& P, const Piece& Q, const Chords& A, const Chords& B, std::size_t ka,
                      std::size_t kb, const PairPlan& plan) const {
    if (&P == &Q) return max_gap(A.s[ka], A.s[ka + 1], B.s[kb], B.s[kb + 1]) >= M_PI * plan.self_r_min;
    for (const SelfClass& c : plan.self) {
      const PieceUse& u = P.uses[static_cast<std::size_t>(c.members.front().first)];
      const PieceUse& v = Q.uses[static_cast<std::size_t>(c.members.front().second)];
      if (max_gap(u.s_at(A.s[ka]), u.s_at(A.s[ka + 1]), v.s_at(B.s[kb]), v.s_at(B.s[kb + 1])) >= M_PI * c.radius)
        return true;
    }
    return false;
  }

  /// Different cables on the two chords: the smallest distance outside what the common
  /// junctions excuse first, then the pair rules for every cable pair whose radii reach it.
  void cable_pairs(const Piece& P, const Piece& Q, const Chords& A, const Chords& B, std::size_t ka, std::size_t kb,
                   bool one_chord, const SegmentSegmentResult& r, std::vector<PairContact>& out) {
    double du = std::sqrt(r.dist2);
    const bool in_box = std::any_of(boxes_.begin(), boxes_.end(), [&](const ParamBox& b) {
      return r.s >= b.l0 && r.s <= b.l1 && r.t >= b.m0 && r.t <= b.m1;
    });
    if (in_box) {
      // Every cable pair is excused at least there: no pair is closer outside than this.
      const auto outside = closest_unexcused(boxes_, A.p[ka], A.p[ka + 1], B.p[kb], B.p[kb + 1]);
      if (!outside) return;
      du = std::sqrt(outside->dist2);
    }
    for (std::size_t i = 0; i < P.uses.size(); ++i) {
      const PieceUse& u = P.uses[i];
      const double ra = radius(u);
      if (!(ra + Q.r_max > du)) break;  // uses by radius, largest first
      for (std::size_t j = 0; j < Q.uses.size(); ++j) {
        const PieceUse& v = Q.uses[j];
        if (!(ra + radius(v) > du)) break;
        if (u.cable == v.cable || (one_chord && j <= i)) continue;  // self; a pair on one chord once
        if (auto c = judge_chord_pair(ctx_.cables, oriented(u, A, ka), oriented(v, B, kb),
                                      oriented(r, u.reversed, v.reversed)))
          out.push_back(*c);
      }
    }
  }

  /// One cable on both chords: the self rule per class, for every member where the class's
  /// first member has a contact.
  void self_pairs(const Piece& P, const Piece& Q, const Chords& A, const Chords& B, std::size_t ka, std::size_t kb,
                  const SegmentSegmentResult& r, double d, const PairPlan& plan, std::vector<PairContact>& out) {
    for (const SelfClass& c : plan.self) {
      if (!(d < 2.0 * c.radius)) break;  // classes by radius, largest first
      bool first = true;
      for (const auto& [i, j] : c.members) {
        const PieceUse& u = P.uses[static_cast<std::size_t>(i)];
        const PieceUse& v = Q.uses[static_cast<std::size_t>(j)];
        const ChordRef x = oriented(u, A, ka), y = oriented(v, B, kb);
        if (first && max_gap(x.s0, x.s1, y.s0, y.s1) < M_PI * c.radius) break;
        const auto contact = judge_chord_pair(ctx_.cables, x, y, oriented(r, u.reversed, v.reversed));
        if (first && !contact) break;  // none for the class
        first = false;
        if (contact) out.push_back(*contact);
      }
    }
  }

  const Context& ctx_;
  const Layout& lay_;
  const std::vector<PieceChords>& pcs_;
  std::vector<ParamBox>& boxes_;  ///< the common junctions' boxes on the current chord pair
};

}  // namespace

void bundle_cable_pairs(Context& ctx, const Layout& lay, std::vector<ClashEntry>& out) {
  if (!ctx.req.check_cable_cable && !ctx.req.check_self) return;
  const std::vector<PieceChords> pcs = flatten_pieces(ctx, lay);
  struct BlockRef {
    std::uint32_t piece, block;
  };
  std::vector<BlockRef> blocks;
  std::vector<AABB> boxes;
  for (std::size_t k = 0; k < pcs.size(); ++k)
    for (std::size_t b = 0; b < pcs[k].blocks.size(); ++b) {
      blocks.push_back({static_cast<std::uint32_t>(k), static_cast<std::uint32_t>(b)});
      boxes.push_back(pcs[k].blocks[b]);
    }
  auto block_sigma = [&](const BlockRef& r) {
    const Chords& ch = pcs[r.piece].ch;
    return std::make_pair(ch.s[r.block * kPieceBlock], ch.s[std::min(ch.size(), (r.block + 1) * kPieceBlock)]);
  };
  // True if blocks x ≤ y of one piece and the chords between them run straight enough that
  // no cable along it has a self contact there (straight_between).
  auto straight_blocks = [&](const BlockRef& x, const BlockRef& y) {
    const PieceChords& pc = pcs[x.piece];
    const std::size_t last = std::min(pc.ch.size(), (std::size_t{y.block} + 1) * kPieceBlock) - 1;
    return straight_between(pc, std::size_t{x.block} * kPieceBlock, last);
  };
  // Keep a block pair only if it may hold a finding: on one piece, chords π r_min apart
  // (self) or cables not bundled there; on two, cables of different pieces not all excused
  // by a shared junction, or one cable along both (self).
  auto keep = [&](std::uint32_t i, std::uint32_t j) {
    const BlockRef& x = blocks[i];
    const BlockRef& y = blocks[j];
    const Piece& P = lay.pieces[x.piece];
    if (x.piece == y.piece) {
      const auto [a0, a1] = block_sigma(x);
      const auto [b0, b1] = block_sigma(y);
      const bool self = ctx.req.check_self && max_gap(a0, a1, b0, b1) >= M_PI * P.r_min && !straight_blocks(x, y);
      return self || (ctx.req.check_cable_cable && P.bundle_segment < 0 && P.uses.size() > 1);
    }
    const Piece& Q = lay.pieces[y.piece];
    const bool one_cable = P.uses.size() == 1 && Q.uses.size() == 1 && P.uses[0].cable == Q.uses[0].cable;
    const bool cc = ctx.req.check_cable_cable && !one_cable &&
                    !in_common_ball(pcs[x.piece].in_ball[x.block], pcs[y.piece].in_ball[y.block]);
    return cc || ctx.req.check_self;
  };
  std::vector<BoxPair> pairs = bounded_block_pairs(ctx, boxes, keep, [&](std::uint32_t k) {
    return lay.pieces[blocks[k].piece].uses.front().cable;
  });
  for (std::uint32_t i = 0; i < blocks.size(); ++i) {
    const Piece& P = lay.pieces[blocks[i].piece];
    if ((ctx.req.check_self && !straight_blocks(blocks[i], blocks[i])) ||
        (ctx.req.check_cable_cable && P.bundle_segment < 0 && P.uses.size() > 1))
      pairs.emplace_back(i, i);
  }
  // One plan per pair of pieces that has block pairs (blocks are numbered piece by piece, so
  // the first block's piece is never after the second's).
  std::unordered_map<std::uint64_t, std::size_t> plan_of;
  std::vector<std::pair<std::size_t, std::size_t>> piece_pairs;
  for (const BoxPair& bp : pairs) {
    const std::uint64_t key = (std::uint64_t{blocks[bp.first].piece} << 32) | blocks[bp.second].piece;
    if (plan_of.emplace(key, piece_pairs.size()).second)
      piece_pairs.emplace_back(blocks[bp.first].piece, blocks[bp.second].piece);
  }
  std::vector<PairPlan> plans(piece_pairs.size());
  parallel_indices(plans.size(), ctx.req.threads,
                   [&](std::size_t k) { plans[k] = plan_pair(ctx, lay, piece_pairs[k].first, piece_pairs[k].second); });
  std::vector<PairContact> contacts = gather_contacts(ctx, pairs.size(), [&](std::size_t k, std::vector<PairContact>& local) {
    const BlockRef& x = blocks[pairs[k].first];
    const BlockRef& y = blocks[pairs[k].second];
    const PairPlan& plan = plans[plan_of.at((std::uint64_t{x.piece} << 32) | y.piece)];
    BlockPairJudge judge(ctx, lay, pcs);
    return judge.run(x.piece, x.block, y.piece, y.block, plan, local);
  });
  group_pair_contacts(contacts, ctx.cables, out);
}

}  // namespace loom::audit
