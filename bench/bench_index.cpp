// Obstacle-index benchmarks (DESIGN §8): Embree BVH build rate and memory per
// triangle from 10k to 5M triangles (generated scenes + the shared motor.stl), closest-point
// queries/s on 1 and 2 threads for points within 10 cable radii of a 1M-triangle scene
// against the brute-force and FCL baselines in the same run, voxelisation time, distance
// map lookups/s, and voxel size against distance error and lookup time.
// Also: Embree LOW / MEDIUM / HIGH builds on 1M triangles (build time against query rate,
// index_build_quality.csv), and the 1M query rows on both the automatic (LOW) and a MEDIUM
// build. Modes: --build-only, --quality-only, --queries-only, --micro-only, and
// --probe TRIS QUALITY (20k closest queries, for callgrind instruction counts).
// Writes bench/results/index_*.csv and index_*.png (gnuplot). Fixed seeds throughout.
#include "core/stopwatch.hpp"
#include "core/io/atomic_file.hpp"
#include "core/io/mesh_read.hpp"
#include "index/brute_force_index.hpp"
#include "index/embree_index.hpp"
#include "index/fcl_index.hpp"
#include "index/voxel_map.hpp"
#include "tests/index/index_test_meshes.hpp"

#include <benchmark/benchmark.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

using namespace loom;
using namespace loom::testmesh;

