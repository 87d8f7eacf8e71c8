// Centerline benchmark: a 1 m, r = 2 mm cable at 0.01 mm chord tolerance
// interpolated + faired + swept on one core (target < 90 µs; the scan seed reports 9 ms per
// cable surface), 1000 cables on 1 and 2 threads (target < 50 ms on 2), against an
// OpenCASCADE baseline run in the same process (GeomAPI_Interpolate + BRepOffsetAPI_MakePipe
// + BRepMesh at the same deflection — the seed's own tool chain), plus the charts
// fairing ε/α → max deviation and ∫κ²ds, and sweep tolerance → triangles and time.
// Writes bench/results/centerline*.csv and .png (gnuplot). Fixed seeds. Scene units: mm.
// `bench_centerline --quick`: only the per-cable and 1-thread batch figures, printed with a
// fingerprint of one cable's results (no baseline, no files) — for profiling changes.
// Each thread sweeps its cables into one SweepResult whose storage it reuses (as a batch
// writer would); the single-cable figures are also given with a new mesh per cable.
#include "core/centerline.hpp"
#include "routing/curve/fairing.hpp"
#include "routing/curve/sweep.hpp"

#include <BRepBuilderAPI_MakeEdge.hxx>
#include <BRepBuilderAPI_MakeWire.hxx>
#include <BRepMesh_IncrementalMesh.hxx>
#include <BRepOffsetAPI_MakePipe.hxx>
#include <BRep_Tool.hxx>
#include <GeomAPI_Interpolate.hxx>
#include <Geom_BSplineCurve.hxx>
#include <Geom_Circle.hxx>
#include <Poly_Triangulation.hxx>
#include <Standard_Failure.hxx>
#include <TColgp_HArray1OfPnt.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Wire.hxx>

#include <tbb/enumerable_thread_specific.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <signal.h>
#include <sys/wait.h>
#include <malloc.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <ctime>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <random>
#include <string>
#include <vector>

using namespace loom;

