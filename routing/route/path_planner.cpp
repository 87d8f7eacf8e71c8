#include "routing/route/path_planner.hpp"

#include "core/scene.hpp"
#include "core/stopwatch.hpp"
#include "routing/route/port_check.hpp"

#include "routing/route/tube_validity.hpp"

#include <ompl/base/Goal.h>
#include <ompl/base/OptimizationObjective.h>
#include <ompl/base/PlannerTerminationCondition.h>
#include <ompl/base/ProblemDefinition.h>
#include <ompl/base/goals/GoalState.h>
#include <ompl/base/spaces/RealVectorStateSpace.h>
#include <ompl/geometric/PathGeometric.h>
#include <ompl/geometric/PathSimplifier.h>
#include <ompl/geometric/planners/fmt/BFMT.h>
#include <ompl/geometric/planners/fmt/FMT.h>
#include <ompl/geometric/planners/informedtrees/ABITstar.h>
#include <ompl/geometric/planners/informedtrees/BITstar.h>
#include <ompl/geometric/planners/prm/LazyPRM.h>
#include <ompl/geometric/planners/prm/LazyPRMstar.h>
#include <ompl/geometric/planners/prm/PRM.h>
#include <ompl/geometric/planners/prm/PRMstar.h>
#include <ompl/geometric/planners/rrt/InformedRRTstar.h>
#include <ompl/geometric/planners/rrt/RRT.h>
#include <ompl/geometric/planners/rrt/RRTConnect.h>
#include <ompl/geometric/planners/rrt/RRTsharp.h>
#include <ompl/geometric/planners/rrt/RRTstar.h>
#include <ompl/geometric/planners/rrt/SORRTstar.h>
#include <ompl/util/Console.h>
#include <ompl/util/RandomNumbers.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdlib>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <mutex>
#include <sstream>
#include <stdexcept>

namespace loom {

namespace ob = ompl::base;
namespace og = ompl::geometric;

namespace {

using Clock = std::chrono::steady_clock;

/// The straight stub is at least this many tube diameters long.
/// Planning bounds extend this many required distances beyond obstacles and ports, so that
/// a tube can always pass around the outside of the scene box.
constexpr double kMarginRequired = 2.0;
/// The diagnosis tube has this fraction of the required distance (a "thin line" that
/// still does not slip through cracks between touching triangles).
constexpr double kThinFraction = 0.05;
/// Rays cast from a stub end to tell a sealed cavity from a merely hard problem.
constexpr int kEnclosureRays = 96;
/// Relative tolerance when comparing two costs of the same stretch (Riemann sums of the
/// clearance term along different sample positions differ at this level).
constexpr double kCostCompareTolerance = 1e-6;
/// Goal-state tolerance, relative to the planning space's maximum extent.
constexpr double kGoalToleranceRel = 1e-9;
/// Points closer than this fraction of the required distance are one key point.
constexpr double kDuplicateRel = 1e-9;
/// Rounds of OMPL path shortcutting after planning (each stops early if nothing changed).
constexpr int kSimplifyRounds = 8;
/// Shortcut attempts per path state in each round.
constexpr unsigned kShortcutStepsPerState = 4;
/// Skip horizon of the cost integration beyond the clearance band, in integration steps:
/// a closest-point query this far out proves the rate constant over that stretch.
constexpr double kSkipSteps = 8.0;

std::uint32_t mix_seed(std::uint32_t seed, std::uint64_t k) {
  // splitmix64 finaliser: decorrelated per-instance seeds from one user seed.
  std::uint64_t z = (static_cast<std::uint64_t>(seed) << 32) ^ (k + 0x9E3779B97F4A7C15ULL);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  z ^= z >> 31;
  return static_cast<std::uint32_t>(z & 0xFFFFFFFFu);
}

std::string fmt_point(const Vec3& p) {
  std::ostringstream os;
  os.precision(6);
  os << "(" << p.x() << ", " << p.y() << ", " << p.z() << ")";
  return os.str();
}

std::string fmt_len(double v) {
  std::ostringstream os;
  os.precision(6);
  os << v;
  return os.str();
}

// --- seeded OMPL pieces -----------------------------------------------------------------

/// Uniform sampler with a local seed.
class SeededSampler : public ob::RealVectorStateSampler {
 public:
  SeededSampler(const ob::StateSpace* space, std::uint32_t seed) : ob::RealVectorStateSampler(space) {
    rng_.setLocalSeed(seed);
  }
};

/// R³ whose default samplers (also those OMPL's informed samplers allocate) are seeded from
/// one plan seed, in allocation order.
class SeededSpace : public ob::RealVectorStateSpace {
 public:
  explicit SeededSpace(std::uint32_t seed) : ob::RealVectorStateSpace(3), seed_(seed) {}
  ob::StateSamplerPtr allocDefaultStateSampler() const override {
    return std::make_shared<SeededSampler>(this, mix_seed(seed_, ++allocations_));
  }

