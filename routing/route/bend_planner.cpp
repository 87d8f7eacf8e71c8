#include "routing/route/bend_planner.hpp"

#include "core/error.hpp"
#include "core/stopwatch.hpp"

#include <iostream>  // NearestNeighborsGNATNoThreadSafety.h uses std::cout without including it

#include <ompl/datastructures/NearestNeighborsGNATNoThreadSafety.h>
#include <ompl/util/RandomNumbers.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>

namespace loom {

namespace {

/// Longest step of a tree, in bend radii: long enough that a step can hold the tangent of a
/// right-angle corner, short enough to turn along a corridor.
constexpr double kStepRadii = 2.0;
/// Nodes near a sample among which the one to step from is chosen.
constexpr unsigned kStepCandidates = 8;
/// Nodes of the other tree a new node tries to join.
constexpr unsigned kJoinCandidates = 8;
/// Share of the samples drawn around the hint (when there is one).
constexpr double kHintShare = 0.5;
/// After the first route, the trees grow on for as many samples again, at least this many.
constexpr std::uint64_t kMoreSamples = 2000;
/// Sweeps of pulling corners towards their neighbours' midpoint (ends early when none moves).
constexpr int kRelaxSweeps = 30;
/// Routes compared (each shortened; the shortest is kept).
constexpr int kMostRoutes = 16;

/// A node of a tree: reached at `p` heading `h` (unit), with `run` of straight leg before it
/// that its corner's tangent (and the leg_slack to the corner before) may use; `normal` is
/// corner_normal of the corner before it (its parent's; zero at a root), in the tree's
/// direction of travel.
struct Node {
  Vec3 p = Vec3::Zero();
  Vec3 h = Vec3::UnitX();
  double run = 0.0;
  int parent = -1;
  Vec3 normal = Vec3::Zero();
};

/// One tree and its neighbour structure (node ids; id −1 stands for the point queried).
struct Tree {
  std::vector<Node> nodes;
  ompl::NearestNeighborsGNATNoThreadSafety<int> nn;
  Vec3 query = Vec3::Zero();
  Tree() {
    nn.setDistanceFunction([this](const int& a, const int& b) { return (at(a) - at(b)).norm(); });
  }
  Tree(const Tree&) = delete;
  Tree& operator=(const Tree&) = delete;
  const Vec3& at(int id) const { return id < 0 ? query : nodes[static_cast<std::size_t>(id)].p; }
  int add(const Node& n) {
    nodes.push_back(n);
    const int id = static_cast<int>(nodes.size()) - 1;
    nn.add(id);
    return id;
  }
  int nearest(const Vec3& q) {
    query = q;
    return nn.nearest(-1);
  }
  void nearest_k(const Vec3& q, unsigned k, std::vector<int>& out) {
    query = q;
    nn.nearestK(-1, k, out);
  }
};

/// True iff the rounding arcs of vertices lo..hi of `v` keep `required` from every part.
bool arcs_clear(const ObstacleIndex& index, const std::vector<Vec3>& v, const ArcLineEnds& ends, double radius,
                double required, std::size_t lo, std::size_t hi) {
  for (std::size_t k = lo; k <= hi && k < v.size(); ++k)
    if (!corner_arc_clear(index, v[k], arc_line_in(v, ends, k), arc_line_out(v, ends, k), radius, required)) return false;
  return true;
}

/// Direction at most `max_turn` from unit heading h, as close to unit u as that allows.
Vec3 steer(const Vec3& h, const Vec3& u, double max_turn) {
  const double th = std::atan2(h.cross(u).norm(), h.dot(u));
  if (th <= max_turn) return u;
  Vec3 w = u - u.dot(h) * h;
  if (w.norm() < 1e-12) w = h.unitOrthogonal();
  w.normalize();
  return std::cos(max_turn) * h + std::sin(max_turn) * w;
}

class Planner {
 public:
  Planner(const ObstacleIndex& index, const BendPlanRequest& req) : index_(index), req_(req), rng_(req.seed) {
    step_ = kStepRadii * req.bend_radius;
    slack_ = kInnerLegSlack * req.bend_radius;
    same_ = kBendPlanSamePoint * req.required;
    width_ = req.hint_width > 0.0 ? req.hint_width : 2.0 * req.bend_radius + req.required;
    for (std::size_t i = 0; i + 1 < req.hint.size(); ++i) hint_len_.push_back((req.hint[i + 1] - req.hint[i]).norm());
    for (double l : hint_len_) hint_total_ += l;
  }

