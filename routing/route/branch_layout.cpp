#include "routing/route/branch_layout.hpp"

#include "core/error.hpp"
#include "routing/curve/cable_geometry.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

namespace loom {

namespace {

/// Weiszfeld iterations for the geometric median of the neighbours.
constexpr int kWeiszfeldIterations = 100;
/// Moving a branch point clear: shells tried, each one required clearance further out.
constexpr int kClearShells = 40;
/// Separating branch points: shells tried, each a quarter of the gap needed further out.
constexpr int kSeparateShells = 40;
/// Compass search: sweeps over a chain of unplaced points, and evaluations per point.
constexpr int kCompassSweeps = 3;
constexpr int kCompassMaxSteps = 400;
/// The compass step starts at this share of the mean leg length and stops below this
/// share of the branch's clearance (finer than that changes nothing a cable can feel).
constexpr double kCompassStartShare = 0.25;
constexpr double kCompassStopShare = 0.01;
/// Rounds of pairwise opening of exit directions at a node without a main line.
constexpr int kOpenRounds = 32;
/// Directions tried for an exit whose run is blocked (≈ 6° apart over the sphere).
constexpr int kExitCandidates = 1024;
/// Least angle between two exits of one node that share no cables (radians).
constexpr double kMinExitGap = M_PI / 6.0;
/// Turns are clamped below a full reversal so that tan(θ/2) stays finite.
constexpr double kMaxTurn = M_PI * (179.0 / 180.0);

/// Directions on the unit sphere: the 26 neighbours of a cube cell, normalised.
const std::vector<Vec3>& shell_directions() {
  static const std::vector<Vec3> d = [] {
    std::vector<Vec3> v;
    for (int x = -1; x <= 1; ++x)
      for (int y = -1; y <= 1; ++y)
        for (int z = -1; z <= 1; ++z)
          if (x || y || z) v.push_back(Vec3(x, y, z).normalized());
    return v;
  }();
  return d;
}

double angle_between(const Vec3& a, const Vec3& b) { return std::atan2(a.cross(b).norm(), a.dot(b)); }

/// The node at the other end of `seg` from `node`.
const std::string& other_end(const Segment& sg, const std::string& node) { return sg.from == node ? sg.to : sg.from; }

}  // namespace

std::vector<SegmentEnds> segment_ends(const HarnessTopology& topo,
                                      const std::function<double(double, double)>& port_stub) {
  const Harness& h = topo.harness();
  std::vector<SegmentEnds> out(h.segments.size());
  for (std::size_t s = 0; s < h.segments.size(); ++s) {
    SegmentEnds& e = out[s];
    e.radius = 0.5 * topo.segment_diameter(static_cast<int>(s));
    for (int c : topo.segment_cables(static_cast<int>(s)))
      e.min_bend_radius = std::max(e.min_bend_radius, h.cables[c].physical.min_bend_radius);
    e.port_stub = port_stub(e.radius, e.min_bend_radius);
  }
  return out;
}

std::vector<std::string> place_branch_points(Harness& h, const HarnessTopology& topo, const ObstacleIndex& index,
                                             const std::vector<SegmentEnds>& ends,
                                             const BranchPlacementOptions& opt) {
  std::vector<int> unplaced;
  for (std::size_t b = 0; b < h.branches.size(); ++b)
    if (!h.branches[b].position) unplaced.push_back(static_cast<int>(b));
  std::vector<std::string> placed;
  if (unplaced.empty()) return placed;

  // Start from the mean of the placed neighbours (or of all ports when none is placed).
  Vec3 port_mean = Vec3::Zero();
  for (const auto& p : h.ports) port_mean += p.position;
  if (!h.ports.empty()) port_mean /= static_cast<double>(h.ports.size());
  std::map<int, Vec3> pos;
  for (int b : unplaced) {
    Vec3 sum = Vec3::Zero();
    int n = 0;
    for (int s : topo.incident_segments(h.branches[b].id))
      if (auto p = h.node_position(other_end(h.segments[s], h.branches[b].id))) sum += *p, ++n;
    pos[b] = n ? Vec3(sum / n) : port_mean;
  }
  // Where a leg from branch b along segment s heads: a port neighbour at the end of its
  // exit stub (the cable leaves the connector straight), any other node at its position.
  auto leg_target = [&](int b, int s) -> Vec3 {
    const std::string& id = other_end(h.segments[s], h.branches[b].id);
    if (int p = h.find_port(id); p >= 0) return h.ports[p].position + ends[s].port_stub * h.ports[p].direction;
    if (int o = h.find_branch(id); o >= 0 && !h.branches[o].position) return pos[o];
    return *h.node_position(id);
  };

  // Weiszfeld: each unplaced point moves to the distance-weighted mean of its leg targets;
  // chains of unplaced points converge together (the sum of leg lengths is convex).
  for (int it = 0; it < kWeiszfeldIterations; ++it)
    for (int b : unplaced) {
      Vec3 num = Vec3::Zero();
      double den = 0.0;
      for (int s : topo.incident_segments(h.branches[b].id)) {
        const Vec3 q = leg_target(b, s);
        const double d = std::max((q - pos[b]).norm(), 1e-9);
        num += q / d;
        den += 1.0 / d;
      }
      if (den > 0) pos[b] = num / den;
    }

  // How far apart two branch points must stay: neighbours by both their breakouts (each
  // leaves its node straight for that long before it may bend), any other two by the larger
  // bundle diameter meeting at either (closer, their bundles would overlap).
  std::map<int, double> diameter;
  for (std::size_t b = 0; b < h.branches.size(); ++b)
    for (int s : topo.incident_segments(h.branches[b].id))
      diameter[static_cast<int>(b)] = std::max(diameter[static_cast<int>(b)], 2.0 * ends[s].radius);
  auto min_gap = [&](int b, int o) {
    const std::string &ib = h.branches[b].id, &io = h.branches[o].id;
    double gap = std::max(diameter[b], diameter[o]);
    if (opt.extra_gap) gap = std::max(gap, opt.extra_gap(b, o));
    for (int s : topo.incident_segments(ib))
      if (other_end(h.segments[s], ib) == io)
        return std::max(gap, breakout_length(topo, ib) + breakout_length(topo, io));
    return gap;
  };
  auto branch_at = [&](int o) -> std::optional<Vec3> {
    if (h.branches[o].position) return *h.branches[o].position;
    auto it = pos.find(o);
    return it == pos.end() ? std::nullopt : std::optional<Vec3>(it->second);
  };
  auto separated = [&](int b, const Vec3& q) {
    for (std::size_t o = 0; o < h.branches.size(); ++o) {
      if (static_cast<int>(o) == b) continue;
      const auto at = branch_at(static_cast<int>(o));
      if (at && (q - *at).norm() < min_gap(b, static_cast<int>(o))) return false;
    }
    return true;
  };
  auto is_free = [&](int b, const Vec3& q) { return !index.inside(q) && !index.any_within(q, opt.clearance_of(b)); };
  auto is_clear = [&](int b, const Vec3& q) { return is_free(b, q) && separated(b, q); };
  // The cost of a position: leg lengths plus the bend deficit of every port leg. A port leg
  // runs B → stub end S → port P; at S it turns by θ from (S − B) into the connector axis,
  // and a corner rounded to radius R needs R·tan(θ/2) of straight run on each side: the
  // stub on one side, and on the other the leg minus the breakout run that leaves B.
  auto cost = [&](int b, const Vec3& q) {
    const std::string& id = h.branches[b].id;
    const double breakout = breakout_length(topo, id);
    double c = 0.0;
    for (int s : topo.incident_segments(id)) {
      const Vec3 target = leg_target(b, s);
      const double leg = (target - q).norm();
      c += leg;
      const int p = h.find_port(other_end(h.segments[s], id));
      if (p < 0 || ends[s].min_bend_radius <= 0.0) continue;
      const double turn = std::min(angle_between(target - q, -h.ports[p].direction), kMaxTurn);
      const double need = ends[s].min_bend_radius * std::tan(0.5 * turn);
      c += opt.bend_deficit_weight * (std::max(0.0, need - ends[s].port_stub) + std::max(0.0, need + breakout - leg));
    }
    return c;
  };

  const auto& dirs = shell_directions();
  for (int b : unplaced) {
    // Move clear first: the nearest free point on growing shells, the candidate keeping the
    // legs shortest on the first shell that has one.
    const double need = opt.clearance_of(b);
    Vec3 p = pos[b];
    if (!is_free(b, p)) {
      bool found = false;
      for (int shell = 1; shell <= kClearShells && !found; ++shell) {
        double best = std::numeric_limits<double>::infinity();
        Vec3 best_p = p;
        for (const auto& d : dirs) {
          const Vec3 q = p + d * (need * shell);
          if (!is_free(b, q)) continue;
          double len = 0;
          for (int s : topo.incident_segments(h.branches[b].id)) len += (leg_target(b, s) - q).norm();
          if (len < best) best = len, best_p = q;
        }
        if (std::isfinite(best)) p = best_p, found = true;
      }
      if (!found)
        throw InputError({h.source_file, h.branches[b].line, "branch '" + h.branches[b].id + "'"},
                         "cannot place this branch point clear of the structure near its neighbours");
    }
    pos[b] = p;
  }
  // Router-placed points collapse onto each other (the median of a chain of unplaced points
  // is often shared): move each one that is too near another branch point to the cheapest
  // position clear of the parts and apart from the others, on shells a quarter of the
  // gap it needs apart.
  for (int b : unplaced) {
    if (separated(b, pos[b])) continue;
    double gap = 0.0;
    for (std::size_t o = 0; o < h.branches.size(); ++o)
      if (static_cast<int>(o) != b) gap = std::max(gap, min_gap(b, static_cast<int>(o)));
    const double step = std::max(0.25 * gap, opt.clearance_of(b));
    bool found = false;
    for (int shell = 1; shell <= kSeparateShells && !found; ++shell) {
      double best = std::numeric_limits<double>::infinity();
      Vec3 best_p = pos[b];
      for (const auto& d : dirs) {
        const Vec3 q = pos[b] + d * (step * shell);
        if (!is_clear(b, q)) continue;
        const double c = cost(b, q);
        if (c < best) best = c, best_p = q;
      }
      if (std::isfinite(best)) pos[b] = best_p, found = true;
    }
    if (!found)
      throw InputError({h.source_file, h.branches[b].line, "branch '" + h.branches[b].id + "'"},
                       "cannot place this branch point clear of the structure and apart from the other branch points");
  }
  // Compass search over clear positions: the cost is not smooth (deficits switch on and
  // off) and each evaluation is cheap, so a derivative-free pattern search is the right tool.
  for (int sweep = 0; sweep < kCompassSweeps; ++sweep)
    for (int b : unplaced) {
      Vec3 p = pos[b];
      double mean_leg = 0.0;
      const auto inc = topo.incident_segments(h.branches[b].id);
      for (int s : inc) mean_leg += (leg_target(b, s) - p).norm();
      mean_leg /= std::max<std::size_t>(inc.size(), 1);
      double step = kCompassStartShare * mean_leg;
      const double stop = kCompassStopShare * opt.clearance_of(b);
      double best = cost(b, p);
      for (int k = 0; k < kCompassMaxSteps && step > stop; ++k) {
        Vec3 best_q = p;
        double best_c = best;
        for (const auto& d : dirs) {
          const Vec3 q = p + step * d;
          const double c = cost(b, q);
          if (c < best_c && is_clear(b, q)) best_c = c, best_q = q;
        }
        if (best_c < best) {
          p = best_q;
          best = best_c;
        } else {
          step *= 0.5;
        }
      }
      pos[b] = p;
    }
  for (int b : unplaced) {
    h.branches[b].position = pos[b];
    placed.push_back(h.branches[b].id);
  }
  return placed;
}

namespace {

/// Cables passing through node `id` between each pair of its segments (ordered pair of
/// segment indices → count).
std::map<std::pair<int, int>, int> passes_at(const Harness& h, const HarnessTopology& topo, const std::string& id) {
  std::map<std::pair<int, int>, int> passes;
  for (std::size_t c = 0; c < h.cables.size(); ++c) {
    const auto& chain = topo.cable_chain(static_cast<int>(c));
    for (std::size_t k = 0; k + 1 < chain.size(); ++k) {
      const Segment& sg = h.segments[chain[k].segment];
      const std::string& at = chain[k].reversed ? sg.from : sg.to;
      if (at == id) passes[std::minmax(chain[k].segment, chain[k + 1].segment)]++;
    }
  }
  return passes;
}

/// `n` unit directions spread evenly over the sphere (a Fibonacci lattice), deterministic.
std::vector<Vec3> sphere_directions(int n) {
  std::vector<Vec3> out;
  const double golden = M_PI * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < n; ++i) {
    const double z = 1.0 - (2.0 * i + 1.0) / n, r = std::sqrt(std::max(0.0, 1.0 - z * z));
    out.emplace_back(r * std::cos(golden * i), r * std::sin(golden * i), z);
  }
  return out;
}

}  // namespace

