// Scene TOML: parts, transforms, derived settings, and the bad-input catalogue.
#include "core/error.hpp"
#include "core/io/mesh_write.hpp"
#include "core/io/scene_load.hpp"

#include <gtest/gtest.h>

#include <fstream>

namespace loom {
namespace {

namespace fs = std::filesystem;

const char* kHarness = R"(<harness name="H" units="mm">
  <attributes>
    <cable id="C1"><electrical><port id="A"/><port id="B"/></electrical>
      <physical type="t" color="c" diameter="2" min_bend_radius="20"/></cable>
    <cable id="C2"><electrical><port id="A2"/><port id="B"/></electrical>
      <physical type="t" color="c" diameter="4" min_bend_radius="20"/></cable>
  </attributes>
  <structure>
    <port id="A" x="0" y="0" z="0" dx="1" dy="0" dz="0"/>
    <port id="A2" x="0" y="10" z="0" dx="1" dy="0" dz="0"/>
    <port id="B" x="100" y="0" z="0" dx="-1" dy="0" dz="0"/>
    <branch id="J"><segment to="A"/><segment to="A2"/><segment to="B"/></branch>
  </structure>
</harness>
)";

/// A scratch directory with a unit cube STL and a harness, removed afterwards.
class SceneDir : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("loom_scene_test_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
                                        "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
    Mesh cube;
    cube.vertices = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
    cube.triangles = {{0, 2, 1}, {0, 3, 2}, {4, 5, 6}, {4, 6, 7}, {0, 1, 5}, {0, 5, 4},
                      {1, 2, 6}, {1, 6, 5}, {2, 3, 7}, {2, 7, 6}, {3, 0, 4}, {3, 4, 7}};
    write_mesh(dir_ / "cube.stl", cube);
    write("harness.xml", kHarness);
  }
  void TearDown() override { fs::remove_all(dir_); }
  void write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name) << text;
  }
  fs::path scene(const std::string& text) {
    write("scene.toml", text);
    return dir_ / "scene.toml";
  }
  void expect_bad(const std::string& text, std::vector<std::string> needles) {
    try {
      load_scene(scene(text));
      FAIL() << "expected an error for:\n" << text;
    } catch (const InputError& e) {
      for (const auto& n : needles) EXPECT_NE(std::string(e.what()).find(n), std::string::npos) << e.what();
    }
  }
  fs::path dir_;
};

TEST_F(SceneDir, LoadsPartsWithTransformAndDerivedSettings) {
  SceneLoadReport rep;
  Scene s = load_scene(scene(R"([scene]
name = "t"
units = "mm"
[[part]]
name = "box"
file = "cube.stl"
transform = { translate = [10, 0, 0], rotate_deg = [0, 0, 90], scale = 2.0 }
role = "keep_out"
clearance = 5.0
[harness]
file = "harness.xml"
)"),
                       {}, &rep);
  EXPECT_EQ(s.name, "t");
  ASSERT_EQ(s.parts.size(), 1u);
  const Part& p = s.parts[0];
  EXPECT_EQ(p.role, PartRole::KeepOut);
  EXPECT_EQ(p.clearance, 5.0);
  EXPECT_TRUE(p.closed);
  EXPECT_EQ(p.mesh.triangle_count(), 12u);
  // scale 2, then rotate 90° about Z: x∈[0,2],y∈[0,2] -> x∈[-2,0], y∈[0,2]; then +10 in x.
  const AABB b = p.mesh.bounds();
  EXPECT_NEAR(b.min.x(), 8, 1e-12);
  EXPECT_NEAR(b.max.x(), 10, 1e-12);
  EXPECT_NEAR(b.max.y(), 2, 1e-12);
  EXPECT_NEAR(b.max.z(), 2, 1e-12);
  EXPECT_NEAR(p.mesh.signed_volume(), 8.0, 1e-9);
  // Derived: smallest cable diameter 2 -> clearance 2, dim_pre 2, deflection 0.1.
  EXPECT_DOUBLE_EQ(s.routing.clearance.value, 2.0);
  EXPECT_NE(s.routing.clearance.source.find("smallest cable diameter"), std::string::npos);
  EXPECT_DOUBLE_EQ(s.simplify.dim_pre.value, 2.0);
  EXPECT_DOUBLE_EQ(s.tessellation.linear_deflection.value, 0.1);
  EXPECT_TRUE(s.has_harness);
  EXPECT_EQ(s.harness.cables.size(), 2u);
  EXPECT_GE(rep.load_ms, 0.0);
}

