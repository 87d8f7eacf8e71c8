// Mesh and CAD files: every format round-trips or loads with the right counts, including
// real public files from ../shared/data (see its LICENSE-NOTE files).
#include "core/error.hpp"
#include "core/io/mesh_file_checks.hpp"
#include "core/io/mesh_read.hpp"
#include "core/io/mesh_write.hpp"
#include "core/io/tessellation_cache.hpp"

#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <IGESControl_Controller.hxx>
#include <IGESControl_Writer.hxx>
#include <STEPControl_Writer.hxx>
#include <gtest/gtest.h>
#include "common/shared_data.hpp"

#include <cstring>
#include <fstream>
#include <iterator>
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

/// The message of the InputError that reading `p` throws ("" and a test failure if none).
std::string read_error(const fs::path& p) {
  try {
    read_mesh_file(p);
    ADD_FAILURE() << "no error for " << p;
  } catch (const InputError& e) {
    return e.what();
  }
  return {};
}

const char* kPlyTriangleHeader =
    "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
    "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n";

// Assimp's PLY reader passes a face index beyond the vertices on, and its post-processing
// reads it out of bounds (SIGSEGV for -5); one far beyond corrupted its heap. Its OFF
// reader clamps such an index instead. Both are checked before Assimp reads.
TEST_F(TempDir, FaceIndexBeyondTheVerticesIsAnInputError) {
  for (const char* face : {"3 0 1 99\n", "3 0 1 -5\n"}) {
    std::ofstream(dir_ / "f.ply") << kPlyTriangleHeader << face;
    const std::string e = read_error(dir_ / "f.ply");
    EXPECT_NE(e.find("f.ply:13: element face instance 0: vertex index " + std::string(face).substr(6, 2)),
              std::string::npos)
        << e;
    EXPECT_NE(e.find("is not one of the 3 vertices (0..2)"), std::string::npos) << e;
  }
  // Assimp's OFF reader replaces such an index by the last vertex (another triangle).
  std::ofstream(dir_ / "f.off") << "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 77\n";
  const std::string e = read_error(dir_ / "f.off");
  EXPECT_NE(e.find("f.off:6: face 0: vertex index 77 is not one of the 3 vertices"), std::string::npos) << e;
}

// Assimp allocates the counts a PLY or OFF header declares before reading any data: a
// 200-byte file declaring 4e9 vertices asks for 48 GB. They are checked against the size.
TEST_F(TempDir, DeclaredCountsBeyondTheFileAreRefused) {
  std::ofstream(dir_ / "a.ply") << "ply\nformat ascii 1.0\nelement vertex 4000000000\nproperty float x\n"
                                   "property float y\nproperty float z\nend_header\n0 0 0\n";
  std::string e = read_error(dir_ / "a.ply");
  EXPECT_NE(e.find("a.ply:3: element vertex: declares 4000000000 instances"), std::string::npos) << e;
  std::string bin = "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                    "property float z\nelement face 100\nproperty list uchar int vertex_indices\nend_header\n";
  bin += std::string(36, '\0') + std::string(1, '\3') + std::string(12, '\0');  // 3 vertices, 1 of 100 faces
  std::ofstream(dir_ / "b.ply", std::ios::binary) << bin;
  e = read_error(dir_ / "b.ply");
  EXPECT_NE(e.find("b.ply:7: element face: declares 100 instances"), std::string::npos) << e;
  std::ofstream(dir_ / "c.off") << "OFF\n# a comment\n4000000000 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  e = read_error(dir_ / "c.off");
  EXPECT_NE(e.find("c.off:3: OFF header: declares 4000000000 vertices"), std::string::npos) << e;
  // Right counts still read.
  std::ofstream(dir_ / "d.ply") << kPlyTriangleHeader << "3 0 1 2\n";
  EXPECT_EQ(read_mesh_file(dir_ / "d.ply").triangle_count(), 1u);
}

