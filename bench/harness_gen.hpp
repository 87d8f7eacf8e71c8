#pragma once
/// Generated harnesses shaped like real ones (the harness-audit bench, and the bundle-level
/// audit tests): a main trunk of branch points along a gently curving spine, side branches
/// leaving it square and splitting further, ports at the leaves, wires between random ports
/// 1–5 m apart along the tree with automotive diameters (bend radius 3·d), and optionally a
/// structure of parts around it: brackets under the trunk (one touching it, some within the
/// clearance band) and scattered volumes. World frame, mm, fixed seeds.
#include "bench/audit_scenes.hpp"
#include "core/harness.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>
#include <random>
#include <string>
#include <utility>
#include <vector>

namespace loom::bench {

/// What to generate.
struct HarnessShape {
  int spine_branches = 40;  ///< branch points on the trunk
  int side_branches = 20;   ///< further branch points in the side trees
  int wires = 250;
  /// Segments meeting at a dense trunk branch point (≥ 3): the trunk's two and
  /// max_degree − 2 side trees rolled around it.
  int max_degree = 16;
  /// Every dense_every-th trunk branch point (from the fifth, or the middle of a shorter
  /// trunk) is dense; the others carry one side tree.
  int dense_every = 10;
  double spacing = 60.0;    ///< trunk length between branch points, mm
  double min_wire = 1000.0, max_wire = 5000.0;  ///< wire length along the tree, mm
  unsigned seed = 1;
};

/// A generated harness and what it is made of.
struct GeneratedHarness {
  Harness harness;
  int most_wires_per_segment = 0;  ///< the fullest trunk segment's wire count
  double length = 0.0;             ///< sum of the wires' tree-path lengths, mm
};

namespace detail {

/// Unit vectors u, v with (t, u, v) orthonormal.
inline std::pair<Vec3, Vec3> frame_of(const Vec3& t) {
  const Vec3 a = std::abs(t.z()) < 0.9 ? Vec3::UnitZ() : Vec3::UnitX();
  const Vec3 u = t.cross(a).normalized();
  return {u, t.cross(u).normalized()};
}

/// The tree as it is grown: node positions, ports, and segments with their key points.
struct Tree {
  Harness h;
  std::vector<Vec3> pos;                          ///< per node (ports and branches, by node id below)
  std::vector<std::string> id;
  std::vector<bool> port;
  std::vector<std::vector<std::pair<int, int>>> adj;  ///< (neighbour, segment)
  std::vector<double> seg_len;                    ///< polyline length of each segment's key points

