// Audit benchmark: a generated scene at the seed paper's "complex" scale (≥ 100 cables of
// 1–3 m, d = 2–10 mm, among ≥ 200 closed parts, ~1 M triangles) and a 10× larger one.
// Measures, in one process: index build; the certified audit (all clash kinds + bend +
// clearance) with 1 and 2 threads; the indexed discrete method; the brute-force discrete
// baseline (every sample against every triangle — measured on a subset of cables and
// scaled, it is O(n·m)); time against cables and against triangles — both finer
// tessellation of the same parts and a larger assembly (far copies of the parts, which must
// leave the findings unchanged: the run fails if they do not); and sample spacing against
// time and missed clashes for discrete vs certified.
// Writes bench/results/audit*.csv and charts (gnuplot). Fixed seeds.
//
//   bench_audit [--quick]      (--quick: smaller scenes, for a smoke run)
//   bench_audit --probe TRIS_PER_PART [THREADS [BUILD_QUALITY [REL_ERROR]]]   (one audit of the
//                triangle-scaling scene; BUILD_QUALITY as EmbreeOptions, -1 = automatic)
//   bench_audit --assembly TRIS_PER_PART [MAX_COPIES]   (the assembly series alone, printed)
#include "bench/audit_scenes.hpp"
#include "bench/audit_timing.hpp"
#include "bench/forwarding_index.hpp"
#include "index/embree_index.hpp"
#include "routing/audit/clash_check.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <ctime>
#include <optional>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>
#include <string>
#include <tuple>
#include <vector>

using namespace loom;
using loom::bench::BenchScene;
using loom::bench::make_scene;

