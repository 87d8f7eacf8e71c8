// Scanned parts: point clouds and OctoMap trees as the union of their occupied voxels,
// against an independent voxelisation (floor(x / resolution)) and its exposed faces.
#include "common/test_files.hpp"
#include "core/io/scene_load.hpp"
#include "core/io/voxel_part.hpp"

#include <gtest/gtest.h>
#include <octomap/OcTree.h>

#include <array>
#include <cmath>
#include <random>
#include <set>
#include <sstream>

namespace {

using loom::testing::input_error;
using loom::testing::scratch_dir;
using loom::testing::slurp;
using loom::testing::write_file;
using Key = std::array<long, 3>;

std::vector<loom::Vec3> random_points(unsigned seed, int n, const loom::Vec3& lo, const loom::Vec3& hi) {
  std::mt19937 rng(seed);
  std::vector<loom::Vec3> pts;
  for (int i = 0; i < n; ++i) {
    loom::Vec3 p;
    for (int a = 0; a < 3; ++a) p[a] = std::uniform_real_distribution<double>(lo[a], hi[a])(rng);
    pts.push_back(p);
  }
  return pts;
}

std::string xyz_text(const std::vector<loom::Vec3>& pts) {
  std::ostringstream s;
  s.precision(17);
  for (const auto& p : pts) s << p.x() << ' ' << p.y() << ' ' << p.z() << '\n';
  return s.str();
}

/// The oracle: voxel keys floor(x / res) and the number of their faces not shared.
std::set<Key> voxel_keys(const std::vector<loom::Vec3>& pts, double res) {
  std::set<Key> keys;
  for (const auto& p : pts)
    keys.insert({long(std::floor(p.x() / res)), long(std::floor(p.y() / res)), long(std::floor(p.z() / res))});
  return keys;
}

std::size_t exposed_faces(const std::set<Key>& keys) {
  std::size_t n = 0;
  for (const Key& k : keys)
    for (int a = 0; a < 3; ++a)
      for (int s = -1; s <= 1; s += 2) {
        Key m = k;
        m[a] += s;
        n += keys.count(m) ? 0 : 1;
      }
  return n;
}

TEST(VoxelPart, PointCloudIsTheUnionOfItsVoxels) {
  const auto d = scratch_dir("voxel_part_");
  const double res = 0.25;
  // Avoid points within float rounding of a voxel face: OctoMap converts through float.
  auto pts = random_points(7, 400, {-2, -1, 0.3}, {3, 2, 1.7});
  for (auto& p : pts)
    for (int a = 0; a < 3; ++a) {
      const double f = p[a] / res - std::floor(p[a] / res);
      if (f < 1e-3 || f > 1 - 1e-3) p[a] += 0.01;
    }
  write_file(d / "c.xyz", xyz_text(pts));
  loom::VoxelPartOptions opt;
  opt.resolution = res;
  const loom::VoxelPart vp = loom::read_voxel_part(d / "c.xyz", opt);
  const auto keys = voxel_keys(pts, res);
  EXPECT_EQ(vp.occupied_voxels, keys.size());
  EXPECT_EQ(vp.points, pts.size());
  EXPECT_EQ(vp.mesh.triangle_count(), 2 * exposed_faces(keys));
  Key lo = *keys.begin(), hi = lo;
  for (const Key& k : keys)
    for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], k[a]), hi[a] = std::max(hi[a], k[a]);
  const loom::AABB box = vp.mesh.bounds();
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(box.min[a], lo[a] * res, 1e-9);
    EXPECT_NEAR(box.max[a], (hi[a] + 1) * res, 1e-9);
  }
  // Outward: the faces enclose the voxels' volume wherever the surface is closed.
  const loom::MeshTopology topo = loom::analyse_topology(vp.mesh);
  EXPECT_EQ(topo.misoriented_edges, 0u);
}

TEST(VoxelPart, OneVoxelIsAClosedOutwardCube) {
  const auto d = scratch_dir("voxel_part_");
  write_file(d / "one.xyz", "0.1 0.2 0.3\n0.15 0.25 0.35\n");
  loom::VoxelPartOptions opt;
  opt.resolution = 0.5;
  const loom::VoxelPart vp = loom::read_voxel_part(d / "one.xyz", opt);
  EXPECT_EQ(vp.occupied_voxels, 1u);
  EXPECT_EQ(vp.mesh.triangle_count(), 12u);
  const loom::MeshTopology topo = loom::analyse_topology(vp.mesh);
  EXPECT_TRUE(topo.closed);
  EXPECT_NEAR(vp.mesh.signed_volume(), 0.125, 1e-12);
}

