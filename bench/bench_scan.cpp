// Scan → centerline benchmark. Fixed seeds; writes bench/results/scan_*.csv and
// charts (gnuplot):
//   scan_speed   points/s of the graph method on 1 and 2 threads (paper-size cloud of 76,503
//                points and a 500k cloud), with the paper's axis method as the baseline
//   scan_noise   centerline RMS error (× d) against noise σ (× d), graph vs axis method
//   scan_blocks  block count against time and error (block length 0.5 d … 16 d)
// Times are wall clock (median of repeats) plus process CPU time, since the machine is shared.
#include "routing/scan/scan_centerline.hpp"

#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <string>
#include <vector>

namespace {

using loom::Vec3;
constexpr double kPi = 3.14159265358979323846;
constexpr double kD = 2.0;  // cable diameter (the paper's cable: 2 mm)

/// The true axis: a knot-free space curve (runs along x, so the paper's axis slabs apply).
struct Axis {
  std::vector<Vec3> p;
  std::vector<double> s;
};

Axis make_axis(double scale = 1.0) {
  Axis a;
  const int n = 4000;
  for (int i = 0; i <= n; ++i) {
    const double u = static_cast<double>(i) / n;
    a.p.emplace_back(scale * 100 * u, scale * 20 * std::sin(2 * kPi * u), scale * 15 * std::sin(3 * kPi * u + 0.5));
  }
  a.s.assign(a.p.size(), 0.0);
  for (std::size_t i = 1; i < a.p.size(); ++i) a.s[i] = a.s[i - 1] + (a.p[i] - a.p[i - 1]).norm();
  return a;
}

std::vector<Vec3> sample(const Axis& a, std::size_t n, double noise, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  std::normal_distribution<double> N(0.0, 1.0);
  std::vector<Vec3> pts;
  pts.reserve(n);
  while (pts.size() < n) {
    const double s = U(rng) * a.s.back();
    const std::size_t j = std::clamp<std::size_t>(
        static_cast<std::size_t>(std::upper_bound(a.s.begin(), a.s.end(), s) - a.s.begin()), 1, a.s.size() - 1);
    const double u = (s - a.s[j - 1]) / (a.s[j] - a.s[j - 1]);
    const Vec3 c = a.p[j - 1] + u * (a.p[j] - a.p[j - 1]);
    const Vec3 T = (a.p[j] - a.p[j - 1]).normalized();
    const Vec3 n1 = T.unitOrthogonal(), n2 = T.cross(n1);
    const double th = 2 * kPi * U(rng);
    pts.push_back(c + 0.5 * kD * (std::cos(th) * n1 + std::sin(th) * n2) + noise * kD * Vec3(N(rng), N(rng), N(rng)));
  }
  return pts;
}

/// RMS distance (× d) of the recovered centerline to the true axis (brute force).
double rms_error(const Axis& a, const loom::Centerline& c) {
  double sq = 0;
  const auto smp = c.sample_by_arc_length(0.25 * kD);
  for (const auto& [s, p] : smp) {
    double best = 1e300;
    for (std::size_t i = 1; i < a.p.size(); ++i) {
      const Vec3 seg = a.p[i] - a.p[i - 1];
      const double u = std::clamp((p - a.p[i - 1]).dot(seg) / seg.squaredNorm(), 0.0, 1.0);
      best = std::min(best, (p - a.p[i - 1] - u * seg).squaredNorm());
    }
    sq += best;
  }
  return std::sqrt(sq / static_cast<double>(smp.size())) / kD;
}

double cpu_ms() {
  timespec t;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return t.tv_sec * 1e3 + t.tv_nsec / 1e6;
}

struct Timed {
  double wall_ms, cpu_ms;
  loom::ScanResult last;
};

Timed time_it(const std::vector<Vec3>& cloud, const loom::ScanOptions& o, int repeats) {
  std::vector<double> wall, cpu;
  Timed t{};
  for (int k = 0; k < repeats; ++k) {
    const double c0 = cpu_ms();
    t.last = loom::extract_centerline(cloud, o);
    cpu.push_back(cpu_ms() - c0);
    wall.push_back(t.last.timing.total_ms);
  }
  std::sort(wall.begin(), wall.end());
  std::sort(cpu.begin(), cpu.end());
  t.wall_ms = wall[wall.size() / 2];
  t.cpu_ms = cpu[cpu.size() / 2];
  return t;
}

void gnuplot(const std::filesystem::path& dir, const std::string& name, const std::string& script) {
  const auto gp = dir / (name + ".gp");
  std::ofstream(gp) << "set terminal pngcairo size 900,560\nset output '" << (dir / (name + ".png")).string()
                    << "'\nset datafile separator ','\nset key top left\nset grid\n"
                    << script;
  const std::string cmd = "gnuplot '" + gp.string() + "'";
  if (std::system(cmd.c_str()) != 0) std::fprintf(stderr, "gnuplot failed for %s\n", name.c_str());
}

}  // namespace