  int add_node(const Vec3& p, bool is_port, const Vec3& exit_dir = Vec3::UnitX()) {
    const int n = static_cast<int>(pos.size());
    pos.push_back(p);
    port.push_back(is_port);
    adj.emplace_back();
    if (is_port) {
      id.push_back("P" + std::to_string(h.ports.size()));
      Port q;
      q.id = id.back();
      q.position = p;
      q.direction = exit_dir.normalized();
      h.ports.push_back(q);
    } else {
      id.push_back("B" + std::to_string(h.branches.size()));
      BranchPoint b;
      b.id = id.back();
      b.position = p;
      h.branches.push_back(b);
    }
    return n;
  }
  void add_segment(int a, int b, std::vector<Vec3> path) {
    Segment s;
    s.from = id[a];
    s.to = id[b];
    double len = 0.0;
    Vec3 prev = pos[a];
    for (const Vec3& q : path) {
      len += (q - prev).norm();
      prev = q;
    }
    len += (pos[b] - prev).norm();
    s.path = std::move(path);
    const int k = static_cast<int>(h.segments.size());
    h.segments.push_back(std::move(s));
    seg_len.push_back(len);
    adj[a].emplace_back(b, k);
    adj[b].emplace_back(a, k);
  }
};

/// The trunk's centreline at x: a gentle 3D wave (bend radii of metres).
inline Vec3 spine_at(double x) { return {x, 40.0 * std::sin(x / 300.0), 30.0 * std::sin(x / 430.0 + 1.0)}; }
inline Vec3 spine_tangent(double x) {
  return Vec3(1.0, 40.0 / 300.0 * std::cos(x / 300.0), 30.0 / 430.0 * std::cos(x / 430.0 + 1.0)).normalized();
}

/// Levels of branch points in a side tree.
constexpr int kMaxSideDepth = 3;

/// Grows a side tree from node `from` along `dir` (angle `ang` from the side's first
/// direction `u0` in the plane of u0 and w, w ⊥ the trunk): a branch point while `pool`
/// lasts (its children ±45° off, so that every turn through it is at most 90°, and no
/// further than 80° from u0: the side tree stays in its slab across the trunk), else a port.
inline void grow(Tree& t, std::mt19937& rng, int from, const Vec3& u0, const Vec3& w, double ang, int depth,
                 int& pool) {
  std::uniform_real_distribution<double> U(0, 1);
  const Vec3 dir = std::cos(ang) * u0 + std::sin(ang) * w;
  const double len = 120.0 + 280.0 * U(rng);
  const Vec3 a = t.pos[from];
  const Vec3 end = a + len * dir;
  // Leaves along dir for 15 mm (the breakout), then bows gently sideways.
  const Vec3 side = dir.cross(u0.cross(w)).normalized();
  const std::vector<Vec3> path{a + 15.0 * dir, a + 0.55 * len * dir + 0.06 * len * (U(rng) - 0.5) * side};
  const bool branch = pool > 0 && depth < kMaxSideDepth && U(rng) < 0.7;
  const int n = t.add_node(end, !branch, -dir);
  t.add_segment(from, n, path);
  if (!branch) return;
  --pool;
  const int children = U(rng) < 0.3 ? 3 : 2;
  for (int c = 0; c < children; ++c) {
    const double off = children == 1 ? 0.0 : -M_PI / 4 + (M_PI / 2) * c / (children - 1);
    grow(t, rng, n, u0, w, std::clamp(ang + off, -80.0 * M_PI / 180, 80.0 * M_PI / 180), depth + 1, pool);
  }
}

}  // namespace detail

/// A harness of `shape`: the trunk of shape.spine_branches branch points from a port at
/// x = 0 to one at its far end, each branch point with one side tree, or max_degree − 2 at
/// a dense one (square to the trunk, rolled by the golden angle from one to the next and
/// evenly around it), side trees splitting in two or three while shape.side_branches lasts, wires between random port pairs whose tree
/// path is within [min_wire, max_wire] (any pair when too few are).
inline GeneratedHarness generate_harness(const HarnessShape& shape) {
  std::mt19937 rng(shape.seed);
  std::uniform_real_distribution<double> U(0, 1);
  detail::Tree t;
  t.h.name = "generated";
  const int K = shape.spine_branches;
  std::vector<int> spine{t.add_node(detail::spine_at(0.0), true, detail::spine_tangent(0.0))};
  std::vector<double> xs{0.0};
  for (int k = 0; k <= K; ++k) {
    const double x = shape.spacing * (k + 1) + (k < K ? 0.2 * shape.spacing * (U(rng) - 0.5) : 0.0);
    const bool last = k == K;
    const int n = t.add_node(detail::spine_at(x), last, -detail::spine_tangent(x));
    const double xm = 0.5 * (xs.back() + x);
    t.add_segment(spine.back(), n, {detail::spine_at(xm)});
    spine.push_back(n);
    xs.push_back(x);
  }
  int pool = shape.side_branches;
  const int max_deg = std::max(3, shape.max_degree);
  for (int k = 1; k <= K; ++k) {
    const Vec3 tan = detail::spine_tangent(xs[k]);
    const auto [e1, e2] = detail::frame_of(tan);
    const int first_dense = std::min(5, (K + 1) / 2);
    const bool dense = shape.dense_every > 0 && k >= first_dense && (k - first_dense) % shape.dense_every == 0;
    const int sides = dense ? max_deg - 2 : 1;
    for (int j = 0; j < sides; ++j) {
      const double roll = 2.399963 * k + 2.0 * M_PI * j / sides;
      const Vec3 u0 = std::cos(roll) * e1 + std::sin(roll) * e2;
      // A dense point's side trees end at once (a connector cluster): split, their legs
      // would fan into each other's wedges.
      detail::grow(t, rng, spine[k], u0, tan.cross(u0).normalized(), 0.0, dense ? detail::kMaxSideDepth : 0, pool);
    }
  }
  // Tree paths between ports: distances from every port (a BFS per port over the tree).
  std::vector<int> ports;
  for (std::size_t n = 0; n < t.pos.size(); ++n)
    if (t.port[n]) ports.push_back(static_cast<int>(n));
  const std::size_t N = t.pos.size();
  std::vector<std::vector<double>> dist(ports.size(), std::vector<double>(N, -1.0));
  for (std::size_t i = 0; i < ports.size(); ++i) {
    std::queue<int> q;
    q.push(ports[i]);
    dist[i][static_cast<std::size_t>(ports[i])] = 0.0;
    while (!q.empty()) {
      const int a = q.front();
      q.pop();
      for (const auto& [b, s] : t.adj[static_cast<std::size_t>(a)])
        if (dist[i][static_cast<std::size_t>(b)] < 0.0) {
          dist[i][static_cast<std::size_t>(b)] = dist[i][static_cast<std::size_t>(a)] + t.seg_len[static_cast<std::size_t>(s)];
          q.push(b);
        }
    }
  }
  std::vector<std::pair<int, int>> fit;
  for (std::size_t i = 0; i < ports.size(); ++i)
    for (std::size_t j = i + 1; j < ports.size(); ++j) {
      const double d = dist[i][static_cast<std::size_t>(ports[j])];
      if (d >= shape.min_wire && d <= shape.max_wire) fit.emplace_back(static_cast<int>(i), static_cast<int>(j));
    }
  if (fit.empty())
    for (std::size_t i = 0; i < ports.size(); ++i)
      for (std::size_t j = i + 1; j < ports.size(); ++j) fit.emplace_back(static_cast<int>(i), static_cast<int>(j));
  const double diameters[] = {1.2, 1.2, 1.4, 1.4, 1.6, 1.9, 2.2, 2.6, 3.0};
  GeneratedHarness g;
  for (int w = 0; w < shape.wires; ++w) {
    auto [i, j] = fit[static_cast<std::size_t>(U(rng) * fit.size()) % fit.size()];
    if (U(rng) < 0.5) std::swap(i, j);  // both directions along the trunk
    Cable c;
    c.id = "W" + std::to_string(w);
    c.ports[0] = t.id[static_cast<std::size_t>(ports[static_cast<std::size_t>(i)])];
    c.ports[1] = t.id[static_cast<std::size_t>(ports[static_cast<std::size_t>(j)])];
    c.physical.type = "FLRY";
    c.physical.color = "black";
    c.physical.diameter = diameters[static_cast<std::size_t>(U(rng) * 9) % 9];
    c.physical.min_bend_radius = 3.0 * c.physical.diameter;
    g.length += dist[static_cast<std::size_t>(std::min(i, j))][static_cast<std::size_t>(ports[static_cast<std::size_t>(std::max(i, j))])];
    t.h.cables.push_back(c);
  }
  g.harness = std::move(t.h);
  return g;
}

/// Distance from p to the polylines through each segment's ends and key points (the
/// routes bow off them by a few mm at most).
inline double distance_to_routes(const Harness& h, const Vec3& p) {
  double best = std::numeric_limits<double>::infinity();
  for (const Segment& s : h.segments) {
    std::vector<Vec3> pts{*h.node_position(s.from)};
    pts.insert(pts.end(), s.path.begin(), s.path.end());
    pts.push_back(*h.node_position(s.to));
    for (std::size_t k = 0; k + 1 < pts.size(); ++k) {
      const Vec3 d = pts[k + 1] - pts[k];
      const double t = std::clamp((p - pts[k]).dot(d) / std::max(d.squaredNorm(), 1e-300), 0.0, 1.0);
      best = std::min(best, (pts[k] + t * d - p).norm());
    }
  }
  return best;
}

/// Parts around a generated harness: `n_parts` closed parts of ~`tris_per_part` triangles —
/// an eighth of them brackets under the trunk (the first touching it, the rest 2–10 mm
/// below its axis), and spheres, drums and rods scattered in the harness's box grown by
/// 300 mm, each placed (50 tries) with its bounding sphere at least `standoff` mm from
/// the routes: structure close by, as a routed harness has it.
inline std::vector<Part> harness_structure(const Harness& h, int n_parts, int tris_per_part, unsigned seed,
                                           double standoff = 10.0) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(0, 1);
  AABB box;
  for (const Port& p : h.ports) box.extend(p.position);
  for (const BranchPoint& b : h.branches) box.extend(*b.position);
  box = box.inflated(300.0);
  std::vector<Part> parts;
  const int n = std::max(4, static_cast<int>(std::sqrt(tris_per_part / 2.0)));
  const Vec3 span = box.size();
  const double x_end = h.ports.size() > 1 ? h.ports[1].position.x() : 0.0;  // the trunk's far port
  for (int i = 0; i < n_parts; ++i) {
    Part p;
    p.closed = true;
    Eigen::Affine3d tr = Eigen::Affine3d::Identity();
    Mesh m;
    const bool bracket = i < n_parts / 8 && x_end > 0.0;
    if (bracket) {
      // A flat drum 40 mm across under the trunk, its top 0.3 mm (the first: every wire of
      // the trunk touches it) or 2–10 mm below the trunk's axis.
      const double x = x_end * (i + 0.5) / (n_parts / 8);
      const double gap = i == 0 ? 0.3 : 2.0 + 8.0 * U(rng);
      const Vec3 c = detail::spine_at(x) - Vec3(0, 0, gap + 6.0);
      m = cylinder(n, std::max(1, n / 2));
      tr.translate(c);
      tr.scale(Vec3(20.0, 20.0, 6.0));
      p.name = "bracket-" + std::to_string(i);
    } else {
      const int kind = i % 3;
      m = kind == 0 ? uv_sphere(n, n) : cylinder(n, std::max(1, n / 2));
      for (int attempt = 0; attempt < 50; ++attempt) {
        const Vec3 at = box.min + Vec3(U(rng) * span.x(), U(rng) * span.y(), U(rng) * span.z());
        const Vec3 axis = Vec3(U(rng) - 0.5, U(rng) - 0.5, U(rng) - 0.5).normalized();
        const double angle = U(rng) * M_PI;
        const Vec3 scale = kind == 0   ? Vec3(10 + 30 * U(rng), 10 + 30 * U(rng), 10 + 30 * U(rng))
                           : kind == 1 ? Vec3(3 + 6 * U(rng), 3 + 6 * U(rng), 60 + 200 * U(rng))
                                       : Vec3(15 + 30 * U(rng), 15 + 30 * U(rng), 10 + 40 * U(rng));
        tr = Eigen::Affine3d::Identity();
        tr.translate(at);
        tr.rotate(Eigen::AngleAxisd(angle, axis));
        tr.scale(scale);
        // The unit sphere and cylinder lie within 1.5 of the origin.
        if (distance_to_routes(h, at) > 1.5 * scale.maxCoeff() + standoff) break;
      }
      p.name = "part-" + std::to_string(i);
    }
    m.transform(tr);
    p.mesh = std::move(m);
    parts.push_back(std::move(p));
  }
  return parts;
}

}  // namespace loom::bench