namespace {

/// Grid pitch (mm) of the assembly series' copies: the base section spans 0–1000 mm in y
/// and z (parts reach ~200 mm past it, cables ~180 mm), so copies a pitch away stay more
/// than 500 mm from every cable.
constexpr double kAssemblyPitch = 2000.0;
/// Triangles per part of the assembly series' base scene (~195k triangles in 200 parts):
/// 64 copies stay within a few GB.
constexpr int kAssemblyTrisPerPart = 1500;

/// The assembly series' scene: `base` plus `copies` − 1 copies of all its parts, moved by
/// multiples of kAssemblyPitch on a (y, z) grid (6 columns), appended after the base parts
/// (so part ids of the base are unchanged). No copy comes near a cable: the audit's
/// findings are the base scene's, only the indexed assembly grows.
BenchScene with_far_copies(const BenchScene& base, int copies) {
  BenchScene sc = base;
  for (int j = 1; j < copies; ++j) {
    const Vec3 offset(0.0, kAssemblyPitch * (j % 6), kAssemblyPitch * (j / 6));
    for (std::size_t q = 0; q < base.parts.size(); ++q) {
      Part p = base.parts[q];
      p.name += "-copy" + std::to_string(j);
      for (Vec3& v : p.mesh.vertices) v += offset;
      sc.triangles += p.mesh.triangle_count();
      sc.parts.push_back(std::move(p));
    }
  }
  return sc;
}

using bench::cpu_ms;
using bench::now_ms;
using bench::Timed;

/// `req` with only the chosen kinds of check switched on.
ClashRequest with_checks(ClashRequest req, bool structure, bool cable_cable, bool self, bool bend) {
  req.check_structure = structure;
  req.check_cable_cable = cable_cable;
  req.check_self = self;
  req.check_bend = bend;
  return req;
}

/// Best of `reps` runs.
Timed timed_check(const BenchScene& sc, const ObstacleIndex* idx, const ClashRequest& req, int reps = 3) {
  return bench::timed_check(sc.cables, sc.parts, idx, req, reps);
}

using ClashKey = std::tuple<int, int, int>;  // kind, cable, part or other cable
std::set<ClashKey> clash_keys(const ClashResult& r) {
  std::set<ClashKey> k;
  for (const auto& e : r.clashes)
    k.emplace(static_cast<int>(e.kind), e.cable, e.kind == ClashKind::CableStructure ? e.part : e.other);
  return k;
}
int missed(const std::set<ClashKey>& truth, const std::set<ClashKey>& found) {
  int n = 0;
  for (const auto& k : truth)
    if (!found.count(k)) ++n;
  return n;
}

void gnuplot(const std::string& script) {
  const std::string path = std::string(LOOM_SOURCE_DIR) + "/bench/results/audit_plot.gp";
  std::ofstream(path) << script;
  const std::string cmd = "gnuplot " + path + " 2>/dev/null";
  if (std::system(cmd.c_str()) != 0) std::fprintf(stderr, "gnuplot failed (charts not drawn)\n");
  std::filesystem::remove(path);
}

/// Forwards every query to an index and adds up, per method, the calls and the thread CPU
/// time spent in them (single-threaded probes only: the sums are not synchronised). Each
/// call is then made again at once and timed apart: the same work with the index data it
/// touches in cache, so the difference is what the first call waited on memory (plus
/// branch prediction the repeat has learnt).
class SplitIndex : public ForwardingIndex {
 public:
  /// The methods timed, in report order.
  enum Kind { kClosest, kClosestApprox, kSegmentClosest, kSegmentApprox, kSegmentOnPart, kClosestOnPart, kInside, kOther, kKinds };
  explicit SplitIndex(const ObstacleIndex& inner) : ForwardingIndex(inner) {}
  ClosestHit closest(const Vec3& p, double r) const override {
    return timed(kClosest, [&] { return inner_.closest(p, r); });
  }
  ClosestHit closest_approx(const Vec3& p, double r, double e) const override {
    return timed(kClosestApprox, [&] { return inner_.closest_approx(p, r, e); });
  }
  ClosestHit closest_on_part(const Vec3& p, int part, double r) const override {
    return timed(kClosestOnPart, [&] { return inner_.closest_on_part(p, part, r); });
  }
  bool inside(const Vec3& p, int* part) const override {
    return timed(kInside, [&] { return inner_.inside(p, part); });
  }
  void inside_parts(const Vec3& p, std::vector<int>& out) const override {
    timed(kInside, [&] {
      inner_.inside_parts(p, out);
      return out.size();
    });
  }
  RayHit ray(const Vec3& o, const Vec3& d, double t) const override {
    return timed(kOther, [&] { return inner_.ray(o, d, t); });
  }
  bool any_within(const Vec3& p, double r) const override {
    return timed(kOther, [&] { return inner_.any_within(p, r); });
  }
  bool segment_within(const Vec3& a, const Vec3& b, double r) const override {
    return timed(kOther, [&] { return inner_.segment_within(a, b, r); });
  }
  ClosestHit segment_closest(const Vec3& a, const Vec3& b, double r, double* t) const override {
    return timed(kSegmentClosest, [&] { return inner_.segment_closest(a, b, r, t); });
  }
  ClosestHit segment_closest_approx(const Vec3& a, const Vec3& b, double r, double e, double* t) const override {
    return timed(kSegmentApprox, [&] { return inner_.segment_closest_approx(a, b, r, e, t); });
  }
  ClosestHit segment_closest_on_part(const Vec3& a, const Vec3& b, int part, double r, double* t) const override {
    return timed(kSegmentOnPart, [&] { return inner_.segment_closest_on_part(a, b, part, r, t); });
  }
  /// Prints calls and CPU ms per method, and per call the first call's and the repeat's.
  void print() const {
    const char* names[kKinds] = {"closest", "closest_approx", "segment_closest", "segment_approx", "segment_on_part",
                                 "closest_on_part", "inside", "other"};
    for (int k = 0; k < kKinds; ++k)
      if (calls_[k] > 0)
        std::printf("  %-16s %7lld calls %8.1f cpu ms %6.2f us/call (repeated at once: %5.2f us)\n", names[k],
                    calls_[k], ms_[k], 1000.0 * ms_[k] / static_cast<double>(calls_[k]),
                    1000.0 * hot_ms_[k] / static_cast<double>(calls_[k]));
  }