 private:
  std::uint32_t seed_;
  mutable std::atomic<std::uint64_t> allocations_{0};
};

/// A planner whose own random generator is seeded locally.
template <class P>
class Seeded : public P {
 public:
  Seeded(const ob::SpaceInformationPtr& si, std::uint32_t seed) : P(si) { this->rng_.setLocalSeed(seed); }
};

/// PathSimplifier with our objective and a locally seeded generator.
class SeededSimplifier : public og::PathSimplifier {
 public:
  SeededSimplifier(const ob::SpaceInformationPtr& si, const ob::OptimizationObjectivePtr& obj,
                   std::uint32_t seed)
      : og::PathSimplifier(si, ob::GoalPtr(), obj) {
    rng_.setLocalSeed(seed);
  }
};

// --- planner table ----------------------------------------------------------------------

struct PlannerEntry {
  const char* name;
  bool optimizing;   ///< improves the objective until convergence / budget
  bool multi_query;  ///< keeps a roadmap usable by later queries
  std::function<ob::PlannerPtr(const ob::SpaceInformationPtr&, std::uint32_t)> make;
};

template <class P>
ob::PlannerPtr make_seeded(const ob::SpaceInformationPtr& si, std::uint32_t seed) {
  return std::make_shared<Seeded<P>>(si, seed);
}
template <class P>
ob::PlannerPtr make_plain(const ob::SpaceInformationPtr& si, std::uint32_t) {
  return std::make_shared<P>(si);
}

const std::vector<PlannerEntry>& planner_table() {
  static const std::vector<PlannerEntry> table = {
      {"abitstar", true, false, make_plain<og::ABITstar>},
      {"bfmt", false, false, make_plain<og::BFMT>},
      {"bitstar", true, false, make_plain<og::BITstar>},
      {"fmt", false, false, make_plain<og::FMT>},
      {"informedrrtstar", true, false, make_seeded<og::InformedRRTstar>},
      {"lazyprm", false, true, make_plain<og::LazyPRM>},
      {"lazyprmstar", true, true, make_plain<og::LazyPRMstar>},
      {"prm", false, true, make_seeded<og::PRM>},
      {"prmstar", true, true, make_seeded<og::PRMstar>},
      {"rrt", false, false, make_seeded<og::RRT>},
      {"rrtconnect", false, false, make_seeded<og::RRTConnect>},
      {"rrtsharp", true, false, make_seeded<og::RRTsharp>},
      {"rrtstar", true, false, make_seeded<og::RRTstar>},
      {"sorrtstar", true, false, make_seeded<og::SORRTstar>},
  };
  return table;
}

const PlannerEntry& find_planner(const std::string& name) {
  for (const auto& e : planner_table())
    if (name == e.name) return e;
  std::string valid;
  for (const auto& e : planner_table()) valid += std::string(valid.empty() ? "" : ", ") + e.name;
  throw std::invalid_argument("unknown planner '" + name + "'; valid planners: " + valid);
}

// --- objective --------------------------------------------------------------------------

/// Length + clearance term + per-part preferences (see PlanObjective), integrated along
/// segments with a step of tube_resolution(required), skipping stretches where a
/// closest-point query proves every term constant.
class TubeObjective : public ob::OptimizationObjective {
 public:
  TubeObjective(const ob::SpaceInformationPtr& si, const ObstacleIndex& index, double required,
                const PlanObjective& terms)
      : ob::OptimizationObjective(si),
        index_(index),
        required_(required),
        w_len_(terms.length_weight),
        w_clear_(terms.clearance_weight),
        w_pref_(terms.preference_weight),
        band_(terms.clearance_band > 0.0 ? terms.clearance_band : required),
        step_(tube_resolution(required)),
        w_sup_(terms.support_weight),
        sup_reach_(terms.support_reach),
        sup_band_(terms.support_band > 0.0 ? terms.support_band : terms.support_reach) {
    description_ = "tube length + clearance";
    if (w_sup_ > 0.0) {
      for (int i = 0; i < index.part_count(); ++i) {
        const bool supports = terms.part_supports.empty() ||
                              (static_cast<std::size_t>(i) < terms.part_supports.size() && terms.part_supports[i]);
        (supports ? supporting_ : non_supporting_).push_back(i);
      }
      if (supporting_.empty()) w_sup_ = 0.0;  // nothing can hold a clamp: the term is constant
    }
    for (std::size_t i = 0; i < terms.part_preference.size(); ++i) {
      if (static_cast<int>(i) >= index.part_count()) break;
      if (terms.part_preference[i] == PartPreference::Near) near_.push_back(static_cast<int>(i));
      if (terms.part_preference[i] == PartPreference::Avoid) avoid_.push_back(static_cast<int>(i));
    }
    if (w_pref_ == 0.0) {
      near_.clear();
      avoid_.clear();
    }
    const double w = w_len_;
    setCostToGoHeuristic([w](const ob::State* s, const ob::Goal* g) {
      return ob::Cost(w * std::max(0.0, g->as<ob::GoalRegion>()->distanceGoal(s)));
    });
  }

  /// True if the cost is w_len × length (no distance queries needed).
  bool pure_length() const { return w_clear_ == 0.0 && near_.empty() && avoid_.empty() && w_sup_ == 0.0; }

  ob::Cost stateCost(const ob::State* s) const override {
    double constant_for = 0.0;
    return ob::Cost(rate(state_point(s), constant_for));
  }
  ob::Cost motionCost(const ob::State* s1, const ob::State* s2) const override {
    return ob::Cost(segment_cost(state_point(s1), state_point(s2)));
  }
  ob::Cost motionCostHeuristic(const ob::State* s1, const ob::State* s2) const override {
    return ob::Cost(w_len_ * si_->distance(s1, s2));
  }

  /// Cost of the straight segment ab.
  double segment_cost(const Vec3& a, const Vec3& b) const {
    const double len = (b - a).norm();
    if (pure_length() || len == 0.0) return w_len_ * len;
    const Vec3 dir = (b - a) / len;
    double integral = 0.0;
    double s = 0.0;
    while (s < len) {
      double constant_for = 0.0;
      const double r = rate(a + s * dir, constant_for) - w_len_;
      const double ds = std::min(std::max(step_, constant_for), len - s);
      integral += r * ds;
      s += ds;
    }
    return w_len_ * len + integral;
  }

