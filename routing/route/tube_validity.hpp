#pragma once
/// OMPL validity for a tube in R³ (DESIGN §6 "Planning"): the state is the tube's centre
/// point; it is valid iff it lies in the planning bounds, outside every closed part, and at
/// distance ≥ `required` = tube radius + clearance from every part surface. Motions are
/// checked exactly as capsules (ObstacleIndex::segment_within), never by sampling at OMPL's
/// default 1% of the space extent, through which thin obstacles slip (DESIGN §9).
/// This header includes OMPL: link loom::dep::ompl where it is used.

#include "core/geometry.hpp"
#include "index/obstacle_index.hpp"

#include <ompl/base/MotionValidator.h>
#include <ompl/base/SpaceInformation.h>
#include <ompl/base/StateValidityChecker.h>

#include <atomic>
#include <cstdint>

namespace loom {

/// Counters of the obstacle queries made through the validity classes (for benchmarks).
struct TubeQueryCounters {
  std::atomic<std::uint64_t> state_checks{0};   ///< isValid() calls
  std::atomic<std::uint64_t> motion_checks{0};  ///< checkMotion() calls (capsule queries)
  std::atomic<std::uint64_t> clearance_queries{0};  ///< clearance() / isValid(s, dist) calls
};

/// The world point of an R³ OMPL state (RealVectorStateSpace of dimension 3).
Vec3 state_point(const ompl::base::State* s);
/// Writes p into an R³ OMPL state.
void set_state_point(ompl::base::State* s, const Vec3& p);

/// State validity for a tube of centre-line distance `required` (scene units, > 0).
/// All methods are const and thread-safe (the index is).
class TubeValidityChecker : public ompl::base::StateValidityChecker {
 public:
  /// `index` must outlive the checker. `clearance_horizon` (> required) bounds the distance
  /// search of clearance(): farther obstacles are not looked for (speed, DESIGN §9 Embree).
  TubeValidityChecker(const ompl::base::SpaceInformationPtr& si, const ObstacleIndex& index,
                      double required, double clearance_horizon,
                      TubeQueryCounters* counters = nullptr);

  /// True iff the point is within bounds, not inside a closed part, and no surface is
  /// closer than `required`.
  bool isValid(const ompl::base::State* s) const override;
  /// As isValid(s); `dist` receives clearance(s).
  bool isValid(const ompl::base::State* s, double& dist) const override;
  /// Distance (scene units) the point may move before it becomes invalid: distance to the
  /// nearest surface minus `required` (negative when invalid; −required inside a closed
  /// part), capped at clearance_horizon − required when nothing is within the horizon.
  double clearance(const ompl::base::State* s) const override;

  /// The tube's required centre-line distance to obstacles (radius + clearance).
  double required() const { return required_; }

 private:
  const ObstacleIndex& index_;
  double required_;
  double horizon_;
  TubeQueryCounters* counters_;
};

/// Exact motion validator: the motion s1→s2 is valid iff s2 is within bounds and the
/// capsule of radius `required` around the segment touches no part (s1 is assumed valid,
/// as OMPL's contract says; then the segment cannot enter a closed part either, since it
/// would have to cross its surface).
class CapsuleMotionValidator : public ompl::base::MotionValidator {
 public:
  /// `last_valid_tolerance` (> 0, scene units) is the accuracy of the last valid point
  /// reported by the three-argument checkMotion (bisection along the segment).
  CapsuleMotionValidator(const ompl::base::SpaceInformationPtr& si, const ObstacleIndex& index,
                         double required, double last_valid_tolerance,
                         TubeQueryCounters* counters = nullptr);

  /// True iff the capsule around s1→s2 is clear and s2 is within bounds.
  bool checkMotion(const ompl::base::State* s1, const ompl::base::State* s2) const override;
  /// As above; on failure lastValid receives the last clear point (within the tolerance)
  /// and its fraction along the segment.
  bool checkMotion(const ompl::base::State* s1, const ompl::base::State* s2,
                   std::pair<ompl::base::State*, double>& lastValid) const override;

 private:
  bool within_bounds(const Vec3& p) const;
  const ObstacleIndex& index_;
  double required_;
  double tolerance_;
  TubeQueryCounters* counters_;
};

/// Longest segment OMPL may still treat as one discrete step (cost integration, path
/// interpolation), derived from the clearance: half the required distance, so that no
/// obstacle thinner than the tube's diameter fits between two steps. Scene units.
double tube_resolution(double required);

/// Installs TubeValidityChecker + CapsuleMotionValidator on `si` and sets the state space's
/// longestValidSegmentFraction to tube_resolution(required) / maximum extent (never OMPL's
/// default 1%). Calls si->setup(). The space must be a bounded 3-D RealVectorStateSpace.
void configure_tube_space(const ompl::base::SpaceInformationPtr& si, const ObstacleIndex& index,
                          double required, double clearance_horizon,
                          TubeQueryCounters* counters = nullptr);

}  // namespace loom
