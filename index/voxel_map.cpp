#include "index/voxel_map.hpp"

#include "core/stopwatch.hpp"
#include "core/error.hpp"
#include "core/io/atomic_file.hpp"
#include "index/embree_index.hpp"
#include "index/triangle_distance.hpp"

#include <octomap/OcTree.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <fstream>
#include <stdexcept>

namespace loom {

namespace {

/// OctoMap's 16-bit keys: voxel coordinates floor(x/res) must lie in [-32768, 32767].
constexpr long kKeyHalf = 32768;
/// Squared-distance marker for "no seed" in the EDT (voxel units²).
constexpr double kEdtFar = 1e30;
/// Cell flags: free, a surface passes through it, interior of a closed part, or free as far
/// as the interior fill knows but in a row it could not decide (every line offset touched an
/// edge): refine() then asks the exact index whether the centre lies inside.
constexpr std::uint8_t kFree = 0, kSurface = 1, kInterior = 2, kUndecided = 3;
/// Occupied cells: the ones in the OcTree and the seeds of the distance transform.
bool occupied(std::uint8_t flag) { return flag == kSurface || flag == kInterior; }
/// Default max_distance in voxels when VoxelOptions::max_distance ≤ 0.
constexpr double kDefaultMaxDistanceVoxels = 8.0;
/// Offsets (in voxels) of the scan lines used for the interior fill; all below
/// half a voxel diagonal, so they classify non-surface voxels like their centres.
constexpr double kLineOffsets[][2] = {{0.1234567, 0.0765432}, {-0.2113249, 0.1591549}, {0.0577350, -0.2718281},
                                      {-0.1414213, -0.1732050}};
/// Relative size of a 2D edge function below which a scan line is said to touch an edge.
constexpr double kEdgeTouchRel = 1e-10;


template <class Body>
void parallel_range(std::size_t n, int threads, std::size_t grain, const Body& body) {
  if (n == 0) return;
  tbb::task_arena arena(threads > 0 ? threads : tbb::task_arena::automatic);
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, grain),
                      [&](const tbb::blocked_range<std::size_t>& r) { body(r.begin(), r.end()); });
  });
}

/// 1D squared distance transform (Felzenszwalb & Huttenlocher) of f (length n, stride 1):
/// d[q] = min_p (q - p)² + f[p]. v, z are scratch of size n and n + 1.
void edt_1d(const double* f, long n, double* d, long* v, double* z) {
  long k = -1;
  for (long q = 0; q < n; ++q) {
    if (f[q] >= kEdtFar) continue;
    if (k < 0) {
      k = 0;
      v[0] = q;
      z[0] = -std::numeric_limits<double>::infinity();
      z[1] = std::numeric_limits<double>::infinity();
      continue;
    }
    double s;
    while (true) {
      const long p = v[k];
      s = ((f[q] + double(q) * q) - (f[p] + double(p) * p)) / (2.0 * (q - p));
      if (s <= z[k] && k > 0) {
        --k;
        continue;
      }
      if (s <= z[k]) {  // k == 0: replace the only parabola
        k = -1;
      }
      break;
    }
    ++k;
    v[k] = q;
    z[k] = k == 0 ? -std::numeric_limits<double>::infinity() : s;
    z[k + 1] = std::numeric_limits<double>::infinity();
  }
  if (k < 0) {
    for (long q = 0; q < n; ++q) d[q] = kEdtFar;
    return;
  }
  long j = 0;
  for (long q = 0; q < n; ++q) {
    while (z[j + 1] < q) ++j;
    const double dq = double(q - v[j]);
    d[q] = dq * dq + f[v[j]];
  }
}

}  // namespace

double VoxelMap::derive_resolution(double cable_radius, double clearance) {
  const double gap = cable_radius + clearance;
  if (!(gap > 0.0) || !std::isfinite(gap))
    throw std::invalid_argument("voxel map: cable radius + clearance must be positive to derive a resolution");
  return gap / std::sqrt(3.0);
}

VoxelMap::~VoxelMap() = default;