  /// Cost of a polyline.
  double polyline_cost(const std::vector<Vec3>& p) const {
    double c = 0.0;
    for (std::size_t i = 1; i < p.size(); ++i) c += segment_cost(p[i - 1], p[i]);
    return c;
  }

  double length_weight() const { return w_len_; }

 private:
  /// φ(d): 1 at the required distance, 0 beyond required + band.
  double ramp(double d) const { return std::clamp(1.0 - (d - required_) / band_, 0.0, 1.0); }
  /// Length along which φ(d) stays at 0 from a point at distance d (1-Lipschitz distance).
  double flat_for(double d) const { return std::max(0.0, d - required_ - band_); }

  /// Cost per unit length at p; constant_for receives a length along any direction over
  /// which the rate provably does not change.
  double rate(const Vec3& p, double& constant_for) const {
    const double horizon = required_ + band_ + kSkipSteps * step_;
    constant_for = horizon;
    double r = w_len_;
    // Beyond the band every ramp is 0: an index that proves it cheaply (the voxel layer's
    // lower bound) saves the closest-point queries, and the bound says how far the rate
    // stays so.
    const bool ramps = w_clear_ > 0.0 || !avoid_.empty() || !near_.empty();
    const double far = ramps ? index_.distance_lower_bound(p) : 0.0;
    if (far >= required_ + band_) {
      if (!near_.empty()) r += w_pref_;
      constant_for = std::min(constant_for, flat_for(far));
    } else {
      r += near_rate(p, horizon, constant_for);
    }
    if (w_sup_ > 0.0) {
      // σ is constant (0) within reach − step and (1) beyond reach + band: 1-Lipschitz
      // distance gives how far it stays so.
      const double d = support_distance(p);
      r += w_sup_ * std::clamp((d - sup_reach_) / sup_band_, 0.0, 1.0);
      const double inside = sup_reach_ - d, outside = d - sup_reach_ - sup_band_;
      constant_for = std::min(constant_for, std::max({0.0, inside, outside}));
    }
    return r;
  }

  /// The clearance and preference terms of rate() from exact queries (horizon: their search
  /// radius); lowers constant_for to how far they provably stay.
  double near_rate(const Vec3& p, double horizon, double& constant_for) const {
    double r = 0.0;
    if (w_clear_ > 0.0) {
      const ClosestHit hit = index_.closest(p, horizon);
      const double d = hit.found() ? hit.distance : horizon;
      const bool near_part = hit.found() && is_near(hit.part);
      if (!near_part) r += w_clear_ * ramp(d);
      constant_for = std::min(constant_for, near_part ? 0.0 : flat_for(d));
    }
    for (int part : avoid_) {
      const ClosestHit hit = index_.closest_on_part(p, part, horizon);
      const double d = hit.found() ? hit.distance : horizon;
      r += w_pref_ * ramp(d);
      constant_for = std::min(constant_for, flat_for(d));
    }
    if (!near_.empty()) {
      double d = horizon;
      for (int part : near_) {
        const ClosestHit hit = index_.closest_on_part(p, part, d);
        if (hit.found()) d = std::min(d, hit.distance);
      }
      r += w_pref_ * (1.0 - ramp(d));
      constant_for = std::min(constant_for, flat_for(d));
    }
    return r;
  }

  /// Distance from p to the nearest supporting part, capped kSkipSteps steps beyond reach +
  /// band (σ is 1 there whatever the distance; the margin lets segment_cost skip ahead).
  /// One query over all parts decides it unless its answer is a part that cannot hold a
  /// clamp; then the supporting parts are asked one by one.
  double support_distance(const Vec3& p) const {
    const double cap = sup_reach_ + sup_band_ + kSkipSteps * step_;
    const ClosestHit hit = index_.closest(p, cap);
    if (!hit.found()) return cap;
    if (non_supporting_.empty() || std::find(non_supporting_.begin(), non_supporting_.end(), hit.part) == non_supporting_.end())
      return hit.distance;
    double d = cap;
    for (int part : supporting_) {
      const ClosestHit h = index_.closest_on_part(p, part, d);
      if (h.found()) d = std::min(d, h.distance);
    }
    return d;
  }

  bool is_near(int part) const { return std::find(near_.begin(), near_.end(), part) != near_.end(); }

