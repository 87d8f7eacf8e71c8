#include "routing/route/tube_validity.hpp"

#include <ompl/base/spaces/RealVectorStateSpace.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace loom {

namespace ob = ompl::base;

namespace {

/// Fraction of the required distance used as the discrete step of OMPL's own
/// interpolation: half the tube's centre-line clearance.
constexpr double kResolutionPerRequired = 0.5;
/// Accuracy of the last valid point of a blocked motion, as a fraction of the resolution.
constexpr double kLastValidPerResolution = 0.25;

void count(std::atomic<std::uint64_t>* c) {
  if (c != nullptr) c->fetch_add(1, std::memory_order_relaxed);
}

}  // namespace

Vec3 state_point(const ob::State* s) {
  const double* v = s->as<ob::RealVectorStateSpace::StateType>()->values;
  return Vec3(v[0], v[1], v[2]);
}

void set_state_point(ob::State* s, const Vec3& p) {
  double* v = s->as<ob::RealVectorStateSpace::StateType>()->values;
  v[0] = p.x();
  v[1] = p.y();
  v[2] = p.z();
}

double tube_resolution(double required) { return kResolutionPerRequired * required; }

// --- TubeValidityChecker ----------------------------------------------------------------

TubeValidityChecker::TubeValidityChecker(const ob::SpaceInformationPtr& si, const ObstacleIndex& index,
                                         double required, double clearance_horizon,
                                         TubeQueryCounters* counters)
    : ob::StateValidityChecker(si),
      index_(index),
      required_(required),
      horizon_(std::max(clearance_horizon, required)),
      counters_(counters) {
  if (!(required > 0.0) || !std::isfinite(required))
    throw std::invalid_argument("TubeValidityChecker: required distance must be finite and > 0");
  specs_.clearanceComputationType = ob::StateValidityCheckerSpecs::EXACT;
  specs_.hasValidDirectionComputation = false;
}

bool TubeValidityChecker::isValid(const ob::State* s) const {
  if (counters_ != nullptr) count(&counters_->state_checks);
  if (!si_->satisfiesBounds(s)) return false;
  const Vec3 p = state_point(s);
  if (index_.any_within(p, required_)) return false;
  return !index_.inside(p);
}

bool TubeValidityChecker::isValid(const ob::State* s, double& dist) const {
  dist = clearance(s);
  return dist >= 0.0 && si_->satisfiesBounds(s);
}

double TubeValidityChecker::clearance(const ob::State* s) const {
  if (counters_ != nullptr) count(&counters_->clearance_queries);
  const Vec3 p = state_point(s);
  const ClosestHit hit = index_.closest(p, horizon_);
  // Nothing within the horizon: clear up to it, unless the point lies deep inside a part.
  if (!hit.found()) return index_.inside(p) ? -required_ : horizon_ - required_;
  if (hit.distance > required_ && index_.inside(p)) return -required_;
  return hit.distance - required_;
}

// --- CapsuleMotionValidator -------------------------------------------------------------

CapsuleMotionValidator::CapsuleMotionValidator(const ob::SpaceInformationPtr& si,
                                               const ObstacleIndex& index, double required,
                                               double last_valid_tolerance,
                                               TubeQueryCounters* counters)
    : ob::MotionValidator(si),
      index_(index),
      required_(required),
      tolerance_(last_valid_tolerance),
      counters_(counters) {
  if (!(required > 0.0) || !std::isfinite(required))
    throw std::invalid_argument("CapsuleMotionValidator: required distance must be finite and > 0");
  if (!(last_valid_tolerance > 0.0))
    throw std::invalid_argument("CapsuleMotionValidator: last-valid tolerance must be > 0");
}

bool CapsuleMotionValidator::checkMotion(const ob::State* s1, const ob::State* s2) const {
  if (counters_ != nullptr) count(&counters_->motion_checks);
  if (!si_->satisfiesBounds(s2)) return false;
  return !index_.segment_within(state_point(s1), state_point(s2), required_);
}

bool CapsuleMotionValidator::within_bounds(const Vec3& p) const {
  const auto& b = si_->getStateSpace()->as<ob::RealVectorStateSpace>()->getBounds();
  for (int k = 0; k < 3; ++k)
    if (p[k] < b.low[k] || p[k] > b.high[k]) return false;
  return true;
}

bool CapsuleMotionValidator::checkMotion(const ob::State* s1, const ob::State* s2,
                                         std::pair<ob::State*, double>& lastValid) const {
  if (checkMotion(s1, s2)) return true;
  // Bisection on the clear prefix a→a+t(b−a): the prefix capsule grows monotonically with t,
  // so "prefix is clear" is monotone and the largest clear t is found to the tolerance.
  const Vec3 a = state_point(s1);
  const Vec3 b = state_point(s2);
  const double len = (b - a).norm();
  double lo = 0.0;
  double hi = 1.0;
  if (len > 0.0) {
    while ((hi - lo) * len > tolerance_) {
      const double mid = 0.5 * (lo + hi);
      const Vec3 m = a + mid * (b - a);
      if (within_bounds(m) && !index_.segment_within(a, m, required_))
        lo = mid;
      else
        hi = mid;
    }
  }
  if (lastValid.first != nullptr) set_state_point(lastValid.first, a + lo * (b - a));
  lastValid.second = lo;
  return false;
}

// --- configuration ----------------------------------------------------------------------

void configure_tube_space(const ob::SpaceInformationPtr& si, const ObstacleIndex& index,
                          double required, double clearance_horizon, TubeQueryCounters* counters) {
  const double extent = si->getStateSpace()->getMaximumExtent();
  if (!(extent > 0.0) || !std::isfinite(extent))
    throw std::invalid_argument("configure_tube_space: the state space must be bounded and non-empty");
  si->setStateValidityChecker(
      std::make_shared<TubeValidityChecker>(si, index, required, clearance_horizon, counters));
  const double resolution = tube_resolution(required);
  si->setMotionValidator(
      std::make_shared<CapsuleMotionValidator>(si, index, required, kLastValidPerResolution * resolution, counters));
  si->setStateValidityCheckingResolution(std::min(1.0, resolution / extent));
  si->setup();
}

}  // namespace loom
