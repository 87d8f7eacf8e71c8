// One test per reader bug exposed by mutational fuzzing of the loom executable
// (crashes, hangs and silently wrong readings of hostile mesh, STEP, TOML and harness files).
// Each input is written out here (or generated, where it is large); each test fails on a reader
// with that bug. Inputs that crashed or hung the process are run through the command line under
// `timeout`, so that a crash or hang fails the test instead of killing or stalling it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <array>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include <sys/wait.h>

#include "core/error.hpp"
#include "core/io/harness_xml.hpp"
#include "core/io/kbl_read.hpp"
#include "core/io/mesh_node_checks.hpp"
#include "core/io/mesh_read.hpp"
#include "core/io/point_cloud_io.hpp"
#include "core/io/toml_checks.hpp"
#include "common/run_loom.hpp"
#include "common/gltf_seed.hpp"
#include "common/test_files.hpp"

namespace {

namespace fs = std::filesystem;
using loom::InputError;

/// A fresh scratch directory for the running test.
fs::path scratch() { return loom::testing::scratch_dir("loom_fuzz_regression_"); }

void write(const fs::path& p, const std::string& bytes) { loom::testing::write_file(p, bytes); }

using loom::testing::input_error;
using loom::testing::slurp;

/// run_loom under `timeout 60`: an old hang ends with status 124, an old crash with 128 + its
/// signal, instead of stalling or killing the test.
loom::testing::LoomRun run_bounded(const std::string& args) {
  loom::testing::LoomRun r;
  const std::string cmd = "timeout 60 " + std::string(LOOM_EXE) + " " + args + " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return r;
  char buf[4096];
  while (fgets(buf, sizeof buf, p)) r.out += buf;
  const int st = pclose(p);
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  return r;
}

/// `loom info --quiet` (bounded) on a scene of the one part `file` in `dir`.
loom::testing::LoomRun bounded_info_of_part(const fs::path& dir, const std::string& file) {
  write(dir / "scene.toml", "[scene]\n[[part]]\nfile = '" + file + "'\n");
  return run_bounded("info " + (dir / "scene.toml").string() + " --quiet");
}

/// Copies the kept finding `name` (tests/fuzz/findings/<name>) into `dir` as `as`.
void kept_finding(const fs::path& dir, const std::string& name, const std::string& as) {
  fs::copy_file(fs::path(LOOM_SOURCE_DIR) / "tests/fuzz/findings" / name, dir / as);
}

/// Writes `bytes` as `dir`/`file`, the one part of a scene, and expects `loom info` to refuse
/// it (exit 2) with `expected` in its message.
void expect_part_refused(const fs::path& dir, const std::string& file, const std::string& bytes,
                         const std::string& expected) {
  write(dir / file, bytes);
  const auto r = bounded_info_of_part(dir, file);
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find(expected), std::string::npos) << expected << "\n" << r.out;
}

/// Copies the kept finding `name` into `dir` as `as` and expects `loom info` to refuse it
/// (exit 2) with `expected` in its message.
void expect_finding_refused(const fs::path& dir, const std::string& name, const std::string& as,
                            const std::string& expected) {
  kept_finding(dir, name, as);
  const auto r = bounded_info_of_part(dir, as);
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find(expected), std::string::npos) << expected << "\n" << r.out;
}

/// Writes `text` as `file` and expects read_mesh_file to refuse it with `expected` in its
/// message.
void expect_read_refused(const fs::path& file, const std::string& text, const std::string& expected) {
  write(file, text);
  const std::string e = input_error([&] { loom::read_mesh_file(file); });
  EXPECT_NE(e.find(expected), std::string::npos) << expected << "\n" << e;
}

/// The tetrahedron glTF seed of the fuzz corpus (its buffer a base64 data URI).
std::string tetra_gltf() { return loom::testing::tetra_gltf_text(); }

// --- DAE -------------------------------------------------------------------------------------

const char* kDaeHead =
    R"(<?xml version="1.0"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
)";

/// One triangle as a DAE geometry "g", its accessor's stride and its <p> list as given.
std::string dae_triangle_geometry(const std::string& stride, const std::string& p) {
  return R"(<library_geometries><geometry id="g"><mesh>
<source id="p"><float_array id="pa" count="9">0 0 0 1 0 0 0 1 0</float_array>
<technique_common><accessor source="#pa" count="3" stride=")" +
         stride + R"("><param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/></accessor></technique_common></source>
<vertices id="v"><input semantic="POSITION" source="#p"/></vertices>
<triangles count="1"><input semantic="VERTEX" source="#v" offset="0"/><p>)" +
         p + R"(</p></triangles>
</mesh></geometry></library_geometries>
)";
}

const char* kDaeSceneOfG =
    R"(<library_visual_scenes><visual_scene id="S"><node id="n"><instance_geometry url="#g"/></node></visual_scene></library_visual_scenes>
<scene><instance_visual_scene url="#S"/></scene>
</COLLADA>
)";

/// A COLLADA document of dae_triangle_geometry's one triangle, instanced once.
std::string dae_one_triangle() { return kDaeHead + dae_triangle_geometry("3", "0 1 2") + kDaeSceneOfG; }

/// dae_triangle_geometry's primitive for p = "0 1 2", for tests that put another in its place.
const std::string kDaeTriangle =
    R"(<triangles count="1"><input semantic="VERTEX" source="#v" offset="0"/><p>0 1 2</p></triangles>)";

// An accessor stride of 2^31 - 1 on a 9-value array: Assimp read element k at k·stride
// unchecked (SIGSEGV in `loom info`).
TEST(FuzzRegression, DaeAccessorHugeStrideCrashed) {
  const fs::path d = scratch();
  write(d / "stride.dae", kDaeHead + dae_triangle_geometry("2147483647", "0 1 2") + kDaeSceneOfG);
  const auto r = bounded_info_of_part(d, "stride.dae");
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("stride.dae:5: <accessor>: count 3 x stride 2147483647 from offset 0 reaches beyond the 9 "
                       "values of <float_array id=\"pa\">"),
            std::string::npos)
      << r.out;
  // Stride 3 (the array exactly) reads the triangle; stride 4 reaches one value beyond.
  write(d / "ok.dae", dae_one_triangle());
  EXPECT_EQ(loom::read_mesh_file(d / "ok.dae").triangle_count(), 1u);
  write(d / "four.dae", kDaeHead + dae_triangle_geometry("4", "0 1 2") + kDaeSceneOfG);
  const std::string e = input_error([&] { loom::read_mesh_file(d / "four.dae"); });
  EXPECT_NE(e.find("count 3 x stride 4 from offset 0 reaches beyond the 9 values"), std::string::npos) << e;
}

// An empty index list (<p/>, <p></p>, <p> </p>) in a primitive (libFuzzer, a long run):
// Assimp's COLLADA reader dereferenced null (SIGSEGV in `loom info`).
TEST(FuzzRegression, DaeEmptyIndexListCrashed) {
  const fs::path d = scratch();
  for (const std::string p : {"", " "}) {
    write(d / "empty.dae", kDaeHead + dae_triangle_geometry("3", p) + kDaeSceneOfG);
    const auto r = bounded_info_of_part(d, "empty.dae");
    EXPECT_EQ(r.status, 2) << "'" << p << "'\n" << r.out;
    EXPECT_NE(r.out.find("empty.dae:7: <p>: holds no values (an empty index list)"), std::string::npos) << r.out;
  }
}

// A DAE node instancing itself (and A -> B -> A): Assimp followed instance_node without a
// visited set until the stack overflowed (SIGSEGV).
TEST(FuzzRegression, DaeInstanceNodeCycleCrashed) {
  const fs::path d = scratch();
  const std::string scene =
      R"(<library_visual_scenes><visual_scene id="S"><node id="r"><instance_node url="#A"/></node></visual_scene></library_visual_scenes>
<scene><instance_visual_scene url="#S"/></scene>
</COLLADA>
)";
  write(d / "cycle.dae",
        kDaeHead + std::string(R"(<library_nodes><node id="A"><instance_node url="#A"/></node></library_nodes>)") +
            "\n" + scene);
  auto r = bounded_info_of_part(d, "cycle.dae");
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("cycle.dae:3: node 'A': instance_node cycle through node 'A'"), std::string::npos) << r.out;
  write(d / "ab.dae", kDaeHead +
                          std::string(R"(<library_nodes><node id="A"><instance_node url="#B"/></node>)"
                                      R"(<node id="B"><instance_node url="#A"/></node></library_nodes>)") +
                          "\n" + scene);
  r = bounded_info_of_part(d, "ab.dae");
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("ab.dae:3: node 'B': instance_node cycle through node 'A'"), std::string::npos) << r.out;
  // glTF children in a cycle are refused the same way.
  write(d / "cycle.gltf", R"({"asset":{"version":"2.0"},"nodes":[{"children":[1]},{"children":[0]}],)"
                          R"("scenes":[{"nodes":[0]}],"scene":0})");
  const std::string e = input_error([&] { loom::read_mesh_file(d / "cycle.gltf"); });
  EXPECT_NE(e.find("children cycle through node '0'"), std::string::npos) << e;
}

// `<p>0 1 x</p>`: Assimp's COLLADA reader did not move past a token it could not read as an
// index and appended indices without end (>6 GB in 20 s).
TEST(FuzzRegression, DaeNonIntegerIndexHung) {
  const fs::path d = scratch();
  for (const std::string bad : {"x", ".5", "-1e38", "1..2", "-1"}) {
    write(d / "bad.dae", kDaeHead + dae_triangle_geometry("3", "0 1 " + bad) + kDaeSceneOfG);
    const auto r = bounded_info_of_part(d, "bad.dae");
    EXPECT_EQ(r.status, 2) << bad << ": " << r.out;
    EXPECT_NE(r.out.find("bad.dae:7: <p>: '" + bad + "' is not an index (value 2 of the list)"), std::string::npos)
        << r.out;
  }
}

// `<p>1\f2 3</p>` in a polylist (libFuzzer, 175,168 executions): Assimp's COLLADA reader
// does not skip a form feed or vertical tab between two indices and appended indices without
// end (malloc of 3 GB under the fuzzer; std::bad_alloc, no line named, in Release).
TEST(FuzzRegression, DaeIndexListFormFeedGrewWithoutEnd) {
  const fs::path d = scratch();
  expect_finding_refused(d, "mesh_dae/index-list-form-feed-oom.dae", "ff.dae",
                         "ff.dae:21: <p>: '1\\x0c2' is not an index (value 0 of the list): only spaces, tabs and "
                         "line ends separate indices");
  for (const std::string blank : {"\v", "\f"}) {
    write(d / "bad.dae", kDaeHead + dae_triangle_geometry("3", "0" + blank + "1 2") + kDaeSceneOfG);
    EXPECT_EQ(bounded_info_of_part(d, "bad.dae").status, 2);
  }
  write(d / "good.dae", kDaeHead + dae_triangle_geometry("3", "\r\n0\t1\n 2 ") + kDaeSceneOfG);
  EXPECT_EQ(loom::read_mesh_file(d / "good.dae").triangle_count(), 1u);
}