TEST(VoxelPart, RaysFromTheOriginNeverFreeAVoxelHoldingAPoint) {
  const auto d = scratch_dir("voxel_part_");
  // A wall at x ≈ 4 seen from the origin, and points in front of it that rays to the wall cross.
  std::vector<loom::Vec3> pts = random_points(3, 300, {4.05, -2, -2}, {4.2, 2, 2});
  const auto front = random_points(4, 40, {2.05, -1.9, -1.9}, {2.2, 1.9, 1.9});
  pts.insert(pts.end(), front.begin(), front.end());
  write_file(d / "wall.xyz", xyz_text(pts));
  loom::VoxelPartOptions opt;
  opt.resolution = 0.5;
  opt.origin = loom::Vec3(0.1, 0.1, 0.1);
  const loom::VoxelPart vp = loom::read_voxel_part(d / "wall.xyz", opt);
  EXPECT_EQ(vp.occupied_voxels, voxel_keys(pts, 0.5).size());
}

TEST(VoxelPart, UnknownOccupiedFillsTheObservedBounds) {
  const auto d = scratch_dir("voxel_part_");
  write_file(d / "corners.xyz", "0.1 0.1 0.1\n1.9 0.9 2.9\n");
  loom::VoxelPartOptions opt;
  opt.resolution = 1.0;
  EXPECT_EQ(loom::read_voxel_part(d / "corners.xyz", opt).occupied_voxels, 2u);
  opt.unknown_occupied = true;
  const loom::VoxelPart vp = loom::read_voxel_part(d / "corners.xyz", opt);
  EXPECT_EQ(vp.occupied_voxels, 2u * 1u * 3u);
  EXPECT_EQ(vp.unknown_filled, 4u);
  EXPECT_EQ(vp.mesh.triangle_count(), 2u * 2u * (2 * 1 + 1 * 3 + 2 * 3));
}

TEST(VoxelPart, OctomapTreesReadBackTheirOccupiedVoxels) {
  const auto d = scratch_dir("voxel_part_");
  octomap::OcTree tree(0.2);
  const auto pts = random_points(11, 200, {-1, -1, -1}, {1, 1, 1});
  for (const auto& p : pts) tree.updateNode(octomap::point3d(float(p.x()), float(p.y()), float(p.z())), true);
  tree.updateNode(octomap::point3d(3.05f, 3.05f, 3.05f), false);  // a free voxel: not part of the structure
  tree.updateInnerOccupancy();
  std::size_t occupied = 0;  // finest voxels: a pruned leaf of depth d holds 8^(16 - d)
  for (auto it = tree.begin_leafs(); it != tree.end_leafs(); ++it)
    if (tree.isNodeOccupied(*it)) occupied += std::size_t(1) << (3 * (16 - it.getDepth()));
  ASSERT_TRUE(tree.writeBinary((d / "t.bt").string()));
  ASSERT_TRUE(tree.write((d / "t.ot").string()));
  for (const char* f : {"t.bt", "t.ot"}) {
    const loom::VoxelPart vp = loom::read_voxel_part(d / f, {});
    EXPECT_EQ(vp.occupied_voxels, occupied) << f;
    EXPECT_DOUBLE_EQ(vp.resolution, 0.2) << f;
  }
}

TEST(VoxelPart, ReadsTheSharedBuildingScan) {
  const std::filesystem::path f = std::filesystem::path(LOOM_SHARED_DATA) / "octomap" / "geb079.bt";
  if (!std::filesystem::exists(f)) GTEST_SKIP() << f << " not present";
  const loom::VoxelPart vp = loom::read_voxel_part(f, {});
  EXPECT_GT(vp.occupied_voxels, 1000u);
  EXPECT_GT(vp.resolution, 0.0);
  EXPECT_EQ(loom::analyse_topology(vp.mesh).misoriented_edges, 0u);
}