  const ObstacleIndex& index_;
  double required_;
  double w_len_, w_clear_, w_pref_, band_, step_;
  double w_sup_, sup_reach_, sup_band_;
  std::vector<int> near_, avoid_;
  std::vector<int> supporting_, non_supporting_;  ///< part ids that can / cannot carry a clamp
};

// --- planning context -------------------------------------------------------------------

/// Space, validity and objective for one tube size in one box.
struct TubeContext {
  std::shared_ptr<SeededSpace> space;
  ob::SpaceInformationPtr si;
  std::shared_ptr<TubeObjective> objective;
  TubeQueryCounters counters;
  double required = 0.0;
  AABB bounds;
};

std::unique_ptr<TubeContext> make_context(const ObstacleIndex& index, const AABB& bounds,
                                          double required, const PlanObjective& terms,
                                          std::uint32_t seed) {
  auto ctx = std::make_unique<TubeContext>();
  ctx->required = required;
  ctx->bounds = bounds;
  ctx->space = std::make_shared<SeededSpace>(seed);
  ob::RealVectorBounds b(3);
  for (int k = 0; k < 3; ++k) {
    b.setLow(k, bounds.min[k]);
    b.setHigh(k, bounds.max[k]);
  }
  ctx->space->setBounds(b);
  ctx->si = std::make_shared<ob::SpaceInformation>(ctx->space);
  const double band = terms.clearance_band > 0.0 ? terms.clearance_band : required;
  configure_tube_space(ctx->si, index, required, required + band + kSkipSteps * tube_resolution(required),
                       &ctx->counters);
  ctx->objective = std::make_shared<TubeObjective>(ctx->si, index, required, terms);
  return ctx;
}

/// Planning bounds: the scene box and the given points, plus the margin, never flat.
AABB planning_bounds(const AABB& scene_box, const std::vector<Vec3>& points, double margin) {
  AABB b = scene_box;
  for (const auto& p : points) b.extend(p);
  b.min -= Vec3::Constant(margin);
  b.max += Vec3::Constant(margin);
  return b;
}

// --- validation -------------------------------------------------------------------------

void check_finite_nonneg(double v, const char* what) {
  if (!std::isfinite(v) || v < 0.0)
    throw std::invalid_argument(std::string("plan: ") + what + " must be finite and >= 0");
}

void validate_settings(const PlanSettings& s) {
  if (!std::isfinite(s.radius) || !(s.radius > 0.0))
    throw std::invalid_argument("plan: tube radius must be finite and > 0");
  check_finite_nonneg(s.clearance, "clearance");
  check_finite_nonneg(s.min_bend_radius, "min_bend_radius");
  if (!std::isfinite(s.stub_length)) throw std::invalid_argument("plan: stub_length must be finite");
  const auto& o = s.objective;
  if (!std::isfinite(o.length_weight) || !(o.length_weight > 0.0))
    throw std::invalid_argument("plan: objective length_weight must be finite and > 0");
  check_finite_nonneg(o.clearance_weight, "objective clearance_weight");
  check_finite_nonneg(o.clearance_band, "objective clearance_band");
  check_finite_nonneg(o.preference_weight, "objective preference_weight");
  check_finite_nonneg(o.support_weight, "objective support_weight");
  check_finite_nonneg(o.support_reach, "objective support_reach");
  check_finite_nonneg(o.support_band, "objective support_band");
  if (o.support_weight > 0.0 && o.support_reach + o.support_band <= 0.0)
    throw std::invalid_argument("plan: objective support_weight > 0 needs support_reach or support_band > 0");
  check_finite_nonneg(s.convergence_epsilon, "convergence_epsilon");
  if (!std::isfinite(s.convergence_window) || !(s.convergence_window > 0.0) || s.convergence_window > 1.0)
    throw std::invalid_argument("plan: convergence_window must be in (0, 1]");
  check_finite_nonneg(s.diagnosis_fraction, "diagnosis_fraction");
  if (!s.scene_box.empty() && !(s.scene_box.min.allFinite() && s.scene_box.max.allFinite()))
    throw std::invalid_argument("plan: scene box must be finite");
  find_planner(s.planner);
}

PortSpec validated_port(const PortSpec& p, const char* which) {
  if (!p.position.allFinite())
    throw std::invalid_argument(std::string("plan: ") + which + " port position is not finite");
  const double n = p.exit_direction.norm();
  if (!std::isfinite(n) || !(n > 0.0))
    throw std::invalid_argument(std::string("plan: ") + which + " port exit direction is zero or not finite");
  return PortSpec{p.position, p.exit_direction / n};
}

// --- termination ------------------------------------------------------------------------

/// Iteration cap, wall-clock deadline and cost convergence, evaluated from any planner
/// thread. The iteration cap is tested first: a run whose budget and deadline run out on the
/// same evaluation ended on its (deterministic) iteration budget.
class Convergence {
 public:
  Convergence(double time_limit_s, double window_s, double epsilon, std::uint64_t max_iterations)
      : deadline_(Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(time_limit_s))),
        window_s_(window_s),
        eps_(epsilon),
        max_iter_(max_iterations) {}

  void report(double cost) {
    std::lock_guard<std::mutex> lock(m_);
    if (!have_ || cost < best_ * (1.0 - eps_)) last_improvement_ = Clock::now();
    if (!have_ || cost < best_) best_ = cost;
    have_ = true;
  }

  bool should_stop() {
    if (max_iter_ > 0 && ++iterations_ >= max_iter_) return true;
    if (max_iter_ == 0) ++iterations_;
    if (Clock::now() >= deadline_) {
      timed_out_ = true;
      return true;
    }
    if (window_s_ <= 0.0) return false;
    std::lock_guard<std::mutex> lock(m_);
    return have_ && std::chrono::duration<double>(Clock::now() - last_improvement_).count() >= window_s_;
  }

  /// Evaluations of the termination condition so far (at most the iteration budget).
  std::uint64_t iterations() const {
    const std::uint64_t n = iterations_.load();
    return max_iter_ > 0 ? std::min(n, max_iter_) : n;
  }
  /// True if the wall-clock deadline stopped the run.
  bool timed_out() const { return timed_out_.load(); }