  BendPlanResult run() {
    const Stopwatch t0;
    BendPlanResult res;
    trees_[0].add({req_.start, req_.ends.start_heading.normalized(), req_.ends.start_run, -1, Vec3::Zero()});
    trees_[1].add({req_.goal, Vec3(-req_.ends.end_heading.normalized()), req_.ends.end_run, -1, Vec3::Zero()});
    std::vector<Vec3> best;
    double best_len = std::numeric_limits<double>::infinity();
    // Every join is a route: shortened, the shortest is kept. After the first, the trees grow
    // on for as many samples again (at least kMoreSamples), up to kMostRoutes routes.
    int routes = 0;
    std::uint64_t stop = req_.max_iterations;
    auto take = [&](std::vector<Vec3> path) {
      res.shortcuts += shorten(path);
      const double len = arc_line_length(path, req_.ends, req_.bend_radius);
      if (len < best_len) best_len = len, best = std::move(path);
      if (routes++ == 0)
        stop = std::min(req_.max_iterations, std::max(2 * res.iterations, res.iterations + kMoreSamples));
    };
    if (join(0, 0, 0)) take(path_of(0, 0));
    for (int side = 0; routes == 0 || (routes < kMostRoutes && res.iterations < stop); side ^= 1) {
      if (res.iterations >= stop) break;
      if (t0.seconds() >= req_.time_limit) {
        res.time_limited = true;
        break;
      }
      ++res.iterations;
      const int added = extend(trees_[side], sample());
      if (added < 0) continue;
      const int other = side ^ 1;
      std::vector<int> near;
      trees_[other].nearest_k(trees_[side].nodes[added].p, kJoinCandidates, near);
      for (int b : near)
        if (join(side, added, b)) {
          take(side == 0 ? path_of(added, b) : path_of(b, added));
          break;
        }
    }
    if (best.empty()) {
      finish_failure(res);
    } else {
      res.status = BendPlanStatus::Solved;
      res.vertices = best;
      res.length = best_len;
      res.key_points = arc_line_points(best, req_.ends, req_.bend_radius, 0.0);
    }
    res.time_ms = t0.ms();
    return res;
  }

 private:
  Vec3 sample() {
    if (hint_total_ > 0.0 && rng_.uniform01() < kHintShare) {
      double s = rng_.uniformReal(0.0, hint_total_);
      std::size_t i = 0;
      while (i + 1 < hint_len_.size() && s > hint_len_[i]) s -= hint_len_[i++];
      const double f = hint_len_[i] > 0.0 ? std::clamp(s / hint_len_[i], 0.0, 1.0) : 0.0;
      const Vec3 c = req_.hint[i] + f * (req_.hint[i + 1] - req_.hint[i]);
      std::vector<double> b(3);
      rng_.uniformInBall(width_, b);
      return c + Vec3(b[0], b[1], b[2]);
    }
    const AABB& box = req_.bounds;
    return {rng_.uniformReal(box.min.x(), box.max.x()), rng_.uniformReal(box.min.y(), box.max.y()),
            rng_.uniformReal(box.min.z(), box.max.z())};
  }

  /// Tangent plus slack that the corner at node n takes of its run when it leaves along u.
  double taken(const Node& n, const Vec3& u) const {
    return corner_tangent(n.h, u, req_.bend_radius) + leg_slack(n.normal, corner_normal(n.h, u), req_.bend_radius);
  }

  /// Among the kStepCandidates nodes of `tree` nearest to q, the one that reaches q with the
  /// least distance plus R × the turn it lacks (nearest by position alone keeps choosing a
  /// node that heads into a wall with no run left to turn).
  int closest_reachable(Tree& tree, const Vec3& q) {
    std::vector<int> near;
    tree.nearest_k(q, kStepCandidates, near);
    int best = near.front();
    double best_score = std::numeric_limits<double>::infinity();
    for (int i : near) {
      const Node& n = tree.nodes[i];
      const Vec3 e = q - n.p;
      const double len = e.norm();
      const double th = len > 0.0 ? std::atan2(n.h.cross(e).norm(), n.h.dot(e)) : 0.0;
      const double can = 2.0 * std::atan(std::min(n.run, std::min(len, step_)) / req_.bend_radius);
      const double score = len + req_.bend_radius * std::max(0.0, th - can);
      if (score < best_score) best_score = score, best = i;
    }
    return best;
  }