 private:
  static double thread_ms() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return 1e3 * static_cast<double>(ts.tv_sec) + 1e-6 * static_cast<double>(ts.tv_nsec);
  }
  template <class F>
  auto timed(Kind k, const F& f) const -> decltype(f()) {
    const double t0 = thread_ms();
    auto out = f();
    const double t1 = thread_ms();
    (void)f();
    hot_ms_[k] += thread_ms() - t1;
    ms_[k] += t1 - t0;
    ++calls_[k];
    return out;
  }
  mutable double ms_[kKinds] = {};
  mutable double hot_ms_[kKinds] = {};
  mutable long long calls_[kKinds] = {};
};

/// FNV-1a over everything an audit reports (clashes, violations, per-cable summaries,
/// counters), bit for bit: two runs with the same digest gave the same report.
std::uint64_t result_digest(const ClashResult& r) {
  std::uint64_t h = 1469598103934665603ull;
  auto add = [&](const void* p, std::size_t n) {
    for (std::size_t i = 0; i < n; ++i) h = (h ^ static_cast<const unsigned char*>(p)[i]) * 1099511628211ull;
  };
  auto num = [&](double v) { add(&v, sizeof v); };
  auto vec = [&](const Vec3& v) { num(v.x()), num(v.y()), num(v.z()); };
  for (const auto& e : r.clashes) {
    const int ints[] = {static_cast<int>(e.kind), e.cable, e.part, e.other, e.keep_out, e.inside};
    add(ints, sizeof ints);
    for (double v : {e.clearance, e.s, e.s_other, e.s_begin, e.s_end}) num(v);
    vec(e.point);
  }
  for (const auto& v : r.violations) {
    const int ints[] = {static_cast<int>(v.kind), v.cable, v.part};
    add(ints, sizeof ints);
    for (double x : {v.value, v.limit, v.s}) num(x);
    vec(v.point);
  }
  for (const auto& c : r.cables) {
    for (double x : {c.length, c.min_clearance, c.min_bend_radius, c.min_bend_s}) num(x);
    const int e = c.min_clearance_exact;
    add(&e, sizeof e);
  }
  const std::int64_t cnt[] = {r.counters.distance_queries, r.counters.inside_queries, r.counters.pair_tests,
                              r.counters.samples};
  add(cnt, sizeof cnt);
  return h;
}

/// One certified audit of the triangle-scaling scene (seed 7: the same 200 parts and 100
/// cables at every size, only the tessellation changes) with `tris_per_part` triangles per
/// part, for CPU time and instruction counts: `valgrind --tool=callgrind bench_audit --probe
/// N`, then the inclusive count of loom::check_clashes in callgrind_annotate --inclusive=yes
/// (a --toggle-collect on it would be toggled off again by its own nested lambdas). The
/// audit runs twice: the first run pays for anything the index builds lazily. A third,
/// single-threaded run through SplitIndex prints CPU time per index method. The digest
/// identifies the whole report (it must not change when only the speed does).
int probe(int tris_per_part, int threads, int build_quality, double rel_error) {
  const BenchScene sc = make_scene(200, tris_per_part, 100, 1.0, 7);
  const double b0 = cpu_ms();
  EmbreeOptions eo;
  eo.build_quality = build_quality;
  const EmbreeIndex idx(sc.parts, eo);
  const double index_cpu = cpu_ms() - b0;
  ClashRequest req;
  req.routing_clearance = 3.0;
  req.threads = threads;
  if (rel_error >= 0.0) req.distance_rel_error = rel_error;
  const double c0 = cpu_ms();
  const ClashResult r = check_clashes(sc.cables, sc.parts, &idx, req);
  const double first = cpu_ms() - c0;
  const double c1 = cpu_ms();
  check_clashes(sc.cables, sc.parts, &idx, req);  // again: what is left once the index is warm
  std::printf("probe: %zu triangles, %d threads: index cpu %.1f ms, audit cpu %.1f ms (again %.1f ms), %lld distance queries, %lld inside queries, %lld samples, "
              "%zu clashes, %zu violations, digest %016llx\n",
              sc.triangles, threads, index_cpu, first, cpu_ms() - c1, static_cast<long long>(r.counters.distance_queries),
              static_cast<long long>(r.counters.inside_queries), static_cast<long long>(r.counters.samples),
              r.clashes.size(), r.violations.size(), static_cast<unsigned long long>(result_digest(r)));
  const SplitIndex split(idx);
  req.threads = 1;
  const double c2 = cpu_ms();
  const ClashResult rs = check_clashes(sc.cables, sc.parts, &split, req);
  std::printf("split (1 thread, timer overhead and the repeats included): audit cpu %.1f ms, digest %016llx; %lld chords in band deferred, "
              "%lld of them measured exactly\n",
              cpu_ms() - c2, static_cast<unsigned long long>(result_digest(rs)),
              static_cast<long long>(rs.counters.deferred_chords), static_cast<long long>(rs.counters.deferred_measured));
  split.print();
  return 0;
}