namespace {


/// Process CPU seconds (all threads): rates per CPU-second stay meaningful when other
/// jobs share the two cores, wall-clock rates do not.
double cpu_now() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

/// 1-minute load average (other jobs on the machine while measuring).
double load_avg() {
  std::ifstream in("/proc/loadavg");
  double l = 0;
  in >> l;
  return l;
}

/// Cable radius (mm) of the benchmark scenes; query points lie within 10 radii of a surface.
constexpr double kCableRadius = 2.0;
constexpr double kClearance = 3.0;

const std::string kResults = std::string(LOOM_SOURCE_DIR) + "/bench/results/";

/// A generated assembly: closed spheres, tori and boxes of 20–80 mm placed at random in a
/// region whose size grows with the triangle count (≈ constant density).
std::vector<Part> generated_scene(std::size_t target_tris, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u01(0, 1);
  const double side = 400.0 * std::cbrt(static_cast<double>(target_tris) / 1e5);
  std::vector<Part> parts;
  std::size_t tris = 0;
  int k = 0;
  while (tris < target_tris) {
    const Vec3 c(side * u01(rng), side * u01(rng), 0.5 * side * u01(rng));
    const double s = 10 + 30 * u01(rng);
    Mesh m;
    switch (k % 3) {
      case 0: m = uv_sphere(c, s, 24, 12); break;
      case 1: m = torus(c, s, 0.3 * s, 32, 12); break;
      default: m = box(c - Vec3(s, 0.5 * s, 0.3 * s), c + Vec3(s, 0.5 * s, 0.3 * s)); break;
    }
    tris += m.triangle_count();
    parts.push_back(make_part("p" + std::to_string(k++), std::move(m), true));
  }
  return parts;
}

std::size_t count_tris(const std::vector<Part>& parts) {
  std::size_t n = 0;
  for (const Part& p : parts) n += p.mesh.triangle_count();
  return n;
}

/// Points within `reach` of a surface: a random triangle's random point plus a random
/// offset of length ≤ reach.
std::vector<Vec3> near_surface_points(const std::vector<Part>& parts, std::size_t n, double reach, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u01(0, 1);
  std::normal_distribution<double> n01;
  std::vector<Vec3> pts;
  pts.reserve(n);
  while (pts.size() < n) {
    const Part& p = parts[rng() % parts.size()];
    if (p.mesh.empty()) continue;
    const auto c = p.mesh.corners(rng() % p.mesh.triangle_count());
    double a = u01(rng), b = u01(rng);
    if (a + b > 1) a = 1 - a, b = 1 - b;
    const Vec3 on = c[0] + a * (c[1] - c[0]) + b * (c[2] - c[0]);
    pts.push_back(on + reach * u01(rng) * Vec3(n01(rng), n01(rng), n01(rng)).normalized());
  }
  return pts;
}

double rate(std::size_t n, double seconds) { return seconds > 0 ? static_cast<double>(n) / seconds : 0.0; }

void write_csv(const std::string& name, const std::string& content) {
  write_file_atomic(kResults + name, content);
  std::cout << "wrote " << kResults + name << "\n";
}

void run_gnuplot(const std::string& name, const std::string& script) {
  const std::string gp = kResults + name + ".gp";
  write_file_atomic(gp, script);
  const std::string cmd = "cd '" + kResults + "' && gnuplot '" + name + ".gp'";
  if (std::system(cmd.c_str()) != 0) std::cerr << "gnuplot failed for " << name << "\n";
}

// --- scenarios ---------------------------------------------------------------------------

void build_scaling() {
  std::ostringstream csv;
  csv << "scene,triangles,embree_build_s,mtris_per_s,embree_build_cpu_s,mtris_per_cpu_s,embree_bytes_per_tri,fcl_build_s,load_avg\n";
  std::vector<std::pair<std::string, std::vector<Part>>> scenes;
  for (std::size_t n : {10000ul, 100000ul, 1000000ul, 5000000ul})
    scenes.emplace_back("generated", generated_scene(n, 100 + static_cast<unsigned>(n % 97)));
  try {
    Mesh motor = read_mesh_file(std::string(LOOM_SHARED_DATA) + "/occt/motor.stl");
    scenes.emplace_back("motor.stl", std::vector<Part>{make_part("motor", std::move(motor), false)});
  } catch (const std::exception& e) {
    std::cerr << "motor.stl skipped: " << e.what() << "\n";
  }
  for (const auto& [label, parts] : scenes) {
    const std::size_t n = count_tris(parts);
    // Best of 3 builds (the first warms up Embree's allocator and TBB).
    double best = 1e30, best_cpu = 1e30;
    std::size_t bytes = 0;
    for (int rep = 0; rep < (n > 2000000 ? 1 : 3); ++rep) {
      const double c0 = cpu_now();
      const EmbreeIndex e(parts);
      best_cpu = std::min(best_cpu, cpu_now() - c0);
      best = std::min(best, e.build_seconds());
      bytes = e.memory_bytes();
    }
    double fcl_s = -1;
    if (n <= 1000000) {
      const Stopwatch t;
      const FclIndex f(parts);
      fcl_s = t.seconds();
    }
    csv << label << "," << n << "," << best << "," << rate(n, best) / 1e6 << "," << best_cpu << ","
        << rate(n, best_cpu) / 1e6 << "," << static_cast<double>(bytes) / static_cast<double>(n) << "," << fcl_s << ","
        << load_avg() << "\n";
    std::cout << label << " " << n << " tris: embree build " << best << " s wall (" << rate(n, best) / 1e6
              << " M tris/s), " << best_cpu << " s cpu (includes the copy), " << static_cast<double>(bytes) / n
              << " B/tri, fcl build " << fcl_s << " s, load " << load_avg() << "\n";
  }
  write_csv("index_build.csv", csv.str());
  run_gnuplot("index_build",
              "set terminal pngcairo size 900,500\nset output 'index_build.png'\nset datafile separator ','\n"
              "set logscale x\nset xlabel 'triangles'\nset ylabel 'M triangles / s'\nset y2label 'bytes / triangle'\n"
              "set ytics nomirror\nset y2tics\nset y2range [0:*]\nset yrange [0:*]\nset key top right\n"
              "set title 'Embree BVH build (generated scenes; x = motor.stl)'\n"
              "plot 'index_build.csv' every ::1::4 using 2:4 with linespoints title 'M tris/s (wall, shared machine)', "
              "'' every ::1::4 using 2:6 with linespoints title 'M tris per CPU-second', "
              "'' every ::1::4 using 2:7 axes x1y2 with linespoints title 'memory B/tri (right)', "
              "'' every ::5::5 using 2:6 with points pt 2 ps 2 title 'motor.stl (per CPU-s)'\n");
}

/// Build quality trade-off on the 1M-triangle query scene: build time (wall and CPU) and
/// closest-point queries per CPU-second (1 thread, points within 10 cable radii) for
/// Embree's LOW / MEDIUM / HIGH builds. Justifies the automatic choice in EmbreeIndex.
void build_quality_tradeoff() {
  const auto parts = generated_scene(1000000, 7);
  const std::size_t n = count_tris(parts);
  const double reach = 10 * kCableRadius;
  const auto pts = near_surface_points(parts, 100000, reach, 8);
  std::ostringstream csv;
  csv << "quality,triangles,build_s,mtris_per_s,build_cpu_s,queries_per_cpu_s_1t,embree_bytes_per_tri,load_avg\n";
  for (int quality : {0, 1, 2}) {
    EmbreeOptions o;
    o.build_quality = quality;
    double best = 1e30, best_cpu = 1e30;
    std::size_t bytes = 0;
    for (int rep = 0; rep < 2; ++rep) {
      const double c0 = cpu_now();
      const EmbreeIndex e(parts, o);
      best_cpu = std::min(best_cpu, cpu_now() - c0);
      best = std::min(best, e.build_seconds());
      bytes = e.memory_bytes();
    }
    const EmbreeIndex e(parts, o);
    e.closest_batch(std::vector<Vec3>(pts.begin(), pts.begin() + 10000), reach, 1);  // warm-up
    const double c0 = cpu_now();
    const auto hits = e.closest_batch(pts, reach, 1);
    const double qc = cpu_now() - c0;
    benchmark::DoNotOptimize(hits.data());
    csv << quality << "," << n << "," << best << "," << rate(n, best) / 1e6 << "," << best_cpu << "," << rate(pts.size(), qc)
        << "," << static_cast<double>(bytes) / static_cast<double>(n) << "," << load_avg() << "\n";
    std::cout << "build quality " << quality << ": " << best << " s wall (" << rate(n, best) / 1e6 << " M tris/s), "
              << best_cpu << " s cpu, closest " << rate(pts.size(), qc) / 1e6 << " M/cpu-s (1 thread), "
              << static_cast<double>(bytes) / static_cast<double>(n) << " B/tri\n";
  }
  write_csv("index_build_quality.csv", csv.str());
}

void query_throughput() {
  const auto parts = generated_scene(1000000, 7);
  const std::size_t n = count_tris(parts);
  const double reach = 10 * kCableRadius;
  const auto pts = near_surface_points(parts, 400000, reach, 8);
  const EmbreeIndex e(parts);  // automatic build quality (LOW at this size)
  std::ostringstream csv;
  csv << "index,query,threads,points,seconds,queries_per_s,cpu_seconds,queries_per_cpu_s,load_avg\n";
  // Runs f() on n queries and writes a CSV row; returns the wall-clock rate.
  const auto measure = [&](const std::string& index, const std::string& query, int threads, std::size_t n_q,
                           const auto& f) {
    const double c0 = cpu_now();
    const Stopwatch t;
    f();
    const double s = t.seconds(), c = cpu_now() - c0;
    csv << index << "," << query << "," << threads << "," << n_q << "," << s << "," << rate(n_q, s) << "," << c << ","
        << rate(n_q, c) << "," << load_avg() << "\n";
    std::cout << index << " " << query << ", " << threads << " thread(s): " << rate(n_q, s) << " /s wall, "
              << rate(n_q, c) << " /cpu-s\n";
    return rate(n_q, s);
  };
  double one = 0, two = 0;
  e.closest_batch(std::vector<Vec3>(pts.begin(), pts.begin() + 20000), reach, 2);  // warm-up
  for (int threads : {1, 2}) {
    const double r = measure("embree", "closest(r=10 radii)", threads, pts.size(), [&] {
      const auto hits = e.closest_batch(pts, reach, threads);
      benchmark::DoNotOptimize(hits.data());
    });
    (threads == 1 ? one : two) = r;
  }
  // The same queries on a MEDIUM (SAH) build: the automatic choice for this scene size is
  // LOW, which builds ~2.6x faster (build_quality_tradeoff) but visits more nodes per query.
  {
    EmbreeOptions medium;
    medium.build_quality = 1;
    const EmbreeIndex em(parts, medium);
    em.closest_batch(std::vector<Vec3>(pts.begin(), pts.begin() + 20000), reach, 2);  // warm-up
    for (int threads : {1, 2})
      measure("embree-medium-build", "closest(r=10 radii)", threads, pts.size(), [&] {
        const auto hits = em.closest_batch(pts, reach, threads);
        benchmark::DoNotOptimize(hits.data());
      });
  }
  // A tight start radius is most of the speed: a caller walking along a cable knows the
  // previous distance + its step (here: true distance + 1 mm).
  {
    const auto truth = e.closest_batch(pts, reach, 2);
    for (int threads : {1, 2})
      measure("embree", "closest(r=previous+1mm)", threads, pts.size(), [&] {
        std::vector<double> out(pts.size());
        tbb::task_arena arena(threads);
        arena.execute([&] {
          tbb::parallel_for(tbb::blocked_range<std::size_t>(0, pts.size(), 256), [&](const tbb::blocked_range<std::size_t>& r) {
            for (std::size_t i = r.begin(); i != r.end(); ++i)
              out[i] = e.closest(pts[i], truth[i].found() ? truth[i].distance + 1.0 : reach).distance;
          });
        });
        benchmark::DoNotOptimize(out.data());
      });
  }
  // Unbounded radius (no prior knowledge), the any-within early exit, inside tests.
  const std::vector<Vec3> sub(pts.begin(), pts.begin() + 100000);
  for (int threads : {1, 2}) {
    measure("embree", "closest(r=inf)", threads, sub.size(), [&] {
      const auto hits = e.closest_batch(sub, std::numeric_limits<double>::infinity(), threads);
      benchmark::DoNotOptimize(hits.data());
    });
    measure("embree", "any_within(r+c)", threads, sub.size(), [&] {
      const auto w = e.any_within_batch(sub, kCableRadius + kClearance, threads);
      benchmark::DoNotOptimize(w.data());
    });
    measure("embree", "inside", threads, sub.size(), [&] {
      const auto w = e.inside_batch(sub, threads);
      benchmark::DoNotOptimize(w.data());
    });
  }
  // Baselines on subsets: brute force over every triangle (the seed's discrete method) and FCL.
  {
    const BruteForceIndex b(parts);
    const std::vector<Vec3> few(pts.begin(), pts.begin() + 40);
    const double r = measure("brute", "closest(r=10 radii)", 1, few.size(), [&] {
      const auto hits = b.closest_batch(few, reach, 1);
      benchmark::DoNotOptimize(hits.data());
    });
    std::cout << "embree / brute (1 thread, wall): " << one / r << "\n";
    csv << "ratio,embree_vs_brute,1,0,0," << one / r << ",0,0," << load_avg() << "\n";
  }
  {
    const FclIndex f(parts);
    const std::vector<Vec3> few(pts.begin(), pts.begin() + 4000);
    const double r = measure("fcl", "closest(r=10 radii)", 1, few.size(), [&] {
      const auto hits = f.closest_batch(few, reach, 1);
      benchmark::DoNotOptimize(hits.data());
    });
    std::cout << "embree / fcl (1 thread, wall): " << one / r << "\n";
    csv << "ratio,embree_vs_fcl,1,0,0," << one / r << ",0,0," << load_avg() << "\n";
  }
  csv << "ratio,2_vs_1_threads,2,0,0," << two / one << ",0,0," << load_avg() << "\n";
  std::cout << "2 vs 1 thread (wall): " << two / one << "x on " << n << " triangles\n";
  write_csv("index_queries.csv", csv.str());
}

void voxel_tradeoff() {
  // 100k triangles in a ~400 mm region; exact distances from Embree as the reference.
  const auto parts = generated_scene(100000, 9);
  auto exact = std::make_shared<EmbreeIndex>(parts);
  const double derived = VoxelMap::derive_resolution(kCableRadius, kClearance);
  const double reach = 4 * (kCableRadius + kClearance);
  const auto pts = near_surface_points(parts, 200000, reach, 10);
  // Reference semantic distances (0 inside closed parts).
  std::vector<double> truth(pts.size());
  for (std::size_t i = 0; i < pts.size(); ++i)
    truth[i] = exact->inside(pts[i]) ? 0.0 : exact->closest(pts[i]).distance;
  std::ostringstream csv;
  csv << "resolution,voxelise_s,edt_s,refine_s,build_s,grid_cells,memory_mb,max_abs_error,mean_abs_error,bound,"
         "lookups_per_s_1t,lookups_per_s_2t,embree_closest_per_cpu_s_1t,lookups_per_cpu_s_1t,lookups_per_cpu_s_2t,load_avg\n";
  double embree_rate = 0;
  {
    const double c0 = cpu_now();
    const auto hits = exact->closest_batch(pts, reach, 1);
    embree_rate = rate(pts.size(), cpu_now() - c0);  // per CPU-second, like the lookups column
    benchmark::DoNotOptimize(hits.data());
  }
  for (double factor : {4.0, 2.0, 1.0, 0.5}) {
    const double res = derived * factor;
    VoxelOptions vo;
    vo.resolution = res;
    vo.max_distance = reach;
    vo.max_cells = std::size_t(400) << 20;
    const Stopwatch t;
    const VoxelMap vm(parts, vo, exact);
    const double build = t.seconds();
    double max_err = 0, sum_err = 0;
    std::size_t counted = 0;
    for (std::size_t i = 0; i < pts.size(); ++i) {
      if (truth[i] > reach - vm.accuracy().abs_error) continue;
      const double err = std::abs(vm.distance(pts[i]) - truth[i]);
      max_err = std::max(max_err, err);
      sum_err += err;
      ++counted;
    }
    double lookups[2] = {0, 0}, lookups_cpu[2] = {0, 0};
    for (int threads : {1, 2}) {
      // Repeat the lookups to get a measurable time (distance() is a few ns).
      constexpr int kRepeats = 20;
      std::vector<double> sink(pts.size());
      tbb::task_arena arena(threads);
      const double c0 = cpu_now();
      const Stopwatch tq;
      arena.execute([&] {
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, pts.size(), 4096), [&](const tbb::blocked_range<std::size_t>& r) {
          for (int rep = 0; rep < kRepeats; ++rep)
            for (std::size_t i = r.begin(); i != r.end(); ++i) sink[i] += vm.distance(pts[i]);
        });
      });
      lookups[threads - 1] = rate(pts.size() * kRepeats, tq.seconds());
      lookups_cpu[threads - 1] = rate(pts.size() * kRepeats, cpu_now() - c0);
      benchmark::DoNotOptimize(sink.data());
    }
    const auto& st = vm.stats();
    csv << res << "," << st.voxelise_seconds << "," << st.edt_seconds << "," << st.refine_seconds << "," << build << ","
        << st.grid_cells << "," << static_cast<double>(vm.memory_bytes()) / 1048576.0 << "," << max_err << ","
        << (counted ? sum_err / counted : 0.0) << "," << vm.accuracy().abs_error << "," << lookups[0] << ","
        << lookups[1] << "," << embree_rate << "," << lookups_cpu[0] << "," << lookups_cpu[1] << "," << load_avg() << "\n";
    std::cout << "voxel " << res << " mm: build " << build << " s (voxelise " << st.voxelise_seconds << ", edt "
              << st.edt_seconds << ", refine " << st.refine_seconds << "), max err " << max_err << " (bound "
              << vm.accuracy().abs_error << "), lookups " << lookups[0] / 1e6 << " / " << lookups[1] / 1e6
              << " M/s wall (1/2 threads), " << lookups_cpu[0] / 1e6 << " M/cpu-s, embree closest " << embree_rate / 1e6
              << " M/s\n";
  }
  write_csv("index_voxel.csv", csv.str());
  run_gnuplot("index_voxel",
              "set terminal pngcairo size 900,500\nset output 'index_voxel.png'\nset datafile separator ','\n"
              "set logscale x\nset xrange [1:16]\nset xlabel 'voxel edge (mm)'\nset ylabel 'distance error (mm)'\n"
              "set y2label 'query time per CPU (ns, log)'\nset logscale y2\nset ytics nomirror\nset y2tics\nset key top left\n"
              "set title 'Voxel distance map: voxel size vs error and lookup time (100k triangles)'\n"
              "plot 'index_voxel.csv' every ::1 using 1:8 with linespoints title 'max |error|', "
              "'' every ::1 using 1:9 with linespoints title 'mean |error|', "
              "'' every ::1 using 1:10 with lines dashtype 2 title 'stated bound (half diagonal)', "
              "'' every ::1 using 1:(1e9/$14) axes x1y2 with linespoints title 'lookup ns (1 thread, per CPU-s)', "
              "'' every ::1 using 1:(1e9/$13) axes x1y2 with lines dashtype 3 title 'exact Embree closest ns (per CPU-s)'\n");
}