  /// Steps from a node of `tree` near q (closest_reachable) towards it; the new node's id, or −1. The
  /// step turns as far as the node's run allows: first as if no slack were needed (a turn
  /// continuing the corner before), else with the whole slack set aside.
  int extend(Tree& tree, const Vec3& q) {
    const int ni = closest_reachable(tree, q);
    const Node n = tree.nodes[ni];
    Vec3 e = q - n.p;
    const double len = std::min(e.norm(), step_);
    if (len < same_) return -1;
    e.normalize();
    Vec3 u = steer(n.h, e, 2.0 * std::atan(std::min(n.run, len) / req_.bend_radius));
    if (taken(n, u) > n.run) {
      const double room = std::min(std::max(0.0, n.run - slack_), len);
      u = steer(n.h, e, 2.0 * std::atan(room / req_.bend_radius));
    }
    const Vec3 c = n.p + len * u;
    if (!req_.bounds.contains(c) || index_.segment_within(n.p, c, req_.required)) return -1;
    if (!corner_arc_clear(index_, n.p, n.h, u, req_.bend_radius, req_.required)) return -1;
    const double t = corner_tangent(n.h, u, req_.bend_radius);
    return tree.add({c, u, len - t, ni, corner_normal(n.h, u)});
  }

  /// Joins node a of tree `side` to node b of the other tree: the segment between them, the
  /// arcs at both ends, their tangents and slacks on it and on the legs before them must fit.
  bool join(int side, int a, int b) {
    const Node& na = trees_[side].nodes[a];
    const Node& nb = trees_[side ^ 1].nodes[b];
    const Vec3 e = nb.p - na.p;
    const double len = e.norm();
    if (len < same_) return false;
    const Vec3 u = e / len;
    // Each end in its own tree's direction of travel: a leaves along u, b along −u.
    if (taken(na, u) > na.run || taken(nb, -u) > nb.run) return false;
    const double ta = corner_tangent(na.h, u, req_.bend_radius), tb = corner_tangent(nb.h, -u, req_.bend_radius);
    // b's corner seen in a's direction of travel has the opposite normal.
    const double slack = leg_slack(corner_normal(na.h, u), -corner_normal(nb.h, -u), req_.bend_radius);
    if (ta + tb + slack > len) return false;
    if (index_.segment_within(na.p, nb.p, req_.required)) return false;
    return corner_arc_clear(index_, na.p, na.h, u, req_.bend_radius, req_.required) &&
           corner_arc_clear(index_, nb.p, -u, -nb.h, req_.bend_radius, req_.required);
  }

  /// Vertices from the start root to node a of the start tree, then from node b of the goal
  /// tree to its root.
  std::vector<Vec3> path_of(int a, int b) const {
    std::vector<Vec3> out;
    for (int i = a; i >= 0; i = trees_[0].nodes[i].parent) out.push_back(trees_[0].nodes[i].p);
    std::reverse(out.begin(), out.end());
    for (int i = b; i >= 0; i = trees_[1].nodes[i].parent) out.push_back(trees_[1].nodes[i].p);
    return out;
  }

  /// True iff `cand` is bend-feasible and shorter than `len`, and its legs and arcs from
  /// vertex lo to vertex hi (the changed ones) are clear.
  bool better(const std::vector<Vec3>& cand, std::size_t lo, std::size_t hi, double len) const {
    if (arc_line_short_leg(cand, req_.ends, req_.bend_radius).leg >= 0) return false;
    if (!(arc_line_length(cand, req_.ends, req_.bend_radius) < len)) return false;
    for (std::size_t k = lo; k < hi; ++k)
      if (index_.segment_within(cand[k], cand[k + 1], req_.required)) return false;
    return arcs_clear(index_, cand, req_.ends, req_.bend_radius, req_.required, lo, hi);
  }

