// The bundled wing-section example: the generator is deterministic (a fresh run
// reproduces the committed files byte for byte), the committed scene loads, every port sits
// on its receptacle facing free space, and for every segment of the harness tree a witness
// corridor exists that is wider than the segment's bundle plus clearance — so a route
// exists for every cable. Oracles: brute-force point–triangle distances, ray casts and
// winding numbers over the exact tessellated triangles (no spatial index).

#include "examples/generator/number_text.hpp"
#include "examples/generator/step_export.hpp"
#include "examples/generator/wing_layout.hpp"
#include "examples/generator/wing_section.hpp"

#include "core/harness_topology.hpp"
#include "core/io/scene_load.hpp"

#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include "common/brute_geometry.hpp"
#include "common/shared_data.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <sstream>
#include <unistd.h>

namespace fs = std::filesystem;
using loom::Vec3;

namespace {

const fs::path kCommitted = fs::path(LOOM_SOURCE_DIR) / "examples" / "wing-section";

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

/// A temporary directory removed on destruction.
struct TempDir {
  fs::path path;
  TempDir() {
    path = fs::temp_directory_path() / ("loom_example_gen_" + std::to_string(::getpid()));
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
};

// --- brute-force geometry oracles ---------------------------------------------------------


/// Unsigned distance from p to the surface of a mesh (every triangle).
double surface_distance(const loom::Mesh& m, const Vec3& p) { return loom::test_oracle::mesh_distance(m, p); }

/// Distance from p to an AABB (0 inside): a lower bound of the distance to its contents.
double box_distance(const loom::AABB& b, const Vec3& p) {
  const Vec3 d = (b.min - p).cwiseMax(p - b.max).cwiseMax(Vec3::Zero());
  return d.norm();
}

/// Generalised winding number of a closed mesh around p (≈1 inside, ≈0 outside).
double winding_number(const loom::Mesh& m, const Vec3& p) { return loom::test_oracle::mesh_winding_number(m, p); }

/// Nearest hit distance of the ray o + t·dir (t > 0) with any triangle, or +inf.
double ray_hit(const loom::Mesh& m, const Vec3& o, const Vec3& dir) {
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t t = 0; t < m.triangles.size(); ++t) {
    const auto c = m.corners(t);
    const Vec3 e1 = c[1] - c[0], e2 = c[2] - c[0], pv = dir.cross(e2);
    const double det = e1.dot(pv);
    if (std::abs(det) < 1e-14) continue;
    const Vec3 tv = o - c[0];
    const double u = tv.dot(pv) / det;
    if (u < 0 || u > 1) continue;
    const Vec3 qv = tv.cross(e1);
    const double v = dir.dot(qv) / det;
    if (v < 0 || u + v > 1) continue;
    const double s = e2.dot(qv) / det;
    if (s > 1e-9) best = std::min(best, s);
  }
  return best;
}

/// The committed scene, loaded once per process. The tessellation cache lives in a fixed
/// temporary directory (unless LOOM_CACHE_DIR is set): the five ribs share one file and the
/// tests run in separate processes, so most loads are cache hits. Keys hash the file bytes.
const loom::Scene& committed_scene() {
  static const loom::Scene scene = [] {
    if (!std::getenv("LOOM_CACHE_DIR"))
      ::setenv("LOOM_CACHE_DIR", (fs::temp_directory_path() / "loom_test_examples_cache").c_str(), 1);
    return loom::load_scene(kCommitted / "scene.toml");
  }();
  return scene;
}

}  // namespace

TEST(ExampleGenerator, RegeneratesTheCommittedFilesByteForByte) {
  TempDir tmp;
  const auto files = loom::examples::generate_wing_section(tmp.path);
  ASSERT_EQ(files.size(), 8u);
  for (const auto& f : files) {
    SCOPED_TRACE(f);
    ASSERT_TRUE(fs::exists(kCommitted / f)) << "committed example file missing: regenerate_examples";
    const std::string fresh = slurp(tmp.path / f), committed = slurp(kCommitted / f);
    ASSERT_FALSE(fresh.empty());
    if (fresh != committed) {
      std::size_t i = 0;
      while (i < fresh.size() && i < committed.size() && fresh[i] == committed[i]) ++i;
      ADD_FAILURE() << "differs from the committed file at byte " << i << " (sizes " << fresh.size() << " vs "
                    << committed.size() << "): the generator is not deterministic or the files are stale";
    }
  }
  // The STEP header carries no wall-clock time and no directory.
  const std::string spar = slurp(tmp.path / "spar.step");
  EXPECT_NE(spar.find(std::string("FILE_NAME('spar.step','") + loom::examples::kStepTimeStamp), std::string::npos);
  EXPECT_EQ(spar.find(tmp.path.string()), std::string::npos);
}

