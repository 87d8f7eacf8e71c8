// Route quality against an independent reference on scenes shaped like the hard ones: an
// open room with pillars, an enclosed corridor with four 90° turns 4 tube diameters wide, a
// bug trap (start inside a box whose only way out is a slot 3 diameters wide), and Y and
// 5-way harnesses with the branch point left to the router. The reference is a grid
// shortest path (26-connected, spacing d, d/2 in the corridor and the trap) over the cells whose exact Embree distance
// clears the tube by the clearance plus the cell's half diagonal (so every grid edge is
// clear), string-pulled with exact segment checks; for a harness, the hub cell that
// minimises the sum of the legs' grid distances, each leg string-pulled. loom routes each
// scene with the defaults a user gets (portfolio planner, 5 s cap per plan) for several
// seeds; per (scene, seed): routed, clashes, bend violations, length / reference, plan time.
// Writes bench/results/route_reference.csv and route_reference.png.
//
//   bench_route_reference [SEEDS] [SCENE]   (default 4 seeds, every scene; with SCENE the CSV is
//   not written)
//   bench_route_reference --chart           (redraws the chart from the CSV)
#include "box_mesh.hpp"
#include "core/stopwatch.hpp"
#include "index/embree_index.hpp"
#include "routing/route/route_pipeline.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <queue>
#include <string>
#include <vector>

using namespace loom;