// A <polylist> whose <vcount> a mutation had turned into text ("vcount>") (libFuzzer, seed
// 21, 437,246 executions after the form-feed fix): Assimp's COLLADA reader dereferenced null
// (SIGSEGV); a <vcount> after the <p> did the same, and a primitive with a count but no
// <p> aborted it.
TEST(FuzzRegression, DaePolylistWithoutVcountCrashed) {
  const fs::path d = scratch();
  expect_finding_refused(d, "mesh_dae/polylist-without-vcount-segv.dae", "novc.dae",
                         "novc.dae:17: <polylist>: a <polylist> needs its <vcount>");
  const std::string input = R"(<input semantic="VERTEX" source="#v" offset="0"/>)";
  const auto with_primitive = [&](const std::string& primitive) {
    std::string g = dae_triangle_geometry("3", "0 1 2");
    g.replace(g.find(kDaeTriangle), kDaeTriangle.size(), primitive);
    return kDaeHead + g + kDaeSceneOfG;
  };
  expect_part_refused(d, "after.dae",
                      with_primitive(R"(<polylist count="1">)" + input + "<p>0 1 2</p><vcount>3</vcount></polylist>"),
                      "<polylist>: a <polylist> needs its <vcount> (the vertices of each polygon) before its <p>");
  expect_part_refused(d, "nop.dae", with_primitive(R"(<triangles count="1">)" + input + "</triangles>"),
                      "<triangles>: declares 1 primitive(s) but holds no <p> index list");
  write(d / "good.dae", with_primitive(R"(<polylist count="1">)" + input + "<vcount>3</vcount><p>0 1 2</p></polylist>"));
  EXPECT_EQ(loom::read_mesh_file(d / "good.dae").triangle_count(), 1u);
  write(d / "none.dae", with_primitive(R"(<triangles count="0">)" + input + "</triangles>" + kDaeTriangle));
  EXPECT_EQ(loom::read_mesh_file(d / "none.dae").triangle_count(), 1u);
}

// `<vcount>34294967295</vcount>` over a `<p>` of three indices (libFuzzer, seed 22, 392,281
// executions after the vcount-order fix): Assimp allocated by the polygon's vertex count
// before it read the indices (34 GB under the fuzzer; std::bad_alloc in Release).
TEST(FuzzRegression, DaePolylistVcountBeyondItsIndicesAllocated) {
  const fs::path d = scratch();
  expect_finding_refused(d, "mesh_dae/polylist-vcount-beyond-indices-oom.dae", "big.dae",
                         "big.dae:17: <vcount>: the polygons' 34294967295 vertices take 34294967295 indices at 1 "
                         "per vertex, but the <p> holds 3");
  const auto polylist = [&](const std::string& inputs, const std::string& vcount, const std::string& p) {
    std::string g = dae_triangle_geometry("3", "0 1 2");
    g.replace(g.find(kDaeTriangle), kDaeTriangle.size(),
              R"(<polylist count="1">)" + inputs + "<vcount>" + vcount + "</vcount><p>" + p + "</p></polylist>");
    return kDaeHead + g + kDaeSceneOfG;
  };
  const std::string vertex = R"(<input semantic="VERTEX" source="#v" offset="0"/>)";
  expect_part_refused(d, "two.dae", polylist(vertex, "3 3", "0 1 2"),
                      "<vcount>: the polygons' 6 vertices take 6 indices at 1 per vertex, but the <p> holds 3");
  // Two values per vertex (a second input at offset 1): six indices make one triangle.
  const std::string two_inputs = vertex + R"(<input semantic="TEXCOORD" source="#p" offset="1"/>)";
  expect_part_refused(d, "short.dae", polylist(two_inputs, "3", "0 0 1 1 2"),
                      "the polygons' 3 vertices take 6 indices at 2 per vertex, but the <p> holds 5");
  write(d / "ok.dae", polylist(two_inputs, "3", "0 0 1 1 2 2"));
  EXPECT_EQ(loom::read_mesh_file(d / "ok.dae").triangle_count(), 1u);
}

// An <input offset="9999999999999999999999999999999990"> of a <triangles> (libFuzzer, seed
// 23, 70,672 executions after the vcount fix): Assimp sized the index list by the highest
// offset + 1, wrapped, and allocated 412 GB; a count of 10⁹ triangles over twelve indices
// went the same way.
TEST(FuzzRegression, DaeInputOffsetBeyondItsIndicesAllocated) {
  const fs::path d = scratch();
  expect_finding_refused(d, "mesh_dae/input-offset-beyond-indices-oom.dae", "offset.dae",
                         "offset.dae:16: <input>: offset '9999999999999999999999999999999990' is not an index into "
                         "the 12 values of the <p>");
  std::string many = dae_one_triangle();
  many.replace(many.find(R"(<triangles count="1">)"), 21, R"(<triangles count="1000000000">)");
  expect_part_refused(d, "many.dae", many,
                      "<triangles>: count 1000000000 triangles take 3000000000 indices at 1 per vertex, but the <p> "
                      "holds 3");
}

// A second COLLADA document pasted inside a <geometry> (libFuzzer, seed 24, 437,329
// executions after the offset fix), so that two <float_array> share the id
// "tetra-pos-array": Assimp keeps one array per id and dereferenced null (SIGSEGV). Two
// sibling geometries whose arrays share an id do the same.
TEST(FuzzRegression, DaeArrayIdGivenTwiceCrashed) {
  const fs::path d = scratch();
  expect_finding_refused(d, "mesh_dae/array-id-given-twice-segv.dae", "twice.dae",
                         "twice.dae:63: <visual_scene>: id 'scene' is given again (first at line 43, <visual_scene>)");
  std::string two = dae_one_triangle();
  const std::string array = R"(<float_array id="pa" count="9">0 0 0 1 0 0 0 1 0</float_array>)";
  two.insert(two.find("</library_geometries>"),
             R"(<geometry id="g2"><mesh><source id="p2">)" + array + "</source></mesh></geometry>\n");
  expect_part_refused(d, "sibling.dae", two, "sibling.dae:8: <float_array>: id 'pa' is given again (first at line 4, <float_array>)");
}

// A <matrix> of 14 values (libFuzzer, seed 25: fuzz_mesh_dae grew past its 2 GB after
// 375,510 executions; the corpus replayed with leak detection named the inputs): Assimp
// read past the values, threw and leaked the nodes it had built, a kilobyte per file. A
// rotate of "? 1 90" and a <scene> naming no visual scene did the same. A node nested in
// a node with its own matrix reads.
TEST(FuzzRegression, DaeTransformShortOfValuesLeaked) {
  const fs::path d = scratch();
  expect_finding_refused(d, "mesh_dae/matrix-of-14-values-leak.dae", "matrix.dae",
                         "matrix.dae:10: <matrix>: holds 14 values; a <matrix> takes 16");
  const std::string geometry = dae_triangle_geometry("3", "0 1 2");
  const auto scene = [&](const std::string& nodes, const std::string& url) {
    return kDaeHead + geometry + "<library_visual_scenes><visual_scene id=\"S\">" + nodes +
           "</visual_scene></library_visual_scenes>\n<scene><instance_visual_scene url=\"" + url +
           "\"/></scene>\n</COLLADA>\n";
  };
  const std::string leaf = R"(<instance_geometry url="#g"/>)";
  expect_part_refused(d, "rotate.dae", scene("<node id=\"n\"><rotate>? 1 90 0</rotate>" + leaf + "</node>", "#S"),
                      "<rotate>: '?' (value 0) is not a number");
  expect_part_refused(d, "url.dae", scene("<node id=\"n\">" + leaf + "</node>", "#T"),
                      "<instance_visual_scene>: url '#T' names no <visual_scene> of the file");
  write(d / "nested.dae",
        scene("<node id=\"a\"><translate>1 2 3</translate><node id=\"b\"><matrix>1 0 0 5 0 1 0 0 0 0 1 0 0 0 0 "
              "1</matrix>" + leaf + "</node></node>",
              "#S"));
  EXPECT_EQ(loom::read_mesh_file(d / "nested.dae").triangle_count(), 1u);
}

