// Harness-audit benchmark: generated harnesses shaped like real ones (bench/harness_gen.hpp:
// ≈ 250 wires, ≈ 180 segments, trunks of 80+ wires, 1–5 m wires, bend radii 3·d) with and
// without a structure of ≥ 200 parts, and a 10× larger harness. Measures, in one process,
// the certified audit per cable (the reference, ClashRequest::per_cable) and at the bundle
// level, on 1 and 2 threads (wall clock, best of runs, and process CPU time), checks that
// they find the same (bench/audit_compare.hpp, with an exact clearance oracle), and charts
// the time of both against the wires per trunk. The paper-scale scene of bench_audit (100
// scattered cables, no shared segment) is timed both ways too: the bundle level must not
// cost it anything. Writes bench/results/harness_audit*.csv and harness_audit.png (gnuplot).
// Fixed seeds.
//
//   bench_harness_audit [--quick] [--max-degree N] [--10x-reference]
//     --quick: the 250-wire harness only; --10x-reference: the 10× harness's per-cable
//     reference too, findings compared (its pair tests grow with the square of the wires
//     per trunk: expect on the order of 100× the 250-wire harness's per-cable time)
//   bench_harness_audit --probe WIRES [THREADS]      (bundle level alone, per-check CPU split)
#include "bench/audit_compare.hpp"
#include "bench/audit_scenes.hpp"
#include "bench/audit_timing.hpp"
#include "bench/harness_gen.hpp"
#include "core/harness_topology.hpp"
#include "index/embree_index.hpp"
#include "routing/audit/audit.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

using namespace loom;