TEST(VoxelPartInput, CorruptOrTruncatedTreesNameTheFile) {
  const auto d = scratch_dir("voxel_part_");
  octomap::OcTree tree(0.1);
  for (const auto& p : random_points(5, 100, {-1, -1, -1}, {1, 1, 1}))
    tree.updateNode(octomap::point3d(float(p.x()), float(p.y()), float(p.z())), true);
  ASSERT_TRUE(tree.writeBinary((d / "good.bt").string()));
  ASSERT_TRUE(tree.write((d / "good.ot").string()));
  for (const char* ext : {".bt", ".ot"}) {
    const std::string good = slurp(d / (std::string("good") + ext));
    const std::string cut = (d / (std::string("cut") + ext)).string();
    write_file(cut, good.substr(0, good.size() - 7));
    EXPECT_NE(input_error([&] { loom::read_voxel_part(cut, {}); }).find(cut), std::string::npos) << ext;
    // Every child flag set: inner nodes all the way down, far past the bytes and the depth.
    const std::size_t data = good.find("data\n") + 5;
    std::string ones = good;
    for (std::size_t i = data; i < ones.size(); ++i) ones[i] = '\xff';
    const std::string bad = (d / (std::string("ones") + ext)).string();
    write_file(bad, ones);
    EXPECT_NE(input_error([&] { loom::read_voxel_part(bad, {}); }).find(bad), std::string::npos) << ext;
    std::string zero_res = good;
    const std::size_t r = zero_res.find("res ");
    zero_res.replace(r, zero_res.find('\n', r) - r, "res 0");
    const std::string zr = (d / (std::string("zero_res") + ext)).string();
    write_file(zr, zero_res);
    EXPECT_NE(input_error([&] { loom::read_voxel_part(zr, {}); }).find("resolution"), std::string::npos) << ext;
  }
  write_file(d / "text.bt", "not an octree\n");
  EXPECT_NE(input_error([&] { loom::read_voxel_part(d / "text.bt", {}); }).find("text.bt"), std::string::npos);
}

TEST(VoxelPartInput, BadPointCloudsNameTheFile) {
  const auto d = scratch_dir("voxel_part_");
  write_file(d / "nan.xyz", "0 0 0\nnan 1 1\n");
  loom::VoxelPartOptions opt;
  opt.resolution = 0.1;
  const std::string e = input_error([&] { loom::read_voxel_part(d / "nan.xyz", opt); });
  EXPECT_NE(e.find("nan.xyz"), std::string::npos) << e;
  EXPECT_NE(e.find("NaN"), std::string::npos) << e;
  write_file(d / "ok.xyz", "0 0 0\n");
  opt.resolution = 0.0;
  EXPECT_NE(input_error([&] { loom::read_voxel_part(d / "ok.xyz", opt); }).find("ok.xyz"), std::string::npos);
  opt.resolution = 1e-6;  // 1 m away at a micrometre: beyond OctoMap's 16-bit keys
  write_file(d / "far.xyz", "1000 0 0\n");
  EXPECT_NE(input_error([&] { loom::read_voxel_part(d / "far.xyz", opt); }).find("far.xyz"), std::string::npos);
}

TEST(VoxelPartInput, SceneKeysAreChecked) {
  const auto d = scratch_dir("voxel_part_");
  write_file(d / "c.xyz", "0 0 0\n1 1 1\n");
  write_file(d / "m.stl", "solid s\nendsolid s\n");
  const auto scene_with = [&](const std::string& part) {
    write_file(d / "s.toml", "[scene]\nname = \"s\"\nunits = \"mm\"\n[[part]]\n" + part);
    return input_error([&] { loom::load_scene(d / "s.toml"); });
  };
  EXPECT_NE(scene_with("file = \"c.xyz\"\nresolution = 0\n").find("must be positive"), std::string::npos);
  EXPECT_NE(scene_with("file = \"c.xyz\"\n").find("needs a 'resolution'"), std::string::npos);
  EXPECT_NE(scene_with("file = \"c.xyz\"\nresolution = 0.5\nunknown = \"maybe\"\n").find("'free' or 'occupied'"),
            std::string::npos);
  EXPECT_NE(scene_with("file = \"m.stl\"\nresolution = 0.5\n").find("scanned parts only"), std::string::npos);
  EXPECT_NE(scene_with("file = \"x.bt\"\nresolution = 0.5\n").find("own resolution"), std::string::npos);
}

TEST(VoxelPartScene, ScaleAppliesToTheVoxelEdge) {
  const auto d = scratch_dir("voxel_part_");
  write_file(d / "c.xyz", "0.1 0.1 0.1\n");
  write_file(d / "s.toml",
             "[scene]\nname = \"s\"\nunits = \"mm\"\n[[part]]\nfile = \"c.xyz\"\nresolution = 0.5\n"
             "transform = { translate = [10, 0, 0], scale = 4.0 }\n");
  const loom::Scene s = loom::load_scene(d / "s.toml");
  ASSERT_EQ(s.parts.size(), 1u);
  EXPECT_DOUBLE_EQ(s.parts[0].voxel_edge, 2.0);
  EXPECT_NEAR(loom::voxel_accuracy(s.parts[0]), std::sqrt(3.0), 1e-12);
  EXPECT_NEAR(s.parts[0].mesh.bounds().min.x(), 10.0, 1e-9);
  EXPECT_NEAR(s.parts[0].mesh.bounds().max.x(), 12.0, 1e-9);
  EXPECT_TRUE(s.parts[0].closed);
}

}  // namespace
