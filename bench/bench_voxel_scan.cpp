// Scanned structure: OctoMap's geb079.bt (a building floor, 8 cm voxels) as a loom part and
// as a distance field. Writes bench/results/voxel_scan.csv: per step the wall and CPU time
// (best of 3), voxels, triangles and bytes; voxel_scan_edt_agreement.csv: dynamicEDT3D's
// distances against loom's EDT at every voxel centre of the map's box.
//   part         read_voxel_part: file check, OctoMap read, occupied voxels, boundary mesh
//   part-unknown the same with unknown = occupied (unobserved voxels in the map's box filled)
//   embree       EmbreeIndex over the part's mesh (the exact index route and audit use)
//   voxelmap     VoxelMap::load_bt: OctoMap read + dense grid + loom's Felzenszwalb EDT
//   dynamicedt   dynamicEDT3D's DynamicEDTOctomap over the same tree and reach (update())
// Usage: bench_voxel_scan [FILE.bt]
#include "core/io/voxel_part.hpp"
#include "index/embree_index.hpp"
#include "index/voxel_map.hpp"

#include <dynamicEDT3D/dynamicEDTOctomap.h>
#include <octomap/OcTree.h>

#include <chrono>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <algorithm>
#include <cmath>
#include <string>

namespace {

double now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}
double cpu_s() { return static_cast<double>(std::clock()) / CLOCKS_PER_SEC; }

struct Timing {
  double wall = 1e300, cpu = 0.0;
};

/// Best of `reps` runs of f (by wall clock), with that run's CPU time.
Timing best_of(int reps, const std::function<void()>& f) {
  Timing t;
  for (int i = 0; i < reps; ++i) {
    const double w0 = now_s(), c0 = cpu_s();
    f();
    const double w = now_s() - w0, c = cpu_s() - c0;
    if (w < t.wall) t = {w, c};
  }
  return t;
}

/// Resident set size of this process (bytes), from /proc/self/statm.
std::size_t resident_bytes() {
  std::ifstream f("/proc/self/statm");
  std::size_t pages = 0, resident = 0;
  f >> pages >> resident;
  return resident * 4096;
}

}  // namespace

int main(int argc, char** argv) {
  const std::filesystem::path file =
      argc > 1 ? std::filesystem::path(argv[1]) : std::filesystem::path(LOOM_SHARED_DATA) / "octomap" / "geb079.bt";
  const std::filesystem::path out = std::filesystem::path(LOOM_SOURCE_DIR) / "bench" / "results" / "voxel_scan.csv";
  std::ofstream csv(out);
  csv << "step,wall_s,cpu_s,voxels,triangles,bytes\n";
  const auto row = [&](const char* step, const Timing& t, double voxels, double tris, double bytes) {
    csv << step << ',' << t.wall << ',' << t.cpu << ',' << voxels << ',' << tris << ',' << bytes << '\n';
    std::printf("%-12s wall %8.3f s  cpu %8.3f s  voxels %10.0f  triangles %10.0f  bytes %12.0f\n", step, t.wall,
                t.cpu, voxels, tris, bytes);
  };

  loom::VoxelPart part;
  const Timing tp = best_of(3, [&] { part = loom::read_voxel_part(file, {}); });
  row("part", tp, double(part.occupied_voxels), double(part.mesh.triangle_count()),
      double(part.mesh.vertices.size() * sizeof(loom::Vec3) + part.mesh.triangles.size() * 12));

  loom::VoxelPartOptions unk;
  unk.unknown_occupied = true;
  loom::VoxelPart filled;
  const Timing tu = best_of(3, [&] { filled = loom::read_voxel_part(file, unk); });
  row("part-unknown", tu, double(filled.occupied_voxels), double(filled.mesh.triangle_count()),
      double(filled.mesh.vertices.size() * sizeof(loom::Vec3) + filled.mesh.triangles.size() * 12));

  std::vector<loom::Part> parts(1);
  parts[0].name = "floor";
  parts[0].mesh = part.mesh;
  std::size_t embree_bytes = 0;
  const Timing te = best_of(3, [&] {
    const loom::EmbreeIndex idx(parts);
    embree_bytes = idx.memory_bytes();
  });
  row("embree", te, double(part.occupied_voxels), double(part.mesh.triangle_count()), double(embree_bytes));

  loom::VoxelOptions vo;  // reach: the default 8 voxels
  std::unique_ptr<loom::VoxelMap> vm;
  double edt_s = 1e300;  // the EDT alone (wall), best of the same runs
  const Timing tv = best_of(3, [&] {
    vm = loom::VoxelMap::load_bt(file.string(), vo);
    edt_s = std::min(edt_s, vm->stats().edt_seconds);
  });
  row("voxelmap", tv, double(vm->stats().surface_voxels), 0.0, double(vm->memory_bytes()));
  row("voxelmap-edt", {edt_s, 0.0}, double(vm->stats().grid_cells), 0.0, 0.0);

  octomap::OcTree tree(0.1);
  if (!tree.readBinary(file.string())) return 1;
  double mn[3], mx[3];
  tree.getMetricMin(mn[0], mn[1], mn[2]);
  tree.getMetricMax(mx[0], mx[1], mx[2]);
  const float reach = static_cast<float>(vm->max_distance());
  const octomap::point3d lo{float(mn[0]), float(mn[1]), float(mn[2])}, hi{float(mx[0]), float(mx[1]), float(mx[2])};
  std::unique_ptr<DynamicEDTOctomap> edt;
  std::size_t rss_delta = 0;
  const Timing td = best_of(3, [&] {
    edt.reset();
    const std::size_t r0 = resident_bytes();
    edt = std::make_unique<DynamicEDTOctomap>(reach, &tree, lo, hi, false);
    edt->update();
    rss_delta = std::max(rss_delta, resident_bytes() - std::min(r0, resident_bytes()));
  });
  // Agreement with loom's exact EDT (Felzenszwalb–Huttenlocher) at every voxel centre of the
  // map's box where both know a distance below the reach.
  const double res = tree.getResolution();
  std::size_t cells = 0, compared = 0, differ = 0;
  double worst = 0.0;
  for (double z = mn[2] + 0.5 * res; z < mx[2]; z += res)
    for (double y = mn[1] + 0.5 * res; y < mx[1]; y += res)
      for (double x = mn[0] + 0.5 * res; x < mx[0]; x += res) {
        ++cells;
        const float d = edt->getDistance(octomap::point3d(float(x), float(y), float(z)));
        const double ours = vm->distance(loom::Vec3(x, y, z));
        if (d < 0 || !(d < reach) || !(ours < reach)) continue;
        ++compared;
        const double diff = std::abs(double(d) - ours);
        worst = std::max(worst, diff);
        differ += diff > 1e-4 * res ? 1 : 0;
      }
  // Its grid holds a DynamicEDT3D::dataCell per voxel of the box: a float, four ints, a char
  // and a bool, 24 bytes; the resident-set growth of its first build is printed beside it.
  row("dynamicedt", td, double(cells), 0.0, 24.0 * double(cells));
  std::printf("dynamicEDT3D resident-set growth on its first build: %zu bytes\n", rss_delta);
  std::printf("dynamicEDT3D vs loom's EDT: %zu cells compared, %zu differ by > 1e-4 voxel, worst %.6g (scene units)\n",
              compared, differ, worst);
  std::ofstream(std::filesystem::path(out).replace_filename("voxel_scan_edt_agreement.csv"))
      << "cells_compared,cells_differing,worst_difference\n"
      << compared << ',' << differ << ',' << worst << '\n';
  std::printf("wrote %s\n", out.string().c_str());
  return 0;
}