/// A binary PLY of a unit quad's 4 vertices and the given face records (list length field of
/// `count_type`, int indices), in little or big endian byte order.
std::string binary_ply(bool big_endian, const std::string& count_type, const std::vector<std::vector<std::int64_t>>& faces,
                       std::size_t count_bytes) {
  std::string s = std::string("ply\nformat ") + (big_endian ? "binary_big_endian" : "binary_little_endian") +
                  " 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nelement face " +
                  std::to_string(faces.size()) + "\nproperty list " + count_type + " int vertex_indices\nend_header\n";
  auto put = [&](std::uint64_t v, std::size_t bytes) {
    for (std::size_t k = 0; k < bytes; ++k) {
      const std::size_t shift = 8 * (big_endian ? bytes - 1 - k : k);
      s.push_back(static_cast<char>((v >> shift) & 0xFF));
    }
  };
  const float xyz[4][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  for (const auto& v : xyz)
    for (float c : v) {
      std::uint32_t bits = 0;
      std::memcpy(&bits, &c, 4);
      put(bits, 4);
    }
  for (const auto& f : faces) {
    put(static_cast<std::uint64_t>(f[0]), count_bytes);  // the length field as written, maybe a lie
    for (std::size_t k = 1; k < f.size(); ++k) put(static_cast<std::uint64_t>(f[k]), 4);
  }
  return s;
}

// Assimp allocates a PLY list by its length field before reading it: a 100-byte file with a
// face of 10⁸ indices takes 830 MB, and 4·10⁹ ends in std::bad_alloc naming nothing. Every
// list length is checked against the bytes left, in both byte orders and in ASCII.
TEST_F(TempDir, PlyListLengthsBeyondTheFileAreRefused) {
  for (bool big : {false, true}) {
    std::ofstream(dir_ / "l.ply", std::ios::binary) << binary_ply(big, "uint", {{3, 0, 1, 2}, {100000000, 0, 2, 3}}, 4);
    std::string e = read_error(dir_ / "l.ply");
    EXPECT_NE(e.find("l.ply:7: element face instance 1: list length 100000000 is more than the 12 bytes left"),
              std::string::npos)
        << e;
    std::ofstream(dir_ / "n.ply", std::ios::binary) << binary_ply(big, "int", {{-1, 0, 1, 2}}, 4);
    e = read_error(dir_ / "n.ply");
    EXPECT_NE(e.find("n.ply:7: element face instance 0: list length -1 is negative"), std::string::npos) << e;
    std::ofstream(dir_ / "c.ply", std::ios::binary) << binary_ply(big, "char", {{0xFF, 0, 1, 2}}, 1);
    e = read_error(dir_ / "c.ply");
    EXPECT_NE(e.find("list length -1 is negative"), std::string::npos) << e;
    // Right lengths still read: a triangle and a quad (two triangles), either byte order and
    // either width of length field.
    std::ofstream(dir_ / "ok.ply", std::ios::binary) << binary_ply(big, "uchar", {{3, 0, 1, 2}, {4, 0, 1, 2, 3}}, 1);
    EXPECT_EQ(read_mesh_file(dir_ / "ok.ply").triangle_count(), 3u);
    std::ofstream(dir_ / "ok4.ply", std::ios::binary) << binary_ply(big, "int", {{3, 0, 2, 3}}, 4);
    EXPECT_EQ(read_mesh_file(dir_ / "ok4.ply").triangle_count(), 1u);
  }
  std::ofstream(dir_ / "a.ply") << kPlyTriangleHeader << "4000000000 0 1 2\n";
  std::string e = read_error(dir_ / "a.ply");
  EXPECT_NE(e.find("a.ply:7: element face instance 0: list length 4000000000 is more than the"), std::string::npos)
      << e;
  std::ofstream(dir_ / "m.ply") << kPlyTriangleHeader << "-3 0 1 2\n";
  e = read_error(dir_ / "m.ply");
  EXPECT_NE(e.find("list length -3 is negative"), std::string::npos) << e;
  // An ASCII list whose values exactly fill the file's end passes to Assimp.
  std::ofstream(dir_ / "e.ply") << kPlyTriangleHeader << "3 0 1 2";
  EXPECT_EQ(read_mesh_file(dir_ / "e.ply").triangle_count(), 1u);
}

/// A glTF of one triangle under a chain of `depth` nodes.
std::string gltf_chain(std::size_t depth) {
  std::string nodes;
  for (std::size_t i = 0; i + 1 < depth; ++i) nodes += "{\"children\":[" + std::to_string(i + 1) + "]},";
  nodes += "{\"mesh\":0}";
  // 9 floats: (0,0,0) (1,0,0) (0,1,0), base64.
  return R"({"asset":{"version":"2.0"},"buffers":[{"uri":"data:application/octet-stream;base64,)"
         R"(AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA","byteLength":36}],)"
         R"("bufferViews":[{"buffer":0,"byteLength":36}],"accessors":[{"bufferView":0,"componentType":5126,)"
         R"("count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}],"meshes":[{"primitives":[{"attributes":)"
         R"({"POSITION":0}}]}],"nodes":[)" + nodes + R"(],"scenes":[{"nodes":[0]}],"scene":0})";
}

// Assimp walks DAE and glTF node hierarchies recursively: 8,000 nested DAE nodes or 20,000
// glTF nodes overflowed the stack (SIGSEGV). Deeper than kMaxMeshNesting is refused.
TEST_F(TempDir, NestingDeeperThanTheLimitIsRefused) {
  std::string dae = R"(<?xml version="1.0"?><COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" )"
                    R"(version="1.4.1"><library_visual_scenes><visual_scene id="s">)";
  for (int i = 0; i < 2000; ++i) dae += "<node>";
  for (int i = 0; i < 2000; ++i) dae += "</node>";
  dae += R"(</visual_scene></library_visual_scenes><scene><instance_visual_scene url="#s"/></scene></COLLADA>)";
  std::ofstream(dir_ / "deep.dae") << dae;
  std::string e = read_error(dir_ / "deep.dae");
  EXPECT_NE(e.find("deep.dae:1: <node>: nested more than 1000 levels deep"), std::string::npos) << e;
  std::ofstream(dir_ / "deep.gltf") << gltf_chain(kMaxMeshNesting + 2);
  e = read_error(dir_ / "deep.gltf");
  EXPECT_NE(e.find("deep.gltf: node"), std::string::npos) << e;
  EXPECT_NE(e.find("nested more than 1000 levels deep"), std::string::npos) << e;
  std::ofstream(dir_ / "ok.gltf") << gltf_chain(50);
  EXPECT_EQ(read_mesh_file(dir_ / "ok.gltf").triangle_count(), 1u);
}

TEST(RealMeshes, CountsMatchTheirSources) {
  LOOM_SHARED_DATA_OR_SKIP(loom::testing::shared_data(""));
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
  LOOM_SHARED_DATA_OR_SKIP(loom::testing::shared_data(""));
  Mesh m = read_mesh_file(kData / "trimesh/CesiumMilkTruck.glb");
  EXPECT_GT(m.triangle_count(), 1000u);
  EXPECT_EQ(first_non_finite_vertex(m), -1);
}

TEST(RealCad, StepAssemblyKeepsProductNames) {
  LOOM_SHARED_DATA_OR_SKIP(loom::testing::shared_data(""));
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
  LOOM_SHARED_DATA_OR_SKIP(loom::testing::shared_data(""));
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
  LOOM_SHARED_DATA_OR_SKIP(loom::testing::shared_data(""));
  TessellationParams coarse, fine;
  coarse.linear_deflection = 1.0;
  fine.linear_deflection = 0.05;
  auto a = read_cad_file(kData / "occt/screw.step", coarse, false);
  auto b = read_cad_file(kData / "occt/screw.step", fine, false);
  EXPECT_GT(b[0].mesh.triangle_count(), a[0].mesh.triangle_count());
}

// A store keeps a file's transferred shapes: meshing them again at another deflection, for
// other leaves, or coarse after fine, gives exactly the meshes of a fresh reading
// (OpenCASCADE's mesher would otherwise keep the finer triangulation it finds).
TEST(RealCad, StoredShapesMeshAsAFreshReading) {
  LOOM_SHARED_DATA_OR_SKIP(loom::testing::shared_data(""));
  const fs::path file = kData / "stepcode/as1-oc-214.stp";
  TessellationParams coarse, fine;
  coarse.linear_deflection = 2.0;
  fine.linear_deflection = 0.25;
  auto same = [](const std::vector<NamedMesh>& a, const std::vector<NamedMesh>& b) {
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t i = 0; i < a.size(); ++i) {
      EXPECT_EQ(a[i].name, b[i].name);
      EXPECT_EQ(a[i].leaf, b[i].leaf);
      EXPECT_EQ(a[i].mesh.vertices, b[i].mesh.vertices) << a[i].name;
      EXPECT_EQ(a[i].mesh.triangles, b[i].mesh.triangles) << a[i].name;
    }
  };
  CadShapeStore store;
  const auto c1 = read_cad_file(file, coarse, true, nullptr, &store);
  EXPECT_EQ(store.size(), 1u);
  same(c1, read_cad_file(file, coarse, true));
  const std::vector<int> leaves{1, 4, 17};
  const auto f = read_cad_file(file, fine, true, &leaves, &store);
  same(f, read_cad_file(file, fine, true, &leaves));
  EXPECT_NE(f[0].mesh.vertices, c1[1].mesh.vertices);  // meshed again, not the coarse triangulation
  same(read_cad_file(file, coarse, false, nullptr, &store), read_cad_file(file, coarse, false));  // coarse after fine
  EXPECT_EQ(store.size(), 1u);
}