 private:
  std::mutex m_;
  Clock::time_point deadline_;
  double window_s_, eps_;
  std::uint64_t max_iter_;
  std::atomic<std::uint64_t> iterations_{0};
  std::atomic<bool> timed_out_{false};
  bool have_ = false;
  double best_ = std::numeric_limits<double>::infinity();
  Clock::time_point last_improvement_;
};

// --- one planner run --------------------------------------------------------------------

struct RunOutcome {
  bool solved = false;
  std::vector<Vec3> path;  ///< planner states, stub end to stub end
  double ms = 0.0;
  std::uint64_t iterations = 0;  ///< evaluations of the termination condition
  bool timed_out = false;        ///< the wall-clock time limit stopped the planner
};

/// Solves start→goal with `planner` (already bound to ctx.si) under the time/iteration/
/// convergence conditions of the settings.
RunOutcome run_planner(TubeContext& ctx, const ob::PlannerPtr& planner, bool optimizing,
                       const Vec3& from, const Vec3& to, double time_limit,
                       const PlanSettings& settings) {
  RunOutcome out;
  const Stopwatch t0;
  auto pdef = std::make_shared<ob::ProblemDefinition>(ctx.si);
  ob::ScopedState<> s(ctx.space), g(ctx.space);
  set_state_point(s.get(), from);
  set_state_point(g.get(), to);
  pdef->setStartAndGoalStates(s, g, kGoalToleranceRel * ctx.space->getMaximumExtent());
  const double lower = ctx.objective->length_weight() * (to - from).norm();
  if (optimizing && settings.convergence_epsilon > 0.0)
    ctx.objective->setCostThreshold(ob::Cost(lower * (1.0 + settings.convergence_epsilon)));
  else if (optimizing)
    ctx.objective->setCostThreshold(ob::Cost(0.0));  // never satisfied: use the whole budget
  else
    ctx.objective->setCostThreshold(ctx.objective->infiniteCost());  // first solution ends it
  pdef->setOptimizationObjective(ctx.objective);

  const bool converge = optimizing && settings.convergence_epsilon > 0.0 && settings.max_iterations == 0;
  auto conv = std::make_shared<Convergence>(time_limit, converge ? settings.convergence_window * time_limit : 0.0,
                                            settings.convergence_epsilon, settings.max_iterations);
  pdef->setIntermediateSolutionCallback(
      [conv](const ob::Planner*, const std::vector<const ob::State*>&, const ob::Cost c) {
        conv->report(c.value());
      });
  planner->setProblemDefinition(pdef);
  if (!planner->isSetup()) planner->setup();

  const ob::PlannerTerminationCondition ptc([conv] { return conv->should_stop(); });
  planner->solve(ptc);
  out.ms = t0.ms();
  out.iterations = conv->iterations();
  out.timed_out = conv->timed_out();

  if (!pdef->hasExactSolution()) return out;
  const auto path = std::dynamic_pointer_cast<og::PathGeometric>(pdef->getSolutionPath());
  if (!path || path->getStateCount() < 1) return out;
  for (std::size_t i = 0; i < path->getStateCount(); ++i) out.path.push_back(state_point(path->getState(i)));
  out.path.front() = from;  // the goal tolerance is ~1e-9 of the extent: snap both ends
  out.path.back() = to;
  out.solved = true;
  return out;
}

/// OMPL shortcutting with our objective, then greedy reduction to key points: from each
/// kept point, jump to the farthest later point whose straight capsule is clear and no
/// costlier than the stretch it replaces.
std::vector<Vec3> simplify_to_key_points(const ObstacleIndex& index, TubeContext& ctx,
                                         const std::vector<Vec3>& raw, std::uint32_t seed) {
  std::vector<Vec3> pts = raw;
  if (pts.size() > 2) {
    og::PathGeometric path(ctx.si);
    for (const auto& p : pts) {
      ob::State* st = ctx.si->allocState();
      set_state_point(st, p);
      path.append(st);
      ctx.si->freeState(st);
    }
    SeededSimplifier simplifier(ctx.si, ctx.objective, mix_seed(seed, 0x5151));
    // Rounds of shortcutting (cost-aware in OMPL 1.5) until nothing changes; vertex
    // reduction only checks validity, so it runs only when the cost is the length.
    // A fixed number of rounds, not a time limit, keeps seeded runs reproducible.
    for (int round = 0; round < kSimplifyRounds; ++round) {
      bool changed = false;
      if (ctx.objective->pure_length()) changed = simplifier.reduceVertices(path);
      changed = simplifier.shortcutPath(path, kShortcutStepsPerState * static_cast<unsigned>(path.getStateCount())) ||
                changed;
      if (!changed) break;
    }
    pts.clear();
    for (std::size_t i = 0; i < path.getStateCount(); ++i) pts.push_back(state_point(path.getState(i)));
    pts.front() = raw.front();
    pts.back() = raw.back();
  }
  pts = dedupe_consecutive(pts, kDuplicateRel * ctx.required);
  if (pts.size() <= 2) return pts;

  // Prefix costs of the stretch (our objective).
  std::vector<double> prefix(pts.size(), 0.0);
  for (std::size_t i = 1; i < pts.size(); ++i)
    prefix[i] = prefix[i - 1] + ctx.objective->segment_cost(pts[i - 1], pts[i]);
  std::vector<Vec3> out{pts.front()};
  std::size_t i = 0;
  while (i + 1 < pts.size()) {
    std::size_t next = i + 1;
    for (std::size_t j = pts.size() - 1; j > i + 1; --j) {
      if (index.segment_within(pts[i], pts[j], ctx.required)) continue;
      const double chain = prefix[j] - prefix[i];
      if (!ctx.objective->pure_length() &&
          ctx.objective->segment_cost(pts[i], pts[j]) > chain * (1.0 + kCostCompareTolerance))
        continue;
      next = j;
      break;
    }
    out.push_back(pts[next]);
    i = next;
  }
  return out;
}

/// Exact re-check of a polyline; fills length, min clearance and cost on success.
bool verify_polyline(const ObstacleIndex& index, const TubeContext& ctx, double radius,
                     const std::vector<Vec3>& pts, PlanResult& r) {
  double length = 0.0;
  double min_dist = std::numeric_limits<double>::infinity();
  for (std::size_t i = 1; i < pts.size(); ++i) {
    if (index.segment_within(pts[i - 1], pts[i], ctx.required)) {
      double t = 0.0;
      const ClosestHit hit = index.segment_closest(pts[i - 1], pts[i], ctx.required, &t);
      r.blocked_at = pts[i - 1] + t * (pts[i] - pts[i - 1]);
      r.blocking_part = hit.part;
      return false;
    }
    const ClosestHit hit = index.segment_closest(pts[i - 1], pts[i]);
    if (hit.found()) min_dist = std::min(min_dist, hit.distance);
    length += (pts[i] - pts[i - 1]).norm();
  }
  if (pts.size() == 1) {
    const ClosestHit hit = index.closest(pts[0]);
    if (hit.found()) min_dist = hit.distance;
  }
  r.length = length;
  // No part at all: report the clearance as the largest finite number rather than inf.
  r.min_clearance = std::isfinite(min_dist) ? min_dist - radius : std::numeric_limits<double>::max();
  r.cost = ctx.objective->polyline_cost(pts);
  return true;
}

/// The planner's port check: the port and its stub end inside the planning bounds, then
/// check_port_exit (no part excused).
bool check_port(const ObstacleIndex& index, const AABB& bounds, double required, const PortSpec& port,
                const Vec3& stub_end, bool is_start, PlanResult& r) {
  const std::string who = is_start ? "start port" : "goal port";
  if (!bounds.contains(port.position) || !bounds.contains(stub_end)) {
    r.reason = is_start ? NoPathReason::StartInObstacle : NoPathReason::GoalInObstacle;
    r.blocked_at = port.position;
    r.message = who + " at " + full_precision(port.position) + " or its stub lies outside the planning bounds";
    return false;
  }
  return check_port_exit(index, {}, PortExit{who, port.position, stub_end, is_start, {}, 0.0}, required, {}, r);
}


/// The part that seals p in a cavity: every one of kEnclosureRays directions (a Fibonacci
/// sphere) hits a part within `reach`. Returns the part hit by most rays, or -1 as soon as
/// one ray escapes.
int enclosing_part(const ObstacleIndex& index, const Vec3& p, double reach) {
  std::map<int, int> hits;
  const double golden = M_PI * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < kEnclosureRays; ++i) {
    const double z = 1.0 - 2.0 * (i + 0.5) / kEnclosureRays, rho = std::sqrt(1.0 - z * z);
    const Vec3 d(rho * std::cos(golden * i), rho * std::sin(golden * i), z);
    const RayHit h = index.ray(p, d, reach);
    if (!h.found()) return -1;
    ++hits[h.part];
  }
  return std::max_element(hits.begin(), hits.end(), [](const auto& a, const auto& b) { return a.second < b.second; })
      ->first;
}

