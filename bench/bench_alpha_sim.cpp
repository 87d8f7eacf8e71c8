// α-SIM benchmark. Scenario program, fixed seeds, baselines in the same run:
//  1. the bundled wing-section scene and the real meshes at dim_pre = the scene's value
//     (smallest cable diameter) / a fixed fraction of each part's size: triangle ratio,
//     Hausdorff distance, containment, time;
//  2. clearance (closest-point) query speed on the simplified vs the original geometry,
//     both through EmbreeIndex;
//     and for points within 5·dim_pre of the original surface (routing's clearance queries);
//  3. throughput (input triangles/s, wall and CPU) with 1 and 2 TBB threads (the wing's
//     translated copies — ribs, boxes — are simplified once, as simplify_parts does);
//  4. sweep of dim_pre on occt/motor.stl: triangles, Hausdorff, time, query speed;
//  5. the wing's CAD files at four tessellations (50k -> 420k triangles): throughput and
//     clearance-query speed-up against the input size (`--tessellation` runs only this);
//  6. the planner's own queries: every index call OMPL planning makes while routing the
//     wing's cables port to port on the original parts, logged and replayed on the
//     original and on the simplified parts (`--planner` runs only this).
// Writes bench/results/alpha_sim_parts.csv, alpha_sim_sweep.csv, alpha_sim_throughput.csv,
// alpha_sim_tessellation.csv, alpha_sim_planner_queries.csv, alpha_sim.png,
// alpha_sim_tessellation.png.
#include "bench/forwarding_index.hpp"
#include "core/stopwatch.hpp"
#include "core/io/mesh_read.hpp"
#include "core/io/scene_load.hpp"
#include "core/units.hpp"
#include "index/simplify/alpha_sim.hpp"
#include "index/embree_index.hpp"
#include "routing/route/path_planner.hpp"

#include <sys/resource.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <cstdio>
#include <cstdlib>
#include <algorithm>
#include <atomic>
#include <limits>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <random>
#include <string>
#include <vector>

using namespace loom;
namespace fs = std::filesystem;

namespace {


/// CPU time (user + system) of the process so far, all threads (s): comparable on a busy
/// machine, unlike wall time.
double cpu_seconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) + 1e-6 * static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

/// Throughput measurements are the fastest of this many runs (the median beside it): this
/// machine's neighbours slow single runs by 10–25% at times.
constexpr int kThroughputRuns = 3;

/// The fastest of `runs` calls of f: its wall and CPU seconds, and the median wall time.
struct Fastest {
  double sec = std::numeric_limits<double>::infinity(), cpu = 0.0, median = 0.0;
};
template <class F>
Fastest fastest_of(int runs, F&& f) {
  Fastest out;
  std::vector<double> walls;
  for (int run = 0; run < runs; ++run) {
    const Stopwatch t0;
    const double cpu0 = cpu_seconds();
    f();
    const double wall = t0.seconds(), cpu = cpu_seconds() - cpu0;
    walls.push_back(wall);
    if (wall < out.sec) {
      out.sec = wall;
      out.cpu = cpu;
    }
  }
  std::sort(walls.begin(), walls.end());
  out.median = walls[walls.size() / 2];
  return out;
}

/// `n` random points in `box` (fixed seed).
std::vector<Vec3> box_points(const AABB& box, int n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<Vec3> pts(static_cast<std::size_t>(n));
  for (auto& p : pts)
    for (int k = 0; k < 3; ++k) p[k] = std::uniform_real_distribution<double>(box.min[k], box.max[k])(rng);
  return pts;
}

/// Up to `n` points near the surface of `near` (what routing asks): surface samples moved
/// by up to `spread` in a random direction (fixed seed).
std::vector<Vec3> near_points(const std::vector<Part>& near, double spread, int n, std::uint64_t seed) {
  Mesh all;
  for (const auto& p : near) all.append(p.mesh);
  auto surf = dense_surface_samples(all, spread, 0.0, 0, seed);
  std::mt19937_64 rng(seed);
  std::shuffle(surf.begin(), surf.end(), rng);
  surf.resize(std::min<std::size_t>(surf.size(), static_cast<std::size_t>(n)));
  std::normal_distribution<double> g(0.0, 1.0);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (auto& p : surf) {
    const Vec3 dir = Vec3(g(rng), g(rng), g(rng)).normalized();
    p += dir * (spread * u(rng));
  }
  return surf;
}