// A COLLADA tetrahedron mutated into a polylist without inputs ahead of the mesh's
// <vertices> and a second polylist after it (libFuzzer, seed 27, 1,201,733 executions;
// minimised): Assimp read the first primitive's faces without positions, so the second's
// faces named vertices past the mesh's, and its sub-mesh copy read 36 bytes beyond the
// positions (ASan heap-buffer-overflow). A mesh now holds one <vertices>, before its
// primitives.
TEST(FuzzRegression, DaePrimitiveBeforeVerticesOverflowed) {
  const fs::path d = scratch();
  expect_finding_refused(d, "mesh_dae/primitive-before-vertices-hbo.dae", "early.dae",
                         "early.dae:1: <polylist>: comes before the mesh's <vertices> (line 1): a mesh's primitives "
                         "follow its <vertices>");
  const std::string one = dae_one_triangle();
  write(d / "one.dae", one);
  EXPECT_EQ(loom::read_mesh_file(d / "one.dae").triangle_count(), 1u);
  std::string none = one;
  none.erase(none.find("<vertices"), none.find("</vertices>") + 11 - none.find("<vertices"));
  expect_part_refused(d, "none.dae", none, "<triangles>: comes before the mesh's <vertices> (the mesh has none)");
  std::string two = one;
  two.insert(two.find("<triangles"), R"(<vertices id="v2"><input semantic="POSITION" source="#p"/></vertices>)");
  expect_part_refused(d, "two.dae", two, "two.dae:7: <vertices>: a second <vertices> in the mesh (the first at line 6)");
}

// A `<triangles count="4777…777">` a mutation had put inside an `<accessor>` (libFuzzer,
// seed 32, 397,729 executions after the geometry-only reduction): Assimp walks all of a
// mesh's descendants for its primitives, read this one as the mesh's and allocated by its
// count (103 GB); the pre-check took only the mesh's children for primitives. A
// <vertices> or primitive within a mesh is now a child of it.
TEST(FuzzRegression, DaePrimitiveInsideAnAccessorAllocated) {
  const fs::path d = scratch();
  expect_finding_refused(d, "mesh_dae/primitive-inside-accessor-oom.dae", "deep.dae",
                         "deep.dae:12: <polylist>: inside <accessor>, not a child of the <mesh> on line 6");
  std::string deep = dae_one_triangle();
  deep.insert(deep.find("</technique_common>"), R"(<vertices id="v2"><input semantic="POSITION" source="#p"/></vertices>)");
  expect_part_refused(d, "vertices.dae", deep, "<vertices>: inside <technique_common>, not a child of the <mesh> on line 3");
}

// An `<accessor stride="0">` over a float_array whose count a mutation had spoilt
// (libFuzzer, seed 33, 776,170 executions after the mesh-children fix; minimised by
// libFuzzer to 551 bytes): the bound check let a stride of 0 through, and Assimp read
// every position at the offset of an empty array (SIGSEGV).
TEST(FuzzRegression, DaeAccessorStrideZeroCrashed) {
  const fs::path d = scratch();
  expect_finding_refused(d, "mesh_dae/accessor-stride-zero-segv.dae", "zero.dae",
                         "zero.dae:6: <accessor>: stride 0 for 0 params");
  expect_part_refused(d, "two.dae", kDaeHead + dae_triangle_geometry("2", "0 1 2") + kDaeSceneOfG,
                      "<accessor>: stride 2 for 3 params");
}

// The same input cut by a mutation inside a start tag (`<node  <instance_geometry`): the
// XML does not parse, yet Assimp read the part before the error and overflowed the same
// way, while the pre-check had left malformed XML to Assimp. Malformed XML is refused,
// naming the line of the error.
TEST(FuzzRegression, DaeMalformedXmlReadInPartOverflowed) {
  const fs::path d = scratch();
  expect_finding_refused(d, "mesh_dae/malformed-xml-read-in-part-hbo.dae", "cut.dae",
                         "cut.dae:1: XML: the XML does not parse: Error parsing start element tag");
  std::string cut = dae_one_triangle();
  cut.resize(cut.find("</mesh>") + 3);
  expect_part_refused(d, "end.dae", cut, "end.dae:8: XML: the XML does not parse: Start-end tags mismatch");
}

// `<float_array count="3333…312">` over 12 values (libFuzzer, seed 26, 10,714 executions
// after the transform fix): Assimp reserved the declared count, wrapped, before it read the
// values (the fuzzer past its 2 GB), then reported the values missing.
TEST(FuzzRegression, DaeArrayCountBeyondItsValuesAllocated) {
  const fs::path d = scratch();
  expect_finding_refused(d, "mesh_dae/array-count-beyond-values-oom.dae", "count.dae",
                         "count.dae:8: <float_array>: attribute 'count' = '3333");
  std::string more = dae_one_triangle();
  more.replace(more.find(R"(count="9")"), 9, R"(count="10")");
  expect_part_refused(d, "more.dae", more, "<float_array>: count 10 but it holds 9 values");
}

/// A DAE of one triangle instanced through `levels` library nodes, each instancing the one
/// below twice, under one scene node.
std::string dae_fan(int levels) {
  std::string nodes = R"(<node id="N0"><instance_geometry url="#g"/></node>)";
  for (int i = 1; i <= levels; ++i)
    nodes += "<node id=\"N" + std::to_string(i) + "\"><instance_node url=\"#N" + std::to_string(i - 1) +
             "\"/><instance_node url=\"#N" + std::to_string(i - 1) + "\"/></node>";
  return kDaeHead + dae_triangle_geometry("3", "0 1 2") + "<library_nodes>" + nodes +
         "</library_nodes>\n<library_visual_scenes><visual_scene id=\"S\"><node id=\"r\"><instance_node url=\"#N" +
         std::to_string(levels) +
         "\"/></node></visual_scene></library_visual_scenes>\n<scene><instance_visual_scene url=\"#S\"/></scene>\n"
         "</COLLADA>\n";
}

/// The glTF of the same fan: node i has children [i+1, i+1], the last one the triangle.
std::string gltf_fan(int levels) {
  std::string nodes;
  for (int i = 0; i < levels; ++i)
    nodes += "{\"children\":[" + std::to_string(i + 1) + "," + std::to_string(i + 1) + "]},";
  return R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[)" + nodes +
         R"({"mesh":0}],"meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1}]}],)"
         R"("buffers":[{"uri":"data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAAAAABAAIAAAA=","byteLength":44}],)"
         R"("bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":36},{"buffer":0,"byteOffset":36,"byteLength":6}],)"
         R"("accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","max":[1,1,0],"min":[0,0,0]},)"
         R"({"bufferView":1,"componentType":5123,"count":3,"type":"SCALAR"}]})";
}

// 24 levels of nodes each instancing the one below twice (2.7 kB of DAE, 1.2 kB of glTF):
// Assimp built all 2^24 instances of the triangle (>6 GB, no end in 20 s).
TEST(FuzzRegression, MeshNodeFanOutExpandedExponentially) {
  const fs::path d = scratch();
  // Node instances, closed form: the scene node plus 2^k instances of level 24 - k.
  const double dae_instances = 1.0 + (std::pow(2.0, 25) - 1.0);
  write(d / "fan.dae", dae_fan(24));
  auto r = bounded_info_of_part(d, "fan.dae");
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("fan.dae:10: <visual_scene>: shared nodes expand to " +
                       std::to_string(static_cast<long long>(dae_instances)) + " node instances, more than the " +
                       std::to_string(static_cast<long long>(loom::kMaxMeshNodeInstances)) +
                       " accepted from a file of 26 nodes"),
            std::string::npos)
      << r.out;
  write(d / "fan.gltf", gltf_fan(24));
  r = bounded_info_of_part(d, "fan.gltf");
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("fan.gltf: scene nodes: shared nodes expand to " +
                       std::to_string(static_cast<long long>(std::pow(2.0, 25) - 1.0)) + " node instances"),
            std::string::npos)
      << r.out;
  // Ten levels (1,024 instances of the triangle) are well within the cap and read whole:
  // the expansion the check counts is the one Assimp builds.
  write(d / "ten.dae", dae_fan(10));
  EXPECT_EQ(loom::read_mesh_file(d / "ten.dae").triangle_count(), 1024u);
  write(d / "ten.gltf", gltf_fan(10));
  EXPECT_EQ(loom::read_mesh_file(d / "ten.gltf").triangle_count(), 1024u);
  // The triangle cap: a fan of 12 levels over a geometry of 1,100 triangles expands to
  // 4,505,600 > 2^22 triangles with only 4,096 node instances.
  std::string p;
  for (int t = 0; t < 1100; ++t) p += "0 1 2 ";
  std::string big = dae_fan(12);
  big.replace(big.find("<triangles count=\"1\">"), 21, "<triangles count=\"1100\">");
  big.replace(big.find("<p>0 1 2</p>"), 12, "<p>" + p + "</p>");
  write(d / "wide.dae", big);
  const std::string e = input_error([&] { loom::read_mesh_file(d / "wide.dae"); });
  EXPECT_NE(e.find("shared nodes expand to 4505600 triangles, more than the 4194304 accepted"), std::string::npos) << e;
}

// --- OBJ -------------------------------------------------------------------------------------

// 40,000 one-triangle `o` objects took 4.7 s of CPU where the same triangles in one object
// took 0.4 s, growing quadratically (100,000: 28 s): Assimp looks each object (and `usemtl`
// material) name up in a list. Assimp gets those statements as comments, byte for byte.
TEST(FuzzRegression, ObjManyObjectsLoadedQuadratically) {
  const std::string text = "o a\nv 0 0 0\n  usemtl m1\nv 1 0 0\nv 0 1 0 \\\no x\nf 1 2 3\nobj\ng grp\n";
  const std::string served = loom::obj_text_for_assimp(text);
  EXPECT_EQ(served, "# a\nv 0 0 0\n  #semtl m1\nv 1 0 0\nv 0 1 0 \\\no x\nf 1 2 3\nobj\ng grp\n");
  // Oracle: the same triangles in one object. 2,000 objects of one triangle each read as the
  // 2,000 triangles of the single-object file, vertex for vertex.
  const fs::path d = scratch();
  std::string many, one = "o all\n";
  for (int i = 0; i < 2000; ++i) {
    const std::string tri = "v 0 0 " + std::to_string(i) + "\nv 1 0 " + std::to_string(i) + "\nv 0 1 " +
                            std::to_string(i) + "\nf -3 -2 -1\n";
    many += "o g" + std::to_string(i) + "\nusemtl m" + std::to_string(i) + "\n" + tri;
    one += tri;
  }
  write(d / "many.obj", many);
  write(d / "one.obj", one);
  const loom::Mesh a = loom::read_mesh_file(d / "many.obj"), b = loom::read_mesh_file(d / "one.obj");
  ASSERT_EQ(a.triangle_count(), 2000u);
  ASSERT_EQ(a.vertices.size(), b.vertices.size());
  for (std::size_t i = 0; i < a.vertices.size(); ++i) EXPECT_EQ(a.vertices[i], b.vertices[i]) << i;
  EXPECT_EQ(a.triangles, b.triangles);
}

// --- STL -------------------------------------------------------------------------------------

/// An ASCII STL solid of the given facet bodies (each between `facet` and `endfacet`).
std::string ascii_stl(const std::vector<std::string>& facets, const std::string& name = "part") {
  std::string s = "solid " + name + "\n";
  for (const std::string& f : facets) s += "  facet " + f + "\n  endfacet\n";
  return s + "endsolid " + name + "\n";
}

const std::string kStlFacet =
    "normal 0 0 1\n    outer loop\n      vertex 0 0 0\n      vertex 1 0 0\n      vertex 0 1 0\n    endloop";