std::map<std::pair<int, bool>, Vec3> branch_exit_directions(const Harness& h, const HarnessTopology& topo,
                                                            const std::vector<SegmentEnds>& ends) {
  std::map<std::pair<int, bool>, Vec3> exit_dir;
  for (const auto& br : h.branches) {
    if (!br.position) continue;
    const Vec3 bp = *br.position;
    const auto inc = topo.incident_segments(br.id);
    // Natural direction of each segment: towards its far end (a port's stub end).
    std::map<int, Vec3> natural;
    for (int s : inc) {
      const std::string& id = other_end(h.segments[s], br.id);
      Vec3 target = *h.node_position(id);
      if (int p = h.find_port(id); p >= 0) target += ends[s].port_stub * h.ports[p].direction;
      const Vec3 d = target - bp;
      natural[s] = d.norm() > 1e-12 ? Vec3(d.normalized()) : Vec3::UnitX();
    }
    std::map<std::pair<int, int>, int> passes = passes_at(h, topo, br.id);
    // The main line: most cables among the pairs that are nearly a straight line; ties go
    // to the straighter pair.
    std::pair<int, int> main{-1, -1};
    int best_passes = -1;
    double best_angle = 0.0;
    for (std::size_t i = 0; i < inc.size(); ++i)
      for (std::size_t j = i + 1; j < inc.size(); ++j) {
        const double a = angle_between(natural[inc[i]], natural[inc[j]]);
        if (a < M_PI - kMaxMainLineTurn) continue;
        const auto key = std::minmax(inc[i], inc[j]);
        const int n = passes.count(key) ? passes[key] : 0;
        if (n > best_passes || (n == best_passes && a > best_angle)) best_passes = n, best_angle = a, main = key;
      }
    std::map<int, Vec3> e = natural;
    if (main.first >= 0) {
      const Vec3 d = (natural[main.first] - natural[main.second]).normalized();
      e[main.first] = d;
      e[main.second] = -d;
    }
    // A cable passing between two segments turns by π minus the angle between their exit
    // directions. Past a right angle the cable folds back on itself at the node (a kink
    // sharper than ~100° is a self-contact by DESIGN §5), so exits of segments that share
    // cables are opened to at least 90°: a side leg is tilted into the plane normal to the
    // main line (a T), two free legs are pushed apart symmetrically.
    auto shares = [&](int a, int b) { return passes.count(std::minmax(a, b)) > 0; };
    auto open_up = [](Vec3& moved, const Vec3& fixed) {
      const double c = moved.dot(fixed);
      if (c <= 0.0) return;
      const Vec3 p = moved - c * fixed;
      moved = p.norm() > 1e-12 ? Vec3(p.normalized()) : fixed.unitOrthogonal();
    };
    for (int k : inc) {
      if (k == main.first || k == main.second) continue;
      for (int m : {main.first, main.second})
        if (m >= 0 && shares(k, m)) open_up(e[k], e[m]);
    }
    // Without a main line, pairs are opened in turn; opening one pair can close another, so
    // repeat. At most six directions can be pairwise ≥ 90° apart (±x, ±y, ±z): at a node of
    // higher degree whose legs all share cables the rounds end with some pairs closer, and
    // the audit judges a cable's turn there as a bend within the breakout (NodeTurn).
    for (int round = 0; main.first < 0 && round < kOpenRounds; ++round) {
      bool changed = false;
      for (std::size_t i = 0; i < inc.size(); ++i)
        for (std::size_t j = i + 1; j < inc.size(); ++j) {
          Vec3& a = e[inc[i]];
          Vec3& b = e[inc[j]];
          if (!shares(inc[i], inc[j]) || a.dot(b) <= 0.0) continue;
          // Rotate both away from their bisector, in their plane, to 90° apart.
          const Vec3 bis = (a + b).normalized();
          Vec3 perp = a - b - (a - b).dot(bis) * bis;
          perp = perp.norm() > 1e-12 ? Vec3(perp.normalized()) : bis.unitOrthogonal();
          a = (bis + perp).normalized();
          b = (bis - perp).normalized();
          changed = true;
        }
      if (!changed) break;
    }
    for (int s : inc) exit_dir[{s, h.segments[s].from == br.id}] = e[s];
  }
  return exit_dir;
}