void VoxelMap::init_grid(const AABB& box, const std::string& what) {
  half_diag_ = 0.5 * std::sqrt(3.0) * res_;
  const double margin = max_distance_ + res_;
  const long total_margin = static_cast<long>(std::ceil(margin / res_));
  std::size_t cells = 1;
  for (int a = 0; a < 3; ++a) {
    const long lo = box.empty() ? 0 : static_cast<long>(std::floor(box.min[a] / res_));
    const long hi = box.empty() ? 0 : static_cast<long>(std::floor(box.max[a] / res_));
    base_[a] = lo - total_margin;
    n_[a] = hi + total_margin - base_[a] + 1;
    if (base_[a] < -kKeyHalf || base_[a] + n_[a] - 1 > kKeyHalf - 1)
      throw InputError({what, 0, "voxel map"},
                       "the scene (plus max_distance " + full_precision(max_distance_) + ") spans voxel coordinates " +
                           std::to_string(base_[a]) + ".." + std::to_string(base_[a] + n_[a] - 1) + " on axis " +
                           std::string(1, "xyz"[a]) + " at resolution " + full_precision(res_) +
                           ", beyond OctoMap's 16-bit key range of +/-32768 voxels around the origin (+/-" +
                           full_precision(kKeyHalf * res_) + " scene units); use a coarser voxel size or move the scene");
    cells *= static_cast<std::size_t>(n_[a]);
  }
  if (cells > max_cells_)
    throw InputError({what, 0, "voxel map"},
                     "the distance grid needs " + std::to_string(cells) + " cells at resolution " + full_precision(res_) +
                         ", more than the budget of " + std::to_string(max_cells_) + " cells; coarsen the voxel size");
  stats_.grid_cells = cells;
  dist_.assign(cells, std::numeric_limits<float>::infinity());
  part_.assign(cells, -1);
  flags_.assign(cells, 0);
}

Vec3 VoxelMap::cell_centre(long i, long j, long k) const {
  return Vec3((base_[0] + i + 0.5) * res_, (base_[1] + j + 0.5) * res_, (base_[2] + k + 0.5) * res_);
}

long VoxelMap::cell_of(const Vec3& p) const {
  long c[3];
  for (int a = 0; a < 3; ++a) {
    const double v = std::floor(p[a] / res_) - static_cast<double>(base_[a]);
    if (!(v >= 0.0) || v >= static_cast<double>(n_[a])) return -1;
    c[a] = static_cast<long>(v);
  }
  return (c[2] * n_[1] + c[1]) * n_[0] + c[0];
}

VoxelMap::VoxelMap(const std::vector<Part>& parts, const VoxelOptions& opt, std::shared_ptr<const ObstacleIndex> exact)
    : res_(opt.resolution), threads_(opt.threads), max_cells_(opt.max_cells), exact_(std::move(exact)) {
  if (!(res_ > 0.0) || !std::isfinite(res_)) throw std::invalid_argument("voxel map: resolution must be positive");
  max_distance_ = opt.max_distance > 0.0 ? opt.max_distance : kDefaultMaxDistanceVoxels * res_;
  part_count_ = static_cast<int>(parts.size());
  AABB box;
  for (const Part& p : parts) box.extend(p.mesh.bounds());
  init_grid(box, parts.empty() ? std::string() : parts.front().source_file);
  if (!exact_) exact_ = std::make_shared<EmbreeIndex>(parts);
  const Stopwatch t0;
  voxelise(parts);
  fill_tree();
  stats_.voxelise_seconds = t0.seconds();
  edt_only_ = !opt.exact_refine;
  const Stopwatch t1;
  run_edt();
  stats_.edt_seconds = t1.seconds();
  if (!edt_only_) {
    const Stopwatch t2;
    refine();
    stats_.refine_seconds = t2.seconds();
  }
}