TEST(ExampleGenerator, CommittedSceneLoadsWithTheExpectedModel) {
  const auto& s = committed_scene();
  EXPECT_EQ(s.name, "wing-section");
  ASSERT_EQ(s.parts.size(), 14u);
  for (const char* name : {"spar-front", "spar-rear", "rib-1", "rib-5", "avionics-1", "avionics-3", "actuator",
                           "actuator-envelope", "connector-root", "connector-tip"})
    EXPECT_GE(s.find_part(name), 0) << name;
  for (const auto& p : s.parts) {
    EXPECT_TRUE(p.closed) << p.name << " should be a closed solid";
    EXPECT_GT(p.mesh.triangle_count(), 0u) << p.name;
  }
  EXPECT_EQ(s.parts[s.find_part("actuator-envelope")].role, loom::PartRole::KeepOut);
  EXPECT_DOUBLE_EQ(s.parts[s.find_part("actuator")].clearance, 5.0);
  EXPECT_DOUBLE_EQ(s.routing.clearance.value, 3.0);
  // The rear spar is the front one turned about Z: mirrored bounds in Y.
  const auto f = s.parts[s.find_part("spar-front")].mesh.bounds(), r = s.parts[s.find_part("spar-rear")].mesh.bounds();
  EXPECT_NEAR(f.min.y() + r.max.y(), loom::examples::layout::kChord, 1e-6);
  EXPECT_NEAR(f.max.y() + r.min.y(), loom::examples::layout::kChord, 1e-6);
  // Overall size: about 1500 × 640 × 200 mm.
  const auto b = s.bounds();
  EXPECT_NEAR(b.max.x() - b.min.x(), 1500.0, 1e-6);
  EXPECT_NEAR(b.max.z() - b.min.z(), 200.0, 1e-6);
  // Harness: 24 cables, 9 ports, 7 branch points (two left for the router), a valid tree.
  ASSERT_TRUE(s.has_harness);
  const auto& h = s.harness;
  EXPECT_EQ(h.cables.size(), 24u);
  EXPECT_EQ(h.ports.size(), 9u);
  ASSERT_EQ(h.branches.size(), 7u);
  int unplaced = 0;
  for (const auto& br : h.branches) unplaced += br.position ? 0 : 1;
  EXPECT_EQ(unplaced, 2);
  const loom::HarnessTopology topo(h);
  for (const auto& br : h.branches) EXPECT_EQ(topo.incident_segments(br.id).size(), 3u) << br.id;
  EXPECT_EQ(h.segments.size(), h.ports.size() + h.branches.size() - 1);  // a tree
  int power = 0;
  for (const auto& c : h.cables) {
    EXPECT_GE(c.physical.min_bend_radius, 6.0 * c.physical.diameter - 1e-9) << c.id;
    EXPECT_LE(c.physical.min_bend_radius, 10.0 * c.physical.diameter + 1e-9) << c.id;
    power += c.physical.diameter >= 5.0 ? 1 : 0;
  }
  EXPECT_GE(power, 2);
  EXPECT_GE(topo.bundles().size(), 10u);
}

TEST(ExampleGenerator, PortsSitOnTheirReceptaclesAndFaceFreeSpace) {
  const auto& s = committed_scene();
  using loom::examples::layout::kActReceptacle;
  using loom::examples::layout::kBoxReceptacle;
  using loom::examples::layout::kTrunkReceptacle;
  const double tol = 10.0 * s.tessellation.linear_deflection.value;
  for (const auto& port : s.harness.ports) {
    SCOPED_TRACE(port.id);
    const bool trunk = port.id == "ROOT-J1" || port.id == "TIP-J1";
    const auto& spec = trunk ? kTrunkReceptacle : port.id == "ACT-J1" ? kActReceptacle : kBoxReceptacle;
    double back = std::numeric_limits<double>::infinity(), ahead = back;
    for (const auto& p : s.parts) {
      if (p.role != loom::PartRole::Structure) continue;
      back = std::min(back, ray_hit(p.mesh, port.position, -port.direction));
      ahead = std::min(ahead, ray_hit(p.mesh, port.position, port.direction));
    }
    // Looking back along the connector axis: through the mouth onto the insert.
    EXPECT_NEAR(back, spec.port_gap + spec.bore_depth, tol);
    // Looking out: free space for well over a bend radius.
    EXPECT_GT(ahead, 60.0);
  }
}