namespace {

constexpr double kDiameter = 8.0;              ///< mm
constexpr double kBendRadius = 3.0 * kDiameter;  ///< mm
constexpr double kClearance = 1.0;             ///< mm
constexpr double kTimeLimit = 5.0;             ///< s per plan (the issue's cap)

/// One bench scene: its parts and harness, and the terminals of the reference.
struct Case {
  std::string name;
  Scene scene;
  std::vector<std::string> terminals;  ///< ports; 2: a path, more: a star through one hub
  double grid = kDiameter;             ///< the reference's grid spacing (d/2 where space is tight)
};

Part block(const std::string& name, const Vec3& lo, const Vec3& hi) {
  Part p;
  p.name = name;
  p.mesh = bench::box_mesh(lo, hi);
  p.closed = true;
  return p;
}

Scene base_scene(const std::string& name) {
  Scene sc;
  sc.name = name;
  sc.has_harness = true;
  sc.harness.name = name;
  sc.routing.clearance = {kClearance, "bench"};
  sc.routing.time_limit = {kTimeLimit, "bench"};
  sc.simplify.dim_pre = {kDiameter, "bench"};
  return sc;
}

void add_port(Scene& sc, const std::string& id, const Vec3& at, const Vec3& dir) {
  Port p;
  p.id = id;
  p.position = at;
  p.direction = dir.normalized();
  sc.harness.ports.push_back(p);
}

void add_cable(Scene& sc, const std::string& id, const std::string& a, const std::string& b) {
  Cable c;
  c.id = id;
  c.ports[0] = a;
  c.ports[1] = b;
  c.physical.diameter = kDiameter;
  c.physical.min_bend_radius = kBendRadius;
  sc.harness.cables.push_back(c);
}

void add_segment(Scene& sc, const std::string& from, const std::string& to) {
  Segment s;
  s.from = from;
  s.to = to;
  sc.harness.segments.push_back(s);
}

/// A room 1200 × 800 × 400 with pillars across the straight line; one cable across.
Case open_room() {
  Case c{"open-room", base_scene("open-room"), {"A", "B"}};
  c.scene.parts.push_back(block("floor", {-50, -50, -60}, {1250, 850, -50}));
  for (int i = 0; i < 4; ++i) {
    const double x = 250.0 + 220.0 * i, y = i % 2 == 0 ? 250.0 : 330.0;
    c.scene.parts.push_back(block("pillar-" + std::to_string(i), {x, y, -50}, {x + 80, y + 240, 400}));
  }
  add_port(c.scene, "A", {0, 400, 150}, {1, 0, 0});
  add_port(c.scene, "B", {1200, 400, 150}, {-1, 0, 0});
  add_cable(c.scene, "C1", "A", "B");
  add_segment(c.scene, "A", "B");
  return c;
}

/// An enclosed corridor 4 d wide and 4 d high, S-shaped with four 90° turns, carved from a
/// plan of cells 4 d on a side: walls are the blocked cells, with a floor and a ceiling.
Case corridor() {
  Case c{"corridor-4d", base_scene("corridor-4d"), {"A", "B"}, 0.5 * kDiameter};
  const double w = 4.0 * kDiameter, h = 4.0 * kDiameter;
  // A 7 × 7 plan, its top row first ('#' blocked, ' ' free): from the bottom of column 5,
  // left along row 2, up column 1, right along row 4, to the top of column 5 — four
  // right-angle turns — closed all round by a ring of blocked cells. The ports sit in the
  // two end cells, facing along the corridor, two cells before the first turn (room for
  // the port's straight exit and a bend radius of 3 d).
  const char* plan[7] = {"##### #", "##### #", "#     #", "# #####", "#     #", "##### #", "##### #"};
  const int nx = 7, ny = 7;
  for (int j = -1; j <= ny; ++j)
    for (int i = -1; i <= nx; ++i) {
      const bool inside = i >= 0 && j >= 0 && i < nx && j < ny;
      const bool blocked = !inside || plan[ny - 1 - j][i] == '#';
      if (blocked)
        c.scene.parts.push_back(block("wall-" + std::to_string(i + 1) + "-" + std::to_string(j + 1),
                                      {i * w, j * w, 0}, {(i + 1) * w, (j + 1) * w, h}));
    }
  c.scene.parts.push_back(block("floor", {-w, -w, -10}, {(nx + 1) * w, (ny + 1) * w, 0}));
  c.scene.parts.push_back(block("ceiling", {-w, -w, h}, {(nx + 1) * w, (ny + 1) * w, h + 10}));
  add_port(c.scene, "A", {5.5 * w, 0.5 * w, 0.5 * h}, {0, 1, 0});
  add_port(c.scene, "B", {5.5 * w, (ny - 0.5) * w, 0.5 * h}, {0, -1, 0});
  add_cable(c.scene, "C1", "A", "B");
  add_segment(c.scene, "A", "B");
  return c;
}

/// A closed box 300 × 300 × 200 (walls 10 thick) with one slot 3 d wide in the face away
/// from the goal: the cable starts inside, facing the goal, and must turn back to get out.
Case bug_trap() {
  Case c{"bug-trap", base_scene("bug-trap"), {"A", "B"}, 0.5 * kDiameter};
  const double t = 10.0, s = 1.5 * kDiameter;  // half the slot width
  auto& parts = c.scene.parts;
  parts.push_back(block("trap-front", {300 - t, 0, 0}, {300, 300, 200}));  // faces the goal
  parts.push_back(block("trap-y0", {t, 0, 0}, {300 - t, t, 200}));
  parts.push_back(block("trap-y1", {t, 300 - t, 0}, {300 - t, 300, 200}));
  parts.push_back(block("trap-z0", {t, t, 0}, {300 - t, 300 - t, t}));
  parts.push_back(block("trap-z1", {t, t, 200 - t}, {300 - t, 300 - t, 200}));
  // The back face, with the slot at mid height across y.
  parts.push_back(block("trap-back-low", {0, 0, 0}, {t, 300, 100 - s}));
  parts.push_back(block("trap-back-high", {0, 0, 100 + s}, {t, 300, 200}));
  add_port(c.scene, "A", {200, 150, 100}, {1, 0, 0});
  add_port(c.scene, "B", {600, 150, 100}, {-1, 0, 0});
  add_cable(c.scene, "C1", "A", "B");
  add_segment(c.scene, "A", "B");
  return c;
}

/// A star harness in a room with a block in the middle: `legs` ports on a circle, facing
/// inwards, every cable from the first port to one of the others, the hub left to the router.
Case star(const std::string& name, int legs) {
  Case c{name, base_scene(name), {}};
  c.scene.parts.push_back(block("floor", {-450, -450, -60}, {450, 450, -50}));
  c.scene.parts.push_back(block("block", {-60, -60, -50}, {60, 60, 300}));
  BranchPoint hub;
  hub.id = "H";
  c.scene.harness.branches.push_back(hub);
  for (int k = 0; k < legs; ++k) {
    const double a = 2.0 * M_PI * k / legs;
    const Vec3 at(400.0 * std::cos(a), 400.0 * std::sin(a), 100.0);
    const std::string id = "P" + std::to_string(k);
    add_port(c.scene, id, at, -at.normalized());
    add_segment(c.scene, id, "H");
    c.terminals.push_back(id);
    if (k > 0) add_cable(c.scene, "C" + std::to_string(k), "P0", id);
  }
  return c;
}

// --- the reference ---------------------------------------------------------------------

/// The free cells of a grid over the scene and shortest distances on it.
class Grid {
 public:
  Grid(const EmbreeIndex& index, const AABB& box, double h, double required) : index_(index), h_(h) {
    lo_ = box.min;
    for (int a = 0; a < 3; ++a) n_[a] = std::max(1, static_cast<int>(std::ceil((box.max[a] - box.min[a]) / h)) + 1);
    free_.assign(static_cast<std::size_t>(n_[0]) * n_[1] * n_[2], 0);
    // A cell is free when its centre clears every part by the tube's requirement plus half a
    // cell diagonal: then every grid edge (at most a diagonal long) is clear as well.
    const double need = required + 0.5 * std::sqrt(3.0) * h;
    for (std::size_t i = 0; i < free_.size(); ++i) {
      const Vec3 p = at(i);
      free_[i] = !index_.any_within(p, need) && !index_.inside(p);
    }
  }
  /// Grid distances (scene units) from the cell nearest p, Dijkstra on 26 neighbours.
  std::vector<double> distances(const Vec3& p) const {
    std::vector<double> d(free_.size(), kInf);
    const std::size_t s = nearest_free(p);
    if (s == kNone) return d;
    using Item = std::pair<double, std::size_t>;
    std::priority_queue<Item, std::vector<Item>, std::greater<Item>> q;
    d[s] = 0.0;
    q.push({0.0, s});
    while (!q.empty()) {
      const auto [dist, i] = q.top();
      q.pop();
      if (dist > d[i]) continue;
      for_neighbours(i, [&](std::size_t j, double len) {
        if (dist + len < d[j]) {
          d[j] = dist + len;
          q.push({d[j], j});
        }
      });
    }
    return d;
  }
  /// The grid path from p's cell to cell `to` following `d` (distances from p) down.
  std::vector<Vec3> path_to(const std::vector<double>& d, std::size_t to) const {
    std::vector<Vec3> out{at(to)};
    std::size_t i = to;
    while (d[i] > 0.0) {
      std::size_t best = i;
      double best_d = d[i];
      for_neighbours(i, [&](std::size_t j, double len) {
        if (d[j] + len <= d[i] + 1e-9 && d[j] < best_d) best = j, best_d = d[j];
      });
      if (best == i) break;
      i = best;
      out.push_back(at(i));
    }
    std::reverse(out.begin(), out.end());
    return out;
  }
  std::size_t nearest_free(const Vec3& p) const {
    std::size_t best = kNone;
    double bd = kInf;
    const int r = 3;  // the port's own cell may be blocked by the port's part: look around it
    int c[3];
    for (int a = 0; a < 3; ++a) c[a] = static_cast<int>(std::lround((p[a] - lo_[a]) / h_));
    for (int dz = -r; dz <= r; ++dz)
      for (int dy = -r; dy <= r; ++dy)
        for (int dx = -r; dx <= r; ++dx) {
          const int x = c[0] + dx, y = c[1] + dy, z = c[2] + dz;
          if (x < 0 || y < 0 || z < 0 || x >= n_[0] || y >= n_[1] || z >= n_[2]) continue;
          const std::size_t i = index_of(x, y, z);
          const double dd = (at(i) - p).norm();
          if (free_[i] && dd < bd && !index_.segment_within(p, at(i), required_radius_)) bd = dd, best = i;
        }
    return best;
  }
  void set_required(double r) { required_radius_ = r; }
  Vec3 at(std::size_t i) const {
    const std::size_t x = i % n_[0], y = (i / n_[0]) % n_[1], z = i / (static_cast<std::size_t>(n_[0]) * n_[1]);
    return lo_ + h_ * Vec3(static_cast<double>(x), static_cast<double>(y), static_cast<double>(z));
  }
  std::size_t size() const { return free_.size(); }
  bool free(std::size_t i) const { return free_[i] != 0; }