int main() {
  const std::filesystem::path dir = std::filesystem::path(LOOM_SOURCE_DIR) / "bench" / "results";
  std::filesystem::create_directories(dir);
  const Axis axis = make_axis();
  loom::ScanOptions graph;
  graph.diameter = kD;
  loom::ScanOptions axis_m = graph;
  axis_m.method = loom::ScanMethod::Axis;
  loom::ScanOptions estimate;  // unknown diameter

  // ---- speed: paper-size cloud and a large one, 1 and 2 threads ------------------------
  {
    std::ofstream csv(dir / "scan_speed.csv");
    csv << "points,method,threads,wall_ms,cpu_ms,points_per_s_wall,error_rms_d\n";
    std::printf("%-9s %-15s %7s %10s %10s %14s %10s\n", "points", "method", "threads", "wall_ms", "cpu_ms",
                "points/s", "rms/d");
    for (std::size_t n : {std::size_t{76503}, std::size_t{500000}}) {
      const auto cloud = sample(axis, n, 0.01, 11);
      for (int threads : {1, 2}) {
        tbb::global_control gc(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(threads));
        const std::pair<const char*, const loom::ScanOptions*> runs[] = {
            {"graph", &graph}, {"graph-estimate-d", &estimate}, {"axis(paper)", &axis_m}};
        for (const auto& [name, opt] : runs) {
          const Timed t = time_it(cloud, *opt, n > 100000 ? 3 : 7);
          const double err = t.last.status == loom::ScanStatus::Ok ? rms_error(axis, t.last.centerline) : -1.0;
          const double pps = static_cast<double>(n) / (t.wall_ms / 1e3);
          csv << n << ',' << name << ',' << threads << ',' << t.wall_ms << ',' << t.cpu_ms << ',' << pps << ',' << err
              << '\n';
          std::printf("%-9zu %-15s %7d %10.1f %10.1f %14.0f %10.4f\n", n, name, threads, t.wall_ms, t.cpu_ms, pps, err);
        }
      }
    }
  }
  gnuplot(dir, "scan_speed",
          "set title 'Scan centerline throughput (curve3d, d = 2, sigma = 1% d)'\nset ylabel 'points / s (wall)'\n"
          "set style data histograms\nset style fill solid 0.8\nset xtics rotate by -20\nset logscale y\n"
          "plot '< grep -v points " + (dir / "scan_speed.csv").string() +
              "' using 6:xtic(sprintf('%s n=%d t=%d',strcol(2),$1,$3)) title 'points/s' lc rgb '#3070b0', "
              "1e6 with lines dt 2 lc rgb 'red' title 'target 1 M/s'\n");

  // ---- noise against centerline error ---------------------------------------------------
  {
    std::ofstream csv(dir / "scan_noise.csv");
    csv << "noise_d,graph_rms_d,axis_rms_d,graph_estimated_d_rms_d,estimated_diameter\n";
    for (double noise : {0.0, 0.005, 0.01, 0.02, 0.03, 0.05, 0.075, 0.1}) {
      const auto cloud = sample(axis, 76503, noise, 21);
      const auto rg = loom::extract_centerline(cloud, graph);
      const auto ra = loom::extract_centerline(cloud, axis_m);
      const auto re = loom::extract_centerline(cloud, estimate);
      auto err = [&](const loom::ScanResult& r) {
        return r.status == loom::ScanStatus::Ok ? rms_error(axis, r.centerline) : -1.0;
      };
      csv << noise << ',' << err(rg) << ',' << err(ra) << ',' << err(re) << ',' << re.diameter << '\n';
      std::printf("noise %.3f d: graph %.4f d, axis %.4f d, graph(estimated d=%.4f) %.4f d\n", noise, err(rg), err(ra),
                  re.diameter, err(re));
    }
  }
  gnuplot(dir, "scan_noise",
          "set title 'Centerline error against scan noise (76,503 points, d = 2)'\nset xlabel 'noise sigma / d'\n"
          "set ylabel 'centerline RMS error / d'\nset logscale y\n"
          "plot '" + (dir / "scan_noise.csv").string() + "' every ::1 using 1:2 with linespoints title 'graph (given d)', "
          "'' every ::1 using 1:4 with linespoints title 'graph (estimated d)', "
          "'' every ::1 using 1:3 with linespoints title 'axis slabs (paper)', 0.02 with lines dt 2 title '2% d'\n");

  // ---- block count against time --------------------------------------------------------
  {
    std::ofstream csv(dir / "scan_blocks.csv");
    csv << "block_length_d,method,blocks,wall_ms,cpu_ms,rms_d\n";
    const auto cloud = sample(axis, 76503, 0.01, 31);
    for (double bl : {0.5, 1.0, 2.0, 4.0, 8.0, 16.0}) {
      for (auto [name, base] : {std::pair<const char*, loom::ScanOptions>{"graph", graph}, {"axis", axis_m}}) {
        loom::ScanOptions o = base;
        o.block_length = bl * kD;
        const Timed t = time_it(cloud, o, 5);
        const double e = t.last.status == loom::ScanStatus::Ok ? rms_error(axis, t.last.centerline) : -1.0;
        csv << bl << ',' << name << ',' << t.last.blocks.size() << ',' << t.wall_ms << ',' << t.cpu_ms << ',' << e << '\n';
        std::printf("block %.1f d %-5s: %3zu blocks, %.1f ms wall, %.1f ms cpu, rms %.4f d\n", bl, name,
                    t.last.blocks.size(), t.wall_ms, t.cpu_ms, e);
      }
    }
  }
  gnuplot(dir, "scan_blocks",
          "set title 'Block count against time and error (76,503 points)'\nset xlabel 'blocks'\n"
          "set ylabel 'time (ms, wall)'\nset y2label 'centerline RMS error / d'\nset y2tics\nset logscale y2\n"
          "plot '< grep graph " + (dir / "scan_blocks.csv").string() + "' using 3:4 with linespoints title 'graph time', "
          "'< grep axis " + (dir / "scan_blocks.csv").string() + "' using 3:4 with linespoints title 'axis time', "
          "'< grep graph " + (dir / "scan_blocks.csv").string() + "' using 3:6 axes x1y2 with linespoints dt 2 title 'graph error', "
          "'< grep axis " + (dir / "scan_blocks.csv").string() + "' using 3:6 axes x1y2 with linespoints dt 2 title 'axis error'\n");
  return 0;
}