/// Bounded closest-point queries per second through `idx`: one thread, the points in
/// Morton order (computed before the clock starts), best of three runs.
double rate(const ObstacleIndex& idx, const std::vector<Vec3>& pts, double radius) {
  std::vector<Vec3> ordered;
  for (std::size_t i : coherent_order(pts)) ordered.push_back(pts[i]);
  double best = 0.0;
  for (int rep = 0; rep < 3; ++rep) {
    double sum = 0.0;
    const Stopwatch t0;
    for (const Vec3& p : ordered) {
      const ClosestHit h = idx.closest(p, radius);
      sum += h.found() ? h.distance : 0.0;
    }
    const double s = t0.seconds();
    volatile double sink = sum;
    (void)sink;
    best = std::max(best, static_cast<double>(pts.size()) / s);
  }
  return best;
}

/// Speed-up of `simplified` over `original` on the same points and radius (rate() each).
struct Rates {
  double original = 0, simplified = 0;
  double speedup() const { return simplified / original; }
};
Rates rates(const EmbreeIndex& original, const EmbreeIndex& simplified, const std::vector<Vec3>& pts, double radius) {
  return {rate(original, pts, radius), rate(simplified, pts, radius)};
}

Part load_part(const std::string& rel) {
  Part p;
  p.name = rel;
  p.mesh = read_mesh_file(fs::path(LOOM_SHARED_DATA) / rel);
  p.closed = analyse_topology(p.mesh).closed;
  return p;
}

/// Each distinct file of a scene's parts (in its own frame: copies are left out, since
/// simplify_parts would reuse their results), tessellated at a linear and angular
/// deflection, as parts.
std::vector<Part> scene_files(const Scene& settings_only, double linear, double angular_deg) {
  TessellationParams tp;
  tp.linear_deflection = linear;
  tp.angular_deflection_deg = angular_deg;
  tp.unit_in_mm = unit_in_mm(settings_only.units);
  std::vector<std::string> files;
  for (const Part& sp : settings_only.parts)
    if (std::find(files.begin(), files.end(), sp.source_file) == files.end()) files.push_back(sp.source_file);
  std::vector<Part> parts;
  for (const std::string& f : files) {
    Part p;
    p.name = fs::path(f).filename().string();
    for (const NamedMesh& nm : read_cad_file(f, tp, false)) p.mesh.append(nm.mesh);
    p.closed = analyse_topology(p.mesh).closed;
    parts.push_back(std::move(p));
  }
  return parts;
}

/// One set of parts simplified together at one dim_pre.
struct Set {
  std::string name;
  std::vector<Part> parts;
  double dim_pre;
};

/// The wing-section scene at its own dim_pre (unless `quick`) and the real meshes at 2% of
/// their diagonal.
std::vector<Set> load_sets(bool quick) {
  std::vector<Set> sets;
  if (!quick) try {
    const Scene wing = load_scene(fs::path(LOOM_SOURCE_DIR) / "examples" / "wing-section" / "scene.toml");
    sets.push_back({"wing-section", wing.parts, wing.simplify.dim_pre.value});
    std::printf("wing-section: %zu parts, %zu triangles, dim_pre %g (%s)\n", wing.parts.size(), wing.triangle_count(),
                wing.simplify.dim_pre.value, wing.simplify.dim_pre.source.c_str());
  } catch (const std::exception& e) {
    std::printf("wing-section scene not loaded: %s\n", e.what());
  }
  for (const char* rel : {"occt/motor.stl", "trimesh/featuretype.STL", "fcl/env.obj", "occt/shape.stl",
                          "trimesh/bunny.ply", "trimesh/tube.obj"}) {
    Part p = load_part(rel);
    const double dim = 0.02 * p.mesh.bounds().diagonal();
    sets.push_back({rel, {p}, dim});
  }
  return sets;
}