  /// Random shortcuts between two points along the path, corners pulled towards their
  /// neighbours, then every vertex left out in turn; returns how many changes were kept.
  std::uint64_t shorten(std::vector<Vec3>& path) {
    std::uint64_t kept = 0;
    for (int round = 0; round < req_.shortcut_rounds && path.size() > 2; ++round) {
      std::vector<double> acc{0.0};
      for (std::size_t i = 0; i + 1 < path.size(); ++i) acc.push_back(acc.back() + (path[i + 1] - path[i]).norm());
      double s1 = rng_.uniformReal(0.0, acc.back()), s2 = rng_.uniformReal(0.0, acc.back());
      if (s1 > s2) std::swap(s1, s2);
      // The edges holding s1 and s2.
      auto edge_at = [&](double x) {
        const auto k = std::upper_bound(acc.begin(), acc.end(), x) - acc.begin() - 1;
        return std::min<std::size_t>(static_cast<std::size_t>(std::max<long>(k, 0)), path.size() - 2);
      };
      const std::size_t i = edge_at(s1), j = edge_at(s2);
      if (i == j) continue;
      auto at = [&](std::size_t k, double s) {
        const double l = acc[k + 1] - acc[k];
        return Vec3(path[k] + (l > 0.0 ? (s - acc[k]) / l : 0.0) * (path[k + 1] - path[k]));
      };
      std::vector<Vec3> cand(path.begin(), path.begin() + static_cast<long>(i) + 1);
      const Vec3 x = at(i, s1), y = at(j, s2);
      const bool new_x = (x - path[i]).norm() > same_ && (x - path[i + 1]).norm() > same_;
      const bool new_y = (y - path[j + 1]).norm() > same_ && (y - path[j]).norm() > same_;
      if (new_x) cand.push_back(x);
      const std::size_t lo = cand.size() - 1;
      if (new_y) cand.push_back(y);
      cand.insert(cand.end(), path.begin() + static_cast<long>(j) + 1, path.end());
      if (better(cand, lo, lo + 1, arc_line_length(path, req_.ends, req_.bend_radius))) {
        path = std::move(cand);
        ++kept;
      }
    }
    // Pull each corner towards the midpoint of its neighbours while that shortens the route:
    // shortcuts cut corners, this moves them (a detour a shortcut cannot cross).
    for (int sweep = 0; sweep < kRelaxSweeps; ++sweep) {
      bool moved = false;
      for (std::size_t k = 1; k + 1 < path.size(); ++k)
        for (double a : {0.5, 0.125}) {
          std::vector<Vec3> cand = path;
          cand[k] += a * (0.5 * (path[k - 1] + path[k + 1]) - path[k]);
          if (better(cand, k - 1, k + 1, arc_line_length(path, req_.ends, req_.bend_radius))) {
            path = std::move(cand);
            moved = true;
            ++kept;
            break;
          }
        }
      if (!moved) break;
    }
    for (std::size_t k = 1; k + 1 < path.size();) {
      std::vector<Vec3> cand = path;
      cand.erase(cand.begin() + static_cast<long>(k));
      if (better(cand, k - 1, k, arc_line_length(path, req_.ends, req_.bend_radius))) {
        path = std::move(cand);
        ++kept;
      } else {
        ++k;
      }
    }
    return kept;
  }

  void finish_failure(BendPlanResult& res) const {
    res.status = BendPlanStatus::NoPath;
    res.message = "no bend-feasible route (bend radius " + full_precision(req_.bend_radius) + ") within " +
                  std::to_string(res.iterations) + " samples" + (res.time_limited ? " (time limit)" : "");
    if (req_.hint.size() >= 2) {
      res.tightest = arc_line_short_leg(req_.hint, req_.ends, req_.bend_radius);
      if (res.tightest.leg >= 0)
        res.message += "; the corridor found turns at " + full_precision(res.tightest.at) + " where its legs hold " +
                       full_precision(res.tightest.length) + " of the " + full_precision(res.tightest.needed) +
                       " of straight run the arcs need";
    }
  }

  const ObstacleIndex& index_;
  const BendPlanRequest& req_;
  ompl::RNG rng_;
  Tree trees_[2];  ///< grown from the start, from the goal
  double step_ = 0.0, same_ = 0.0, width_ = 0.0;
  double slack_ = 0.0;  ///< the most leg_slack can be (kInnerLegSlack bend radii)
  std::vector<double> hint_len_;
  double hint_total_ = 0.0;
};

}  // namespace

BendPlanResult plan_bend_feasible(const ObstacleIndex& index, const BendPlanRequest& request) {
  if (!(request.required > 0.0) || !std::isfinite(request.required))
    throw std::invalid_argument("plan_bend_feasible: the required distance must be positive and finite");
  if (!(request.bend_radius > 0.0) || !std::isfinite(request.bend_radius))
    throw std::invalid_argument("plan_bend_feasible: the bend radius must be positive and finite");
  if ((request.goal - request.start).norm() <= kBendPlanSamePoint * request.required)
    throw std::invalid_argument("plan_bend_feasible: the two ends coincide");
  return Planner(index, request).run();
}

bool arcs_fit(const ObstacleIndex& index, const std::vector<Vec3>& v, const ArcLineEnds& ends, double bend_radius,
              double required) {
  if (v.empty() || arc_line_short_leg(v, ends, bend_radius).leg >= 0) return false;
  return arcs_clear(index, v, ends, bend_radius, required, 0, v.size() - 1);
}

}  // namespace loom