/// Everything after the port checks: plan with `planner`, simplify, verify; on failure,
/// diagnose with a thin tube. `ctx` belongs to `planner`.
void plan_between_stubs(const ObstacleIndex& index, TubeContext& ctx, const ob::PlannerPtr& planner,
                        bool optimizing, const PlanSettings& settings, const PortSpec& start,
                        const PortSpec& goal, const Vec3& start_end, const Vec3& goal_end,
                        double time_limit, PlanResult& r) {
  const auto counters_before = ctx.counters.motion_checks.load();
  std::vector<Vec3> interior;
  bool found = false;
  if ((goal_end - start_end).norm() <= kDuplicateRel * ctx.required) {
    interior = {start_end, goal_end};
    found = true;
  } else {
    const RunOutcome run = run_planner(ctx, planner, optimizing, start_end, goal_end, time_limit, settings);
    r.plan_ms = run.ms;
    r.raw_states = run.path.size();
    r.iterations = run.iterations;
    r.time_limited = run.timed_out;
    if (run.solved) {
      const Stopwatch t1;
      interior = simplify_to_key_points(index, ctx, run.path, settings.seed);
      r.simplify_ms = t1.ms();
      found = true;
    }
  }
  r.motion_checks = ctx.counters.motion_checks.load() - counters_before;

  if (!found && settings.diagnosis_fraction > 0.0) {
    // A thin tube tells a missing corridor from a short budget; if its path happens to be
    // clear for the real tube, it is a route.
    const Stopwatch t2;
    const double thin = kThinFraction * ctx.required;
    auto thin_ctx = make_context(index, ctx.bounds, thin, PlanObjective{}, mix_seed(settings.seed, 0xD1A6));
    PlanSettings thin_settings = settings;
    thin_settings.max_iterations = 0;
    auto thin_planner = std::make_shared<Seeded<og::RRTConnect>>(thin_ctx->si, mix_seed(settings.seed, 0xD1A7));
    // The straight stub-to-stub line first (many cables run nearly straight), then RRTConnect.
    RunOutcome run;
    if (!index.segment_within(start_end, goal_end, thin)) {
      run.solved = true;
      run.path = {start_end, goal_end};
    } else {
      run = run_planner(*thin_ctx, thin_planner, false, start_end, goal_end,
                        settings.diagnosis_fraction * time_limit, thin_settings);
      r.time_limited = r.time_limited || run.timed_out;
    }
    if (run.solved) {
      double best = std::numeric_limits<double>::infinity();
      for (std::size_t i = 1; i < run.path.size(); ++i) {
        double t = 0.0;
        const ClosestHit hit = index.segment_closest(run.path[i - 1], run.path[i], ctx.required, &t);
        if (hit.found() && hit.distance < best) {
          best = hit.distance;
          r.blocked_at = run.path[i - 1] + t * (run.path[i] - run.path[i - 1]);
          r.blocking_part = hit.part;
        }
      }
      if (!std::isfinite(best)) {
        r.raw_states = run.path.size();
        interior = simplify_to_key_points(index, ctx, run.path, settings.seed);
        found = true;
        r.blocked_at.reset();
        r.blocking_part = -1;
      } else {
        r.reason = NoPathReason::NoCorridor;
        // Said with the budget: the planner may have run out of time in a corridor that
        // exists (a slow build, a tight limit), which only a longer limit tells apart.
        r.message = "no corridor wider than the tube (radius + clearance = " + fmt_len(ctx.required) +
                    ") found within " + fmt_len(time_limit) + " s; a thin path passes " + fmt_len(best) +
                    " from part " + std::to_string(r.blocking_part) + " at " + fmt_point(*r.blocked_at) +
                    " (a longer time limit may still find one)";
      }
    }
    r.diagnose_ms = t2.ms();
  }
  if (!found) {
    if (r.reason != NoPathReason::NoCorridor && settings.diagnosis_fraction > 0.0) {
      // No thin path either: if an end is sealed in a cavity, say so (an unreachable port).
      const double reach = ctx.bounds.diagonal();
      for (const auto& [end, name] : {std::pair{start_end, "start"}, std::pair{goal_end, "goal"}}) {
        const int part = enclosing_part(index, end, reach);
        if (part < 0) continue;
        r.reason = NoPathReason::Enclosed;
        r.blocked_at = end;
        r.blocking_part = part;
        r.message = std::string("the ") + name + " " + fmt_point(end) + " is sealed in a cavity: all " +
                    std::to_string(kEnclosureRays) + " rays cast from it hit part " + std::to_string(part);
        return;
      }
    }
    if (r.reason != NoPathReason::NoCorridor) {
      r.reason = NoPathReason::Timeout;
      r.message = "no path found within " + fmt_len(time_limit) + " s" +
                  (settings.diagnosis_fraction > 0.0 ? " (not even for a thin line: the ports may be in "
                                                       "disconnected regions)"
                                                     : "");
    }
    return;
  }

  std::vector<Vec3> key;
  key.push_back(start.position);
  key.insert(key.end(), interior.begin(), interior.end());
  key.push_back(goal.position);
  key = dedupe_consecutive(key, kDuplicateRel * ctx.required);
  if (!verify_polyline(index, ctx, settings.radius, key, r)) {
    r.reason = NoPathReason::InvalidSolution;
    r.message = "the planner's path failed the exact capsule re-check near " +
                fmt_point(r.blocked_at.value_or(start.position));
    return;
  }
  r.key_points = std::move(key);
  r.status = PlanStatus::Solved;
  r.reason = NoPathReason::None;
  r.message = "solved";
}

}  // namespace