TEST_F(SceneDir, GivenSettingsWin) {
  Scene s = load_scene(scene(R"([scene]
name = "t"
units = "mm"
[harness]
file = "harness.xml"
[routing]
clearance = 3.5
planner = "rrtstar"
time_limit = 2
seed = 7
[simplify]
dim_pre = 4.0
planes = [[1, 1, 0], [0, -2, 1.5]]
split = false
[tessellation]
linear_deflection = 0.5
)"));
  ASSERT_EQ(s.simplify.planes.size(), 2u);
  EXPECT_EQ(s.simplify.planes[1], Vec3(0, -2, 1.5));
  EXPECT_FALSE(s.simplify.split);
  EXPECT_DOUBLE_EQ(s.routing.clearance.value, 3.5);
  EXPECT_EQ(s.routing.clearance.source, "scene file");
  EXPECT_EQ(s.routing.planner, "rrtstar");
  EXPECT_EQ(s.routing.seed, 7u);
  EXPECT_DOUBLE_EQ(s.simplify.dim_pre.value, 4.0);
  EXPECT_DOUBLE_EQ(s.tessellation.linear_deflection.value, 0.5);
}

TEST_F(SceneDir, MissingSceneFile) {
  try {
    load_scene(dir_ / "nope.toml");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("nope.toml"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("not found"), std::string::npos);
  }
}

TEST_F(SceneDir, MissingPartFileNamesFileAndEntry) {
  expect_bad("[scene]\nname='t'\n[[part]]\nname='p'\nfile='missing.stl'\n",
             {"missing.stl", "file not found", "scene.toml:5", "part 'p'"});
}

TEST_F(SceneDir, UnknownExtension) {
  write("part.abc", "1 2 3\n");
  expect_bad("[scene]\nname='t'\n[[part]]\nname='p'\nfile='part.abc'\n", {"scene.toml:5", "unknown file extension '.abc'"});
}

TEST_F(SceneDir, UnitMismatch) {
  std::string h = kHarness;
  h.replace(h.find("units=\"mm\""), 10, "units=\"m\"");
  write("harness_m.xml", h);
  expect_bad("[scene]\nname='t'\nunits='mm'\n[harness]\nfile='harness_m.xml'\n",
             {"scene.toml:5", "unit mismatch", "harness is in m", "scene is in mm"});
}

TEST_F(SceneDir, UnknownUnitAndKeysAndRole) {
  expect_bad("[scene]\nname='t'\nunits='furlong'\n", {"scene.toml:3", "unknown unit 'furlong'"});
  expect_bad("[scene]\nname='t'\nunit='mm'\n", {"scene.toml:3", "scene.unit", "unknown key"});
  expect_bad("[scene]\nname='t'\n[[part]]\nfile='cube.stl'\nrole='wall'\n", {"scene.toml:5", "role must be"});
}

TEST_F(SceneDir, BadNumbers) {
  expect_bad("[scene]\nname='t'\n[routing]\nclearance=-1\n", {"scene.toml:4", "routing.clearance", "must not be negative"});
  expect_bad("[scene]\nname='t'\n[routing]\nclearance=nan\n", {"routing.clearance", "finite"});
  expect_bad("[scene]\nname='t'\n[simplify]\ndim_pre=0\n", {"simplify.dim_pre", "positive"});
  expect_bad("[scene]\nname='t'\n[simplify]\nplanes=[[0,0,0]]\n", {"scene.toml:4", "simplify.planes[0]", "non-zero"});
  expect_bad("[scene]\nname='t'\n[simplify]\nplanes=[1,0,0]\n", {"simplify.planes[0]", "array of 3"});
  expect_bad("[scene]\nname='t'\n[simplify]\nplanes=[[1,0,0],[1e-200,0,0]]\n", {"simplify.planes[1]", "non-zero"});
  expect_bad("[scene]\nname='t'\n[simplify]\nplanes=1\n", {"simplify.planes", "array of normals"});
  expect_bad("[scene]\nname='t'\n[simplify]\nsplit='yes'\n", {"scene.toml:4", "simplify.split", "true or false"});
  expect_bad("[scene]\nname='t'\n[[part]]\nfile='cube.stl'\ntransform={scale=0}\n", {"scale", "positive"});
  expect_bad("[scene]\nname='t'\n[[part]]\nfile='cube.stl'\ntransform={translate=[1,2]}\n", {"array of 3"});
}

// A section given as anything but a table is an error naming the key and line, not ignored
// (`harness = "h.xml"` would load a scene without its harness).
TEST_F(SceneDir, SectionsMustBeTables) {
  EXPECT_NO_THROW(load_scene(scene("[scene]\nname='t'\n[routing]\n")));
  expect_bad("harness = 'harness.xml'\n[scene]\nname='t'\n", {"scene.toml:1", "harness", "expected a table [harness]"});
  expect_bad("routing = 5\n[scene]\nname='t'\n", {"scene.toml:1", "expected a table [routing]"});
  expect_bad("simplify = [1]\n[scene]\nname='t'\n", {"expected a table [simplify]"});
  expect_bad("tessellation = true\n[scene]\nname='t'\n", {"expected a table [tessellation]"});
  expect_bad("scene = 'x'\n", {"scene.toml:1", "expected a table [scene]"});
}

// The seed is the planner's unsigned 32-bit value: a larger one would be cut to another seed.
TEST_F(SceneDir, SeedMustFitThirtyTwoBits) {
  EXPECT_EQ(load_scene(scene("[scene]\nname='t'\n[routing]\nseed=4294967295\n")).routing.seed, 4294967295u);
  expect_bad("[scene]\nname='t'\n[routing]\nseed=4294967296\n", {"scene.toml:4", "routing.seed", "0..4294967295"});
  expect_bad("[scene]\nname='t'\n[routing]\nseed=1e11\n", {"routing.seed", "0..4294967295"});
}

TEST_F(SceneDir, SceneAndHarnessMustBeRegularFilesWithNames) {
  expect_bad("[scene]\nname='t'\n[harness]\nfile=''\n", {"scene.toml:4", "harness.file", "empty file name"});
  fs::create_directories(dir_ / "sub");
  expect_bad("[scene]\nname='t'\n[harness]\nfile='sub'\n", {"sub: not a regular file", "scene.toml:4 harness.file"});
  try {
    load_scene(dir_);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(dir_.string() + ": not a regular file"), std::string::npos) << e.what();
  }
}