/// One index call planning made, with its arguments, for replay on another index.
struct LoggedQuery {
  enum Kind { kAnyWithin, kInside, kClosest, kSegmentWithin, kKinds };
  Kind kind;
  Vec3 a, b;  ///< the point, or the segment's ends (world frame, scene units)
  double r;   ///< the radius asked (0 for inside)
};
const char* const kLoggedKindNames[LoggedQuery::kKinds] = {"any_within", "inside", "closest", "segment_within"};

/// Logs the four kinds of call OMPL planning makes (validity: any_within + inside;
/// clearance and the objective's clearance term: closest; motions: segment_within) and
/// counts any other call, so a replay knows what it left out; forwards every call to the
/// inner index. Thread-safe (one mutex around the log).
class LoggingIndex : public ForwardingIndex {
 public:
  explicit LoggingIndex(const ObstacleIndex& inner) : ForwardingIndex(inner) {}
  ClosestHit closest(const Vec3& p, double r) const override {
    log({LoggedQuery::kClosest, p, p, r});
    return inner_.closest(p, r);
  }
  bool inside(const Vec3& p, int* part) const override {
    log({LoggedQuery::kInside, p, p, 0.0});
    return inner_.inside(p, part);
  }
  bool any_within(const Vec3& p, double r) const override {
    log({LoggedQuery::kAnyWithin, p, p, r});
    return inner_.any_within(p, r);
  }
  bool segment_within(const Vec3& a, const Vec3& b, double r) const override {
    log({LoggedQuery::kSegmentWithin, a, b, r});
    return inner_.segment_within(a, b, r);
  }
  ClosestHit closest_approx(const Vec3& p, double r, double e) const override {
    ++unlogged_;
    return inner_.closest_approx(p, r, e);
  }
  ClosestHit closest_on_part(const Vec3& p, int part, double r) const override {
    ++unlogged_;
    return inner_.closest_on_part(p, part, r);
  }
  RayHit ray(const Vec3& o, const Vec3& d, double t) const override {
    ++unlogged_;
    return inner_.ray(o, d, t);
  }
  ClosestHit segment_closest(const Vec3& a, const Vec3& b, double r, double* t) const override {
    ++unlogged_;
    return inner_.segment_closest(a, b, r, t);
  }
  ClosestHit segment_closest_approx(const Vec3& a, const Vec3& b, double r, double e, double* t) const override {
    ++unlogged_;
    return inner_.segment_closest_approx(a, b, r, e, t);
  }
  ClosestHit segment_closest_on_part(const Vec3& a, const Vec3& b, int part, double r, double* t) const override {
    ++unlogged_;
    return inner_.segment_closest_on_part(a, b, part, r, t);
  }
  /// The calls logged so far, in call order.
  std::vector<LoggedQuery> queries() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return log_;
  }
  /// Calls of any other method (not replayed).
  long long unlogged() const { return unlogged_; }

 private:
  void log(const LoggedQuery& q) const {
    std::lock_guard<std::mutex> lock(mutex_);
    log_.push_back(q);
  }
  mutable std::mutex mutex_;
  mutable std::vector<LoggedQuery> log_;
  mutable std::atomic<long long> unlogged_{0};
};

/// Mean time per query (ns) of replaying `qs` through `idx`: one thread, in the logged
/// order (the planner's own locality), best of three runs.
double replay_ns(const ObstacleIndex& idx, const std::vector<LoggedQuery>& qs) {
  if (qs.empty()) return 0.0;
  double best = std::numeric_limits<double>::infinity();
  for (int rep = 0; rep < 3; ++rep) {
    double sum = 0.0;
    const Stopwatch t0;
    for (const LoggedQuery& q : qs) switch (q.kind) {
        case LoggedQuery::kAnyWithin: sum += idx.any_within(q.a, q.r) ? 1.0 : 0.0; break;
        case LoggedQuery::kInside: sum += idx.inside(q.a) ? 1.0 : 0.0; break;
        case LoggedQuery::kClosest: {
          const ClosestHit h = idx.closest(q.a, q.r);
          sum += h.found() ? h.distance : 0.0;
          break;
        }
        case LoggedQuery::kSegmentWithin: sum += idx.segment_within(q.a, q.b, q.r) ? 1.0 : 0.0; break;
        case LoggedQuery::kKinds: break;
      }
    const double s = t0.seconds();
    volatile double sink = sum;
    (void)sink;
    best = std::min(best, 1e9 * s / static_cast<double>(qs.size()));
  }
  return best;
}

