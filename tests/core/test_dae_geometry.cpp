// COLLADA through Assimp: the document reduced to its geometry (core/io/dae_geometry) and
// the rules the pre-check adds for what stays (core/io/mesh_node_checks). The inputs in
// tests/data/dae-hazards/ are the fuzz seed tetra.dae with one hostile addition each; every
// one crashed, aborted, hung or allocated gigabytes in Assimp 5.2 before (the README there
// says how).

#include "core/error.hpp"
#include "core/io/mesh_read.hpp"
#include "common/test_files.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

namespace loom {
namespace {

namespace fs = std::filesystem;

const fs::path kHazards = fs::path(LOOM_SOURCE_DIR) / "tests/data/dae-hazards";

// What loom does not read — skins and their weights, animations, effects — is not handed
// to Assimp: each input reads as the seed's geometry, less the instance a skin's
// controller replaced (animations move nodes of the seed, so only counts compare).
TEST(DaeGeometry, AssimpReadsTheGeometryAlone) {
  const Mesh seed = read_mesh_file(fs::path(LOOM_SOURCE_DIR) / "tests/fuzz/seeds/dae/tetra.dae");
  ASSERT_GT(seed.triangle_count(), 0u);
  for (const char* name :
       {"skin-joint-index-beyond-joints.dae", "skin-weight-index-beyond-weights.dae", "skin-vertex-beyond-weights.dae",
        "skin-joints-beyond-bind-matrices.dae", "weights-count-huge.dae", "weights-vcount-huge.dae",
        "anim-matrix-element-overflow.dae", "anim-value-params-beyond-16.dae", "anim-morph-weights-target.dae",
        "anim-target-without-slash-no-transforms.dae", "effect-param-self-reference-hang.dae"}) {
    SCOPED_TRACE(name);
    const Mesh m = read_mesh_file(kHazards / name);
    // The seed instances the tetrahedron twice; a skin replaces one instance.
    const bool skinned = testing::slurp(kHazards / name).find("<instance_controller") != std::string::npos;
    EXPECT_EQ(m.triangle_count(), skinned ? seed.triangle_count() / 2 : seed.triangle_count());
  }
}

// What stays is checked as Assimp reads it: a node instanced by a URL that names no node
// id (Assimp looked it up by name and recursed without end), a self-instancing node whose
// id a camera shared (the check followed the camera, Assimp the node: a stack overflow),
// a <skew> (Assimp asserts), and ids given twice among what Assimp reads.
TEST(DaeGeometry, InstancesAndTransformsAreCheckedAsAssimpReadsThem) {
  struct Case {
    const char* file;
    const char* expected;
  };
  const Case cases[] = {
      {"instance-node-by-name-cycle.dae", "instance-node-by-name-cycle.dae:33: <instance_node>: url '#loopname' names no "
                                          "<node> id of the file"},
      {"duplicate-id-hides-instance-cycle.dae", "instance_node cycle through node 'A'"},
      {"node-skew-abort.dae", "node-skew-abort.dae:28: <skew>: a <skew> transform is not read"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.file);
    const std::string e = testing::input_error([&] { read_mesh_file(kHazards / c.file); });
    EXPECT_NE(e.find(c.expected), std::string::npos) << e;
  }
  const fs::path d = testing::scratch_dir("loom_dae_geometry_");
  std::string twice = testing::slurp(fs::path(LOOM_SOURCE_DIR) / "tests/fuzz/seeds/dae/tetra.dae");
  twice.replace(twice.find(R"(<node id="child")"), 16, R"(<node id="tetra-mesh")");
  testing::write_file(d / "twice.dae", twice);
  const std::string e = testing::input_error([&] { read_mesh_file(d / "twice.dae"); });
  EXPECT_NE(e.find("<node>: id 'tetra-mesh' is given again (first at line 5, <geometry>)"), std::string::npos) << e;
}

}  // namespace
}  // namespace loom