void VoxelMap::voxelise(const std::vector<Part>& parts) {
  const double h2 = half_diag_ * half_diag_ * (1.0 + 1e-12);
  for (std::size_t pi = 0; pi < parts.size(); ++pi) {
    const Mesh& m = parts[pi].mesh;
    // Surface: voxels whose centre is within half a diagonal of a triangle.
    for (std::size_t t = 0; t < m.triangle_count(); ++t) {
      const auto c = m.corners(t);
      long lo[3], hi[3];
      for (int a = 0; a < 3; ++a) {
        const double mn = std::min({c[0][a], c[1][a], c[2][a]}) - half_diag_;
        const double mx = std::max({c[0][a], c[1][a], c[2][a]}) + half_diag_;
        lo[a] = std::max(0L, static_cast<long>(std::floor(mn / res_)) - base_[a]);
        hi[a] = std::min(n_[a] - 1, static_cast<long>(std::floor(mx / res_)) - base_[a]);
      }
      for (long k = lo[2]; k <= hi[2]; ++k)
        for (long j = lo[1]; j <= hi[1]; ++j)
          for (long i = lo[0]; i <= hi[0]; ++i) {
            const long id = (k * n_[1] + j) * n_[0] + i;
            if (flags_[id] == kSurface) continue;
            if (closest_point_on_triangle(cell_centre(i, j, k), c[0], c[1], c[2]).dist2 <= h2) {
              flags_[id] = kSurface;
              part_[id] = static_cast<std::int32_t>(pi);
              ++stats_.surface_voxels;
            }
          }
    }
  }
  // Interior of closed parts: parity of crossings along x scan lines through offset
  // voxel-centre rows; rows whose line touches an edge are retried with another offset.
  for (std::size_t pi = 0; pi < parts.size(); ++pi) {
    const Part& part = parts[pi];
    if (!part.closed || part.mesh.empty()) continue;
    const Mesh& m = part.mesh;
    const AABB pb = m.bounds();
    long lo[3], hi[3];
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::max(0L, static_cast<long>(std::floor(pb.min[a] / res_)) - base_[a]);
      hi[a] = std::min(n_[a] - 1, static_cast<long>(std::floor(pb.max[a] / res_)) - base_[a]);
    }
    const long nj = hi[1] - lo[1] + 1, nk = hi[2] - lo[2] + 1;
    // Bin triangles into rows by their y-z extent (grown by the largest line offset).
    std::vector<std::vector<std::uint32_t>> rows(static_cast<std::size_t>(nj * nk));
    for (std::size_t t = 0; t < m.triangle_count(); ++t) {
      const auto c = m.corners(t);
      long r0[2], r1[2];
      for (int a = 1; a < 3; ++a) {
        const double mn = std::min({c[0][a], c[1][a], c[2][a]}) - 0.5 * res_;
        const double mx = std::max({c[0][a], c[1][a], c[2][a]}) + 0.5 * res_;
        r0[a - 1] = std::max(lo[a], static_cast<long>(std::floor(mn / res_)) - base_[a]);
        r1[a - 1] = std::min(hi[a], static_cast<long>(std::floor(mx / res_)) - base_[a]);
      }
      for (long k = r0[1]; k <= r1[1]; ++k)
        for (long j = r0[0]; j <= r1[0]; ++j) rows[(k - lo[2]) * nj + (j - lo[1])].push_back(static_cast<std::uint32_t>(t));
    }
    std::vector<double> xs;
    for (long k = lo[2]; k <= hi[2]; ++k)
      for (long j = lo[1]; j <= hi[1]; ++j) {
        const auto& tris = rows[(k - lo[2]) * nj + (j - lo[1])];
        if (tris.empty()) continue;
        bool ok = false;
        for (const auto& off : kLineOffsets) {
          const double qy = (base_[1] + j + 0.5 + off[0]) * res_, qz = (base_[2] + k + 0.5 + off[1]) * res_;
          xs.clear();
          bool touch = false;
          for (std::uint32_t t : tris) {
            const auto c = m.corners(t);
            const auto e = [&](const Vec3& a, const Vec3& b) {
              return (b.y() - a.y()) * (qz - a.z()) - (b.z() - a.z()) * (qy - a.y());
            };
            const double e0 = e(c[0], c[1]), e1 = e(c[1], c[2]), e2 = e(c[2], c[0]);
            const Vec3 n = (c[1] - c[0]).cross(c[2] - c[0]);
            const double scale = kEdgeTouchRel * std::max({(c[1] - c[0]).squaredNorm(), (c[2] - c[1]).squaredNorm(),
                                                           (c[0] - c[2]).squaredNorm()});
            const bool any_pos = e0 > scale || e1 > scale || e2 > scale;
            const bool any_neg = e0 < -scale || e1 < -scale || e2 < -scale;
            if (any_pos && any_neg) continue;  // clearly outside the projected triangle
            const bool all_pos = e0 > scale && e1 > scale && e2 > scale;
            const bool all_neg = e0 < -scale && e1 < -scale && e2 < -scale;
            if ((all_pos || all_neg) && std::abs(n.x()) > scale) {
              xs.push_back(c[0].x() - (n.y() * (qy - c[0].y()) + n.z() * (qz - c[0].z())) / n.x());
              continue;
            }
            touch = true;
            break;
          }
          if (touch || xs.size() % 2 != 0) continue;
          ok = true;
          break;
        }
        if (!ok) {  // every offset touched an edge: refine() decides the row's free cells
          for (long i = lo[0]; i <= hi[0]; ++i) {
            std::uint8_t& f = flags_[(k * n_[1] + j) * n_[0] + i];
            if (f == kFree) f = kUndecided;
          }
          continue;
        }
        std::sort(xs.begin(), xs.end());
        for (std::size_t s = 0; s + 1 < xs.size(); s += 2) {
          const long i0 = std::max(lo[0], static_cast<long>(std::ceil(xs[s] / res_ - 0.5)) - base_[0]);
          const long i1 = std::min(hi[0], static_cast<long>(std::floor(xs[s + 1] / res_ - 0.5)) - base_[0]);
          for (long i = i0; i <= i1; ++i) {
            const long id = (k * n_[1] + j) * n_[0] + i;
            if (flags_[id] != kFree) continue;
            flags_[id] = kInterior;
            part_[id] = static_cast<std::int32_t>(pi);
            ++stats_.interior_voxels;
          }
        }
      }
  }
}