/// 6. What routing asks of the index: each cable of the wing scene planned port to port
/// (Informed RRT*, a fixed iteration count so the log is reproducible) on the original
/// parts through a LoggingIndex; the log replayed on the original and on the simplified
/// parts' indices, per kind and all together (the time planning spends in the index).
void planner_queries(const fs::path& out_dir) {
  const Scene wing = load_scene(fs::path(LOOM_SOURCE_DIR) / "examples" / "wing-section" / "scene.toml");
  AlphaSimOptions o;
  o.dim_pre = wing.simplify.dim_pre.value;
  o.measure = false;
  std::vector<AlphaSimResult> res;
  const std::vector<Part> simplified = simplify_parts(wing.parts, o, &res);
  const EmbreeIndex original_index(wing.parts), simple_index(simplified);
  const LoggingIndex logging(original_index);
  std::map<std::string, const Port*> ports;
  for (const Port& p : wing.harness.ports) ports[p.id] = &p;
  int solved = 0;
  for (std::size_t c = 0; c < wing.harness.cables.size(); ++c) {
    const Cable& cable = wing.harness.cables[c];
    const Port* a = ports.at(cable.ports[0]);
    const Port* b = ports.at(cable.ports[1]);
    PlanRequest req;
    req.radius = cable.radius();
    req.clearance = wing.routing.clearance.value;
    req.min_bend_radius = cable.physical.min_bend_radius;
    req.scene_box = wing.bounds();
    req.planner = "informedrrtstar";
    req.seed = 20261122u + static_cast<std::uint32_t>(c);
    req.max_iterations = 500;
    req.time_limit = 30.0;
    req.start = {a->position, a->direction};
    req.goal = {b->position, b->direction};
    solved += plan_path(logging, req).solved() ? 1 : 0;
  }
  const std::vector<LoggedQuery> all = logging.queries();
  std::ofstream csv(out_dir / "alpha_sim_planner_queries.csv");
  csv << "kind,queries,original_ns,simplified_ns,speedup,original_ms,simplified_ms\n";
  std::printf("planner queries: %zu cables planned port to port on the original parts (%d solved), %zu index calls "
              "logged, %lld others not replayed\n",
              wing.harness.cables.size(), solved, all.size(), logging.unlogged());
  auto row = [&](const char* kind, const std::vector<LoggedQuery>& qs) {
    const double orig = replay_ns(original_index, qs), simp = replay_ns(simple_index, qs);
    const double n = static_cast<double>(qs.size());
    const double speedup = simp > 0 ? orig / simp : 0.0;
    csv << kind << "," << qs.size() << "," << orig << "," << simp << "," << speedup << "," << 1e-6 * orig * n << ","
        << 1e-6 * simp * n << "\n";
    std::printf("  %-15s %8zu calls  original %7.0f ns  simplified %7.0f ns  x%.2f\n", kind, qs.size(), orig, simp,
                speedup);
  };
  for (int k = 0; k < LoggedQuery::kKinds; ++k) {
    std::vector<LoggedQuery> of_kind;
    for (const LoggedQuery& q : all)
      if (q.kind == k) of_kind.push_back(q);
    row(kLoggedKindNames[k], of_kind);
  }
  row("all", all);
}

/// Draws a gnuplot script (the chart is optional: a missing gnuplot is reported, not fatal).
void run_gnuplot(const fs::path& script) {
  const std::string cmd = "gnuplot '" + script.string() + "'";
  if (std::system(cmd.c_str()) != 0) std::printf("gnuplot failed\n");
}

