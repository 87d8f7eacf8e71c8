#include "core/io/voxel_part.hpp"

#include "core/error.hpp"
#include "core/io/input_file.hpp"
#include "core/io/point_cloud_io.hpp"
#include <cstring>

#include <octomap/OcTree.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <vector>

namespace loom {

namespace {

constexpr unsigned kTreeDepth = 16;  // OctoMap's key width
// OctoMap keys are 16-bit around a centre key: coordinates within ±(2^15 − 1) voxels are addressable.
constexpr double kKeyRange = 32767.0;

std::string lower_ext(const std::filesystem::path& p) {
  std::string e = p.extension().string();
  std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return e;
}

[[noreturn]] void fail(const std::filesystem::path& p, const std::string& why) {
  throw InputError({p.string(), 0, ""}, why);
}

std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  if (!in) fail(p, "cannot open the file");
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// The header of an OctoMap file, parsed as AbstractOcTree::readHeader does.
struct TreeHeader {
  std::string id;
  unsigned long long size = 0;
  double res = 0.0;
  std::size_t data = 0;  ///< byte offset of the node data
};

TreeHeader parse_header(const std::string& bytes, const std::string& magic, const std::filesystem::path& p) {
  if (bytes.compare(0, magic.size(), magic) != 0) fail(p, "not an OctoMap file: the first line is not '" + magic + "'");
  std::size_t pos = bytes.find('\n');
  if (pos == std::string::npos) fail(p, "truncated OctoMap header");
  ++pos;
  TreeHeader h;
  bool have_res = false, have_size = false;
  auto next_line = [&](std::size_t from) {
    const std::size_t nl = bytes.find('\n', from);
    return nl == std::string::npos ? bytes.size() : nl + 1;
  };
  // Tokens are whitespace-separated; a header never needs more than a few hundred bytes,
  // so the header is read line by line and stops at "data".
  while (true) {
    if (pos >= bytes.size()) fail(p, "truncated OctoMap header (no 'data' line)");
    const std::size_t end = next_line(pos);
    std::istringstream line(bytes.substr(pos, end - pos));
    std::string key;
    line >> key;
    if (key == "data") {
      h.data = end;
      break;
    }
    if (key.empty() || key[0] == '#') {
    } else if (key == "id") {
      line >> h.id;
    } else if (key == "size") {
      have_size = static_cast<bool>(line >> h.size);
    } else if (key == "res") {
      have_res = static_cast<bool>(line >> h.res);
    }
    pos = end;
  }
  if (h.id == "1") h.id = "OcTree";
  if (h.id != "OcTree")
    fail(p, "OctoMap tree type '" + h.id + "' is not supported (only OcTree: occupancy without colour or stamps)");
  if (!have_size) fail(p, "OctoMap header has no 'size'");
  if (!have_res || !std::isfinite(h.res) || !(h.res > 0.0))
    fail(p, "OctoMap resolution must be positive and finite, got " + full_precision(h.res));
  return h;
}

/// Walks the node structure of a .bt (2 bytes per node, 2 bits per child: 01 occupied leaf,
/// 10 free leaf, 11 inner node) so that OctoMap, which does not check its stream, never reads
/// past the end or builds nodes below the finest level. Returns the node count.
unsigned long long check_bt_nodes(const std::string& b, std::size_t& pos, const std::filesystem::path& p) {
  struct Frame {
    unsigned depth;
  };
  unsigned long long nodes = 0;
  std::vector<Frame> stack{{0}};
  while (!stack.empty()) {
    const Frame f = stack.back();
    stack.pop_back();
    ++nodes;
    if (pos + 2 > b.size()) fail(p, "truncated OctoMap data at byte " + std::to_string(pos));
    const unsigned char c[2] = {static_cast<unsigned char>(b[pos]), static_cast<unsigned char>(b[pos + 1])};
    pos += 2;
    std::vector<Frame> inner;
    for (unsigned i = 0; i < 8; ++i) {
      const unsigned bits = (c[i / 4] >> (2 * (i % 4))) & 3u;
      if (bits == 0) continue;
      if (f.depth + 1 > kTreeDepth) fail(p, "corrupt OctoMap data: nodes below the finest level");
      if (bits == 3) inner.push_back({f.depth + 1});
      else ++nodes;
    }
    // Children are read depth first in child order: push them reversed.
    for (auto it = inner.rbegin(); it != inner.rend(); ++it) {
      if (it->depth >= kTreeDepth) fail(p, "corrupt OctoMap data: an inner node at the finest level");
      stack.push_back(*it);
    }
  }
  return nodes;
}

/// Same for a .ot: per node a float log-odds value and a byte of child flags.
unsigned long long check_ot_nodes(const std::string& b, std::size_t& pos, const std::filesystem::path& p) {
  unsigned long long nodes = 0;
  std::vector<unsigned> stack{0};
  while (!stack.empty()) {
    const unsigned depth = stack.back();
    stack.pop_back();
    ++nodes;
    if (pos + 5 > b.size()) fail(p, "truncated OctoMap data at byte " + std::to_string(pos));
    float v;
    std::memcpy(&v, b.data() + pos, sizeof v);
    if (!std::isfinite(v)) fail(p, "corrupt OctoMap data: a node value is not finite at byte " + std::to_string(pos));
    const auto children = static_cast<unsigned char>(b[pos + 4]);
    pos += 5;
    if (children != 0 && depth >= kTreeDepth) fail(p, "corrupt OctoMap data: nodes below the finest level");
    for (int i = 7; i >= 0; --i)
      if (children & (1u << i)) stack.push_back(depth + 1);
  }
  return nodes;
}

/// Holds std::cerr's output while OctoMap reads: Debian's OctoMap prints debug lines there
/// ("Reading binary octree type OcTree"), and loom's stderr carries loom's messages only
/// (`--quiet` prints nothing). Restored on every exit path.
class QuietCerr {
 public:
  QuietCerr() : old_(std::cerr.rdbuf(sink_.rdbuf())) {}
  ~QuietCerr() { std::cerr.rdbuf(old_); }
  QuietCerr(const QuietCerr&) = delete;
  QuietCerr& operator=(const QuietCerr&) = delete;