// --- Google Benchmark micro-benchmarks ----------------------------------------------------

struct MicroFixture {
  std::vector<Part> parts = generated_scene(100000, 11);
  EmbreeIndex embree{parts};
  std::vector<Vec3> pts = near_surface_points(parts, 4096, 10 * kCableRadius, 12);
};
MicroFixture& micro() {
  static MicroFixture f;
  return f;
}

void BM_EmbreeClosest(benchmark::State& state) {
  auto& f = micro();
  std::size_t i = 0;
  for (auto _ : state) benchmark::DoNotOptimize(f.embree.closest(f.pts[i++ & 4095], 10 * kCableRadius));
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_EmbreeClosest);

void BM_EmbreeAnyWithin(benchmark::State& state) {
  auto& f = micro();
  std::size_t i = 0;
  for (auto _ : state) benchmark::DoNotOptimize(f.embree.any_within(f.pts[i++ & 4095], kCableRadius + kClearance));
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_EmbreeAnyWithin);

void BM_EmbreeSegmentWithin(benchmark::State& state) {
  auto& f = micro();
  std::size_t i = 0;
  for (auto _ : state) {
    const Vec3& a = f.pts[i++ & 4095];
    benchmark::DoNotOptimize(f.embree.segment_within(a, a + Vec3(5, 0, 0), kCableRadius));
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_EmbreeSegmentWithin);

}  // namespace