/// The assembly series: 1, 2, 4, ... `max_copies` copies of a base scene's parts
/// (`tris_per_part` triangles each, 100 cables), index build and certified audit time on 2
/// threads, as "assembly" rows of audit_scaling.csv when `csv` is given. Returns 1 (after
/// saying so) if the findings differ from the base scene's: the copies are far from every
/// cable, so they must not.
int assembly_series(std::ostream* csv, int tris_per_part, int max_copies) {
  const BenchScene base = make_scene(200, tris_per_part, 100, 1.0, 7);
  std::set<ClashKey> base_keys;
  for (int copies = 1; copies <= max_copies; copies *= 2) {
    const BenchScene sc = with_far_copies(base, copies);
    const double t0 = now_ms();
    const EmbreeIndex idx(sc.parts);
    const double index_ms = now_ms() - t0;
    ClashRequest req;
    req.routing_clearance = 3.0;
    req.threads = 2;
    const Timed t = timed_check(sc, &idx, req);
    const std::set<ClashKey> keys = clash_keys(t.res);
    if (copies == 1) base_keys = keys;
    std::printf("assembly x%d: %zu parts, %zu triangles: index %.0f ms, certified %.1f ms (cpu %.1f), %zu clashes, "
                "%zu violations, digest %016llx\n",
                copies, sc.parts.size(), sc.triangles, index_ms, t.ms, t.cpu, t.res.clashes.size(),
                t.res.violations.size(), static_cast<unsigned long long>(result_digest(t.res)));
    if (keys != base_keys) {
      std::fprintf(stderr, "assembly x%d: the findings differ from the base scene's\n", copies);
      return 1;
    }
    if (csv)
      *csv << "assembly," << sc.cables.size() << "," << sc.triangles << "," << t.ms << "," << t.cpu << ",,,,"
           << sc.parts.size() << "," << index_ms << "\n";
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const bool quick = argc > 1 && std::string(argv[1]) == "--quick";
  const std::string dir = std::string(LOOM_SOURCE_DIR) + "/bench/results/";
  std::filesystem::create_directories(dir);
  const int base_parts = quick ? 40 : 200, base_cables = quick ? 20 : 100, tris = 7500;

  if (argc > 2 && std::string(argv[1]) == "--probe")
    return probe(std::atoi(argv[2]), argc > 3 ? std::atoi(argv[3]) : 1, argc > 4 ? std::atoi(argv[4]) : -1,
                 argc > 5 ? std::atof(argv[5]) : -1.0);
  if (argc > 2 && std::string(argv[1]) == "--assembly")
    return assembly_series(nullptr, std::atoi(argv[2]), argc > 3 ? std::atoi(argv[3]) : 64);
  const bool breakdown_only = argc > 1 && std::string(argv[1]) == "--breakdown";
  {
    // Where the certified time goes (each check kind alone), paper-scale scene.
    const BenchScene sc = make_scene(base_parts, tris, base_cables, 1.0, 42);
    EmbreeIndex idx(sc.parts);
    std::ofstream csv(dir + "audit_breakdown.csv");
    csv << "part,ms,cpu_ms,distance_queries,pair_tests,samples\n";
    for (int part = 0; part < 5; ++part) {
      ClashRequest req;
      req.routing_clearance = 3.0;
      req.threads = 2;
      const bool all = part == 4;
      const Timed t = timed_check(
          sc, &idx, with_checks(req, all || part == 0, all || part == 1, all || part == 2, all || part == 3));
      const char* names[] = {"structure", "cable-cable", "self", "bend", "all"};
      csv << names[part] << "," << t.ms << "," << t.cpu << "," << t.res.counters.distance_queries << "," << t.res.counters.pair_tests
          << "," << t.res.counters.samples << "\n";
      std::printf("%-12s %8.1f ms (cpu %.1f)  %lld queries  %lld pair tests  %lld samples\n", names[part], t.ms, t.cpu,
                  static_cast<long long>(t.res.counters.distance_queries),
                  static_cast<long long>(t.res.counters.pair_tests), static_cast<long long>(t.res.counters.samples));
    }
    if (breakdown_only) return 0;
  }

  // ---- 1. paper scale and 10× -------------------------------------------------------
  std::ofstream main_csv(dir + "audit.csv");
  main_csv << "scene,parts,triangles,cables,index_ms,certified_1t_ms,certified_2t_ms,speedup_2t,"
              "certified_1t_cpu_ms,certified_2t_cpu_ms,"
              "discrete_indexed_ms,brute_discrete_ms_extrapolated,ratio_vs_brute,clashes,violations,"
              "distance_queries\n";
  for (int mult : {1, 10}) {
    if (quick && mult == 10) break;
    const BenchScene sc = make_scene(base_parts * mult, tris, base_cables * mult, std::cbrt(mult), 42);
    double t0 = now_ms();
    EmbreeIndex idx(sc.parts);
    const double index_ms = now_ms() - t0;
    ClashRequest req;
    req.routing_clearance = 3.0;
    req.threads = 1;
    const Timed c1 = timed_check(sc, &idx, req);
    req.threads = 2;
    const Timed c2 = timed_check(sc, &idx, req);
    ClashRequest dreq = req;
    dreq.method = ClashMethod::Discrete;
    const Timed d2 = timed_check(sc, &idx, dreq, 1);
    // Brute force (the paper's O(n·m)): every sample against every triangle. Its cost per
    // sample is the same everywhere, so it is measured on a probe cable of 41 samples and
    // scaled to the scene's sample count; cable pairs (quadratic in samples) on 20 cables,
    // scaled by the number of pairs.
    double brute_ms = 0.0;
    {
      double total_samples = 0.0;
      for (const auto& c : sc.cables) total_samples += std::ceil(c.curve.length() / (2.0 * c.radius)) + 1.0;
      BenchScene probe;
      probe.parts = sc.parts;
      CableInput pc = sc.cables[0];
      const Vec3 a = pc.curve.position(pc.curve.u_min());
      pc.curve = Centerline::polyline({a, a + Vec3(80.0 * pc.radius, 0, 0)});
      probe.cables.push_back(pc);
      ClashRequest b = dreq;
      b.use_index = false;
      b.check_cable_cable = false;
      const Timed bs = timed_check(probe, nullptr, b, 1);
      brute_ms += bs.ms / static_cast<double>(bs.res.counters.samples) * total_samples;
      const int kc = std::min<int>(20, static_cast<int>(sc.cables.size()));
      BenchScene sub2;
      sub2.cables.assign(sc.cables.begin(), sc.cables.begin() + kc);
      ClashRequest b2 = b;
      b2.check_structure = false;
      b2.check_self = true;
      b2.check_cable_cable = true;
      const Timed bc = timed_check(sub2, nullptr, b2, 1);
      const double n = static_cast<double>(sc.cables.size());
      brute_ms += bc.ms * (n * (n - 1)) / (kc * (kc - 1.0));
    }
    std::printf("scene x%d: %zu parts, %zu tris, %zu cables: index %.0f ms, certified 1t %.1f ms (cpu %.1f), 2t %.1f ms "
                "(%.2fx), discrete %.1f ms, brute ~%.0f ms (%.0fx), %zu clashes, %zu violations\n",
                mult, sc.parts.size(), sc.triangles, sc.cables.size(), index_ms, c1.ms, c1.cpu, c2.ms, c1.ms / c2.ms, d2.ms,
                brute_ms, brute_ms / c2.ms, c2.res.clashes.size(), c2.res.violations.size());
    main_csv << "x" << mult << "," << sc.parts.size() << "," << sc.triangles << "," << sc.cables.size() << ","
             << index_ms << "," << c1.ms << "," << c2.ms << "," << c1.ms / c2.ms << "," << c1.cpu << "," << c2.cpu
             << "," << d2.ms << "," << brute_ms
             << "," << brute_ms / c2.ms << "," << c2.res.clashes.size() << "," << c2.res.violations.size() << ","
             << c2.res.counters.distance_queries << "\n";
  }
  main_csv.close();

  // ---- 2. time vs cables (fixed parts) and vs triangles (fixed cables) -----------------
  {
    std::ofstream csv(dir + "audit_scaling.csv");
    // Per cable count also the cable–structure pass alone and the cable–cable + self pass
    // alone (with its pair tests): cables added to a fixed volume meet each other more often.
    // Two triangle series: the same 200 parts tessellated finer (the cables meet more
    // facets), and the assembly grown by far copies of its parts (only the index grows).
    csv << "series,cables,triangles,certified_ms,certified_cpu_ms,structure_ms,pairs_ms,pair_tests,parts,index_ms\n";
    const BenchScene big = make_scene(base_parts, tris, quick ? 80 : 400, 1.0, 7);
    EmbreeIndex idx(big.parts);
    for (int n : {25, 50, 100, 200, 400}) {
      if (n > static_cast<int>(big.cables.size())) break;
      BenchScene sub;
      sub.parts = big.parts;
      sub.cables.assign(big.cables.begin(), big.cables.begin() + n);
      ClashRequest req;
      req.routing_clearance = 3.0;
      req.threads = 2;
      const Timed t = timed_check(sub, &idx, req);
      const Timed structure = timed_check(sub, &idx, with_checks(req, true, false, false, false));
      const Timed pairs = timed_check(sub, &idx, with_checks(req, false, true, true, false));
      csv << "cables," << n << "," << big.triangles << "," << t.ms << "," << t.cpu << "," << structure.ms << ","
          << pairs.ms << "," << pairs.res.counters.pair_tests << "," << big.parts.size() << ",\n";
      std::printf("cables %d: %.1f ms (structure %.1f ms, cable-cable + self %.1f ms, %lld pair tests)\n", n, t.ms,
                  structure.ms, pairs.ms, static_cast<long long>(pairs.res.counters.pair_tests));
    }
    for (int tp : {500, 1500, 5000, 15000, 50000}) {
      if (quick && tp > 5000) break;
      const BenchScene sc = make_scene(base_parts, tp, base_cables, 1.0, 7);
      const double t0 = now_ms();
      EmbreeIndex ix(sc.parts);
      const double index_ms = now_ms() - t0;
      ClashRequest req;
      req.routing_clearance = 3.0;
      req.threads = 2;
      const Timed t = timed_check(sc, &ix, req);
      csv << "triangles," << sc.cables.size() << "," << sc.triangles << "," << t.ms << "," << t.cpu << ",,,,"
          << sc.parts.size() << "," << index_ms << "\n";
      std::printf("triangles %zu: %.1f ms\n", sc.triangles, t.ms);
    }
    if (assembly_series(&csv, kAssemblyTrisPerPart, quick ? 4 : 64) != 0) return 1;
  }

  // ---- 3. speed vs accuracy: spacing (discrete) and tolerance (certified) ---------------
  {
    std::ofstream csv(dir + "audit_accuracy.csv");
    csv << "method,parameter,time_ms,cpu_ms,clashes,missed\n";
    const BenchScene sc = make_scene(base_parts, tris, base_cables, 1.0, 42);
    EmbreeIndex idx(sc.parts);
    ClashRequest req;
    req.routing_clearance = 3.0;
    req.threads = 2;
    req.tolerance = 0.001;
    const Timed truth = timed_check(sc, &idx, req, 1);
    const auto truth_keys = clash_keys(truth.res);
    for (double tol : {0.1, 0.03, 0.01, 0.003, 0.001}) {
      req.tolerance = tol;
      const Timed t = timed_check(sc, &idx, req);
      csv << "certified," << tol << "," << t.ms << "," << t.cpu << "," << t.res.clashes.size() << ","
          << missed(truth_keys, clash_keys(t.res)) << "\n";
    }
    for (double sp : {16.0, 8.0, 4.0, 2.0, 1.0, 0.5, 0.25}) {
      ClashRequest d = req;
      d.method = ClashMethod::Discrete;
      d.spacing = sp;
      const Timed t = timed_check(sc, &idx, d, 1);
      const int m = missed(truth_keys, clash_keys(t.res));
      csv << "discrete," << sp << "," << t.ms << "," << t.cpu << "," << t.res.clashes.size() << "," << m << "\n";
      std::printf("discrete spacing %.2f: %.1f ms, missed %d of %zu\n", sp, t.ms, m, truth_keys.size());
    }
    ClashRequest d = req;
    d.method = ClashMethod::Discrete;
    d.spacing = 0.0;  // the paper's rule, 2r per cable
    const Timed t = timed_check(sc, &idx, d, 1);
    csv << "discrete-2r,0," << t.ms << "," << t.cpu << "," << t.res.clashes.size() << "," << missed(truth_keys, clash_keys(t.res))
        << "\n";
  }

  gnuplot("set datafile separator ','\nset terminal pngcairo size 1400,450\nset output '" + dir +
          "audit.png'\nset multiplot layout 1,3\n"
          "set title 'certified audit time vs cables (200 parts)'\nset xlabel 'cables'\nset ylabel 'CPU ms (both threads)'\nset key off\n"
          "plot '" + dir + "audit_scaling.csv' using (strcol(1) eq 'cables' ? $2 : 1/0):5 with linespoints pt 7\n"
          "set title 'certified audit time vs triangles (100 cables)'\nset xlabel 'triangles'\nset logscale x\n"
          "set key top left\n"
          "plot '" + dir + "audit_scaling.csv' using (strcol(1) eq 'triangles' ? $3 : 1/0):5 with linespoints pt 7 "
          "title 'finer tessellation (200 parts)', '' using (strcol(1) eq 'assembly' ? $3 : 1/0):5 with linespoints pt 5 "
          "title 'more parts, far from the cables'\n"
          "unset logscale x\nset title 'speed vs accuracy'\nset xlabel 'CPU time (ms)'\nset ylabel 'missed clashes'\n"
          "set logscale x\nset key top right\n"
          "plot '" + dir + "audit_accuracy.csv' using (strcol(1) eq 'discrete' ? $4 : 1/0):6:(sprintf('%g', $2)) "
          "with labels offset 0,1 notitle, '' using (strcol(1) eq 'discrete' ? $4 : 1/0):6 with linespoints pt 7 "
          "title 'discrete (label: spacing mm)', '' using (strcol(1) eq 'certified' ? $4 : 1/0):6 with linespoints "
          "pt 5 title 'certified (tolerance 0.1 .. 0.001)'\nunset multiplot\n");
  return 0;
}