// --- public API -------------------------------------------------------------------------

std::vector<Vec3> dedupe_consecutive(const std::vector<Vec3>& pts, double tol) {
  std::vector<Vec3> out;
  for (const auto& p : pts)
    if (out.empty() || (p - out.back()).norm() > tol) out.push_back(p);
  if (out.size() == 1 && pts.size() > 1) out.push_back(pts.back());
  return out;
}

const char* preference_name(PartPreference p) {
  switch (p) {
    case PartPreference::Neutral: return "neutral";
    case PartPreference::Near: return "near";
    case PartPreference::Avoid: return "avoid";
  }
  return "neutral";
}

const char* reason_name(NoPathReason r) {
  switch (r) {
    case NoPathReason::None: return "none";
    case NoPathReason::StartInObstacle: return "start_in_obstacle";
    case NoPathReason::GoalInObstacle: return "goal_in_obstacle";
    case NoPathReason::StartPortBlocked: return "start_port_blocked";
    case NoPathReason::GoalPortBlocked: return "goal_port_blocked";
    case NoPathReason::NoCorridor: return "no_corridor";
    case NoPathReason::Timeout: return "timeout";
    case NoPathReason::Enclosed: return "enclosed";
    case NoPathReason::InvalidSolution: return "invalid_solution";
  }
  return "none";
}

std::vector<std::string> planner_names() {
  // The scene model's list is the one users see; every name on it must have a table entry
  // (find_planner throws otherwise: PathPlanner.EveryPlannerNameSolvesAnEasyScene plans with each).
  // "portfolio" is on the scene's list but not an OMPL planner (planner_portfolio.hpp).
  std::vector<std::string> names;
  for (const std::string& n : routing_planner_names())
    if (n != "portfolio") names.push_back(find_planner(n).name);
  return names;
}

bool planner_is_optimizing(const std::string& name) { return find_planner(name).optimizing; }

bool planner_is_threaded(const std::string& name) {
  find_planner(name);  // unknown names throw
  return name == "prm" || name == "prmstar";
}

std::uint32_t seed_ompl_once(std::uint32_t seed) {
  static std::once_flag once;
  static std::uint32_t in_effect = 0;
  std::call_once(once, [seed] {
    ompl::msg::setLogLevel(std::getenv("LOOM_OMPL_LOG") ? ompl::msg::LOG_DEBUG : ompl::msg::LOG_ERROR);
    // OMPL ignores seed 0 ("cannot be 0"): map it to a fixed non-zero seed.
    in_effect = seed == 0 ? 0x9E3779B9u : seed;
    ompl::RNG::setSeed(in_effect);
  });
  return in_effect;
}