  static constexpr double kInf = std::numeric_limits<double>::infinity();
  static constexpr std::size_t kNone = ~std::size_t(0);

 private:
  std::size_t index_of(int x, int y, int z) const {
    return (static_cast<std::size_t>(z) * n_[1] + static_cast<std::size_t>(y)) * n_[0] + static_cast<std::size_t>(x);
  }
  template <class F>
  void for_neighbours(std::size_t i, F&& f) const {
    const int x = static_cast<int>(i % n_[0]), y = static_cast<int>((i / n_[0]) % n_[1]),
              z = static_cast<int>(i / (static_cast<std::size_t>(n_[0]) * n_[1]));
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          if (!dx && !dy && !dz) continue;
          const int a = x + dx, b = y + dy, c = z + dz;
          if (a < 0 || b < 0 || c < 0 || a >= n_[0] || b >= n_[1] || c >= n_[2]) continue;
          const std::size_t j = index_of(a, b, c);
          if (free_[j]) f(j, h_ * std::sqrt(static_cast<double>(dx * dx + dy * dy + dz * dz)));
        }
  }

  const EmbreeIndex& index_;
  double h_;
  Vec3 lo_;
  int n_[3];
  std::vector<char> free_;
  double required_radius_ = 0.0;
};

/// Length of `path` (from `from`, through its points, to `to`) after string pulling: from
/// each point, the farthest later one a straight segment reaches clear of `required`.
double pulled_length(const EmbreeIndex& index, const Vec3& from, std::vector<Vec3> path, const Vec3& to, double required) {
  path.insert(path.begin(), from);
  path.push_back(to);
  double len = 0.0;
  std::size_t i = 0;
  while (i + 1 < path.size()) {
    std::size_t j = path.size() - 1;
    while (j > i + 1 && index.segment_within(path[i], path[j], required)) --j;
    len += (path[j] - path[i]).norm();
    i = j;
  }
  return len;
}