void VoxelMap::fill_tree() {
  tree_ = std::make_unique<octomap::OcTree>(res_);
  for (long k = 0; k < n_[2]; ++k)
    for (long j = 0; j < n_[1]; ++j)
      for (long i = 0; i < n_[0]; ++i) {
        if (!occupied(flags_[(k * n_[1] + j) * n_[0] + i])) continue;
        const octomap::OcTreeKey key(static_cast<octomap::key_type>(base_[0] + i + kKeyHalf),
                                     static_cast<octomap::key_type>(base_[1] + j + kKeyHalf),
                                     static_cast<octomap::key_type>(base_[2] + k + kKeyHalf));
        tree_->updateNode(key, true, true);  // lazy: inner nodes updated once below
      }
  tree_->updateInnerOccupancy();
  tree_->prune();
}

void VoxelMap::run_edt() {
  // Squared distances in voxel units, seeded at occupied cells, in three separable passes.
  const std::size_t cells = dist_.size();
  std::vector<double> g(cells);
  for (std::size_t c = 0; c < cells; ++c) g[c] = occupied(flags_[c]) || (edt_only_ && flags_[c] == kUndecided) ? 0.0 : kEdtFar;
  for (int axis = 0; axis < 3; ++axis) {
    const long n = n_[axis];
    const long stride = axis == 0 ? 1 : axis == 1 ? n_[0] : n_[0] * n_[1];
    const std::size_t lines = cells / static_cast<std::size_t>(n);
    parallel_range(lines, threads_, 64, [&](std::size_t b, std::size_t e) {
      std::vector<double> f(n), d(n), z(n + 1);
      std::vector<long> v(n);
      for (std::size_t line = b; line < e; ++line) {
        // Line start: decompose the line index into the two other coordinates.
        long start;
        if (axis == 0) {
          start = static_cast<long>(line) * n_[0];
        } else if (axis == 1) {
          const long i = static_cast<long>(line) % n_[0], k = static_cast<long>(line) / n_[0];
          start = k * n_[0] * n_[1] + i;
        } else {
          start = static_cast<long>(line);
        }
        for (long q = 0; q < n; ++q) f[q] = g[start + q * stride];
        edt_1d(f.data(), n, d.data(), v.data(), z.data());
        for (long q = 0; q < n; ++q) g[start + q * stride] = d[q];
      }
    });
  }
  for (std::size_t c = 0; c < cells; ++c)
    dist_[c] = g[c] >= kEdtFar ? std::numeric_limits<float>::infinity() : static_cast<float>(std::sqrt(g[c]) * res_);
}