// A facet whose vertices a mutation removed (libFuzzer, 1.1 M runs of fuzz_mesh_stl): Assimp
// read the solid, rejected it ("Normal buffer size does not match position buffer size", no
// line) and leaked the mesh and node it had built, 2.5 kB per file, until the fuzzer ran out
// of memory. Each facet's grammar is now checked before Assimp reads the file.
TEST(FuzzRegression, StlAsciiFacetAssimpRejectedLeakedItsSolid) {
  const fs::path d = scratch();
  kept_finding(d, "mesh_stl/facet-without-vertices-leak.stl", "found.stl");
  auto r = bounded_info_of_part(d, "found.stl");
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("found.stl:16: facet 3: the facet has 0 vertices"), std::string::npos) << r.out;
  const std::vector<std::pair<std::string, std::string>> bad = {
      {ascii_stl({kStlFacet, "normal 0 0 1\n vertex 0 0 0\n vertex 1 0 0"}), "stl:9: facet 2: the facet has 2 vertices"},
      {ascii_stl({"outer loop\n vertex 0 0 0\n vertex 1 0 0\n vertex 0 1 0"}),
       "stl:2: facet 1: 'facet' without 'normal x y z'"},
      {ascii_stl({"normal 0 0 1\n vertex 0 0 0\n vertex 1 0 0\n vertex 0 1 0\n vertex 1 1 0"}),
       "stl:6: facet 1: a fourth vertex (STL facets are triangles)"},
      {ascii_stl({"normal 0 0 1\n vertex 0 0 0\n vertex 1 x 0\n vertex 0 1 0"}),
       "stl:4: facet 1: 'vertex' coordinate 2 is 'x', not a number"},
      {ascii_stl({"normal 0 0\n vertex 0 0 0\n vertex 1 0 0\n vertex 0 1 0"}),
       "stl:3: facet 1: 'normal' coordinate 3 is 'vertex', not a number"},
      {"solid part\n  facet normal 0 0 1\n    vertex 0 0 0\n    vertex 1 0 0\n", "stl:2: facet 1: the file ends inside"},
      {"solid part\n  vertex 0 0 0\n" + ascii_stl({kStlFacet}).substr(11), "stl:2: solid: 'vertex' outside a facet"},
      {ascii_stl({kStlFacet}, std::string(1024, 'n')), "stl:1: solid: a solid name of 1024 characters"},
      {ascii_stl({kStlFacet}) + std::string(1, '\0'), ""},  // after the last solid: ignored, as Assimp does
      {"solid part\n  facet normal 0 0 1\n" + std::string(1, '\0') + "vertex 0 0 0\n", "stl:3: ASCII STL: a NUL byte"},
  };
  for (std::size_t k = 0; k < bad.size(); ++k) {
    const fs::path f = d / ("bad" + std::to_string(k) + ".stl");
    write(f, bad[k].first);
    if (bad[k].second.empty()) {
      EXPECT_EQ(loom::read_mesh_file(f).triangle_count(), 1u) << k;
      continue;
    }
    const std::string e = input_error([&] { loom::read_mesh_file(f); });
    EXPECT_NE(e.find(bad[k].second), std::string::npos) << k << ": " << e;
  }
  // What CAD systems write stays readable: names with spaces, CRLF, '+' and exponents, two
  // solids, a last solid without endsolid.
  write(d / "two.stl", "solid Part 1 exported\r\n  facet normal +0.0e+000 0 1\r\n    outer loop\r\n"
                       "      vertex 0 0 0\r\n      vertex 1.5E+01 0 0\r\n      vertex 0 -1 0\r\n    endloop\r\n"
                       "  endfacet\r\nendsolid Part 1\r\n" +
                           ascii_stl({kStlFacet}, "second").substr(0, ascii_stl({kStlFacet}, "second").find("endsolid")));
  EXPECT_EQ(loom::read_mesh_file(d / "two.stl").triangle_count(), 2u);
  // A binary STL whose 80-byte header starts with "solid" is binary (its size says so).
  std::string bin = "solid but binary";
  bin.resize(80, ' ');
  const std::uint32_t one = 1;
  bin.append(reinterpret_cast<const char*>(&one), 4);
  for (const float v : {0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f})
    bin.append(reinterpret_cast<const char*>(&v), sizeof v);
  bin.append(2, '\0');
  write(d / "bin.stl", bin);
  EXPECT_EQ(loom::read_mesh_file(d / "bin.stl").triangle_count(), 1u);
}

// --- PLY -------------------------------------------------------------------------------------

const std::string kPlyQuadHeader =
    "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
    "element face 2\nproperty list uchar int vertex_indices\nend_header\n";

// Four vertices and a face all on one line, the second face missing: Assimp reads one
// instance per line, took the missing values as 0, and a face of no vertices failed an
// assertion in its triangulation (SIGABRT).
TEST(FuzzRegression, PlyAsciiShortFaceListAborted) {
  const fs::path d = scratch();
  write(d / "short.ply", kPlyQuadHeader + "0 0 0 1 0 0 0 1 0 1 1 1 3 0 1 2\n");
  const auto r = bounded_info_of_part(d, "short.ply");
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("short.ply:10: element vertex instance 0: 16 values on the line, its properties take 3"),
            std::string::npos)
      << r.out;
  const std::string vertices = "0 0 0\n1 0 0\n0 1 0\n1 1 1\n";
  write(d / "missing.ply", kPlyQuadHeader + vertices + "3 0 1 2\n");
  std::string e = input_error([&] { loom::read_mesh_file(d / "missing.ply"); });
  EXPECT_NE(e.find("missing.ply:7: element face: 2 declared, 1 in the file"), std::string::npos) << e;
  write(d / "inf.ply", kPlyQuadHeader + "0 0 0\n1 0 -inf\n0 1 0\n1 1 1\n3 0 1 2\n3 1 2 3\n");
  e = input_error([&] { loom::read_mesh_file(d / "inf.ply"); });
  EXPECT_NE(e.find("inf.ply:11: element vertex instance 1: value '-inf' is not a finite number"), std::string::npos)
      << e;
  write(d / "few.ply", kPlyQuadHeader + vertices + "3 0 1\n3 1 2 3\n");
  e = input_error([&] { loom::read_mesh_file(d / "few.ply"); });
  EXPECT_NE(e.find("few.ply:14: element face instance 0: 3 values on the line, too few for its properties"),
            std::string::npos)
      << e;
  // Whole instances read, a triangle and a quad (three triangles).
  write(d / "ok.ply", kPlyQuadHeader + vertices + "3 0 1 2\n4 0 1 3 2\n");
  EXPECT_EQ(loom::read_mesh_file(d / "ok.ply").triangle_count(), 3u);
}

// Point clouds (libFuzzer, seed 12, within four minutes each). A PCD header with
// "DATA 0" and WIDTH × HEIGHT = 1.8·10¹² points: the unknown encoding was refused only after
// the points had been reserved (ASan: a 42 TB allocation). A binary PLY face whose list
// length, of type float, read 7.7e31: converted to a size before it was checked
// (UBSan: not representable).
TEST(FuzzRegression, PointCloudCountsJudgedBeforeUse) {
  const std::string pcd = "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 44444444110\n"
                          "HEIGHT 40\nVIEWPOINT 0 0 0 1 0 0 0\nDATA 0\n";
  std::string e = input_error([&] { loom::parse_point_cloud(pcd, "big.pcd"); });
  EXPECT_NE(e.find("big.pcd:9: DATA: unknown PCD data encoding '0'"), std::string::npos) << e;
  // The face comes first: the reader steps over it to reach the vertices.
  std::string ply = "ply\nformat binary_little_endian 1.0\nelement face 1\nproperty list float uint vertex_indices\n"
                    "element vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
  for (const float v : {7.68184e31f, 0.f, 0.f, 0.f}) ply.append(reinterpret_cast<const char*>(&v), sizeof v);
  ply += std::string(8, '\0');
  e = input_error([&] { loom::parse_point_cloud(ply, "list.ply"); });
  EXPECT_NE(e.find("truncated data: a list length beyond the bytes left"), std::string::npos) << e;
}

// A .gltf of 37 bytes that is not JSON ("indexarray{..."; libFuzzer, seed 11): both of Assimp's
// glTF importers declined it, Assimp offered it to every other importer by content, and
// the OpenGEX one read past its buffer (ASan heap-buffer-overflow in strncmp). A glTF or GLB
// whose JSON does not parse to an object is refused before Assimp sees it.
TEST(FuzzRegression, GltfThatIsNotJsonWentToAnotherImporter) {
  const fs::path d = scratch();
  kept_finding(d, "mesh_gltf/not-json-other-importer-overread.gltf", "other.gltf");
  const std::string e = input_error([&] { loom::read_mesh_file(d / "other.gltf"); });
  EXPECT_NE(e.find("other.gltf: glTF: the JSON does not parse (not a glTF file)"), std::string::npos) << e;
  write(d / "array.gltf", "[1, 2]");
  const std::string a = input_error([&] { loom::read_mesh_file(d / "array.gltf"); });
  EXPECT_NE(a.find("array.gltf: glTF: the JSON is not an object"), std::string::npos) << a;
}

// A GLB tetrahedron whose primitive a mutation had made a LINE_LOOP and whose index data
// had slipped a byte (indices 65, 512, ... of 4 vertices; libFuzzer, seed 21, 45,816
// executions): Assimp skipped the lines with an index out of range but left their faces
// empty and dereferenced one later (SIGSEGV). Every glTF 2.0 index is now read from its
// buffer (BIN chunk, data URI or file) and checked against the primitive's vertices.
TEST(FuzzRegression, GlbLineLoopIndexOutOfRangeCrashed) {
  const fs::path d = scratch();
  expect_finding_refused(d, "mesh_glb/line-loop-index-out-of-range-segv.glb", "loop.glb",
                         "loop.glb: mesh 0 primitive 0: index 0 of accessor 1 names vertex 65; the primitive has 4");
  // The seed tetrahedron (a base64 data URI) reads; its buffer as a file beside it too.
  const std::string seed = tetra_gltf();
  write(d / "uri.gltf", seed);
  EXPECT_EQ(loom::read_mesh_file(d / "uri.gltf").triangle_count(), 4u);
  std::string text = seed;
  const std::size_t uri = text.find("data:application");
  text.replace(uri, text.find('"', uri) - uri, "tetra.bin");
  write(d / "file.gltf", text);
  std::string bin = loom::testing::tetra_gltf_buffer();
  write(d / "tetra.bin", bin);
  EXPECT_EQ(loom::read_mesh_file(d / "file.gltf").triangle_count(), 4u);
  bin[48 + 22] = 9;
  write(d / "tetra.bin", bin);
  expect_read_refused(d / "file.gltf", text,
                      "mesh 0 primitive 0: index 11 of accessor 1 names vertex 9; the primitive has 4");
  text.replace(text.find("\"count\": 12"), 11, "\"count\": 13");
  expect_read_refused(d / "long.gltf", text,
                      "index accessor 1 (13 elements of 2 bytes, 2 apart, from byte 0) reaches beyond its bufferView's 24 "
                      "bytes");
}

// The GLB tetrahedron with its POSITION attribute and its indices misspelt and mode 5
// (libFuzzer, seed 22, 119,073 executions after the index fix): Assimp sized a triangle
// strip's faces as its 0 vertices − 2, unsigned — 2³² faces, 69 GB.
TEST(FuzzRegression, GlbStripWithoutVerticesAllocated) {
  const fs::path d = scratch();
  expect_finding_refused(d, "mesh_glb/strip-without-vertices-oom.glb", "strip.glb",
                         "strip.glb: mesh 0 primitive 0: mode 5 needs at least 3 vertices; it has 0 (no POSITION "
                         "attribute, no indices)");
  const std::string seed = tetra_gltf();
  std::string fan = seed;
  fan.replace(fan.find("\"mode\": 4"), 9, "\"mode\": 6");
  write(d / "fan.gltf", fan);
  EXPECT_GT(loom::read_mesh_file(d / "fan.gltf").triangle_count(), 0u);
  fan.replace(fan.find("\"count\": 12"), 11, "\"count\": 2");
  expect_read_refused(d / "short.gltf", fan, "mesh 0 primitive 0: mode 6 needs at least 3 vertices; it has 2 indices");
}