int free_blocked_exits(const ObstacleIndex& index, const Harness& h, const HarnessTopology& topo,
                       const std::vector<SegmentEnds>& ends, const std::map<std::string, double>& breakout,
                       double clearance, std::map<std::pair<int, bool>, Vec3>& exit_dir) {
  const std::vector<Vec3> candidates = sphere_directions(kExitCandidates);
  int turned = 0;
  for (const auto& br : h.branches) {
    if (!br.position) continue;
    const Vec3 bp = *br.position;
    const auto inc = topo.incident_segments(br.id);
    const auto passes = passes_at(h, topo, br.id);
    const double out = breakout.count(br.id) ? breakout.at(br.id) : 0.0;
    for (int s : inc) {
      const std::pair<int, bool> key{s, h.segments[s].from == br.id};
      Vec3& e = exit_dir.at(key);
      const double required = ends[s].radius + clearance;
      const double run = out + ends[s].min_bend_radius;
      auto free = [&](const Vec3& u) { return !index.segment_within(bp, bp + run * u, required); };
      if (!(run > 0.0) || free(e)) continue;
      // The other exits of this node: those sharing cables with s stay ≥ 90° away, the rest
      // kMinExitGap (two legs leaving along one line would lie in each other's bundle).
      auto apart = [&](const Vec3& u) {
        for (int t : inc) {
          if (t == s) continue;
          const Vec3& o = exit_dir.at({t, h.segments[t].from == br.id});
          const double limit = passes.count(std::minmax(s, t)) ? 0.0 : std::cos(kMinExitGap);
          if (u.dot(o) > limit) return false;
        }
        return true;
      };
      const Vec3* best = nullptr;
      for (const Vec3& u : candidates)
        if ((!best || u.dot(e) > best->dot(e)) && apart(u) && free(u)) best = &u;
      if (!best) continue;
      e = *best;
      ++turned;
    }
  }
  return turned;
}

}  // namespace loom