namespace {

/// A harness audited: its cables as the checker sees them, the parts and their index.
struct HarnessScene {
  std::string name;
  Harness harness;
  std::vector<CableInput> cables;
  std::vector<Part> parts;
  std::unique_ptr<EmbreeIndex> index;
  int most_per_segment = 0;
  std::size_t triangles = 0;
};

HarnessScene make_harness_scene(const std::string& name, const bench::HarnessShape& shape, int n_parts) {
  HarnessScene sc;
  sc.name = name;
  sc.harness = bench::generate_harness(shape).harness;
  const HarnessTopology topo(sc.harness);
  for (std::size_t s = 0; s < sc.harness.segments.size(); ++s)
    sc.most_per_segment = std::max(sc.most_per_segment, static_cast<int>(topo.segment_cables(static_cast<int>(s)).size()));
  if (n_parts > 0) sc.parts = bench::harness_structure(sc.harness, n_parts, 2000, shape.seed + 1);
  for (const Part& p : sc.parts) sc.triangles += p.mesh.triangle_count();
  sc.index = std::make_unique<EmbreeIndex>(sc.parts);
  std::vector<AuditCable> ac;
  sc.cables = audit_cable_inputs(sc.harness, ac);
  attach_ports(sc.harness, sc.parts, 3.0, sc.cables, sc.index.get());
  return sc;
}

using bench::cpu_ms;
using bench::now_ms;
using bench::Timed;

/// Best of `reps` runs of the audit (bench::timed_check).
Timed timed(const std::vector<CableInput>& cables, const std::vector<Part>& parts, const ObstacleIndex* index,
            const ClashRequest& req, int reps) {
  return bench::timed_check(cables, parts, index, req, reps);
}

ClashRequest request(bool per_cable, int threads) {
  ClashRequest req;
  req.routing_clearance = 3.0;
  req.per_cable = per_cable;
  req.threads = threads;
  return req;
}

/// The exact clearance of a scene's cable to a part at arc length s (−r inside it).
bench::ClearanceOracle oracle_of(const HarnessScene& sc) {
  return [&sc](int cable, int part, double s) {
    const CableInput& c = sc.cables[static_cast<std::size_t>(cable)];
    const Vec3 p = c.curve.position(c.curve.parameter_at_length(s));
    std::vector<int> inside;
    sc.index->inside_parts(p, inside);
    if (std::find(inside.begin(), inside.end(), part) != inside.end()) return -c.radius;
    return sc.index->closest_on_part(p, part).distance - c.radius;
  };
}

/// One row of harness_audit.csv: both audits, 1 and 2 threads, and the comparison.
struct Row {
  Timed ref[2], bundle[2];
  bench::FindingsDiff diff;
  bool compared = true;  ///< the per-cable reference was run and compared
};

Row measure(const HarnessScene& sc, int ref_reps, int bundle_reps, bool ref_one_thread = true, bool ref = true) {
  Row row;
  for (int t = 0; t < 2; ++t) {
    if (ref && (t == 1 || ref_one_thread))
      row.ref[t] = timed(sc.cables, sc.parts, sc.index.get(), request(true, t + 1), ref_reps);
    row.bundle[t] = timed(sc.cables, sc.parts, sc.index.get(), request(false, t + 1), bundle_reps);
  }
  if (ref)
    row.diff = bench::compare_findings(row.ref[1].res, row.bundle[1].res, sc.cables, oracle_of(sc));
  row.compared = ref;
  const ClashResult& r = row.bundle[1].res;
  std::printf("%s: %zu wires, %zu segments, fullest %d, %zu parts (%zu triangles)\n", sc.name.c_str(), sc.cables.size(),
              sc.harness.segments.size(), sc.most_per_segment, sc.parts.size(), sc.triangles);
  std::printf("  per-cable: 1t %9.1f ms (cpu %9.1f)  2t %9.1f ms (cpu %9.1f)  %lld pair tests %lld samples %lld queries\n",
              row.ref[0].ms, row.ref[0].cpu, row.ref[1].ms, row.ref[1].cpu,
              static_cast<long long>(row.ref[1].res.counters.pair_tests),
              static_cast<long long>(row.ref[1].res.counters.samples),
              static_cast<long long>(row.ref[1].res.counters.distance_queries));
  std::printf("  bundle:    1t %9.1f ms (cpu %9.1f)  2t %9.1f ms (cpu %9.1f)  %lld pair tests %lld samples %lld queries\n",
              row.bundle[0].ms, row.bundle[0].cpu, row.bundle[1].ms, row.bundle[1].cpu,
              static_cast<long long>(r.counters.pair_tests), static_cast<long long>(r.counters.samples),
              static_cast<long long>(r.counters.distance_queries));
  std::printf("  speed-up 2t %.1fx (cpu %.1fx); %zu clashes, %zu violations; findings %s (%d splits, %d edges, %d joins, "
              "max |dclearance| %.2g)\n",
              row.ref[1].ms / row.bundle[1].ms, row.ref[1].cpu / row.bundle[1].cpu, r.clashes.size(), r.violations.size(),
              !row.compared ? "not compared" : row.diff.problems.empty() ? "identical" : "DIFFER", row.diff.splits, row.diff.edges, row.diff.joins,
              row.diff.max_clearance_diff);
  for (const auto& p : row.diff.problems) std::printf("    %s\n", p.c_str());
  return row;
}

/// The bundle level alone on the WIRES harness (no structure), with the CPU time of each
/// check kind alone: where its time goes.
int probe(int wires, int threads) {
  bench::HarnessShape shape;
  shape.wires = wires;
  const HarnessScene sc = make_harness_scene("probe", shape, 0);
  std::printf("%zu wires, %zu segments, %zu branch points, fullest segment %d\n", sc.cables.size(),
              sc.harness.segments.size(), sc.harness.branches.size(), sc.most_per_segment);
  const char* names[] = {"all", "bend", "cable-cable", "self"};
  for (int part = 0; part < 4; ++part) {
    ClashRequest req = request(false, threads);
    req.check_bend = part == 0 || part == 1;
    req.check_cable_cable = part == 0 || part == 2;
    req.check_self = part == 0 || part == 3;
    const Timed t = timed(sc.cables, sc.parts, sc.index.get(), req, 7);
    std::printf("%-12s %8.2f ms (cpu %8.2f)  %lld pair tests  %lld samples\n", names[part], t.ms, t.cpu,
                static_cast<long long>(t.res.counters.pair_tests), static_cast<long long>(t.res.counters.samples));
  }
  return 0;
}

void gnuplot(const std::string& dir) {
  const std::string path = dir + "harness_audit_plot.gp";
  std::ofstream(path) << "set datafile separator ','\nset terminal pngcairo size 900,600\nset output '" + dir +
                             "harness_audit.png'\nset title 'certified audit of a harness: time against wires per "
                             "trunk'\nset xlabel 'wires in the fullest trunk segment'\nset ylabel 'check time, ms (2 "
                             "threads)'\nset logscale y\nset key top left\nplot '" + dir +
                             "harness_audit_trunk.csv' using 2:4 with linespoints pt 7 title 'per cable', '' using 2:6 "
                             "with linespoints pt 5 title 'bundle level'\n";
  const std::string cmd = "gnuplot " + path + " 2>/dev/null";
  if (std::system(cmd.c_str()) != 0) std::fprintf(stderr, "gnuplot failed (chart not drawn)\n");
  std::filesystem::remove(path);
}

}  // namespace