TEST_F(SceneDir, MalformedToml) {
  expect_bad("[scene]\nname = 't\n", {"scene.toml:2", "malformed TOML"});
}

TEST_F(SceneDir, EmptyAndNonFiniteMeshes) {
  write("empty.obj", "# nothing\n");
  expect_bad("[scene]\nname='t'\n[[part]]\nfile='empty.obj'\n", {"empty.obj"});
  write("nan.obj", "v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n");
  expect_bad("[scene]\nname='t'\n[[part]]\nfile='nan.obj'\n", {"nan.obj"});
}

TEST_F(SceneDir, DuplicatePartNames) {
  expect_bad("[scene]\nname='t'\n[[part]]\nname='a'\nfile='cube.stl'\n[[part]]\nname='a'\nfile='cube.stl'\n",
             {"duplicate part name"});
}

TEST_F(SceneDir, RoutesReplaceTheHarnessAndMustShareItsUnit) {
  Scene s = load_scene(scene("[scene]\nname='t'\nunits='mm'\n"));
  EXPECT_FALSE(s.has_harness);
  apply_routes(s, dir_ / "harness.xml");
  EXPECT_TRUE(s.has_harness);
  EXPECT_EQ(s.harness.cables.size(), 2u);
  std::string h = kHarness;
  h.replace(h.find("units=\"mm\""), 10, "units=\"m\"");
  write("routes_m.xml", h);
  try {
    apply_routes(s, dir_ / "routes_m.xml");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("routes_m.xml"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("unit mismatch"), std::string::npos) << e.what();
  }
}

TEST_F(SceneDir, HarnessErrorsCarryTheHarnessFile) {
  std::string h = kHarness;
  h.replace(h.find("diameter=\"4\""), 12, "diameter=\"-4\"");
  write("bad_harness.xml", h);
  expect_bad("[scene]\nname='t'\n[harness]\nfile='bad_harness.xml'\n", {"bad_harness.xml:6", "diameter must be positive"});
}

}  // namespace
}  // namespace loom