int main(int argc, char** argv) {
  std::filesystem::create_directories(kResults);
  // --micro-only: Google Benchmark only; --build-only / --quality-only / --queries-only:
  // one scenario.
  const std::string mode = argc > 1 ? argv[1] : "";
  if (mode == "--build-only") {
    build_scaling();
    build_quality_tradeoff();
    return 0;
  }
  if (mode == "--probe" && argc > 3) {
    // For instruction counts: valgrind --tool=callgrind --collect-atstart=no
    //   --toggle-collect='loom::ObstacleIndex::closest_batch*' bench_index --probe TRIS QUALITY
    const auto parts = generated_scene(std::strtoul(argv[2], nullptr, 10), 7);
    EmbreeOptions o;
    o.build_quality = std::atoi(argv[3]);
    const EmbreeIndex e(parts, o);
    const auto pts = near_surface_points(parts, 20000, 10 * kCableRadius, 8);
    const double c0 = cpu_now();
    const auto hits = e.closest_batch(pts, 10 * kCableRadius, 1);
    std::cout << "probe: " << count_tris(parts) << " triangles, quality " << o.build_quality << ": "
              << rate(pts.size(), cpu_now() - c0) / 1e6 << " M closest/cpu-s\n";
    benchmark::DoNotOptimize(hits.data());
    return 0;
  }
  if (mode == "--quality-only") {
    build_quality_tradeoff();
    return 0;
  }
  if (mode == "--queries-only") {
    query_throughput();
    return 0;
  }
  if (mode != "--micro-only") {
    build_scaling();
    build_quality_tradeoff();
    query_throughput();
    voxel_tradeoff();
  }
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  return 0;
}