void VoxelMap::refine() {
  // Exact distance at each voxel centre within max_distance (+ the EDT's own error of one
  // half diagonal). Interior voxels are 0; surface voxels of closed parts are 0 when the
  // centre lies inside.
  const double band = max_distance_ + 2.0 * half_diag_;
  std::atomic<std::size_t> refined{0};
  const std::size_t cells = dist_.size();
  parallel_range(cells, threads_, 4096, [&](std::size_t b, std::size_t e) {
    std::size_t local = 0;
    for (std::size_t c = b; c < e; ++c) {
      const float edt = dist_[c];
      if (flags_[c] == kInterior) {
        dist_[c] = 0.0f;
        continue;
      }
      const long i = static_cast<long>(c % static_cast<std::size_t>(n_[0]));
      const long j = static_cast<long>((c / static_cast<std::size_t>(n_[0])) % static_cast<std::size_t>(n_[1]));
      const long k = static_cast<long>(c / static_cast<std::size_t>(n_[0] * n_[1]));
      const Vec3 p = cell_centre(i, j, k);
      // A cell the interior fill could not decide may lie deep inside a part, beyond the band.
      int inside_part = -1;
      if (flags_[c] == kUndecided && exact_->inside(p, &inside_part)) {
        dist_[c] = 0.0f;
        part_[c] = inside_part;
        continue;
      }
      if (!(edt <= band)) {
        dist_[c] = std::numeric_limits<float>::infinity();
        continue;
      }
      const ClosestHit h = exact_->closest(p, static_cast<double>(edt) + 2.0 * half_diag_);
      ++local;
      if (!h.found()) {
        dist_[c] = std::numeric_limits<float>::infinity();
        continue;
      }
      if (flags_[c] == kSurface && exact_->inside(p, &inside_part)) {
        dist_[c] = 0.0f;
        part_[c] = inside_part;
        continue;
      }
      dist_[c] = h.distance > max_distance_ ? std::numeric_limits<float>::infinity() : static_cast<float>(h.distance);
      part_[c] = h.part;
    }
    refined += local;
  });
  stats_.refined_voxels = refined.load();
}

std::unique_ptr<VoxelMap> VoxelMap::load_bt(const std::string& path, const VoxelOptions& opt) {
  std::unique_ptr<VoxelMap> vm(new VoxelMap());
  auto tree = std::make_unique<octomap::OcTree>(0.1);
  std::ifstream in(path, std::ios::binary);
  if (!in || !tree->readBinary(in)) throw InputError({path, 0, "octomap"}, "cannot read an OctoMap binary (.bt) tree");
  vm->res_ = tree->getResolution();
  vm->max_distance_ = opt.max_distance > 0.0 ? opt.max_distance : kDefaultMaxDistanceVoxels * vm->res_;
  vm->threads_ = opt.threads;
  vm->max_cells_ = opt.max_cells;
  vm->from_file_ = true;
  vm->part_count_ = 1;
  AABB box;
  for (auto it = tree->begin_leafs(); it != tree->end_leafs(); ++it) {
    if (!tree->isNodeOccupied(*it)) continue;
    const double hs = 0.5 * it.getSize() - 0.25 * vm->res_;
    const Vec3 c(it.getX(), it.getY(), it.getZ());
    box.extend(c - Vec3::Constant(hs));
    box.extend(c + Vec3::Constant(hs));
  }
  vm->init_grid(box, path);
  for (auto it = tree->begin_leafs(); it != tree->end_leafs(); ++it) {
    if (!tree->isNodeOccupied(*it)) continue;
    const double hs = 0.5 * it.getSize();
    const Vec3 c(it.getX(), it.getY(), it.getZ());
    // A pruned leaf covers several voxels: mark every voxel centre inside it.
    const long steps = std::max(1L, static_cast<long>(std::llround(it.getSize() / vm->res_)));
    for (long a = 0; a < steps; ++a)
      for (long b = 0; b < steps; ++b)
        for (long d = 0; d < steps; ++d) {
          const Vec3 p = c - Vec3::Constant(hs) + (Vec3(a, b, d) + Vec3::Constant(0.5)) * vm->res_;
          const long id = vm->cell_of(p);
          if (id >= 0 && vm->flags_[id] == kFree) {
            vm->flags_[id] = kSurface;
            vm->part_[id] = 0;
            ++vm->stats_.surface_voxels;
          }
        }
  }
  vm->tree_ = std::move(tree);
  const Stopwatch t1;
  vm->run_edt();
  vm->stats_.edt_seconds = t1.seconds();
  for (std::size_t c = 0; c < vm->dist_.size(); ++c) {
    if (vm->dist_[c] > vm->max_distance_) vm->dist_[c] = std::numeric_limits<float>::infinity();
    else vm->part_[c] = 0;
  }
  return vm;
}