// The GLB tetrahedron as a LINE_LOOP whose `attributes` key a mutation had spoilt (CI's
// libFuzzer run, seed 1, 21,509 executions): twelve indices over no POSITION accessor;
// Assimp built the lines over no vertices and dereferenced null (SIGSEGV).
TEST(FuzzRegression, GlbIndicesWithoutPositionsCrashed) {
  const fs::path d = scratch();
  expect_finding_refused(d, "mesh_glb/indices-without-positions-segv.glb", "nopos.glb",
                         "nopos.glb: mesh 0 primitive 0: indices (accessor 1) name vertices, but the primitive has no "
                         "POSITION attribute");
  std::string text = tetra_gltf();
  text.replace(text.find("\"POSITION\": 0"), 13, "\"POSITION\": 7");
  expect_read_refused(d / "far.gltf", text,
                      "mesh 0 primitive 0: POSITION accessor 7 is not an accessor of the file");
}

// A binary tetrahedron whose first vertex begins with the byte 0x0a (libFuzzer, seed 7, after
// the carriage-return fix): Assimp took that newline for the end of the header line, read
// the data one byte off and aborted in its triangulation (SIGABRT in a Release `loom info`).
// Other first bytes are read as written.
TEST(FuzzRegression, PlyBinaryDataStartingWithANewlineAborted) {
  const fs::path d = scratch();
  expect_finding_refused(d, "mesh_ply/binary-data-starts-with-newline-abort.ply", "nl.ply",
                         "nl.ply:10: PLY data: the binary data starts with a newline byte");
  std::string other = slurp(d / "nl.ply");
  other[other.find("end_header\n") + 11] = '\x0b';
  write(d / "other.ply", other);
  try {
    loom::read_mesh_file(d / "other.ply");
  } catch (const InputError& e) {  // its first vertex is far out; only the newline rule is under test
    EXPECT_EQ(std::string(e.what()).find("newline byte"), std::string::npos) << e.what();
  }
}

// `element 5555…5555face 4` (71 fives) in a binary header (libFuzzer, seed 7, 261,673
// executions): Assimp reads the count of an element whose name it does not know from the
// name itself — its leading digits, wrapping at 32 bits: 3,817,748,707 instances, 91 GB
// reserved. The same rule read no instances of an unknown element with data before the
// faces, and took its data for faces.
TEST(FuzzRegression, PlyElementCountReadFromTheNameAllocated) {
  const fs::path d = scratch();
  expect_finding_refused(d, "mesh_ply/element-name-digits-count-oom.ply", "digits.ply",
                         "digits.ply:8: element " + std::string(71, '5') +
                             "face: declares 4 instance(s), but Assimp, which reads PLY meshes for loom, would read "
                             "3817748707");
  const std::string vertices = "0 0 0\n1 0 0\n0 1 0\n1 1 1\n";
  const std::string faces = "3 0 1 2\n3 1 2 3\n";
  const std::string extra = "element normal_cone 2\nproperty float a\n";
  const std::string head = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
                           "property float z\n";
  const std::string face_head = "element face 2\nproperty list uchar int vertex_indices\n";
  // Before the faces: Assimp would read none of its two lines and take them for faces.
  expect_part_refused(d, "before.ply", head + extra + face_head + "end_header\n" + vertices + "7\n8\n" + faces,
                      "before.ply:7: element normal_cone: declares 2 instance(s), but Assimp");
  // After them its data goes unread: the mesh reads as written.
  write(d / "after.ply", head + face_head + extra + "end_header\n" + vertices + faces + "7\n8\n");
  EXPECT_EQ(loom::read_mesh_file(d / "after.ply").triangle_count(), 2u);
  // A name starting with a digit is read as that count even at the end.
  expect_part_refused(d, "five.ply",
                      head + face_head + "element 5cones 2\nproperty float a\nend_header\n" + vertices + faces +
                          "7\n8\n",
                      "five.ply:9: element 5cones: declares 2 instance(s), but Assimp, which reads PLY meshes for loom, "
                      "would read 5");
}

// A binary big-endian tetrahedron with a comment line between its vertex properties
// (libFuzzer, seed 23, 1,154,918 executions after the element-count fix): Assimp ends an
// element's properties at a comment, so its vertices were one float to it and three to
// the pre-check; the data was read apart and Assimp's triangulation aborted (SIGABRT). In
// ASCII the same header gave a mesh of no triangles. A comment after the last property
// stays readable.
TEST(FuzzRegression, PlyCommentBetweenPropertiesAborted) {
  const fs::path d = scratch();
  expect_finding_refused(d, "mesh_ply/comment-between-properties-abort.ply", "comment.ply",
                         "comment.ply:8: property: a property after the comment line 7, inside element vertex");
  const std::string body = "0 0 0\n1 0 0\n0 1 0\n1 1 1\n3 0 1 2\n3 1 2 3\n";
  std::string header = kPlyQuadHeader;
  header.insert(header.find("property float y"), "obj_info scanned\n");
  expect_part_refused(d, "info.ply", header + body, "info.ply:6: property: a property after the obj_info line 5");
  std::string after = kPlyQuadHeader;
  after.insert(after.find("element face"), "comment after the vertex properties\n");
  write(d / "after.ply", after + body);
  EXPECT_EQ(loom::read_mesh_file(d / "after.ply").triangle_count(), 2u);
}

// `comment teloat z\felement face 0000…1557 ...` (libFuzzer, seed 24, 756,621 executions
// after the comment fix): a form feed ends a header line for Assimp, comments included,
// so Assimp read an element of a 32-bit-wrapped count that this check took for part of a
// comment, and read it for longer than the fuzzer's 30 s. A vertical tab in a comment is
// only a byte of the comment to both.
TEST(FuzzRegression, PlyCommentFormFeedHidAnElement) {
  const fs::path d = scratch();
  expect_finding_refused(d, "mesh_ply/comment-form-feed-hides-element-hang.ply", "ff.ply",
                         "ff.ply:3: PLY header: a form feed inside the line (column 17): Assimp ends a line there");
  std::string header = kPlyQuadHeader;
  header.insert(header.find("element vertex"), "comment a\vb\n");
  write(d / "vt.ply", header + "0 0 0\n1 0 0\n0 1 0\n1 1 1\n3 0 1 2\n3 1 2 3\n");
  EXPECT_EQ(loom::read_mesh_file(d / "vt.ply").triangle_count(), 2u);
}

// An ASCII vertex line "0 1\r 1" (libFuzzer, seed 7, after the element fix): Assimp ends a
// data line at a carriage return, read a vertex of two values and a line of one, laid the
// instances out apart from the pre-check and aborted in its triangulation (SIGABRT in a
// Release `loom info`). CRLF files stay readable.
TEST(FuzzRegression, PlyDataCarriageReturnInsideALineAborted) {
  const fs::path d = scratch();
  kept_finding(d, "mesh_ply/data-carriage-return-abort.ply", "cr.ply");
  const auto r = bounded_info_of_part(d, "cr.ply");
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("cr.ply:13: element vertex instance 2: a carriage return inside the line"), std::string::npos)
      << r.out;
  std::string crlf = kPlyQuadHeader + "0 0 0\n1 0 0\n0 1 0\n1 1 1\n3 0 1 2\n3 1 2 3\n";
  for (std::size_t at = crlf.find('\n'); at != std::string::npos; at = crlf.find('\n', at + 2)) crlf.insert(at, "\r");
  write(d / "crlf.ply", crlf);
  EXPECT_EQ(loom::read_mesh_file(d / "crlf.ply").triangle_count(), 2u);
}

// A binary big-endian PLY declaring "element vertex" three times (8 vertices of x, y, z, then
// 8 and 9 of x alone; libFuzzer, seed 7, caught twice within 16,000 runs once the inputs
// before the crash were kept): Assimp keeps one list per element name and wrote the later
// elements' values past the first one's (`free(): invalid pointer`, SIGABRT, in a Release
// `loom info`; under ASan a CHECK on a corrupted chunk at a later free, under another input).
TEST(FuzzRegression, PlyElementDeclaredTwiceCorruptedTheHeap) {
  const fs::path d = scratch();
  expect_finding_refused(d, "mesh_ply/element-declared-twice-heap.ply", "twice.ply",
                         "twice.ply:10: element vertex: declared again (first at line 4)");
  write(d / "ascii.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nelement vertex 2\n"
                         "property float x\nend_header\n0\n1\n2\n");
  const std::string e = input_error([&] { loom::read_mesh_file(d / "ascii.ply"); });
  EXPECT_NE(e.find("ascii.ply:5: element vertex: declared again (first at line 3)"), std::string::npos) << e;
}

// A binary PLY whose vertex property z has the type "floa`" (libFuzzer, from the tetrahedron
// seed): Assimp took the unknown type as zero bytes, read the faces misaligned and aborted
// in its triangulation (ai_assert, SIGABRT in `loom info`). The header check names it.
TEST(FuzzRegression, PlyUnknownPropertyTypeAborted) {
  const fs::path d = scratch();
  std::string body;
  for (const float v : {0.f, 0.f, 0.f, 10.f, 0.f, 0.f, 0.f, 10.f, 0.f, 0.f, 0.f, 10.f})
    body.append(reinterpret_cast<const char*>(&v), sizeof v);
  for (const std::array<std::int32_t, 3>& f : {std::array<std::int32_t, 3>{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}}) {
    body += '\3';
    body.append(reinterpret_cast<const char*>(f.data()), sizeof f);
  }
  const std::string header_before = "ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty float x\n"
                                    "property float y\nproperty ";
  const std::string header_after = " z\nelement face 4\nproperty list uchar int vertex_indices\nend_header\n";
  write(d / "good.ply", header_before + "float" + header_after + body);
  EXPECT_EQ(loom::read_mesh_file(d / "good.ply").triangle_count(), 4u);
  write(d / "typo.ply", header_before + "floa`" + header_after + body);
  const auto r = bounded_info_of_part(d, "typo.ply");
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("typo.ply:6: property: 'floa`' is not a PLY type"), std::string::npos) << r.out;
  write(d / "list.ply", header_before + "float" + " z\nelement face 4\nproperty list uchr int vertex_indices\nend_header\n" + body);
  const std::string e = input_error([&] { loom::read_mesh_file(d / "list.ply"); });
  EXPECT_NE(e.find("list.ply:8: property: 'uchr' is not a PLY type"), std::string::npos) << e;
}