/// Part 3: throughput on all the sets together, 1 vs 2 threads (alpha_sim_throughput.csv).
void throughput(const fs::path& out_dir, const std::vector<Set>& sets) {
  std::size_t all_tris = 0;
  for (const Set& set : sets)
    for (const auto& p : set.parts) all_tris += p.mesh.triangle_count();
  std::ofstream tp_csv(out_dir / "alpha_sim_throughput.csv");
  tp_csv << "threads,triangles,seconds,triangles_per_second,measure,cpu_seconds,triangles_per_cpu_second,runs,"
            "median_seconds\n";
  // Without the mesh verification, then with it, as loom runs.
  // LOOM_TP_ONE=1 runs the first only (for profiling).
  struct Config {
    bool measure;
    const char* what;
  };
  const Config configs[] = {{false, "without mesh verification"}, {true, "with verification"}};
  const std::size_t n_configs = std::getenv("LOOM_TP_ONE") ? 1 : std::size(configs);
  for (std::size_t c = 0; c < n_configs; ++c)
    for (int threads : {1, 2}) {
      const Config& cf = configs[c];
      tbb::global_control gc(tbb::global_control::max_allowed_parallelism, threads);
      // The sets run concurrently, as the parts of one scene would (each set has its own
      // dim_pre, so they cannot be one simplify_parts call).
      const Fastest f = fastest_of(kThroughputRuns, [&] {
        tbb::parallel_for(std::size_t(0), sets.size(), [&](std::size_t s) {
          AlphaSimOptions o;
          o.dim_pre = sets[s].dim_pre;
          o.measure = cf.measure;
          std::vector<AlphaSimResult> res;
          simplify_parts(sets[s].parts, o, &res);
        });
      });
      const double sec = f.sec, cpu = f.cpu, median = f.median;
      tp_csv << threads << "," << all_tris << "," << sec << "," << all_tris / sec << "," << int(cf.measure) << ","
             << cpu << "," << all_tris / cpu << "," << kThroughputRuns << "," << median << "\n";
      std::printf("throughput (%s): %d thread(s): %zu triangles in %.3f s = %.3g triangles/s (CPU %.2f s = %.3g "
                  "triangles per CPU second; fastest of %d, median %.3f s = %.3g/s)\n",
                  cf.what, threads, all_tris, sec, all_tris / sec, cpu, all_tris / cpu, kThroughputRuns, median, all_tris / median);
    }
}