TEST(ExampleGenerator, EverySegmentHasACorridorWiderThanItsBundle) {
  const auto& s = committed_scene();
  const auto& h = s.harness;
  const loom::HarnessTopology topo(h);
  // Witness positions for the branch points the file leaves to the router.
  const std::map<std::string, Vec3> witness{{"T2", Vec3(520, 230, 100)}, {"K3", Vec3(1200, 300, 100)}};
  auto node_pos = [&](const std::string& id) -> Vec3 {
    if (int p = h.find_port(id); p >= 0) return h.ports[p].position;
    const auto& br = h.branches[h.find_branch(id)];
    return br.position ? *br.position : witness.at(id);
  };
  const double clearance = s.routing.clearance.value;
  std::vector<loom::AABB> bounds;
  for (const auto& p : s.parts) bounds.push_back(p.mesh.bounds());
  double narrowest = std::numeric_limits<double>::infinity();  // smallest spare width over all segments
  constexpr double kStep = 4.0;  // sample spacing; d ≥ R + kStep/2 at samples proves the stretch (1-Lipschitz)
  for (std::size_t si = 0; si < h.segments.size(); ++si) {
    const auto& seg = h.segments[si];
    SCOPED_TRACE(seg.from + " -> " + seg.to);
    // Witness polyline: leave a port along its axis until level with the other end, then go straight.
    const Vec3 start = node_pos(seg.from), end = node_pos(seg.to);
    std::vector<Vec3> poly{start};
    auto corner = [&](const std::string& id, const Vec3& other) {
      const auto& port = h.ports[h.find_port(id)];
      poly.push_back(port.position + port.direction * (other - port.position).dot(port.direction));
    };
    if (h.find_port(seg.from) >= 0) corner(seg.from, end);
    if (h.find_port(seg.to) >= 0) corner(seg.to, start);
    poly.push_back(end);
    const double radius = 0.5 * topo.segment_diameter(static_cast<int>(si));
    double worst = std::numeric_limits<double>::infinity();
    std::string worst_part;
    for (std::size_t k = 0; k + 1 < poly.size(); ++k) {
      const Vec3 a = poly[k], b = poly[k + 1];
      const int n = std::max(1, static_cast<int>(std::ceil((b - a).norm() / kStep)));
      for (int i = 0; i <= n; ++i) {
        const Vec3 q = a + (b - a) * (static_cast<double>(i) / n);
        for (std::size_t pi = 0; pi < s.parts.size(); ++pi) {
          const auto& p = s.parts[pi];
          const double need = radius + clearance + p.clearance + 0.5 * kStep;
          if (box_distance(bounds[pi], q) - need >= worst) continue;  // cannot lower the margin
          const double margin = surface_distance(p.mesh, q) - need;
          if (margin < worst) worst = margin, worst_part = p.name;
        }
      }
    }
    EXPECT_GE(worst, 0.0) << "corridor too narrow near part " << worst_part << " (bundle Ø"
                          << 2 * radius << " mm)";
    narrowest = std::min(narrowest, worst);
    std::printf("%s -> %s: spare %.2f near %s\n", seg.from.c_str(), seg.to.c_str(), worst, worst_part.c_str());
    // The witness starts outside every part (so, staying clear, it never enters one).
    for (const auto& p : s.parts) EXPECT_LT(std::abs(winding_number(p.mesh, poly.front())), 0.01) << p.name;
  }
  RecordProperty("narrowest_spare_mm", std::to_string(narrowest));
  std::printf("narrowest corridor spare width beyond bundle radius + clearance: %.2f mm\n", narrowest);
}