namespace {

const std::string kResults = std::string(LOOM_SOURCE_DIR) + "/bench/results/";
constexpr double kCableLength = 1000.0;   // mm
constexpr double kRadius = 2.0;           // mm
constexpr double kChordTolerance = 0.01;  // mm
constexpr double kFairingTolerance = 0.5; // mm: how far fairing may move a key point
constexpr int kCables = 1000;
/// The OpenCASCADE baseline runs in a child process killed after this long (MakePipe may hang).
constexpr unsigned kBaselineTimeoutSeconds = 900;
/// Cables timed in the OpenCASCADE baseline (it takes seconds per cable).
constexpr int kBaselineCables = 3;
/// Heap the process keeps instead of returning freed pages to the kernel, in the second
/// measurement (larger than all meshes of a batch in flight).
constexpr int kRetainedHeapBytes = 1 << 30;

/// Single-thread measures use this thread's CPU time (the machine is shared: wall time
/// would count other processes); batch measures use wall time.
struct Clock {
  using time_point = double;
  static double now() {
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return t.tv_sec * 1e6 + t.tv_nsec * 1e-3;
  }
};
double us_since(double t0) { return Clock::now() - t0; }
using Wall = std::chrono::steady_clock;
double wall_us_since(Wall::time_point t0) {
  return std::chrono::duration<double, std::micro>(Wall::now() - t0).count();
}

/// A routed-cable-like set of key points: ~1 m long, legs of 60–120 mm turning ≤ 50°, with
/// a little noise (as a planner's waypoints), leaving along +x.
std::vector<Vec3> cable_points(unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> leg(60.0, 120.0), ang(-1.0, 1.0);
  std::normal_distribution<double> noise(0.0, 0.3);
  std::vector<Vec3> p{Vec3::Zero()};
  Vec3 dir = Vec3::UnitX();
  double len = 0.0;
  while (len < kCableLength) {
    const double l = std::min(leg(rng), kCableLength - len + 1e-9);
    p.push_back(p.back() + l * dir + Vec3(noise(rng), noise(rng), noise(rng)));
    len += l;
    const Vec3 axis = Vec3(ang(rng), ang(rng), ang(rng)).normalized();
    dir = (Eigen::AngleAxisd(0.87 * ang(rng), axis) * dir).normalized();
  }
  return p;
}

struct Pipeline {
  double interp_us = 0, fair_us = 0, sweep_us = 0;
  std::size_t triangles = 0;
  int rings = 0;
};

/// One cable: interpolate (exit tangents), fair (energy), sweep (tube) into `sw` (its
/// storage reused when the caller keeps it across cables).
Pipeline run_cable(const std::vector<Vec3>& p, bool timed, SweepResult& sw) {
  Pipeline r;
  InterpolationOptions io;
  io.start_tangent = Vec3::UnitX();
  io.end_tangent = (p.back() - p[p.size() - 2]).normalized();
  auto t0 = Clock::now();
  const Centerline c = Centerline::interpolate(p, io);
  if (timed) r.interp_us = us_since(t0);
  t0 = Clock::now();
  FairingOptions f;
  f.tolerance = kFairingTolerance;
  const FairingResult fr = fair_energy(c, f);
  if (timed) r.fair_us = us_since(t0);
  t0 = Clock::now();
  sweep_tube(fr.curve, kRadius, {kChordTolerance, true}, sw);
  if (timed) r.sweep_us = us_since(t0);
  r.triangles = sw.mesh.triangle_count();
  r.rings = sw.rings;
  return r;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

/// The seed's tool chain in OpenCASCADE: interpolate, pipe a circle along it, mesh at the
/// same chord deflection. Returns {µs per cable, triangles}, run in a child process with a
/// time limit; {-1, 0} if it failed or timed out.
std::pair<double, double> occt_baseline(const std::vector<std::vector<Vec3>>& cables) {
  int fds[2];
  if (pipe(fds) != 0) return {-1, 0};
  const pid_t pid = fork();
  if (pid == 0) {
    close(fds[0]);
    alarm(kBaselineTimeoutSeconds);
    double total = 0, tris = 0, failed = 0;
    for (const auto& p : cables) try {
      const auto t0 = Clock::now();
      Handle(TColgp_HArray1OfPnt) P = new TColgp_HArray1OfPnt(1, static_cast<int>(p.size()));
      for (std::size_t i = 0; i < p.size(); ++i) P->SetValue(static_cast<int>(i) + 1, gp_Pnt(p[i].x(), p[i].y(), p[i].z()));
      GeomAPI_Interpolate gi(P, Standard_False, 1e-9);
      const Vec3 t1 = (p.back() - p[p.size() - 2]).normalized();
      gi.Load(gp_Vec(1, 0, 0), gp_Vec(t1.x(), t1.y(), t1.z()));
      gi.Perform();
      const TopoDS_Edge spine_e = BRepBuilderAPI_MakeEdge(gi.Curve());
      const TopoDS_Wire spine = BRepBuilderAPI_MakeWire(spine_e);
      Handle(Geom_Circle) circ = new Geom_Circle(gp_Ax2(gp_Pnt(p[0].x(), p[0].y(), p[0].z()), gp_Dir(1, 0, 0)), kRadius);
      const TopoDS_Wire prof = BRepBuilderAPI_MakeWire(BRepBuilderAPI_MakeEdge(circ));
      BRepOffsetAPI_MakePipe pipe_op(spine, prof);
      pipe_op.Build();
      if (!pipe_op.IsDone()) {  // OpenCASCADE could not pipe this spine: counted, not timed
        ++failed;
        continue;
      }
      BRepMesh_IncrementalMesh mesh(pipe_op.Shape(), kChordTolerance, Standard_False, 0.5, Standard_False);
      for (TopExp_Explorer ex(pipe_op.Shape(), TopAbs_FACE); ex.More(); ex.Next()) {
        TopLoc_Location loc;
        const Handle(Poly_Triangulation) tr = BRep_Tool::Triangulation(TopoDS::Face(ex.Current()), loc);
        if (!tr.IsNull()) tris += tr->NbTriangles();
      }
      total += us_since(t0);
    } catch (const Standard_Failure&) {
      ++failed;
    }
    const double ok = static_cast<double>(cables.size()) - failed;
    const double out[3] = {ok > 0 ? total / ok : -1.0, ok > 0 ? tris / ok : 0.0, failed};
    if (write(fds[1], out, sizeof out) != static_cast<ssize_t>(sizeof out)) _exit(3);
    _exit(0);
  }
  close(fds[1]);
  double in[3] = {-1, 0, 0};
  const ssize_t got = read(fds[0], in, sizeof in);
  close(fds[0]);
  int status = 0;
  waitpid(pid, &status, 0);
  if (got != static_cast<ssize_t>(sizeof in) || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    std::fprintf(stderr, "OpenCASCADE baseline failed (exit %d, signal %d)\n", WIFEXITED(status) ? WEXITSTATUS(status) : -1,
                 WIFSIGNALED(status) ? WTERMSIG(status) : 0);
    return {-1, 0};
  }
  if (in[2] > 0) std::fprintf(stderr, "OpenCASCADE MakePipe failed on %.0f of %zu cables\n", in[2], cables.size());
  return {in[0], in[1]};
}

/// Single-cable and batch figures of one heap configuration.
struct Measures {
  double single = 0, interp = 0, fair = 0, sweep = 0;  ///< medians, µs of thread CPU time
  double triangles = 0, rings = 0;                      ///< means per cable
  double batch1 = 0, batch2 = 0;                        ///< 1000 cables, ms wall, 1 and 2 threads
  double batch1_cpu = 0;                                ///< 1000 cables on 1 thread, ms of process CPU time
};

double process_cpu_ms() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return t.tv_sec * 1e3 + t.tv_nsec * 1e-6;
}

/// One cable on one core (600 runs over 200 cables), then 1000 cables on 1 and (unless
/// quick) 2 threads, three runs each (medians). With `reuse`, each thread sweeps into one
/// SweepResult kept across its cables; without, every cable gets a new one.
Measures measure(const std::vector<std::vector<Vec3>>& cables, bool quick, bool reuse) {
  Measures m;
  SweepResult kept_result;
  std::vector<double> ti, tf, ts, tt;
  std::size_t tris = 0;
  int rings = 0;
  for (int rep = 0; rep < 3; ++rep)
    for (int i = 0; i < 200; ++i) {
      const auto t0 = Clock::now();
      SweepResult fresh_result;
      const Pipeline p = run_cable(cables[i], true, reuse ? kept_result : fresh_result);
      tt.push_back(us_since(t0));
      ti.push_back(p.interp_us);
      tf.push_back(p.fair_us);
      ts.push_back(p.sweep_us);
      tris += p.triangles;
      rings += p.rings;
    }
  m.single = median(tt);
  m.interp = median(ti);
  m.fair = median(tf);
  m.sweep = median(ts);
  m.triangles = static_cast<double>(tris) / tt.size();
  m.rings = static_cast<double>(rings) / tt.size();
  auto batch = [&](int threads, double* cpu_ms) {
    tbb::global_control gc(tbb::global_control::max_allowed_parallelism, threads);
    std::vector<double> runs, cpu;
    tbb::enumerable_thread_specific<SweepResult> per_thread;
    for (int rep = 0; rep < 3; ++rep) {
      const auto t0 = Wall::now();
      const double c0 = process_cpu_ms();
      tbb::parallel_for(0, kCables, [&](int i) {
        SweepResult fresh_result;
        run_cable(cables[i], false, reuse ? per_thread.local() : fresh_result);
      });
      cpu.push_back(process_cpu_ms() - c0);
      runs.push_back(wall_us_since(t0) / 1000.0);
    }
    if (cpu_ms) *cpu_ms = median(cpu);
    return median(runs);
  };
  m.batch1 = batch(1, &m.batch1_cpu);
  m.batch2 = quick ? 0.0 : batch(2, nullptr);
  return m;
}

void gnuplot(const std::string& name, const std::string& script) {
  const std::string gp = kResults + name + ".gp";
  std::ofstream(gp) << "set terminal pngcairo size 900,560\nset output '" << kResults << name << ".png'\n"
                    << "set datafile separator ','\nset grid\n"
                    << script;
  const std::string cmd = "gnuplot '" + gp + "' 2>/dev/null";
  if (std::system(cmd.c_str()) != 0) std::fprintf(stderr, "gnuplot failed for %s\n", name.c_str());
  std::remove(gp.c_str());
}

}  // namespace