// A face whose vertex list is empty, ASCII or binary (libFuzzer): every count agrees with the
// data, yet Assimp's triangulation aborted on it (SIGABRT in `loom info`).
TEST(FuzzRegression, PlyEmptyFaceAborted) {
  const fs::path d = scratch();
  const std::string head = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                           "property float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n";
  write(d / "ascii.ply", head + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n0\n");
  auto r = bounded_info_of_part(d, "ascii.ply");
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("ascii.ply:14: element face instance 1: a face of no vertices"), std::string::npos) << r.out;
  std::string bin = "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                    "property float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n";
  for (const float v : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) bin.append(reinterpret_cast<const char*>(&v), sizeof v);
  bin += '\0';  // the empty face first
  bin += '\3';
  for (const std::int32_t i : {0, 1, 2}) bin.append(reinterpret_cast<const char*>(&i), sizeof i);
  write(d / "binary.ply", bin);
  r = bounded_info_of_part(d, "binary.ply");
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("binary.ply:7: element face instance 0: a face of no vertices"), std::string::npos) << r.out;
}

// "end_header" followed by a NUL byte (libFuzzer, a long run): the pre-check took it for
// the header's end (strchr finds the NUL as its string's terminator) and checked the data
// from the next newline; Assimp read it from elsewhere, into faces that abort its
// triangulation (ai_assert).
TEST(FuzzRegression, PlyEndHeaderFollowedByNulAborted) {
  const fs::path d = scratch();
  std::string bin = "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                    "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header";
  bin += std::string(4, '\0') + "\n";
  for (const float v : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) bin.append(reinterpret_cast<const char*>(&v), sizeof v);
  bin += '\3';
  for (const std::int32_t i : {0, 1, 2}) bin.append(reinterpret_cast<const char*>(&i), sizeof i);
  write(d / "nul.ply", bin);
  const auto r = bounded_info_of_part(d, "nul.ply");
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("nul.ply:9: PLY header: holds a NUL byte"), std::string::npos) << r.out;
}

// OFF counts with a letter, a comma or a NUL after the digits (libFuzzer): the pre-check
// could not parse them and left the file to Assimp, which read the leading digits and
// allocated 10⁹ faces (16 GB) before reading one.
TEST(FuzzRegression, OffCountWithTrailingBytesAllocatedByItsDigits) {
  const fs::path d = scratch();
  const std::pair<std::string, std::string> cases[] = {
      {"1000000000x", "1000000000x"}, {"1000000000,", "1000000000,"}, {std::string("10\0", 3), "10\\x00"}};
  for (const auto& [bad, shown] : cases) {
    write(d / "bad.off", "OFF\n4 " + bad + " 0\n");
    const std::string e = input_error([&] { loom::read_mesh_file(d / "bad.off"); });
    EXPECT_NE(e.find("bad.off:2: OFF header: face count '" + shown + "' is not a count"), std::string::npos) << e;
  }
  write(d / "v.off", "OFF 4x 1 0\n");
  const std::string e = input_error([&] { loom::read_mesh_file(d / "v.off"); });
  EXPECT_NE(e.find("v.off:1: OFF header: vertex count '4x' is not a count"), std::string::npos) << e;
}

// An OFF comment ended by a lone carriage return (libFuzzer, a long run): Assimp ends the
// line there and read "2222222224 6" after it as the counts, allocating 26 GB; the
// pre-check took the whole line for the comment and checked the "0 3" below instead.
TEST(FuzzRegression, OffCommentEndedByACarriageReturnHidTheCounts) {
  const fs::path d = scratch();
  write(d / "cr.off", std::string("OFF\n#`\r2222222224 6\n0 3\n"));
  const std::string e = input_error([&] { loom::read_mesh_file(d / "cr.off"); });
  EXPECT_NE(e.find("cr.off:3: OFF header: declares 2222222224 vertices"), std::string::npos) << e;
  // Windows line endings stay one line end each: a valid triangle reads, line numbers hold.
  write(d / "crlf.off", "OFF\r\n3 1 0\r\n0 0 0\r\n1 0 0\r\n0 1 0\r\n3 0 1 2\r\n");
  EXPECT_EQ(loom::read_mesh_file(d / "crlf.off").triangle_count(), 1u);
  write(d / "crlf-bad.off", "OFF\r\n3 1 0\r\n0 0 0\r\n1 0 0\r\n0 1 0\r\n3 0 1 7\r\n");
  const std::string e2 = input_error([&] { loom::read_mesh_file(d / "crlf-bad.off"); });
  EXPECT_NE(e2.find("crlf-bad.off:6: face 0: vertex index 7"), std::string::npos) << e2;
}

// A port direction that is not unit (dx = 5, dy = -2) read, written at full precision and
// read again (libFuzzer, the harness XML round trip): normalised a second time it moved in
// its last bits, so routed.xml read back was not the harness that was written.
TEST(FuzzRegression, PortDirectionNormalisedTwiceMovedInItsLastBits) {
  const std::string xml =
      "<harness name='h' units='mm'><attributes><cable id='C'><electrical><port id='A'/><port id='B'/>"
      "</electrical><physical diameter='2'/></cable></attributes><structure>"
      "<port id='A' x='0' y='0' z='0' dx='5' dy='-2' dz='0'/><port id='B' x='100' y='0' z='0' dx='-1' dy='0' dz='0'/>"
      "<segment from='A' to='B'/></structure></harness>";
  const loom::Harness h = loom::parse_harness_xml(xml, "h.xml");
  const std::string written = loom::harness_to_xml(h);
  const loom::Harness again = loom::parse_harness_xml(written, "written.xml");
  EXPECT_EQ(again.ports[0].direction, h.ports[0].direction) << loom::full_precision(again.ports[0].direction) << " vs "
                                                              << loom::full_precision(h.ports[0].direction);
  EXPECT_EQ(loom::harness_to_xml(again), written);
  EXPECT_NEAR(h.ports[0].direction.norm(), 1.0, 1e-15);
}

// Every minimised input of tests/fuzz/findings: a mesh as the one part of a scene, a harness
// XML as its harness; `loom info` refuses each, exit 2, naming the file.
TEST(FuzzRegression, EveryKeptFindingIsRefusedNamingTheFile) {
  const fs::path findings = fs::path(LOOM_SOURCE_DIR) / "tests/fuzz/findings";
  int seen = 0;
  for (const auto& folder : fs::directory_iterator(findings)) {
    if (!folder.is_directory()) continue;
    for (const auto& entry : fs::directory_iterator(folder.path())) {
      const fs::path d = scratch() / folder.path().filename();
      fs::create_directories(d);
      const std::string name = entry.path().filename().string();
      fs::copy_file(entry.path(), d / name);
      const bool harness = entry.path().extension() == ".xml" || entry.path().extension() == ".kbl";
      write(d / "scene.toml", harness ? "[scene]\n[harness]\nfile = '" + name + "'\n"
                                      : "[scene]\n[[part]]\nfile = '" + name + "'\n");
      const auto r = run_bounded("info " + (d / "scene.toml").string() + " --quiet");
      EXPECT_EQ(r.status, 2) << name << ": " << r.out;
      EXPECT_NE(r.out.find(name), std::string::npos) << r.out;
      ++seen;
    }
  }
  EXPECT_GE(seen, 10);
}

// A processing instruction with a malformed target (<?ele'na ...?>, libFuzzer from a real
// KBL's header): the reader's parse skipped it, the writer's, which keeps instructions,
// refused it, and writing routed.kbl threw past the command's error handling.
TEST(FuzzRegression, KblMalformedInstructionReadButNotWritable) {
  const std::string kbl = slurp(fs::path(LOOM_TEST_DATA) / "formboard/mini-2d.kbl");
  const std::size_t decl_end = kbl.find("?>") + 2;
  ASSERT_NE(decl_end, std::string::npos + 2);
  const std::string bad = kbl.substr(0, decl_end) + "\n<?ele'na version=\"2.8\"?>" + kbl.substr(decl_end);
  const std::string e = input_error([&] { loom::parse_harness_kbl(bad, "h.kbl"); });
  EXPECT_NE(e.find("h.kbl:2: malformed XML"), std::string::npos) << e;
  // A well-formed instruction, as CAD exports write them, is read.
  const std::string good = kbl.substr(0, decl_end) + "\n<?pc checksum=\"695947884\"?>" + kbl.substr(decl_end);
  EXPECT_EQ(loom::parse_harness_kbl(good, "h.kbl").cables.size(), loom::parse_harness_kbl(kbl, "h.kbl").cables.size());
}

// "end_headerrty" where end_header belongs (libFuzzer): the pre-check found the substring
// and passed the file; Assimp, which wants end_header as a word of its own, read on past
// the end of the file forever.
TEST(FuzzRegression, PlyEndHeaderRunIntoTheNextWordHung) {
  const fs::path d = scratch();
  write(d / "run.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nend_headerrty float y\n1\n");
  const auto r = bounded_info_of_part(d, "run.ply");
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("run.ply:6: end_header: PLY header does not end"), std::string::npos) << r.out;
  // Blanks before it and a carriage return after it still end the header.
  write(d / "ok.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                      "property float z\nelement face 1\nproperty list uchar int vertex_indices\n  end_header\r\n"
                      "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  EXPECT_EQ(loom::read_mesh_file(d / "ok.ply").triangle_count(), 1u);
}

// A mesh PLY whose header never reaches end_header: Assimp's line reader spun forever (and
// read out of bounds, SIGSEGV, with a NUL after the header's last line).
TEST(FuzzRegression, PlyMeshUnterminatedHeaderHung) {
  const fs::path d = scratch();
  write(d / "open.ply", "ply\nformat ascii 1.0\n");
  auto r = bounded_info_of_part(d, "open.ply");
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("open.ply:2: end_header: PLY header does not end (truncated file?)"), std::string::npos)
      << r.out;
  write(d / "bin.ply", "ply\nformat binary_little_endian 1.0\nelement vertex 3");
  r = bounded_info_of_part(d, "bin.ply");
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("bin.ply:3: end_header: PLY header does not end"), std::string::npos) << r.out;
  write(d / "nul.ply", std::string("ply\nformat ascii 1.0\n\0", 22));
  r = bounded_info_of_part(d, "nul.ply");
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("nul.ply:3: PLY header: holds a NUL byte"), std::string::npos) << r.out;
}