/// The reference length of a case (scene units), or infinity if the grid finds no way.
double reference_length(const Case& c) {
  const EmbreeIndex index(c.scene.parts);
  const double required = 0.5 * kDiameter + kClearance;
  AABB box = c.scene.bounds();
  box = box.inflated(2.0 * kDiameter);
  Grid grid(index, box, c.grid, required);
  grid.set_required(required);
  std::vector<Vec3> ends;
  std::vector<std::vector<double>> dist;
  for (const std::string& t : c.terminals) {
    ends.push_back(*c.scene.harness.node_position(t));
    dist.push_back(grid.distances(ends.back()));
  }
  if (c.terminals.size() == 2) {
    const std::size_t goal = grid.nearest_free(ends[1]);
    if (goal == Grid::kNone || !std::isfinite(dist[0][goal])) return Grid::kInf;
    return pulled_length(index, ends[0], grid.path_to(dist[0], goal), ends[1], required);
  }
  // A star: the hub cell with the least sum of grid distances, each leg pulled.
  std::size_t hub = Grid::kNone;
  double best = Grid::kInf;
  for (std::size_t i = 0; i < grid.size(); ++i) {
    if (!grid.free(i)) continue;
    double sum = 0.0;
    for (const auto& d : dist) sum += d[i];
    if (sum < best) best = sum, hub = i;
  }
  if (hub == Grid::kNone) return Grid::kInf;
  double len = 0.0;
  for (std::size_t k = 0; k < ends.size(); ++k) {
    std::vector<Vec3> leg = grid.path_to(dist[k], hub);
    const Vec3 h = leg.back();
    leg.pop_back();
    len += pulled_length(index, ends[k], leg, h, required);
  }
  return len;
}

/// Draws route_reference.png from the CSV (gnuplot): length / reference and the longest plan
/// of each (scene, seed), clean pairs filled, the others open.
void chart(const std::string& dir) {
  const std::string gp = dir + "route_reference.gp";
  std::ofstream(gp)
      << "set datafile separator ','\nset terminal pngcairo size 1200,450\nset output '" << dir
      << "route_reference.png'\nset multiplot layout 1,2 title 'Routing hard scenes against a grid shortest path "
         "(4 seeds each; filled: 0 clashes and 0 bend violations)'\nset xtics rotate by 60 right font ',8'\n"
         "set grid\nset key off\nclean(c, b) = (c == 0 && b == 0)\n"
         "set ylabel 'routed length / reference'\n"
         "plot '" << dir << "route_reference.csv' every ::1 using 0:(clean($5, $6) ? $9 : 1/0):xtic(sprintf('%s %d', "
         "strcol(1), $2)) with points pt 7 ps 1.2, '' every ::1 using 0:(clean($5, $6) ? 1/0 : $9) with points pt 6 "
         "ps 1.5, 1.1 with lines dt 2\n"
         "set ylabel 'longest plan of a segment (s)'\n"
         "plot '" << dir << "route_reference.csv' every ::1 using 0:($11 / 1000):xtic(sprintf('%s %d', strcol(1), $2)) "
         "with impulses lw 6, 5 with lines dt 2\nunset multiplot\n";
  const std::string cmd = "gnuplot " + gp + " 2>/dev/null";
  if (std::system(cmd.c_str()) != 0) std::fprintf(stderr, "gnuplot failed (chart not drawn)\n");
  std::filesystem::remove(gp);
}

