#pragma once
/// Cable–cable and self contacts of the audit's pair passes (certified: chord pairs,
/// clash_pairs.cpp; discrete: sample pairs, clash_discrete.cpp), grouped into one clash
/// entry per contact stretch. Internal to the audit; world frame, scene units, s and t arc
/// lengths on the two cables.

#include "routing/audit/clash_context.hpp"

#include "index/box_pairs.hpp"

#include <functional>

#include <vector>

namespace loom::audit {

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
                         std::vector<ClashEntry>& out);

/// Why the pair passes refuse an audit that reaches a ClashLimits limit.
inline const char* const kFoldBack = "a route folds back on itself or runs over another along great lengths";

/// Refuses the audit: more pairs of `what` (chords, samples) in contact than
/// ClashLimits::max_pair_contacts. The message names the cable pair with the most of the
/// `found` contacts (lowest ids on a tie): which contacts were stored when the limit was
/// passed depends on thread timing, the pair that dominates them hardly does.
[[noreturn]] void refuse_contacts(const Context& ctx, const std::vector<PairContact>& found, const char* what);

/// The broad phase of a certified pair pass (cable chords, or the pieces of the bundle
/// level) under the request's ClashLimits: the pairs of overlapping chord-block boxes that
/// `keep` keeps (overlapping_box_pairs), counted into block_overlaps_estimate and
/// block_pairs. Refuses (std::invalid_argument) past max_block_overlaps or
/// max_block_pairs, naming the cable of the busiest box (`cable_of`: box → cable).
std::vector<BoxPair> bounded_block_pairs(Context& ctx, const std::vector<AABB>& boxes,
                                         std::function<bool(std::uint32_t, std::uint32_t)> keep,
                                         const std::function<int(std::uint32_t)>& cable_of);

/// The narrow phase of a certified pair pass: narrow(k, out) for every block pair k < n
/// (appending its contacts, returning its exact segment tests), on the request's threads;
/// the contacts gathered, refused past max_pair_contacts, counted into pair_tests and
/// pair_contacts.
std::vector<PairContact> gather_contacts(Context& ctx, std::size_t n,
                                         const std::function<std::int64_t(std::size_t, std::vector<PairContact>&)>& narrow);

}  // namespace loom::audit