 private:
  std::ostringstream sink_;
  std::streambuf* old_;
};

std::unique_ptr<octomap::OcTree> read_tree(const std::filesystem::path& p) {
  const std::string bytes = slurp(p);
  const bool binary = lower_ext(p) == ".bt";
  const TreeHeader h = parse_header(bytes, binary ? "# Octomap OcTree binary file" : "# Octomap OcTree file", p);
  if (h.size == 0) fail(p, "the OctoMap tree is empty");
  std::size_t pos = h.data;
  const unsigned long long n = binary ? check_bt_nodes(bytes, pos, p) : check_ot_nodes(bytes, pos, p);
  if (n != h.size)
    fail(p, "corrupt OctoMap file: the header says " + std::to_string(h.size) + " nodes, the data holds " +
                std::to_string(n));
  std::istringstream in(bytes);
  const QuietCerr quiet;
  std::unique_ptr<octomap::OcTree> tree;
  if (binary) {
    tree = std::make_unique<octomap::OcTree>(h.res);
    if (!tree->readBinary(in)) fail(p, "OctoMap cannot read the binary tree");
  } else {
    std::unique_ptr<octomap::AbstractOcTree> t(octomap::AbstractOcTree::read(in));
    auto* oc = dynamic_cast<octomap::OcTree*>(t.get());
    if (!oc) fail(p, "OctoMap cannot read the tree");
    t.release();
    tree.reset(oc);
  }
  return tree;
}

void check_in_key_range(const Vec3& v, double res, const std::filesystem::path& p, const std::string& what) {
  if (!(v.cwiseAbs().maxCoeff() < kKeyRange * res))
    fail(p, what + " at " + full_precision(v) + " is beyond OctoMap's ±32767 voxels of " + full_precision(res) +
                " (use a coarser resolution)");
}

std::unique_ptr<octomap::OcTree> cloud_tree(const std::filesystem::path& p, const VoxelPartOptions& opt,
                                            std::size_t& points) {
  if (!std::isfinite(opt.resolution) || !(opt.resolution > 0.0))
    fail(p, "a point cloud part needs a resolution > 0, got " + full_precision(opt.resolution));
  const PointCloud pc = read_point_cloud(p);
  if (pc.dropped_nonfinite > 0)
    fail(p, std::to_string(pc.dropped_nonfinite) + " point(s) with a NaN or infinite coordinate");
  auto tree = std::make_unique<octomap::OcTree>(opt.resolution);
  octomap::Pointcloud cloud;
  cloud.reserve(pc.points.size());
  for (const Vec3& v : pc.points) {
    check_in_key_range(v, opt.resolution, p, "a point");
    cloud.push_back(static_cast<float>(v.x()), static_cast<float>(v.y()), static_cast<float>(v.z()));
  }
  points = pc.points.size();
  if (opt.origin) {
    check_in_key_range(*opt.origin, opt.resolution, p, "the origin");
    // One insertion: within a scan, a voxel holding a point stays occupied even if other
    // rays pass through it, so every point lies in an occupied voxel.
    tree->insertPointCloud(cloud, octomap::point3d(static_cast<float>(opt.origin->x()),
                                                   static_cast<float>(opt.origin->y()),
                                                   static_cast<float>(opt.origin->z())));
  } else {
    for (const auto& q : cloud) tree->updateNode(q, true, true);
    tree->updateInnerOccupancy();
  }
  return tree;
}

std::uint64_t pack(unsigned x, unsigned y, unsigned z) {
  return std::uint64_t(x) | (std::uint64_t(y) << 21) | (std::uint64_t(z) << 42);
}

/// Finest-level keys of the occupied voxels (and, if asked, the unknown ones within the
/// bounds of the observed voxels), sorted.
std::vector<std::uint64_t> occupied_keys(const octomap::OcTree& tree, const VoxelPartOptions& opt,
                                         const std::filesystem::path& p, std::size_t& unknown_filled) {
  const double res = tree.getResolution();
  std::unordered_set<std::uint64_t> keys;
  double total = 0.0;
  for (auto it = tree.begin_leafs(); it != tree.end_leafs(); ++it)
    if (tree.isNodeOccupied(*it)) total += std::pow(8.0, static_cast<double>(kTreeDepth - it.getDepth()));
  if (total > static_cast<double>(opt.max_voxels))
    fail(p, "too many occupied voxels (" + full_precision(total) + " > " + std::to_string(opt.max_voxels) +
                "); use a coarser resolution");
  for (auto it = tree.begin_leafs(); it != tree.end_leafs(); ++it) {
    if (!tree.isNodeOccupied(*it)) continue;
    const unsigned steps = 1u << (kTreeDepth - it.getDepth());
    const octomap::OcTreeKey k0 = tree.coordToKey(
        octomap::point3d(it.getX(), it.getY(), it.getZ()) -
        octomap::point3d(1, 1, 1) * static_cast<float>(0.5 * it.getSize() - 0.5 * res));
    for (unsigned a = 0; a < steps; ++a)
      for (unsigned b = 0; b < steps; ++b)
        for (unsigned c = 0; c < steps; ++c) keys.insert(pack(k0[0] + a, k0[1] + b, k0[2] + c));
  }
  unknown_filled = 0;
  if (opt.unknown_occupied && tree.size() > 0) {
    double mn[3], mx[3];
    tree.getMetricMin(mn[0], mn[1], mn[2]);
    tree.getMetricMax(mx[0], mx[1], mx[2]);
    const octomap::OcTreeKey lo = tree.coordToKey(mn[0] + 0.5 * res, mn[1] + 0.5 * res, mn[2] + 0.5 * res);
    const octomap::OcTreeKey hi = tree.coordToKey(mx[0] - 0.5 * res, mx[1] - 0.5 * res, mx[2] - 0.5 * res);
    const double volume = double(hi[0] - lo[0] + 1) * double(hi[1] - lo[1] + 1) * double(hi[2] - lo[2] + 1);
    if (volume > static_cast<double>(opt.max_voxels))
      fail(p, "unknown = \"occupied\" would fill up to " + full_precision(volume) + " voxels (> " +
                  std::to_string(opt.max_voxels) + "); use a coarser resolution");
    for (unsigned x = lo[0]; x <= hi[0]; ++x)
      for (unsigned y = lo[1]; y <= hi[1]; ++y)
        for (unsigned z = lo[2]; z <= hi[2]; ++z)
          if (!tree.search(octomap::OcTreeKey(x, y, z)) && keys.insert(pack(x, y, z)).second) ++unknown_filled;
  }
  std::vector<std::uint64_t> out(keys.begin(), keys.end());
  std::sort(out.begin(), out.end());
  return out;
}

/// Outward quads between occupied voxels and the rest, two triangles each, corners shared.
Mesh boundary_mesh(const std::vector<std::uint64_t>& keys, double res) {
  const std::unordered_set<std::uint64_t> occ(keys.begin(), keys.end());
  std::unordered_map<std::uint64_t, std::uint32_t> corner_index;
  Mesh m;
  const auto corner = [&](unsigned x, unsigned y, unsigned z) {
    const auto [it, fresh] = corner_index.emplace(pack(x, y, z), static_cast<std::uint32_t>(m.vertices.size()));
    if (fresh) {
      // Corner c of key k lies at (c − 2^15)·res: the voxel with key k spans [k, k + 1).
      m.vertices.emplace_back((double(x) - 32768.0) * res, (double(y) - 32768.0) * res, (double(z) - 32768.0) * res);
    }
    return it->second;
  };
  constexpr std::uint64_t kMask = (std::uint64_t(1) << 21) - 1;
  for (const std::uint64_t k : keys) {
    const unsigned v[3] = {unsigned(k & kMask), unsigned((k >> 21) & kMask), unsigned((k >> 42) & kMask)};
    for (int a = 0; a < 3; ++a)
      for (int s = -1; s <= 1; s += 2) {
        unsigned n[3] = {v[0], v[1], v[2]};
        n[a] = unsigned(int(n[a]) + s);
        if (occ.count(pack(n[0], n[1], n[2]))) continue;
        const int u = (a + 1) % 3, w = (a + 2) % 3;
        // Corners (0,0), (1,0), (1,1), (0,1) in (u, w) turn about e_u × e_w = e_a.
        std::uint32_t q[4];
        const int du[4] = {0, 1, 1, 0}, dw[4] = {0, 0, 1, 1};
        for (int i = 0; i < 4; ++i) {
          unsigned c[3] = {v[0], v[1], v[2]};
          c[a] += s > 0 ? 1 : 0;
          c[u] += unsigned(du[i]);
          c[w] += unsigned(dw[i]);
          q[i] = corner(c[0], c[1], c[2]);
        }
        if (s > 0) {
          m.triangles.push_back({q[0], q[1], q[2]});
          m.triangles.push_back({q[0], q[2], q[3]});
        } else {
          m.triangles.push_back({q[0], q[2], q[1]});
          m.triangles.push_back({q[0], q[3], q[2]});
        }
      }
  }
  return m;
}

}  // namespace

bool is_octree_file(const std::filesystem::path& p) {
  const std::string e = lower_ext(p);
  return e == ".bt" || e == ".ot";
}

bool is_point_cloud_only_file(const std::filesystem::path& p) {
  const std::string e = lower_ext(p);
  return e == ".pcd" || e == ".xyz";
}

VoxelPart read_voxel_part(const std::filesystem::path& path, const VoxelPartOptions& opt) {
  require_input_file(path, "scanned part");
  VoxelPart out;
  std::unique_ptr<octomap::OcTree> tree;
  if (is_octree_file(path)) {
    if (opt.resolution != 0.0) fail(path, "an OctoMap tree has its own resolution: 'resolution' applies to point clouds");
    if (opt.origin) fail(path, "an OctoMap tree is already a map: 'origin' applies to point clouds");
    tree = read_tree(path);
  } else {
    tree = cloud_tree(path, opt, out.points);
  }
  out.resolution = tree->getResolution();
  const std::vector<std::uint64_t> keys = occupied_keys(*tree, opt, path, out.unknown_filled);
  if (keys.empty()) fail(path, "no occupied voxel");
  out.occupied_voxels = keys.size();
  out.mesh = boundary_mesh(keys, out.resolution);
  return out;
}

}  // namespace loom