PlanResult plan_path(const ObstacleIndex& index, const PlanRequest& request) {
  const Stopwatch t0;
  validate_settings(request);
  if (!std::isfinite(request.time_limit) || request.time_limit < 0.0)
    throw std::invalid_argument("plan: time limit must be finite and >= 0");
  const PortSpec start = validated_port(request.start, "start");
  const PortSpec goal = validated_port(request.goal, "goal");
  if ((start.position - goal.position).norm() == 0.0)
    throw std::invalid_argument("plan: start and goal ports coincide");
  seed_ompl_once(request.seed);
  const PlannerEntry& entry = find_planner(request.planner);

  PlanResult r;
  r.planner = request.planner;
  const double required = request.radius + request.clearance;
  const double stub = request.stub_length >= 0.0 ? request.stub_length
                                                  : derived_stub_length(request.radius, request.min_bend_radius);
  r.stub_length = stub;
  const Vec3 start_end = start.position + stub * start.exit_direction;
  const Vec3 goal_end = goal.position + stub * goal.exit_direction;
  r.lower_bound = request.objective.length_weight * (goal_end - start_end).norm();
  const AABB bounds = planning_bounds(request.scene_box, {start.position, goal.position, start_end, goal_end},
                                      kMarginRequired * required);

  const bool ok = check_port(index, bounds, required, start, start_end, true, r) &&
                  check_port(index, bounds, required, goal, goal_end, false, r);
  if (!ok) {
    r.time_ms = t0.ms();
    return r;
  }
  if (request.time_limit == 0.0) {
    r.reason = NoPathReason::Timeout;
    r.message = "time budget is 0 s: ports checked, no planning done";
    r.time_ms = t0.ms();
    return r;
  }
  auto ctx = make_context(index, bounds, required, request.objective, request.seed);
  const ob::PlannerPtr planner = entry.make(ctx->si, mix_seed(request.seed, 0x91A2));
  plan_between_stubs(index, *ctx, planner, entry.optimizing, request, start, goal, start_end, goal_end,
                     request.time_limit, r);
  r.time_ms = t0.ms();
  return r;
}

// --- RoadmapPlanner ---------------------------------------------------------------------

struct RoadmapPlanner::Impl {
  const ObstacleIndex& index;
  PlanSettings settings;
  const PlannerEntry* entry = nullptr;
  std::unique_ptr<TubeContext> ctx;
  ob::PlannerPtr planner;
  Impl(const ObstacleIndex& i, const PlanSettings& s) : index(i), settings(s) {}
};

bool RoadmapPlanner::supports(const std::string& name) {
  for (const auto& e : planner_table())
    if (name == e.name) return e.multi_query;
  return false;
}

RoadmapPlanner::RoadmapPlanner(const ObstacleIndex& index, const PlanSettings& settings)
    : impl_(std::make_unique<Impl>(index, settings)) {
  validate_settings(settings);
  if (!supports(settings.planner)) {
    std::string valid;
    for (const auto& e : planner_table())
      if (e.multi_query) valid += std::string(valid.empty() ? "" : ", ") + e.name;
    throw std::invalid_argument("RoadmapPlanner: '" + settings.planner +
                                "' is not a multi-query planner; use one of: " + valid);
  }
  seed_ompl_once(settings.seed);
  impl_->entry = &find_planner(settings.planner);
  const double required = settings.radius + settings.clearance;
  const double stub = settings.stub_length >= 0.0 ? settings.stub_length
                                                  : derived_stub_length(settings.radius, settings.min_bend_radius);
  if (settings.scene_box.empty())
    throw std::invalid_argument("RoadmapPlanner: the scene box must not be empty (it fixes the roadmap's bounds)");
  const AABB bounds = planning_bounds(settings.scene_box, {}, kMarginRequired * required + stub);
  impl_->ctx = make_context(index, bounds, required, settings.objective, settings.seed);
  impl_->planner = impl_->entry->make(impl_->ctx->si, mix_seed(settings.seed, 0x91A2));
}

RoadmapPlanner::~RoadmapPlanner() = default;

std::size_t RoadmapPlanner::roadmap_vertices() const {
  if (!impl_->planner->isSetup()) return 0;
  ob::PlannerData data(impl_->ctx->si);
  impl_->planner->getPlannerData(data);
  return data.numVertices();
}

PlanResult RoadmapPlanner::plan(const PortSpec& start_in, const PortSpec& goal_in, double time_limit) {
  const Stopwatch t0;
  if (!std::isfinite(time_limit) || time_limit < 0.0)
    throw std::invalid_argument("RoadmapPlanner: time limit must be finite and >= 0");
  const PortSpec start = validated_port(start_in, "start");
  const PortSpec goal = validated_port(goal_in, "goal");
  if ((start.position - goal.position).norm() == 0.0)
    throw std::invalid_argument("RoadmapPlanner: start and goal ports coincide");
  const PlanSettings& s = impl_->settings;
  TubeContext& ctx = *impl_->ctx;
  PlanResult r;
  r.planner = s.planner;
  const double stub = s.stub_length >= 0.0 ? s.stub_length : derived_stub_length(s.radius, s.min_bend_radius);
  r.stub_length = stub;
  const Vec3 start_end = start.position + stub * start.exit_direction;
  const Vec3 goal_end = goal.position + stub * goal.exit_direction;
  r.lower_bound = s.objective.length_weight * (goal_end - start_end).norm();
  const bool ok = check_port(impl_->index, ctx.bounds, ctx.required, start, start_end, true, r) &&
                  check_port(impl_->index, ctx.bounds, ctx.required, goal, goal_end, false, r);
  if (ok && time_limit == 0.0) {
    r.reason = NoPathReason::Timeout;
    r.message = "time budget is 0 s: ports checked, no planning done";
  } else if (ok) {
    // setProblemDefinition of PRM/LazyPRM calls clearQuery(): the roadmap stays.
    plan_between_stubs(impl_->index, ctx, impl_->planner, impl_->entry->optimizing, s, start, goal, start_end,
                       goal_end, time_limit, r);
  }
  r.time_ms = t0.ms();
  return r;
}

}  // namespace loom