// "format binary_big_enproperty uint16 ..." (libFuzzer): the pre-check could not parse the
// format, left the file to Assimp, which read the header its own way, misaligned the data
// and aborted in its triangulation (ai_assert numOut != mNumFaces). Every header line the
// check does not understand is refused now, naming its line.
TEST(FuzzRegression, PlyFormatLineNotParsedAborted) {
  const fs::path d = scratch();
  const std::string vertices = "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n";
  const std::string faces = "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
  const std::string body = "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  const std::pair<std::string, std::string> cases[] = {
      {"ply\nformat binary_big_enproperty uint16 x\n" + vertices + faces,
       "f.ply:2: format: 'binary_big_enproperty' is not a PLY format"},
      {"ply\nformat ascii 1.0\n" + vertices + "pproperty int8 w\n" + faces, "f.ply:7: pproperty: 'pproperty' is not a PLY header keyword"},
      {"ply\n" + vertices + faces, "f.ply:1: format: the PLY header has no format line"},
      {"ply\nformat ascii 1.0\nelement vertex\n" + faces, "f.ply:3: element: expected 'element NAME COUNT'"},
      {"ply\nformat ascii 1.0\nproperty float x\n" + vertices + faces, "f.ply:3: property: a property before any element"},
  };
  for (const auto& [text, expected] : cases) expect_part_refused(d, "f.ply", text + body, expected);
  // Comments and obj_info lines anywhere in the header are read as before.
  write(d / "ok.ply", "ply\nformat ascii 1.0\ncomment made by hand\n" + vertices + "obj_info a triangle\n" + faces + body);
  EXPECT_EQ(loom::read_mesh_file(d / "ok.ply").triangle_count(), 1u);
}

// "4294945910  255OBFF" with no magic and only comments after it (libFuzzer): the pre-check
// needed three tokens to check the counts and let the file through; Assimp took 4294945910
// as the vertex count and allocated 3.5 GB.
TEST(FuzzRegression, OffCountsWithoutMagicAllocated) {
  const fs::path d = scratch();
  expect_part_refused(d, "a.off", "4294945910  255OBFF\n# OOFF\n# STTOFF\n# ",
                      "a.off:1: OFF header: face count '255OBFF' is not a count");
  expect_part_refused(d, "b.off", "4294945910\n",
                      "b.off:1: OFF header: expected [magic] vertex and face counts, found 1 token(s)");
  expect_part_refused(d, "c.off", "OFF\n", "c.off:1: OFF header: expected [magic] vertex and face counts, found 0 token(s)");
}

// No OFF line and a first count starting with 4 (libFuzzer, a long run): Assimp's reader
// took that 4 for the homogeneous flag of a "4OFF" magic, read the counts one token on
// ("642949672tetrahedron" as 642949672 faces) and allocated 10 GB; the pre-check read the
// counts from the first token. A "nOFF" magic has a dimension before the counts.
TEST(FuzzRegression, OffWithoutMagicLeadingFourShiftedTheCounts) {
  const fs::path d = scratch();
  expect_part_refused(d, "four.off", "\n4 4 642949672tetrahedron\n4 4 6429496729 50 0\n",
                      "four.off:2: OFF header: no OFF line, and a vertex count starting with 4");
  // With the OFF line the same counts read as a tetrahedron would.
  write(d / "tetra.off", "OFF\n4 4 6\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n");
  EXPECT_EQ(loom::read_mesh_file(d / "tetra.off").triangle_count(), 4u);
  // nOFF: dimension 3, then the counts.
  expect_part_refused(d, "n.off", "nOFF\n3\n4 4000000000 0\n", "n.off:3: OFF header: declares 4 vertices and 4000000000 faces");
}

/// An ASCII PLY of one triangle whose header has `y_line` (line 5) for the y property and
/// `list_line` (line 8) for the face list.
std::string ascii_ply_triangle(const std::string& y_line, const std::string& list_line) {
  return "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n" + y_line + "\nproperty float z\nelement face 1\n" +
         list_line + "\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
}

// A PLY list whose count type is float (libFuzzer, a long run): Assimp read the counts as
// floats, the pre-check as integers, and the two walked different faces; Assimp's
// triangulation aborted (ai_assert).
TEST(FuzzRegression, PlyListWithAFloatCountAborted) {
  expect_part_refused(scratch(), "f.ply", ascii_ply_triangle("property float y", "property list float int vertex_indices"),
                      "f.ply:8: property: a list's count type must be an integer type");
}

// "property\ffloat y" (libFuzzer, the CI-length run): Assimp separates header words by
// spaces and tabs only and skipped the line, the pre-check read a property; the data was
// laid out apart and Assimp's triangulation aborted.
TEST(FuzzRegression, PlyHeaderFormFeedSeparatorAborted) {
  expect_part_refused(scratch(), "ff.ply", ascii_ply_triangle("property\ffloat y", "property list uchar int vertex_indices"),
                      "ff.ply:5: PLY header: words separated by a form feed or vertical tab (byte 12)");
}

// A binary face naming vertex −67,108,867 of 4 (libFuzzer, seed 7): Assimp took the index as
// given and corrupted its heap (an ASan CHECK on a freed chunk). Every face index is checked
// against the vertex count now, binary (signed and unsigned types) and ASCII.
TEST(FuzzRegression, PlyFaceIndexOutsideTheVerticesCorruptedTheHeap) {
  const fs::path d = scratch();
  const std::string head = "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
                           "property float y\nproperty float z\nelement face 1\nproperty list uchar ";
  std::string verts;
  for (const float v : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) verts.append(reinterpret_cast<const char*>(&v), 4);
  auto face = [](std::initializer_list<std::int32_t> ids) {
    std::string f(1, static_cast<char>(ids.size()));
    for (const std::int32_t i : ids) f.append(reinterpret_cast<const char*>(&i), 4);
    return f;
  };
  expect_part_refused(d, "neg.ply", head + "int vertex_indices\nend_header\n" + verts + face({0, -67108867, 2}),
                      "neg.ply:7: element face instance 0: vertex index -67108867 is not one of the 3 vertices");
  expect_part_refused(d, "big.ply", head + "uint vertex_indices\nend_header\n" + verts + face({0, 1, -2}),
                      "big.ply:7: element face instance 0: vertex index 4294967294 is not one of the 3 vertices");
  expect_part_refused(d, "three.ply", head + "int vertex_index\nend_header\n" + verts + face({0, 1, 3}),
                      "vertex index 3 is not one of the 3 vertices");
  std::string ascii = ascii_ply_triangle("property float y", "property list uchar int vertex_indices");
  ascii.replace(ascii.rfind("3 0 1 2"), 7, "3 0 -1 2");
  expect_part_refused(d, "a.ply", ascii, "a.ply:13: element face instance 0: vertex index -1 is not one of the 3 vertices");
}

// "property float \rz" (libFuzzer, seed 7): Assimp ends a header line at a carriage return
// and read a property with no name and a line "z", the pre-check "property float z"; the
// data was laid out apart and Assimp's triangulation aborted. A comment hides nothing either.
TEST(FuzzRegression, PlyHeaderCarriageReturnInsideALineAborted) {
  const fs::path d = scratch();
  expect_part_refused(d, "cr.ply", ascii_ply_triangle("property float \rz", "property list uchar int vertex_indices"),
                      "cr.ply:5: PLY header: a carriage return inside the line (byte 13 at column 16)");
  std::string comment = ascii_ply_triangle("property float y", "property list uchar int vertex_indices");
  comment.insert(comment.find("element vertex"), "comment a\relement vertex 9\n");
  expect_part_refused(d, "c.ply", comment, "c.ply:3: PLY header: a carriage return inside the line");
  // CRLF line ends stay readable.
  std::string crlf = ascii_ply_triangle("property float y", "property list uchar int vertex_indices");
  for (std::size_t at = crlf.find('\n'); at != std::string::npos; at = crlf.find('\n', at + 2)) crlf.insert(at, "\r");
  write(d / "crlf.ply", crlf);
  EXPECT_EQ(bounded_info_of_part(d, "crlf.ply").status, 0);
}

// A face whose vertex count is beyond 64 bits (libFuzzer): the count saturated to 2^64 − 1,
// the check's "count + 1 > words" wrapped to 0 and it read past the face's words (ASan
// heap-buffer-overflow in the pre-check itself).
TEST(FuzzRegression, OffFaceVertexCountWrappedPastItsWords) {
  const fs::path d = scratch();
  expect_part_refused(d, "f.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n99999999999999999999999 0 1 2\n", "f.off");
}

// Four bytes before "ply" (libFuzzer): the pre-check took the file for something else and
// left it to Assimp, which found the magic a few bytes in and hung reading the header.
TEST(FuzzRegression, PlyMagicNotAtStartHung) {
  const fs::path d = scratch();
  expect_part_refused(d, "m.ply", std::string("\0\0\xc0\x7f", 4) + "ply\nformat ascii 1.0\nelement vertex 1\nend_header\n0\n",
                      "m.ply:1: PLY header: the file does not start with 'ply'");
}

/// A GLB (glTF 2.0 binary) of one triangle: `json` in the JSON chunk, `bin` in the BIN chunk,
/// each padded to 4 bytes as the format asks.
std::string glb_file(std::string json, std::string bin) {
  while (json.size() % 4) json += ' ';
  while (bin.size() % 4) bin += '\0';
  auto u32 = [](std::uint32_t v) { return std::string(reinterpret_cast<const char*>(&v), 4); };
  const std::uint32_t total = static_cast<std::uint32_t>(12 + 8 + json.size() + 8 + bin.size());
  return "glTF" + u32(2) + u32(total) + u32(static_cast<std::uint32_t>(json.size())) + "JSON" + json +
         u32(static_cast<std::uint32_t>(bin.size())) + std::string("BIN\0", 4) + bin;
}

// A GLB whose header declares 4,294,966,532 bytes and whose JSON chunk 4.1 GB (libFuzzer):
// the pre-check found no JSON to check and let the file through; Assimp allocated the chunk
// by its declared length. The container is checked first now, and every buffer's byteLength
// against the bytes behind it.
TEST(FuzzRegression, GlbChunkLengthBeyondFileAllocated) {
  const fs::path d = scratch();
  std::string bin;
  for (const float v : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) bin.append(reinterpret_cast<const char*>(&v), 4);
  auto json = [](int byte_length) {
    return R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],)"
           R"("meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],"buffers":[{"byteLength":)" +
           std::to_string(byte_length) + R"(}],"bufferViews":[{"buffer":0,"byteLength":36}],)"
           R"("accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","max":[1,1,0],"min":[0,0,0]}]})";
  };
  const std::string good = glb_file(json(36), bin);
  write(d / "good.glb", good);
  EXPECT_EQ(loom::read_mesh_file(d / "good.glb").triangle_count(), 1u);
  struct Case {
    std::string bytes, expected;
  };
  std::string total_too_long = good, chunk_too_long = good, not_json_first = good;
  total_too_long[8] = '\xff';  // total length: low byte
  total_too_long[9] = '\xff';
  chunk_too_long[14] = '\x7f';  // JSON chunk length: third byte
  not_json_first.replace(16, 4, "JSOX");
  const Case cases[] = {
      {total_too_long, "g.glb: GLB header: declares 65535 bytes, the file holds " + std::to_string(good.size())},
      {chunk_too_long, "g.glb: GLB chunk 0: declares "},
      {not_json_first, "g.glb: GLB chunk 0: the first chunk is not JSON"},
      {glb_file(json(4096), bin), "g.glb: buffer 0: byteLength 4096 is more than the BIN chunk's 36 bytes"},
      {good.substr(0, 10), "g.glb: GLB header: not a binary glTF file"},
  };
  for (const Case& c : cases) expect_part_refused(d, "g.glb", c.bytes, c.expected);
}