/// 5. The wing's CAD files at four tessellations, 0.4 mm / 20° to 0.01 mm / 2.5° (the
/// scene's own is 0.065 mm / 20°; a CAD export for clash analysis may be finer): α-SIM's
/// cost follows the projected area in L_max² cells and the input size, its benefit the
/// triangles it removes. Throughput on 2 threads (without the mesh verification, as in 3)
/// and clearance-query speed-up per tessellation.
void tessellation_sweep(const fs::path& out_dir, const Scene& wing_settings, int n_queries) {
  const double dim_pre = wing_settings.simplify.dim_pre.value;
  std::ofstream csv(out_dir / "alpha_sim_tessellation.csv");
  csv << "linear_deflection,angular_deflection_deg,triangles_before,triangles_after,seconds,triangles_per_second,"
         "cpu_seconds,clearance_box_original,clearance_box_simplified,clearance_box_speedup,clearance_near_original,"
         "clearance_near_simplified,clearance_near_speedup\n";
  const std::pair<double, double> levels[] = {{0.4, 20.0}, {0.1, 10.0}, {0.04, 5.0}, {0.01, 2.5}};
  for (const auto& [linear, angular] : levels) {
    const std::vector<Part> parts = scene_files(wing_settings, linear, angular);
    std::size_t before = 0, after = 0;
    for (const auto& p : parts) before += p.mesh.triangle_count();
    AlphaSimOptions o;
    o.dim_pre = dim_pre;
    o.measure = false;
    std::vector<AlphaSimResult> res;
    std::vector<Part> simple;
    double sec = 0.0, cpu = 0.0;
    {
      tbb::global_control gc(tbb::global_control::max_allowed_parallelism, 2);
      const Fastest f = fastest_of(kThroughputRuns, [&] {  // as in part 3
        res.clear();
        simple = simplify_parts(parts, o, &res);
      });
      sec = f.sec;
      cpu = f.cpu;
    }
    for (const auto& r : res) after += r.triangles_after;
    AABB box;
    for (const auto& p : parts) box.extend(p.mesh.bounds());
    const EmbreeIndex original_index(parts), simple_index(simple);
    const Rates cb = rates(original_index, simple_index, box_points(box, n_queries, 17), dim_pre);
    const Rates cn = rates(original_index, simple_index, near_points(parts, 5.0 * dim_pre, n_queries, 19), dim_pre);
    csv << linear << "," << angular << "," << before << "," << after << "," << sec << "," << before / sec << "," << cpu
        << "," << cb.original << "," << cb.simplified << "," << cb.speedup() << "," << cn.original << ","
        << cn.simplified << "," << cn.speedup() << "\n";
    std::printf("wing files at deflection %g / %g deg: %zu -> %zu triangles, simplified in %.2f s on 2 threads = %.3g "
                "triangles/s (CPU %.2f s); clearance queries x%.2f in box, x%.2f near surface\n",
                linear, angular, before, after, sec, before / sec, cpu, cb.speedup(), cn.speedup());
  }
  csv.close();
  const fs::path gp = out_dir / "alpha_sim_tessellation.gp";
  std::ofstream g(gp);
  g << "set terminal pngcairo size 1200,450 noenhanced\n"
    << "set output '" << (out_dir / "alpha_sim_tessellation.png").string() << "'\n"
    << "set datafile separator ','\nset key top left\nset multiplot layout 1,2 title "
       "'alpha-SIM on the wing-section CAD files at four tessellations (dim_pre = " << dim_pre << " mm)'\n"
    << "set logscale x\nset xlabel 'input triangles'\nset grid\n"
    << "set ylabel 'clearance queries/s: simplified / original'\nplot '"
    << (out_dir / "alpha_sim_tessellation.csv").string()
    << "' using 3:10 with linespoints title 'in the box', '' using 3:13 with linespoints title 'near the surface', "
       "5 with lines dashtype 2 title 'target 5x'\n"
    << "set ylabel 'input triangles/s (2 threads)'\nset logscale y\nset yrange [1e4:2e6]\nplot '' using 3:6 with linespoints title "
       "'throughput', 1e6 with lines dashtype 2 title 'target 1e6/s'\nunset multiplot\n";
  g.close();
  run_gnuplot(gp);
}

}  // namespace