int main(int argc, char** argv) {
  // --quick: only the single-cable and 1000-cable measures, printed (process CPU time for the
  // batch), no OpenCASCADE baseline, no CSV or charts — for profiling on a busy machine.
  const bool quick = argc > 1 && std::string(argv[1]) == "--quick";
  std::vector<std::vector<Vec3>> cables;
  for (int i = 0; i < kCables; ++i) cables.push_back(cable_points(1000u + i));

  // --- same-process baseline: OpenCASCADE pipe + mesh (forked before TBB starts threads) ---
  const std::vector<std::vector<Vec3>> sample(cables.begin(), cables.begin() + kBaselineCables);
  const auto [occt_us, occt_tris] = quick ? std::pair<double, double>(-1, 0) : occt_baseline(sample);

  // --- one cable on one core; 1000 cables on 1 and 2 threads -----------------------------
  // Measured with glibc's default heap policy, each thread reusing one SweepResult (the
  // headline figures); with a new mesh per cable (every discarded ~0.5 MB mesh goes back to
  // the kernel and the next cable page-faults it in again: what a program that keeps all
  // its meshes pays too, once per mesh); then with the freed heap kept by the process.
  const Measures fresh = measure(cables, quick, true);
  const Measures unreused = measure(cables, quick, false);
  mallopt(M_MMAP_THRESHOLD, kRetainedHeapBytes);
  mallopt(M_TRIM_THRESHOLD, kRetainedHeapBytes);
  const Measures kept = measure(cables, quick, true);
  auto heap_name = [&](const Measures* m) {
    return m == &fresh ? "default heap, mesh reused"
                       : m == &unreused ? "default heap, new mesh per cable" : "heap kept, mesh reused";
  };
  if (quick) {
    {  // fingerprint of one cable's pipeline output (to check that speed-ups change no result)
      InterpolationOptions io;
      io.start_tangent = Vec3::UnitX();
      io.end_tangent = (cables[5].back() - cables[5][cables[5].size() - 2]).normalized();
      FairingOptions f;
      f.tolerance = kFairingTolerance;
      const FairingResult fr = fair_energy(Centerline::interpolate(cables[5], io), f);
      const SweepResult sw = sweep_tube(fr.curve, kRadius, {kChordTolerance, true});
      double sum = 0.0;
      for (const Vec3& v : sw.mesh.vertices) sum += v.x() + 2.0 * v.y() + 3.0 * v.z();
      std::printf("fingerprint: length %.17g alpha %.17g energy %.17g vertices %zu sum %.17g turn %.17g\n",
                  fr.curve.length(), fr.alpha, bending_energy(fr.curve), sw.mesh.vertices.size(), sum, sw.max_frame_turn);
    }
    for (const Measures* m : {&fresh, &unreused, &kept})
      std::printf("%s: one cable %.1f us CPU (interp %.1f, fair %.1f, sweep %.1f), %.0f triangles, %.0f rings; "
                  "1000 cables on 1 thread %.1f ms CPU\n",
                  heap_name(m), m->single, m->interp, m->fair, m->sweep, m->triangles, m->rings, m->batch1_cpu);
    return 0;
  }
  const double single = fresh.single, batch1 = fresh.batch1, batch2 = fresh.batch2;

  {
    std::ofstream o(kResults + "centerline.csv");
    o << "measure,value,unit,target\n";
    o << "single_cable_total," << single << ",us_cpu,90\n";
    o << "single_cable_interpolate," << fresh.interp << ",us_cpu,\n";
    o << "single_cable_fair," << fresh.fair << ",us_cpu,\n";
    o << "single_cable_sweep," << fresh.sweep << ",us_cpu,\n";
    o << "single_cable_triangles," << fresh.triangles << ",count,\n";
    o << "single_cable_rings," << fresh.rings << ",count,\n";
    o << "batch_1000_cables_1_thread," << batch1 << ",ms,\n";
    o << "batch_1000_cables_2_threads," << batch2 << ",ms,50\n";
    o << "speedup_2_threads," << batch1 / batch2 << ",ratio,\n";
    o << "batch_1000_cables_1_thread_cpu," << fresh.batch1_cpu << ",ms_cpu,\n";
    // The same with a new SweepResult per cable (its mesh memory page-faulted in each time).
    o << "new_mesh_single_cable_total," << unreused.single << ",us_cpu,90\n";
    o << "new_mesh_single_cable_sweep," << unreused.sweep << ",us_cpu,\n";
    o << "new_mesh_batch_1000_cables_1_thread_cpu," << unreused.batch1_cpu << ",ms_cpu,\n";
    o << "new_mesh_batch_1000_cables_2_threads," << unreused.batch2 << ",ms,50\n";
    // The same with the freed heap kept by the process (no page faults for discarded meshes).
    o << "heap_kept_single_cable_total," << kept.single << ",us_cpu,90\n";
    o << "heap_kept_single_cable_interpolate," << kept.interp << ",us_cpu,\n";
    o << "heap_kept_single_cable_fair," << kept.fair << ",us_cpu,\n";
    o << "heap_kept_single_cable_sweep," << kept.sweep << ",us_cpu,\n";
    o << "heap_kept_batch_1000_cables_1_thread," << kept.batch1 << ",ms,\n";
    o << "heap_kept_batch_1000_cables_1_thread_cpu," << kept.batch1_cpu << ",ms_cpu,\n";
    o << "heap_kept_batch_1000_cables_2_threads," << kept.batch2 << ",ms,50\n";
    o << "occt_pipe_mesh_baseline," << occt_us << ",us_cpu,\n";
    o << "occt_baseline_triangles," << occt_tris << ",count,\n";
    o << "speedup_vs_occt," << (occt_us > 0 ? occt_us / single : 0.0) << ",ratio,\n";
    o << "speedup_vs_seed_9ms," << 9000.0 / single << ",ratio,100\n";
    double load[3] = {0, 0, 0};
    getloadavg(load, 3);
    o << "machine_load_average_1min," << load[0] << ",processes,\n";
  }
  for (const Measures* m : {&fresh, &unreused, &kept}) {
    std::printf("%s: one cable (1 m, r 2 mm, tol 0.01 mm): %.1f us total (interp %.1f, fair %.1f, sweep %.1f), "
                "%.0f triangles, %.0f rings\n",
                heap_name(m), m->single, m->interp, m->fair, m->sweep, m->triangles,
                m->rings);
    std::printf("  1000 cables: %.1f ms on 1 thread (%.1f ms CPU), %.1f ms on 2 threads (x%.2f)\n", m->batch1,
                m->batch1_cpu, m->batch2, m->batch1 / m->batch2);
  }
  std::printf("OpenCASCADE pipe + mesh baseline: %.1f us per cable (%.0f triangles) -> x%.1f\n", occt_us, occt_tris,
              occt_us > 0 ? occt_us / single : 0.0);

  // --- fairing: ε → α, max deviation, ∫κ²ds; and fixed α → deviation, ∫κ²ds -------------------
  {
    const std::vector<Vec3>& p = cables[7];
    InterpolationOptions io;
    io.start_tangent = Vec3::UnitX();
    const Centerline c = Centerline::interpolate(p, io);
    const double energy_interpolant = bending_energy(c);
    std::ofstream o(kResults + "centerline_fairing.csv");
    o << "mode,epsilon_mm,alpha_mm3,max_deviation_mm,energy_per_mm,energy_interpolant_per_mm,time_us_cpu\n";
    for (double e = 0.001; e <= 20.0; e *= 1.5) {
      FairingOptions f;
      f.tolerance = e;
      const auto t0 = Clock::now();
      const FairingResult r = fair_energy(c, f);
      const double t = us_since(t0);
      o << "epsilon," << e << "," << r.alpha << "," << r.max_deviation << "," << bending_energy(r.curve) << ","
        << energy_interpolant << "," << t << "\n";
    }
    for (double a = 1e-2; a <= 1e7; a *= 2.0) {
      FairingOptions f;
      f.tolerance = 1e9;  // accept the first α: just measure it
      f.alpha = a;
      f.max_iterations = 1;
      const auto t0 = Clock::now();
      const FairingResult r = fair_energy(c, f);
      const double t = us_since(t0);
      o << "alpha,," << r.alpha << "," << r.max_deviation << "," << bending_energy(r.curve) << ","
        << energy_interpolant << "," << t << "\n";
    }
  }
  gnuplot("centerline_fairing",
          "set multiplot layout 1,2 title 'Energy fairing of a 1 m cable (13 key points)'\n"
          "set logscale xy\nset xlabel 'allowed deviation epsilon (mm)'\nset ylabel 'mm'\nset y2label 'int kappa^2 ds (1/mm)'\n"
          "set y2tics\nset logscale y2\nset key top left\n"
          "plot '" + kResults + "centerline_fairing.csv' every ::1 using (strcol(1) eq 'epsilon' ? $2 : NaN):4 with linespoints title 'max deviation',"
          " '' every ::1 using (strcol(1) eq 'epsilon' ? $2 : NaN):5 axes x1y2 with linespoints title 'int kappa^2 ds'\n"
          "set xlabel 'smoothing factor alpha (mm^3)'\nset format x '10^{%L}'\nset format y '10^{%L}'\n"
          "plot '" + kResults + "centerline_fairing.csv' every ::1 using (strcol(1) eq 'alpha' ? $3 : NaN):4 with linespoints title 'max deviation',"
          " '' every ::1 using (strcol(1) eq 'alpha' ? $3 : NaN):5 axes x1y2 with linespoints title 'int kappa^2 ds'\n"
          "unset multiplot\n");

  // --- sweep tolerance → triangles, time (with the freed heap kept, as set above) ----------------
  {
    InterpolationOptions io;
    io.start_tangent = Vec3::UnitX();
    const Centerline c = Centerline::interpolate(cables[3], io);
    std::ofstream o(kResults + "centerline_sweep.csv");
    o << "chord_tolerance_mm,triangles,rings,circumferential,time_us_cpu\n";
    for (double tol : {1.0, 0.5, 0.2, 0.1, 0.05, 0.02, 0.01, 0.005, 0.002, 0.001}) {
      std::vector<double> t;
      SweepResult sw;
      for (int rep = 0; rep < 30; ++rep) {
        const auto t0 = Clock::now();
        sweep_tube(c, kRadius, {tol, true}, sw);  // storage reused across repetitions
        t.push_back(us_since(t0));
      }
      o << tol << "," << sw.mesh.triangle_count() << "," << sw.rings << "," << sw.circumferential << "," << median(t)
        << "\n";
    }
  }
  gnuplot("centerline_sweep",
          "set title 'Tube sweep of a 1 m, r = 2 mm cable: chord tolerance vs size and time (1 core)'\n"
          "set logscale xy\nset xlabel 'chord tolerance (mm)'\nset ylabel 'triangles'\nset y2label 'time (us)'\n"
          "set y2tics\nset logscale y2\n"
          "plot '" + kResults + "centerline_sweep.csv' every ::1 using 1:2 with linespoints title 'triangles',"
          " '' every ::1 using 1:5 axes x1y2 with linespoints title 'time (us)'\n");
  return 0;
}