void VoxelMap::save_bt(const std::string& path) const {
  AtomicFile out(path, true);
  if (!tree_->writeBinaryConst(out.stream())) throw std::runtime_error("voxel map: cannot write " + path);
  out.commit();
}

std::size_t VoxelMap::memory_bytes() const {
  return dist_.capacity() * sizeof(float) + part_.capacity() * sizeof(std::int32_t) + flags_.capacity() +
         (tree_ ? tree_->memoryUsage() : 0);
}

std::size_t VoxelMap::octree_leaf_count() const { return tree_ ? tree_->getNumLeafNodes() : 0; }

IndexAccuracy VoxelMap::accuracy() const {
  IndexAccuracy a;
  a.exact = false;
  // Nearest-centre lookup of a 1-Lipschitz function: ≤ half a diagonal; float storage adds
  // a relative 2^-24 of max_distance.
  const double storage = max_distance_ * 6e-8;
  if (edt_only_) {
    a.abs_error = 2.0 * half_diag_ + storage;
    a.description = "voxel map " + full_precision(res_) + ", EDT of occupied voxels: <= voxel diagonal " +
                    full_precision(a.abs_error) + " scene units";
  } else if (from_file_) {
    a.abs_error = 2.0 * half_diag_ + storage;
    a.description = "voxel map loaded from .bt, EDT of occupied voxel centres: <= voxel diagonal " +
                    full_precision(a.abs_error) + " scene units up to " + full_precision(max_distance_);
  } else {
    a.abs_error = half_diag_ + storage;
    a.description = "voxel map " + full_precision(res_) + " (exact distances at voxel centres): <= half voxel diagonal " +
                    full_precision(a.abs_error) + " scene units up to " + full_precision(max_distance_);
  }
  return a;
}

double VoxelMap::distance(const Vec3& p) const {
  const long c = cell_of(p);
  if (c < 0) return std::numeric_limits<double>::infinity();
  return static_cast<double>(dist_[c]);
}

ClosestHit VoxelMap::closest(const Vec3& p, double max_radius) const {
  ClosestHit h;
  const long c = cell_of(p);
  if (c < 0) return h;
  const double d = dist_[c];
  if (!(d <= max_radius) || !std::isfinite(d)) return h;
  h.distance = d;
  h.part = part_[c] >= 0 ? part_[c] : 0;
  h.point = p;
  if (d > 0.0) {
    // Direction to the surface: minus the central-difference gradient of the grid.
    Vec3 g = Vec3::Zero();
    for (int a = 0; a < 3; ++a) {
      Vec3 e = Vec3::Zero();
      e[a] = res_;
      const double dp = distance(p + e), dm = distance(p - e);
      if (std::isfinite(dp) && std::isfinite(dm)) g[a] = dp - dm;
      else if (std::isfinite(dp)) g[a] = 2.0 * (dp - d);
      else if (std::isfinite(dm)) g[a] = 2.0 * (d - dm);
    }
    if (g.norm() > 0.0) h.point = p - d * g.normalized();
  }
  return h;
}

ClosestHit VoxelMap::closest_on_part(const Vec3& p, int part, double max_radius) const {
  if (part < 0 || part >= part_count_) throw std::out_of_range("voxel map: part id " + std::to_string(part) + " out of range");
  if (exact_) return exact_->closest_on_part(p, part, max_radius);
  return closest(p, max_radius);  // a loaded map has a single pseudo-part
}

ClosestHit VoxelMap::segment_closest_on_part(const Vec3& a, const Vec3& b, int part, double max_radius,
                                            double* segment_param) const {
  if (part < 0 || part >= part_count_) throw std::out_of_range("voxel map: part id " + std::to_string(part) + " out of range");
  if (exact_) return exact_->segment_closest_on_part(a, b, part, max_radius, segment_param);
  return segment_closest(a, b, max_radius, segment_param);  // a loaded map has a single pseudo-part
}