int main(int argc, char** argv) {
  // `bench_alpha_sim --tessellation [DIR]` runs only part 5, `--planner [DIR]` only part 6,
  // `--throughput [DIR]` only part 3.
  const bool tessellation_only = argc > 1 && std::string(argv[1]) == "--tessellation";
  const bool planner_only = argc > 1 && std::string(argv[1]) == "--planner";
  const bool throughput_only = argc > 1 && std::string(argv[1]) == "--throughput";
  const int arg0 = tessellation_only || planner_only || throughput_only ? 2 : 1;
  const fs::path out_dir = argc > arg0 ? fs::path(argv[arg0]) : fs::path(LOOM_SOURCE_DIR) / "bench" / "results";
  fs::create_directories(out_dir);
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  const int n_queries = 20000;
  // The wing's settings (dim_pre = its smallest cable diameter) and part files, without
  // tessellating them.
  SceneLoadOptions settings_only;
  settings_only.load_parts = false;
  const Scene wing_settings =
      load_scene(fs::path(LOOM_SOURCE_DIR) / "examples" / "wing-section" / "scene.toml", settings_only);
  if (tessellation_only) {
    tessellation_sweep(out_dir, wing_settings, n_queries);
    return 0;
  }
  if (planner_only) {
    planner_queries(out_dir);
    return 0;
  }
  // LOOM_BENCH_QUICK=1 skips the wing-section scene (14 STEP parts: seconds to load and simplify).
  const bool quick = std::getenv("LOOM_BENCH_QUICK") != nullptr;
  if (throughput_only) {
    throughput(out_dir, load_sets(quick));
    return 0;
  }

  // ---- 1 + 2: per part, at the scene's dim_pre (wing) or 2% of the part diagonal (real meshes).
  std::ofstream parts_csv(out_dir / "alpha_sim_parts.csv");
  parts_csv << "set,part,dim_pre,triangles_before,triangles_after,ratio,hausdorff,containment,status,fallback,time_ms,"
               "query_rate_original,query_rate_simplified,query_speedup,near_rate_original,near_rate_simplified,"
               "near_speedup,clearance_box_original,clearance_box_simplified,clearance_box_speedup,"
               "clearance_near_original,clearance_near_simplified,clearance_near_speedup,copy_of,shapes_ms,mesh_ms,measure_ms\n";
  const std::vector<Set> sets = load_sets(quick);
  std::size_t total_in = 0;
  for (const auto& set : sets) {
    AlphaSimOptions opt;
    opt.dim_pre = set.dim_pre;
    std::vector<AlphaSimResult> res;
    const double cpu0 = cpu_seconds();
    const Stopwatch t_set;
    const auto simple = simplify_parts(set.parts, opt, &res);
    const double set_cpu = cpu_seconds() - cpu0, set_wall = t_set.seconds();
    AABB box;
    for (const auto& p : set.parts) box.extend(p.mesh.bounds());
    const EmbreeIndex original_index(set.parts), simple_index(simple);
    // Closest within 5% of the diagonal in the box, and within 5·dim_pre of points up to
    // that far from the surface (5 cable diameters).
    const Rates qb = rates(original_index, simple_index, box_points(box, n_queries, 11), 0.05 * box.diagonal());
    const Rates qn =
        rates(original_index, simple_index, near_points(set.parts, 5.0 * set.dim_pre, n_queries, 13), 5.0 * set.dim_pre);
    // Clearance queries (closest within dim_pre: a cable of diameter dim_pre kept dim_pre/2
    // off) at the same two kinds of points.
    const Rates cb = rates(original_index, simple_index, box_points(box, n_queries, 17), set.dim_pre);
    const Rates cn =
        rates(original_index, simple_index, near_points(set.parts, 5.0 * set.dim_pre, n_queries, 19), set.dim_pre);
    std::size_t before = 0, after = 0;
    double haus = 0, time_ms = 0, cont = 1;
    for (std::size_t i = 0; i < res.size(); ++i) {
      const auto& r = res[i];
      before += r.triangles_before;
      after += r.triangles_after;
      haus = std::max(haus, r.hausdorff);
      time_ms += r.time_ms;
      cont = std::min(cont, r.containment);
      parts_csv << set.name << "," << r.name << "," << set.dim_pre << "," << r.triangles_before << ","
                << r.triangles_after << "," << double(r.triangles_after) / std::max<std::size_t>(1, r.triangles_before)
                << "," << r.hausdorff << "," << r.containment << "," << alpha_sim_status_name(r.status) << ","
                << alpha_sim_fallback_name(r.fallback) << "," << r.time_ms << "," << qb.original << "," << qb.simplified
                << "," << qb.speedup() << "," << qn.original << "," << qn.simplified << "," << qn.speedup() << ","
                << cb.original
                << "," << cb.simplified << "," << cb.speedup() << "," << cn.original << "," << cn.simplified << ","
                << cn.speedup() << "," << r.copy_of << "," << r.shapes_ms << "," << r.mesh_ms << "," << r.measure_ms << "\n";
    }
    total_in += before;
    std::printf("%-24s dim_pre %-8.4g tris %7zu -> %6zu (%5.1f%%) hausdorff %-9.4g containment %.6f  %7.0f ms parts, "
                "simplify_parts %.2f s CPU %.2f s wall  queries/s in box %.3g -> %.3g (x%.2f), near surface %.3g -> "
                "%.3g (x%.2f)\n",
                set.name.c_str(), set.dim_pre, before, after, 100.0 * after / std::max<std::size_t>(1, before), haus,
                cont, time_ms, set_cpu, set_wall, qb.original, qb.simplified, qb.speedup(), qn.original, qn.simplified,
                qn.speedup());
    std::printf("%-24s clearance queries (r = dim_pre) per second, original -> simplified: in box %.3g -> %.3g "
                "(x%.2f), near surface %.3g -> %.3g (x%.2f)\n",
                set.name.c_str(), cb.original, cb.simplified, cb.speedup(), cn.original, cn.simplified, cn.speedup());
  }

  throughput(out_dir, sets);

  // ---- 4: dim_pre sweep on the motor.
  Part motor = load_part("occt/motor.stl");
  const AABB mbox = motor.mesh.bounds();
  const double diag = mbox.diagonal();
  const EmbreeIndex motor_index({motor});
  const std::vector<Vec3> sweep_box = box_points(mbox, n_queries, 5), clear_box = box_points(mbox, n_queries, 17);
  std::ofstream sweep_csv(out_dir / "alpha_sim_sweep.csv");
  sweep_csv << "dim_pre,dim_pre_rel,triangles_after,triangle_ratio,hausdorff,hausdorff_rel,time_ms,query_rate,"
               "query_speedup,status,clearance_box_speedup,clearance_near_speedup\n";
  for (double rel : {0.005, 0.01, 0.02, 0.04, 0.08, 0.16}) {
    AlphaSimOptions o;
    o.dim_pre = rel * diag;
    const auto sp = simplify_part(motor, o);
    Part simple = motor;
    simple.mesh = sp.mesh;
    const EmbreeIndex simple_index({simple});
    const Rates q = rates(motor_index, simple_index, sweep_box, 0.05 * diag);
    const Rates cb = rates(motor_index, simple_index, clear_box, o.dim_pre);
    const Rates cn = rates(motor_index, simple_index, near_points({motor}, 5.0 * o.dim_pre, n_queries, 19), o.dim_pre);
    const auto& r = sp.result;
    sweep_csv << o.dim_pre << "," << rel << "," << r.triangles_after << ","
              << double(r.triangles_after) / r.triangles_before << "," << r.hausdorff << "," << r.hausdorff / diag
              << "," << r.time_ms << "," << q.simplified << "," << q.speedup() << "," << alpha_sim_status_name(r.status) << ","
              << cb.speedup() << "," << cn.speedup() << "\n";
    std::printf("motor dim_pre %.4g (%.3f diag): tris %zu (%.1f%%) hausdorff %.4g  %.0f ms  speedup x%.2f  %s  "
                "clearance queries x%.2f in box, x%.2f near surface\n",
                o.dim_pre, rel, r.triangles_after, 100.0 * r.triangles_after / r.triangles_before, r.hausdorff,
                r.time_ms, q.speedup(), alpha_sim_status_name(r.status), cb.speedup(), cn.speedup());
  }
  sweep_csv.close();

  tessellation_sweep(out_dir, wing_settings, n_queries);
  if (!quick) planner_queries(out_dir);

  // Chart.
  const fs::path gp = out_dir / "alpha_sim.gp";
  std::ofstream g(gp);
  g << "set terminal pngcairo size 1200,800\n"
    << "set output '" << (out_dir / "alpha_sim.png").string() << "'\n"
    << "set datafile separator ','\nset key autotitle columnhead\nset multiplot layout 2,2 title "
       "'alpha-SIM on occt/motor.stl (13,502 triangles): level of detail dim_pre'\n"
    << "set logscale x\nset xlabel 'dim_pre / bbox diagonal'\nset grid\n"
    << "set ylabel 'triangles after / before (%)'\nplot '" << (out_dir / "alpha_sim_sweep.csv").string()
    << "' using 2:($4*100) with linespoints title 'triangle ratio'\n"
    << "set ylabel 'Hausdorff / diagonal'\nplot '' using 2:6 with linespoints title 'one-sided Hausdorff'\n"
    << "set ylabel 'time (ms)'\nplot '' using 2:7 with linespoints title 'simplification time'\n"
    << "set ylabel 'queries/s: simplified / original'\nset logscale y\nplot '' using 2:9 with linespoints title "
       "'closest within 5% diag', '' using 2:11 with linespoints title "
       "'clearance r = dim_pre, in the box', '' using 2:12 with linespoints title "
       "'clearance r = dim_pre, near the surface'\nunset multiplot\n";
  g.close();
  run_gnuplot(gp);
  std::printf("wrote %s\n", out_dir.string().c_str());
  return 0;
}