/// Length of the routed harness: every segment's curve once.
double routed_length(const Harness& h) {
  double len = 0.0;
  for (const Segment& s : h.segments)
    if (s.bspline) len += Centerline(s.bspline->degree, s.bspline->knots, s.bspline->control_points).length();
  return len;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc > 1 && std::string(argv[1]) == "--chart") {  // redraw from the CSV only
    chart(std::string(LOOM_SOURCE_DIR) + "/bench/results/");
    return 0;
  }
  const int seeds = argc > 1 ? std::max(1, std::atoi(argv[1])) : 4;
  std::vector<Case> cases = {open_room(), corridor(), bug_trap(), star("y-harness", 3), star("5-way", 5)};
  const std::string only = argc > 2 ? argv[2] : "";
  if (!only.empty())
    cases.erase(std::remove_if(cases.begin(), cases.end(), [&](const Case& c) { return c.name != only; }), cases.end());
  const std::string path =
      only.empty() ? std::string(LOOM_SOURCE_DIR) + "/bench/results/route_reference.csv" : "/dev/null";
  std::ofstream csv(path);
  csv << "scene,seed,routed,cables,clashes,bend_violations,length_mm,reference_mm,ratio,plan_ms,longest_plan_ms\n";
  int pairs = 0, clean = 0;
  std::vector<double> ratios;
  double longest_plan = 0.0;
  for (const Case& c : cases) {
    const Stopwatch tr;
    const double ref = reference_length(c);
    std::printf("%-12s reference %.1f mm (%.2f s)\n", c.name.c_str(), ref, tr.seconds());
    for (int seed = 1; seed <= seeds; ++seed) {
      Scene scene = c.scene;
      scene.routing.seed = static_cast<unsigned>(seed);
      RouteOptions opt;
      opt.threads = 2;
      const RouteReport rep = route_scene(scene, opt);
      std::size_t clashes = rep.audit.result.clashes.size(), bends = 0;
      for (const auto& v : rep.audit.result.violations) bends += v.kind == ViolationKind::BendRadius;
      double longest = 0.0;
      for (const auto& s : rep.segments) longest = std::max(longest, s.plan.time_ms);
      const std::size_t routed = rep.routed.cables.size() - rep.unrouted.size();
      const double len = routed_length(rep.routed);
      const bool ok = rep.unrouted.empty() && clashes == 0 && bends == 0;
      ++pairs;
      clean += ok;
      if (rep.unrouted.empty()) ratios.push_back(len / ref);
      longest_plan = std::max(longest_plan, longest);
      int bend_plans = 0;
      for (const auto& s : rep.segments) bend_plans += s.bend_plan == "planned";
      std::printf("  seed %d: %zu/%zu routed, %zu clashes, %zu bend violations, %.1f mm = %.3f x reference, plan %.2f s "
                  "(longest segment %.2f s), %d of %zu segments bend-feasibly re-planned%s\n",
                  seed, routed, rep.routed.cables.size(), clashes, bends, len, len / ref, rep.timing.plan / 1000.0,
                  longest / 1000.0, bend_plans, rep.segments.size(), ok ? "" : "  <-");
      for (const auto& u : rep.unrouted) std::printf("    not routed %s: %s\n", u.cable.c_str(), u.message.c_str());
      if (bends > 0)
        for (const auto& sg : rep.segments)
          if (!sg.bend_status.empty())
            std::printf("    segment %d: bend %s%s%s\n", sg.segment, sg.bend_status.c_str(),
                        sg.bend_plan.empty() ? "" : "; bend-feasible plan ", sg.bend_plan.c_str());
      csv << c.name << ',' << seed << ',' << routed << ',' << rep.routed.cables.size() << ',' << clashes << ','
          << bends << ',' << len << ',' << ref << ',' << len / ref << ',' << rep.timing.plan << ',' << longest << '\n';
      csv.flush();
    }
  }
  std::sort(ratios.begin(), ratios.end());
  const double median = ratios.empty() ? 0.0 : ratios[ratios.size() / 2];
  std::printf("%d/%d (scene, seed) pairs routed clean (%.0f%%); median length %.3f x reference; longest plan %.2f s\n",
              clean, pairs, 100.0 * clean / pairs, median, longest_plan / 1000.0);
  std::printf("wrote %s\n", path.c_str());
  if (only.empty()) {
    csv.close();
    chart(std::string(LOOM_SOURCE_DIR) + "/bench/results/");
  }
  return 0;
}