bool VoxelMap::inside(const Vec3& p, int* part) const {
  const long c = cell_of(p);
  if (c < 0 || flags_[c] == kFree) return false;
  if (flags_[c] == kInterior) {
    if (part) *part = part_[c];
    return true;
  }
  if (exact_) return exact_->inside(p, part);
  if (part) *part = 0;
  return true;  // loaded map: occupied voxels are solid
}

void VoxelMap::inside_parts(const Vec3& p, std::vector<int>& out) const {
  if (exact_) {
    exact_->inside_parts(p, out);
    return;
  }
  out.clear();
  int part = -1;
  if (inside(p, &part)) out.push_back(part);
}

RayHit VoxelMap::ray(const Vec3& origin, const Vec3& dir, double t_max) const {
  const double n = dir.norm();
  if (!(n > 0.0) || !std::isfinite(n)) throw std::invalid_argument("voxel map: ray direction is zero or not finite");
  const Vec3 u = dir / n;
  RayHit out;
  const double reach = std::sqrt(double(n_[0] * n_[0] + n_[1] * n_[1] + n_[2] * n_[2])) * res_ +
                       (origin - cell_centre(n_[0] / 2, n_[1] / 2, n_[2] / 2)).norm();
  const double range = std::min(t_max, reach);
  const octomap::point3d o(float(origin.x()), float(origin.y()), float(origin.z()));
  const octomap::point3d d(float(u.x()), float(u.y()), float(u.z()));
  octomap::point3d end;
  if (!tree_->castRay(o, d, end, true, range)) return out;
  octomap::point3d entry;
  double t = (Vec3(end.x(), end.y(), end.z()) - origin).dot(u);
  if (tree_->getRayIntersection(o, d, end, entry, 0.0)) t = (Vec3(entry.x(), entry.y(), entry.z()) - origin).dot(u);
  t = std::max(0.0, t);
  if (t > t_max) return out;
  out.t = t;
  const long c = cell_of(Vec3(end.x(), end.y(), end.z()));
  out.part = c >= 0 && part_[c] >= 0 ? part_[c] : 0;
  out.triangle = -1;
  out.normal = -u;  // voxel answers carry no surface normal: facing the ray
  return out;
}

bool VoxelMap::any_within(const Vec3& p, double r) const {
  if (!(r >= 0.0)) return false;
  if (r > max_distance_ && exact_) return exact_->any_within(p, r);
  return distance(p) <= r;
}

bool VoxelMap::segment_within(const Vec3& a, const Vec3& b, double r) const {
  if (!(r >= 0.0)) return false;
  if (r > max_distance_ && exact_) return exact_->segment_within(a, b, r);
  // Sphere tracing on the map: steps of (d − r) never skip a closer surface (1-Lipschitz),
  // with a floor of half a voxel.
  const double len = (b - a).norm();
  const Vec3 u = len > 0.0 ? Vec3((b - a) / len) : Vec3::Zero();
  double t = 0.0;
  while (true) {
    const double d = distance(a + t * u);
    if (d <= r) return true;
    if (t >= len) return false;
    const double step = std::isfinite(d) ? std::max(d - r, 0.5 * res_) : std::max(max_distance_ - r, 0.5 * res_);
    t = std::min(len, t + step);
  }
}

ClosestHit VoxelMap::segment_closest(const Vec3& a, const Vec3& b, double max_radius, double* segment_param) const {
  const double len = (b - a).norm();
  const int n = std::max(1, static_cast<int>(std::ceil(len / (0.5 * res_))));
  ClosestHit best;
  double best_s = 0.0;
  for (int k = 0; k <= n; ++k) {
    const double s = static_cast<double>(k) / n;
    const Vec3 p = a + s * (b - a);
    const ClosestHit h = closest(p, std::min(max_radius, best.distance));
    if (h.found() && h.distance < best.distance) {
      best = h;
      best_s = s;
    }
  }
  if (best.found() && segment_param) *segment_param = best_s;
  return best;
}

}  // namespace loom