int main(int argc, char** argv) {
  const std::string dir = std::string(LOOM_SOURCE_DIR) + "/bench/results/";
  bool quick = false, ref_10x = false;
  bench::HarnessShape base;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--probe" && i + 1 < argc)
      return probe(std::atoi(argv[i + 1]), i + 2 < argc ? std::atoi(argv[i + 2]) : 1);
    if (a == "--quick") quick = true;
    if (a == "--10x-reference") ref_10x = true;
    if (a == "--max-degree" && i + 1 < argc) base.max_degree = std::atoi(argv[++i]);
  }
  std::filesystem::create_directories(dir);

  // ---- 1. the 250-wire harness without and with structure, and the 10× harness --------
  std::ofstream csv(dir + "harness_audit.csv");
  csv << "scene,wires,segments,fullest_segment,parts,triangles,per_cable_1t_ms,per_cable_2t_ms,per_cable_1t_cpu_ms,"
         "per_cable_2t_cpu_ms,bundle_1t_ms,bundle_2t_ms,bundle_1t_cpu_ms,bundle_2t_cpu_ms,speedup_2t,clashes,"
         "violations,identical,splits,edges,joins,per_cable_pair_tests,bundle_pair_tests\n";
  auto write_row = [&](const HarnessScene& sc, const Row& r) {
    csv << sc.name << "," << sc.cables.size() << "," << sc.harness.segments.size() << "," << sc.most_per_segment << ","
        << sc.parts.size() << "," << sc.triangles << "," << r.ref[0].ms << "," << r.ref[1].ms << "," << r.ref[0].cpu
        << "," << r.ref[1].cpu << "," << r.bundle[0].ms << "," << r.bundle[1].ms << "," << r.bundle[0].cpu << ","
        << r.bundle[1].cpu << "," << r.ref[1].ms / r.bundle[1].ms << "," << r.bundle[1].res.clashes.size() << ","
        << r.bundle[1].res.violations.size() << "," << (!r.compared ? "" : r.diff.problems.empty() ? "1" : "0") << "," << r.diff.splits << ","
        << r.diff.edges << "," << r.diff.joins << "," << r.ref[1].res.counters.pair_tests << ","
        << r.bundle[1].res.counters.pair_tests << "\n";
    csv.flush();
  };
  int differ = 0;
  for (int parts : {0, 200}) {
    const HarnessScene sc = make_harness_scene(parts ? "harness+structure" : "harness", base, parts);
    const Row r = measure(sc, 1, 7);
    write_row(sc, r);
    differ += r.diff.problems.empty() ? 0 : 1;
  }
  if (!quick) {
    bench::HarnessShape big = base;
    big.spine_branches *= 10;
    big.side_branches *= 10;
    big.wires *= 10;
    for (int parts : {0, 2000}) {
      const HarnessScene sc = make_harness_scene(parts ? "10x+structure" : "10x", big, parts);
      const Row r = measure(sc, 1, 3, false, ref_10x);
      write_row(sc, r);
      differ += r.diff.problems.empty() ? 0 : 1;
    }
  }
  csv.close();

  // ---- 2. time against wires per trunk ----------------------------------------------
  if (!quick) {
    std::ofstream tcsv(dir + "harness_audit_trunk.csv");
    tcsv << "wires,fullest_segment,segments,per_cable_2t_ms,per_cable_2t_cpu_ms,bundle_2t_ms,bundle_2t_cpu_ms\n";
    for (int wires : {15, 30, 60, 120, 180, 250, 370}) {
      bench::HarnessShape shape = base;
      shape.wires = wires;
      const HarnessScene sc = make_harness_scene("trunk", shape, 0);
      const Timed ref = timed(sc.cables, sc.parts, sc.index.get(), request(true, 2), 1);
      const Timed bun = timed(sc.cables, sc.parts, sc.index.get(), request(false, 2), 5);
      const bench::FindingsDiff d = bench::compare_findings(ref.res, bun.res, sc.cables, oracle_of(sc));
      differ += d.problems.empty() ? 0 : 1;
      tcsv << wires << "," << sc.most_per_segment << "," << sc.harness.segments.size() << "," << ref.ms << ","
           << ref.cpu << "," << bun.ms << "," << bun.cpu << "\n";
      tcsv.flush();
      std::printf("trunk %3d wires (fullest segment %3d): per-cable %9.1f ms, bundle %7.2f ms (%.0fx), findings %s\n",
                  wires, sc.most_per_segment, ref.ms, bun.ms, ref.ms / bun.ms, d.problems.empty() ? "identical" : "DIFFER");
    }
    tcsv.close();
    gnuplot(dir);
  }

  // ---- 3. the paper-scale scene of bench_audit: no shared segment -------------------------
  {
    const bench::BenchScene sc = bench::make_scene(200, 7500, 100, 1.0, 42);
    const EmbreeIndex idx(sc.parts);
    const Timed ref = timed(sc.cables, sc.parts, &idx, request(true, 2), 5);
    const Timed bun = timed(sc.cables, sc.parts, &idx, request(false, 2), 5);
    std::printf("paper scale (%zu cables, %zu triangles), 2 threads: per-cable %.1f ms (cpu %.1f), default %.1f ms "
                "(cpu %.1f, bundle level %s), %zu clashes, %zu violations\n",
                sc.cables.size(), sc.triangles, ref.ms, ref.cpu, bun.ms, bun.cpu, bun.res.bundle_level ? "on" : "off",
                bun.res.clashes.size(), bun.res.violations.size());
    std::ofstream(dir + "harness_audit_paper.csv") << "scene,per_cable_2t_ms,per_cable_2t_cpu_ms,default_2t_ms,default_2t_cpu_ms\n"
                                                   << "paper," << ref.ms << "," << ref.cpu << "," << bun.ms << "," << bun.cpu << "\n";
  }
  if (differ) std::fprintf(stderr, "%d scenes: the bundle level's findings differ from the per-cable audit's\n", differ);
  return differ ? 1 : 0;
}
