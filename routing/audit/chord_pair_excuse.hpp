#pragma once
/// The pair rules' excuses on one chord pair, and the closest points outside them. A chord
/// pair whose closest points are excused — |s − t| < π r on one cable (self), both points in
/// one harness segment or both within a shared junction's radius (cable–cable) — may still
/// touch at points of the same chords that are not: the clash is then deepest on the edge of
/// the excused region. Internal to the audit; world frame, scene units, chord parameters in
/// [0, 1], s and t arc lengths on the two cables.

#include "index/triangle_distance.hpp"
#include "routing/audit/clash_context.hpp"
#include "routing/audit/pair_contacts.hpp"

#include <optional>
#include <vector>

namespace loom::audit {

/// The self rule on one chord pair: the closest points of chords P(λ) = pa + λ(pb − pa) and
/// Q(μ) = qa + μ(qb − qa), λ, μ ∈ [0, 1], whose arc lengths s = sa + λ(sb − sa) and
/// t = ta + μ(tb − ta) are at least `gap` apart (std::nullopt if no such points exist).
/// For a pair whose closest points lie within the excused band |s − t| < gap: the squared
/// distance is convex in (λ, μ) and each side of the band is convex, so the closest points
/// outside the band lie on one of its edges s − t = ±gap — a segment of the (λ, μ) square on
/// which the squared distance is a convex quadratic of one parameter. Why: beside a sharp
/// fold the pair's closest points are the excused ones next to the fold, while points of
/// the same chords just πr apart along the cable are in contact (a V of 60° touches itself
/// at clearance −0.43 r there, and nowhere else).
std::optional<SegmentSegmentResult> closest_apart(const Vec3& pa, const Vec3& pb, double sa, double sb, const Vec3& qa,
                                                  const Vec3& qb, double ta, double tb, double gap);

/// A box [l0, l1] × [m0, m1] of chord parameters: λ on chord A, μ on chord B.
struct ParamBox {
  double l0, l1, m0, m1;
};

/// The box of chord parameters where chord A (pa→pb) and chord B (qa→qb) both lie within
/// `radius` of `center` (a junction's excuse on one chord pair), if they both reach it.
std::optional<ParamBox> ball_box(const Vec3& pa, const Vec3& pb, const Vec3& qa, const Vec3& qb, const Vec3& center,
                                 double radius);

/// The cable–cable excuse (excused()) on one chord pair, as boxes of chord parameters:
/// both points in one harness segment, or both within a shared junction's radius — each a
/// product of an interval on each chord.
std::vector<ParamBox> excused_boxes(const CableInput& ca, const Vec3& pa, const Vec3& pb, double sa0, double sa1,
                                    const CableInput& cb, const Vec3& qa, const Vec3& qb, double tb0, double tb1);

/// Closest points of chords A (pa→pb, λ) and B (qa→qb, μ) outside the excused boxes, for a
/// pair whose closest points are excused (std::nullopt: the whole pair is). Why: where
/// two cables part at a junction (or leave a bundle segment) still touching, the pair's
/// closest points lie inside the excused region while points of the same chords just
/// outside it are in contact — the clash is deepest on the region's edge. The squared
/// distance is convex in (λ, μ), so with its minimum excused the infimum outside lies on a
/// box edge not covered by another box; along an edge one chord's point is fixed and the
/// other chord's parameter runs over an interval: a point–segment distance.
std::optional<SegmentSegmentResult> closest_unexcused(const std::vector<ParamBox>& boxes, const Vec3& pa,
                                                      const Vec3& pb, const Vec3& qa, const Vec3& qb);

/// One chord of a cable in its direction of travel: from a (arc length s0) to b (s1 ≥ s0).
struct ChordRef {
  int cable = -1;  ///< index into the checked cables
  Vec3 a = Vec3::Zero(), b = Vec3::Zero();
  double s0 = 0.0, s1 = 0.0;
};

/// The pair rules on chords A and B (one cable for a self pair) whose closest points are r
/// (parameters on A and B): a contact closer than the radii sum, at the closest points or,
/// where those are excused, at the closest points outside the excuse (closest_apart,
/// closest_unexcused); std::nullopt if there is none.
std::optional<PairContact> judge_chord_pair(const std::vector<CableInput>& cables, const ChordRef& A, const ChordRef& B,
                                            SegmentSegmentResult r);

}  // namespace loom::audit