// --- STEP ------------------------------------------------------------------------------------

// The wing section's actuator envelope without the DIRECTION its first VECTOR refers to:
// OpenCASCADE's transfer followed the null reference (SIGSEGV).
TEST(FuzzRegression, StepVectorMissingDirectionCrashed) {
  const fs::path d = scratch();
  const std::string full = slurp(fs::path(LOOM_SOURCE_DIR) / "examples/wing-section/actuator-envelope.step");
  const std::string gone = "#91 = DIRECTION('',(0.,0.,1.));\n";
  const std::size_t at = full.find(gone);
  ASSERT_NE(at, std::string::npos);
  ASSERT_NE(full.find("#90 = VECTOR('',#91,1.);"), std::string::npos);
  std::string text = full;
  text.erase(at, gone.size());
  write(d / "v.step", text);
  // The line of #90: counted in the file written.
  const int line90 = static_cast<int>(std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(
                                                                                  text.find("#90 = VECTOR")),
                                                 '\n')) + 1;
  write(d / "scene.toml", "[scene]\n[[part]]\nfile = 'v.step'\n");
  const auto r = run_bounded("info " + (d / "scene.toml").string() + " --quiet");
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("v.step:" + std::to_string(line90) +
                       ": entity #90 (VECTOR): refers to #91, which the file does not define"),
            std::string::npos)
      << r.out;
  // A reference inside a string or a comment is no reference.
  write(d / "s.step", "ISO-10303-21;\nHEADER;\nENDSEC;\nDATA;\n#1 = CARTESIAN_POINT('#7 /* x',(0.,0.,0.));\n"
                      "/* #2 = VECTOR('',#8,1.); */\n#3 = VECTOR('',#9,1.);\nENDSEC;\nEND-ISO-10303-21;\n");
  loom::TessellationParams tp;
  const std::string e = input_error([&] { loom::read_cad_file(d / "s.step", tp, false); });
  EXPECT_NE(e.find("s.step:7: entity #3 (VECTOR): refers to #9, which the file does not define"), std::string::npos)
      << e;
}

// --- scene TOML ------------------------------------------------------------------------------

// A table header 60,000 keys deep: toml++ bounds arrays and inline tables but not dotted
// keys, and built and destroyed the tables recursively (SIGSEGV).
TEST(FuzzRegression, TomlDeepDottedTableCrashed) {
  const fs::path d = scratch();
  auto header = [](std::size_t keys) {
    std::string h = "[a";
    for (std::size_t i = 1; i < keys; ++i) h += ".a";
    return h + "]\n";
  };
  write(d / "deep.toml", "[scene]\n" + header(60000));
  auto r = run_bounded("info " + (d / "deep.toml").string());
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("deep.toml:2: nesting deeper than 256 levels"), std::string::npos) << r.out;
  // The limit is exact: 256 keys pass the check (and meet loom's unknown key), 257 do not,
  // and a dotted key adds to the header's depth like inline tables and arrays do.
  EXPECT_NO_THROW(loom::check_toml_nesting("[scene]\n" + header(256), "t.toml"));
  std::string e = input_error([&] { loom::check_toml_nesting("[scene]\n" + header(257), "t.toml"); });
  EXPECT_NE(e.find("t.toml:2: nesting deeper than 256"), std::string::npos) << e;
  e = input_error([&] { loom::check_toml_nesting(header(200) + "\n# c\nb" + header(57).substr(2, 2 * 56) + " = 1\n", "t.toml"); });
  EXPECT_NE(e.find("t.toml:4: nesting deeper"), std::string::npos) << e;
  e = input_error(
      [&] { loom::check_toml_nesting(header(250) + "x = { y = [[[[[[1]]]]]] }\n", "t.toml"); });
  EXPECT_NE(e.find("t.toml:2: nesting deeper"), std::string::npos) << e;
  // Dots in values and strings are no keys: 10,000 floats and a dotted string pass.
  std::string floats = "v = [";
  for (int i = 0; i < 10000; ++i) floats += "1.5, ";
  EXPECT_NO_THROW(loom::check_toml_nesting(floats + "]\ns = \"" + header(1000) + "\"\n", "t.toml"));
}

const char* kClearHarness = R"(<harness name="h" units="mm">
  <attributes>
    <cable id="C1"><electrical><port id="J1"/><port id="J2"/></electrical>
      <physical diameter="2" min_bend_radius="10"/></cable>
  </attributes>
  <structure>
    <port id="J1" x="-20" y="5" z="30" dx="1" dy="0" dz="0"/>
    <port id="J2" x="30" y="5" z="30" dx="-1" dy="0" dz="0"/>
    <segment from="J1" to="J2"/>
  </structure>
</harness>
)";

// routing.planner = 'nope' was checked only when route got to plan, in a message naming no
// file, and `loom info` accepted it.
TEST(FuzzRegression, TomlPlannerErrorNamedNoFile) {
  const fs::path d = scratch();
  write(d / "box.obj", "v 0 0 0\nv 10 0 0\nv 0 10 0\nv 0 0 10\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n");
  write(d / "h.xml", kClearHarness);
  write(d / "scene.toml", "[scene]\n[[part]]\nfile = 'box.obj'\n[harness]\nfile = 'h.xml'\n[routing]\n"
                          "planner = 'nope'\n");
  for (const std::string cmd : {"info", "route"}) {
    const auto r = run_bounded(cmd + " " + (d / "scene.toml").string() +
                               (cmd == "route" ? " --iterations 10 --out " + (d / "out").string() : ""));
    EXPECT_EQ(r.status, 2) << cmd << ": " << r.out;
    EXPECT_NE(r.out.find("scene.toml:7: routing.planner: unknown planner 'nope'; valid planners: "), std::string::npos)
        << cmd << ": " << r.out;
    EXPECT_NE(r.out.find("rrtconnect"), std::string::npos) << r.out;
  }
}

// --- harness XML -----------------------------------------------------------------------------

std::string with(const std::string& text, const std::string& from, const std::string& to) {
  std::string s = text;
  const auto at = s.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return at == std::string::npos ? s : s.replace(at, from.size(), to);
}

// A root element named with a byte that is not UTF-8 (<h\x8f/>, libFuzzer) and no 'name'
// attribute: the harness took the element's name unchecked and wrote it into a routed.xml
// that the reader then refused.
TEST(FuzzRegression, XmlRootNameNotUtf8WasWrittenUnreadable) {
  const std::string e =
      input_error([] { loom::parse_harness_xml("<?xml version=\"1.0\"?>\n<h\x8f/>\n", "h.xml"); });
  EXPECT_NE(e.find("h.xml:2: <h\x8f>: the root element's name, the harness name without a 'name' attribute, is not valid UTF-8"),
            std::string::npos)
      << e;
  // Named by its attribute, the element's name does not matter.
  EXPECT_NO_THROW(loom::parse_harness_xml("<?xml version=\"1.0\"?>\n<h\x8f name=\"W\"/>\n", "h.xml"));
}

// x=" " (or a tab, two blanks) read as 0: strtod converted nothing and the trailing blanks
// were skipped before that was asked.
TEST(FuzzRegression, XmlBlankNumberReadAsZero) {
  for (const std::string blank : {" ", "\t", "  "}) {
    std::string e = input_error(
        [&] { loom::parse_harness_xml(with(kClearHarness, "x=\"-20\"", "x=\"" + blank + "\""), "h.xml"); });
    EXPECT_NE(e.find("h.xml:7: <port id=\"J1\">: attribute 'x' is empty"), std::string::npos) << e;
    e = input_error([&] {
      loom::parse_harness_xml(with(kClearHarness, "min_bend_radius=\"10\"", "min_bend_radius=\"" + blank + "\""),
                              "h.xml");
    });
    EXPECT_NE(e.find("h.xml:4: <physical>: attribute 'min_bend_radius' is empty"), std::string::npos) << e;
  }
  // Blanks around a number are still the number.
  const loom::Harness h = loom::parse_harness_xml(with(kClearHarness, "x=\"-20\"", "x=\" -20 \""), "h.xml");
  EXPECT_EQ(h.ports[0].position.x(), -20.0);
}

// A <pt> nested in a <pt> (a point through the box: a clash) and <junk/> inside <port> and
// <physical> were dropped unread: the audit said clean.
TEST(FuzzRegression, XmlLeafChildrenIgnored) {
  const std::string path = R"(<segment from="J1" to="J2">
      <path interp="polyline"><pt x="0" y="5" z="30"><pt x="5" y="5" z="-50"/></pt></path>
    </segment>)";
  std::string e = input_error([&] {
    loom::parse_harness_xml(with(kClearHarness, "<segment from=\"J1\" to=\"J2\"/>", path), "h.xml");
  });
  EXPECT_NE(e.find("h.xml:10: <pt>: unexpected element <pt> inside <pt>"), std::string::npos) << e;
  e = input_error([&] {
    loom::parse_harness_xml(with(kClearHarness, "<port id=\"J1\"/>", "<port id=\"J1\"><junk/></port>"), "h.xml");
  });
  EXPECT_NE(e.find("h.xml:3: <junk>: unexpected element <junk> inside <port>"), std::string::npos) << e;
  e = input_error([&] {
    loom::parse_harness_xml(with(kClearHarness, "min_bend_radius=\"10\"/>", "min_bend_radius=\"10\"><junk/></physical>"),
                            "h.xml");
  });
  EXPECT_NE(e.find("h.xml:4: <junk>: unexpected element <junk> inside <physical>"), std::string::npos) << e;
  e = input_error([&] {
    loom::parse_harness_xml(with(kClearHarness, "dz=\"0\"/>", "dz=\"0\"><cp x=\"0\" y=\"0\" z=\"0\"/></port>"), "h.xml");
  });
  EXPECT_NE(e.find("h.xml:7: <cp>: unexpected element <cp> inside <port>"), std::string::npos) << e;
  e = input_error([&] {
    loom::parse_harness_xml(with(kClearHarness, "<attributes>", "<attributes>stray words"), "h.xml");
  });
  EXPECT_NE(e.find("h.xml:2: <attributes>: unexpected text 'stray words' inside <attributes>"), std::string::npos)
      << e;
}

}  // namespace
