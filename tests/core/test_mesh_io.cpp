// Mesh and CAD files: every format round-trips or loads with the right counts, including
// real public files from ../shared/data (see its LICENSE-NOTE files).
#include "core/error.hpp"
#include "core/io/mesh_read.hpp"
#include "core/io/mesh_write.hpp"
#include "core/io/tessellation_cache.hpp"

#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <IGESControl_Controller.hxx>
#include <IGESControl_Writer.hxx>
#include <STEPControl_Writer.hxx>
#include <gtest/gtest.h>

#include <fstream>
#include <random>
#include <map>
#include <set>

namespace loom {
namespace {

namespace fs = std::filesystem;
const fs::path kData = LOOM_SHARED_DATA;

Mesh tetra() {
  Mesh m;
  m.vertices = {{0, 0, 0}, {10, 0, 0}, {0, 10, 0}, {0, 0, 10}};
  m.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  return m;
}

class TempDir : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("loom_meshio_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

TEST_F(TempDir, WrittenFormatsReadBack) {
  const Mesh m = tetra();
  for (const char* ext : {".stl", ".ply", ".obj"}) {
    const fs::path p = dir_ / (std::string("t") + ext);
    write_mesh(p, m);
    Mesh r = read_mesh_file(p);
    EXPECT_EQ(r.triangle_count(), 4u) << ext;
    EXPECT_EQ(r.vertices.size(), 4u) << ext;
    EXPECT_TRUE(analyse_topology(r).closed) << ext;
    EXPECT_NEAR(std::abs(r.signed_volume()), 1000.0 / 6.0, 1e-3) << ext;
  }
}

TEST_F(TempDir, AsciiStlOffAndDae) {
  {
    std::ofstream f(dir_ / "a.stl");
    f << "solid t\n";
    const Mesh m = tetra();
    for (std::size_t t = 0; t < 4; ++t) {
      f << "facet normal 0 0 0\nouter loop\n";
      for (const auto& v : m.corners(t)) f << "vertex " << v.x() << " " << v.y() << " " << v.z() << "\n";
      f << "endloop\nendfacet\n";
    }
    f << "endsolid t\n";
  }
  {
    std::ofstream f(dir_ / "a.off");
    f << "OFF\n4 4 0\n0 0 0\n10 0 0\n0 10 0\n0 0 10\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
  }
  for (const char* name : {"a.stl", "a.off"}) {
    Mesh r = read_mesh_file(dir_ / name);
    EXPECT_EQ(r.triangle_count(), 4u) << name;
    EXPECT_TRUE(analyse_topology(r).closed) << name;
  }
}

TEST_F(TempDir, ColladaTriangles) {
  std::ofstream(dir_ / "t.dae") << R"(<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><unit name="meter" meter="1"/><up_axis>Z_UP</up_axis></asset>
  <library_geometries><geometry id="g"><mesh>
    <source id="p"><float_array id="pa" count="12">0 0 0 10 0 0 0 10 0 0 0 10</float_array>
      <technique_common><accessor source="#pa" count="4" stride="3">
        <param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/>
      </accessor></technique_common></source>
    <vertices id="v"><input semantic="POSITION" source="#p"/></vertices>
    <triangles count="4"><input semantic="VERTEX" source="#v" offset="0"/><p>0 2 1 0 1 3 0 3 2 1 2 3</p></triangles>
  </mesh></geometry></library_geometries>
  <library_visual_scenes><visual_scene id="s"><node id="n"><instance_geometry url="#g"/></node></visual_scene></library_visual_scenes>
  <scene><instance_visual_scene url="#s"/></scene>
</COLLADA>
)";
  Mesh r = read_mesh_file(dir_ / "t.dae");
  EXPECT_EQ(r.triangle_count(), 4u);
  EXPECT_TRUE(analyse_topology(r).closed);
  EXPECT_NEAR(std::abs(r.signed_volume()), 1000.0 / 6.0, 1e-3);
}

TEST_F(TempDir, StepAndIgesWrittenByOpenCascadeReadBack) {
  // A 10 x 20 x 30 box and an r = 5, h = 40 cylinder: closed forms for volume.
  const TopoDS_Shape box = BRepPrimAPI_MakeBox(10, 20, 30).Shape();
  const TopoDS_Shape cyl = BRepPrimAPI_MakeCylinder(5, 40).Shape();
  {
    STEPControl_Writer w;
    w.Transfer(box, STEPControl_AsIs);
    ASSERT_EQ(w.Write((dir_ / "box.step").c_str()), IFSelect_RetDone);
  }
  {
    IGESControl_Controller::Init();
    IGESControl_Writer w("MM", 1);
    w.AddShape(cyl);
    w.ComputeModel();
    ASSERT_TRUE(w.Write((dir_ / "cyl.igs").c_str()));
  }
  TessellationParams tp;
  tp.linear_deflection = 0.001;
  auto b = read_cad_file(dir_ / "box.step", tp, true);
  ASSERT_EQ(b.size(), 1u);
  EXPECT_EQ(b[0].brep_faces, 6);
  EXPECT_TRUE(analyse_topology(b[0].mesh).closed);
  EXPECT_NEAR(b[0].mesh.signed_volume(), 6000.0, 1e-6);
  auto c = read_cad_file(dir_ / "cyl.igs", tp, false);
  ASSERT_EQ(c.size(), 1u);
  // A tessellated cylinder lies inside the true one: volume error O(deflection / r).
  EXPECT_NEAR(std::abs(c[0].mesh.signed_volume()), M_PI * 25 * 40, M_PI * 25 * 40 * 2 * tp.linear_deflection / 5 * 2);
  // Scene unit metres: lengths divided by 1000.
  tp.unit_in_mm = 1000.0;
  tp.linear_deflection = 0.001 / 1000.0;
  auto m = read_cad_file(dir_ / "box.step", tp, true);
  EXPECT_NEAR(m[0].mesh.bounds().size().z(), 0.03, 1e-12);
}

TEST_F(TempDir, BadMeshFiles) {
  EXPECT_THROW(read_mesh_file(dir_ / "missing.stl"), InputError);
  std::ofstream(dir_ / "junk.stl") << "this is not an stl";
  EXPECT_THROW(read_mesh_file(dir_ / "junk.stl"), InputError);
  std::ofstream(dir_ / "x.abc") << "x";
  try {
    read_mesh_file(dir_ / "x.abc");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("unknown mesh extension"), std::string::npos);
  }
}

TEST(RealMeshes, CountsMatchTheirSources) {
  struct Case {
    const char* file;
    std::size_t triangles;
  };
  // Triangle counts as published (LICENSE-NOTE / data README), after dropping degenerate triangles.
  for (const Case& c : {Case{"occt/motor.stl", 13506}, Case{"fcl/env.obj", 2180}, Case{"trimesh/bunny.ply", 16301}}) {
    Mesh m = read_mesh_file(kData / c.file);
    EXPECT_NEAR(static_cast<double>(m.triangle_count()), static_cast<double>(c.triangles), 0.002 * c.triangles)
        << c.file;
  }
}

TEST(RealMeshes, GlbLoads) {
  Mesh m = read_mesh_file(kData / "trimesh/CesiumMilkTruck.glb");
  EXPECT_GT(m.triangle_count(), 1000u);
  EXPECT_EQ(first_non_finite_vertex(m), -1);
}

TEST(RealCad, StepAssemblyKeepsProductNames) {
  TessellationParams tp;
  tp.linear_deflection = 0.5;
  auto parts = read_cad_file(kData / "stepcode/as1-oc-214.stp", tp, true);
  // AS1: 5 distinct solids (plate, l-bracket, bolt, nut, rod) in sub-assemblies joined by 13
  // assembly relations (NEXT_ASSEMBLY_USAGE_OCCURRENCE); expanded, that places 18 solids:
  // 8 nuts, 6 bolts, 2 l-brackets, 1 rod, 1 plate. loom makes one part per placed solid.
  EXPECT_EQ(parts.size(), 18u);
  std::set<std::string> names;
  std::map<std::string, int> per_product;
  for (const auto& p : parts) {
    names.insert(p.name);
    per_product[p.name.substr(0, p.name.find('#'))]++;
    EXPECT_GT(p.mesh.triangle_count(), 0u) << p.name;
    EXPECT_GT(p.brep_faces, 0) << p.name;
  }
  EXPECT_EQ(names.size(), parts.size());  // repeated products get #k suffixes
  EXPECT_EQ(per_product, (std::map<std::string, int>{{"bolt", 6}, {"l-bracket", 2}, {"nut", 8}, {"plate", 1}, {"rod", 1}}));
  auto compound = read_cad_file(kData / "stepcode/as1-oc-214.stp", tp, false);
  ASSERT_EQ(compound.size(), 1u);
  std::size_t sum = 0;
  for (const auto& p : parts) sum += p.mesh.triangle_count();
  EXPECT_EQ(compound[0].mesh.triangle_count(), sum);
}

TEST(RealCad, StepAndStlOfTheSamePartAgree) {
  // featuretype.STEP and featuretype.STL are the same part (trimesh notes). The STEP file
  // carries its units (OpenCASCADE converts to mm); the STL has none and was written in
  // inches, so it is scaled by 25.4 here: a scene would say transform.scale = 25.4.
  TessellationParams tp;
  tp.linear_deflection = 0.05;
  auto step = read_cad_file(kData / "trimesh/featuretype.STEP", tp, false);
  ASSERT_EQ(step.size(), 1u);
  Mesh stl = read_mesh_file(kData / "trimesh/featuretype.STL");
  Eigen::Affine3d inch = Eigen::Affine3d::Identity();
  inch.linear() *= 25.4;
  stl.transform(inch);
  const AABB a = step[0].mesh.bounds(), b = stl.bounds();
  EXPECT_LT((a.min - b.min).norm(), 0.05 * b.diagonal());
  EXPECT_LT((a.max - b.max).norm(), 0.05 * b.diagonal());
  const auto ta = analyse_topology(step[0].mesh);
  EXPECT_TRUE(ta.closed) << ta.boundary_edges << " boundary edges";
  EXPECT_NEAR(std::abs(step[0].mesh.signed_volume()), std::abs(stl.signed_volume()), 0.02 * std::abs(stl.signed_volume()));
}

TEST(RealCad, FinerDeflectionMoreTriangles) {
  TessellationParams coarse, fine;
  coarse.linear_deflection = 1.0;
  fine.linear_deflection = 0.05;
  auto a = read_cad_file(kData / "occt/screw.step", coarse, false);
  auto b = read_cad_file(kData / "occt/screw.step", fine, false);
  EXPECT_GT(b[0].mesh.triangle_count(), a[0].mesh.triangle_count());
}

TEST(RealCad, CacheReturnsTheSameMeshes) {
  const fs::path dir = fs::temp_directory_path() / "loom_tess_cache_test";
  fs::remove_all(dir);
  ::setenv("LOOM_CACHE_DIR", dir.c_str(), 1);
  TessellationParams tp;
  tp.linear_deflection = 0.5;
  bool hit = true;
  auto a = read_cad_file_cached(kData / "occt/linkrods.step", tp, true, &hit);
  EXPECT_FALSE(hit);
  auto b = read_cad_file_cached(kData / "occt/linkrods.step", tp, true, &hit);
  EXPECT_TRUE(hit);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].name, b[i].name);
    EXPECT_EQ(a[i].mesh.vertices, b[i].mesh.vertices);
    EXPECT_EQ(a[i].mesh.triangles, b[i].mesh.triangles);
  }
  tp.linear_deflection = 0.25;  // other parameters: a different key
  read_cad_file_cached(kData / "occt/linkrods.step", tp, true, &hit);
  EXPECT_FALSE(hit);
  ::unsetenv("LOOM_CACHE_DIR");
  fs::remove_all(dir);
}

TEST(RealCad, BadCadFiles) {
  const fs::path p = fs::temp_directory_path() / "loom_bad.step";
  std::ofstream(p) << "ISO-10303-21;\nthis is not step\n";
  TessellationParams tp;
  EXPECT_THROW(read_cad_file(p, tp, true), InputError);
  fs::remove(p);
  EXPECT_THROW(read_cad_file("/nonexistent.step", tp, true), InputError);
}

}  // namespace
}  // namespace loom