TEST(RealCad, CacheReturnsTheSameMeshes) {
  LOOM_SHARED_DATA_OR_SKIP(loom::testing::shared_data(""));
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

// A cache entry whose vertex count is corrupt (2^32) must not size arrays from it (96 GB,
// std::bad_alloc on every run until the cache is deleted): it is a miss, re-tessellated
// and stored again.
TEST(RealCad, CorruptCacheEntryIsAMiss) {
  LOOM_SHARED_DATA_OR_SKIP(loom::testing::shared_data(""));
  const fs::path dir = fs::temp_directory_path() / "loom_tess_cache_corrupt";
  fs::remove_all(dir);
  ::setenv("LOOM_CACHE_DIR", dir.c_str(), 1);
  TessellationParams tp;
  tp.linear_deflection = 0.5;
  bool hit = true;
  const auto a = read_cad_file_cached(kData / "occt/linkrods.step", tp, true, &hit);
  ASSERT_FALSE(a.empty());
  const fs::path entry = dir / (tessellation_cache_key(kData / "occt/linkrods.step", tp, true) + ".tess");
  std::string bytes;
  {
    std::ifstream in(entry, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  // magic (8), mesh count (8), name length (8), name, B-rep faces (4), vertex count (8)
  std::uint64_t name_length = 0;
  std::memcpy(&name_length, bytes.data() + 16, 8);
  const std::uint64_t corrupt = std::uint64_t{1} << 32;
  std::memcpy(bytes.data() + 24 + name_length + 4, &corrupt, 8);
  std::ofstream(entry, std::ios::binary) << bytes;
  const auto b = read_cad_file_cached(kData / "occt/linkrods.step", tp, true, &hit);
  EXPECT_FALSE(hit);
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(a[0].mesh.vertices, b[0].mesh.vertices);
  read_cad_file_cached(kData / "occt/linkrods.step", tp, true, &hit);
  EXPECT_TRUE(hit) << "stored again";
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