TEST(RealMeshesExample, LoadsWithPortsAndBranchPointClearOfEveryPart) {
  const fs::path toml = fs::path(LOOM_SOURCE_DIR) / "examples" / "real-meshes" / "scene.toml";
  LOOM_SHARED_DATA_OR_SKIP(loom::testing::shared_data("fcl/env.obj"));
  loom::SceneLoadOptions opt;
  opt.use_cache = false;
  const loom::Scene s = loom::load_scene(toml, opt);
  // room + AS1 (18 leaf product occurrences) + featuretype + motor
  ASSERT_EQ(s.parts.size(), 21u);
  EXPECT_GE(s.find_part("room"), 0);
  EXPECT_GE(s.find_part("motor"), 0);
  EXPECT_GE(s.find_part("featuretype"), 0);
  EXPECT_GE(s.find_part("as1/plate"), 0);
  const auto& h = s.harness;
  ASSERT_EQ(h.cables.size(), 6u);
  ASSERT_EQ(h.ports.size(), 4u);
  ASSERT_EQ(h.branches.size(), 2u);
  const loom::HarnessTopology topo(h);
  // Every port and placed branch point is clear of every part by its widest segment's
  // radius plus the required clearance, and every port looks out into free space.
  auto check_clear = [&](const std::string& id, const Vec3& q) {
    double radius = 0.0;
    for (int si : topo.incident_segments(id)) radius = std::max(radius, 0.5 * topo.segment_diameter(si));
    for (const auto& p : s.parts) {
      const double need = radius + s.routing.clearance.value + p.clearance;
      if (box_distance(p.mesh.bounds(), q) >= need) continue;
      EXPECT_GE(surface_distance(p.mesh, q), need) << id << " too close to " << p.name;
      if (p.closed) {
        EXPECT_LT(std::abs(winding_number(p.mesh, q)), 0.01) << id << " inside " << p.name;
      }
    }
  };
  for (const auto& port : h.ports) {
    check_clear(port.id, port.position);
    double ahead = std::numeric_limits<double>::infinity();
    for (const auto& p : s.parts) ahead = std::min(ahead, ray_hit(p.mesh, port.position, port.direction));
    EXPECT_GT(ahead, 100.0) << port.id << " faces a wall";
  }
  for (const auto& br : h.branches)
    if (br.position) check_clear(br.id, *br.position);
}

TEST(BuildingScanExample, LoadsWithPortsInObservedFreeSpace) {
  const fs::path toml = fs::path(LOOM_SOURCE_DIR) / "examples" / "building-scan" / "scene.toml";
  LOOM_SHARED_DATA_OR_SKIP(loom::testing::shared_data("octomap/geb079.bt"));
  const loom::Scene s = loom::load_scene(toml);
  ASSERT_EQ(s.parts.size(), 1u);
  const loom::Part& floor = s.parts[0];
  EXPECT_DOUBLE_EQ(floor.voxel_edge, 80.0);  // 8 cm voxels scaled to millimetres
  EXPECT_TRUE(floor.unknown_occupied);
  ASSERT_EQ(s.harness.ports.size(), 2u);
  const loom::HarnessTopology topo(s.harness);
  for (const auto& port : s.harness.ports) {
    double radius = 0.0;
    for (int si : topo.incident_segments(port.id)) radius = std::max(radius, 0.5 * topo.segment_diameter(si));
    // Clear of the voxels by the bundle radius + clearance + one voxel (the exit's first step).
    EXPECT_GE(surface_distance(floor.mesh, port.position), radius + s.routing.clearance.value + 80.0) << port.id;
    EXPECT_GT(ray_hit(floor.mesh, port.position, port.direction), 300.0) << port.id << " faces a wall";
  }
  // The rooms lie on either side of the corridor (y from -1.0 to 0.9 m).
  EXPECT_LT(std::min(s.harness.ports[0].position.y(), s.harness.ports[1].position.y()), -1400.0);
  EXPECT_GT(std::max(s.harness.ports[0].position.y(), s.harness.ports[1].position.y()), 1300.0);
}

RC_GTEST_PROP(ExampleNumberText, ShortestTextReadsBackExactly, (double v)) {
  RC_PRE(std::isfinite(v));
  const std::string t = loom::examples::num(v);
  RC_ASSERT(std::strtod(t.c_str(), nullptr) == v);
  RC_ASSERT(t.find(',') == std::string::npos);  // locale independent
}

TEST(ExampleNumberText, DegenerateValues) {
  EXPECT_EQ(loom::examples::num(0.0), "0");
  EXPECT_EQ(loom::examples::num(-0.0), "0");
  EXPECT_EQ(loom::examples::num(85.0), "85");
  EXPECT_EQ(loom::examples::num(1.3), "1.3");
}
