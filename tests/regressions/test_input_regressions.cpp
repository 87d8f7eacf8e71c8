// One test per bad-input bug (every input kind truncated, empty, garbage, huge, non-finite,
// non-UTF-8, deeply nested; every option given bad values). Each input is written out in
// full, and each test fails on a loom that mishandles it. The readers' own catalogues of checks are in tests/core/test_*_io.cpp,
// tests/routing/scan/test_point_cloud_io.cpp and tests/app/test_cli.cpp (CliOptions, CliRender,
// CliRoutes, CliNames).
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>
#include <string>

#include <sys/stat.h>
#include <sys/wait.h>

#include "core/error.hpp"
#include "core/harness_topology.hpp"
#include "core/io/harness_xml.hpp"
#include "core/io/mesh_read.hpp"
#include "core/io/scene_load.hpp"
#include "core/io/tessellation_cache.hpp"
#include "routing/curve/cable_geometry.hpp"
#include "core/io/point_cloud_io.hpp"
#include "common/run_loom.hpp"
#include "common/test_files.hpp"
#include "common/shared_data.hpp"

namespace {

namespace fs = std::filesystem;
using loom::InputError;

/// A fresh scratch directory for the running test.
fs::path scratch() { return loom::testing::scratch_dir("loom_input_regression_"); }

void write(const fs::path& p, const std::string& bytes) { loom::testing::write_file(p, bytes); }

using loom::testing::input_error;
using loom::testing::slurp;

/// Runs `loom ARGS` (stderr merged) and returns exit status and output.
std::pair<int, std::string> loom(const std::string& args) {
  auto r = loom::testing::run_loom(args);
  return {r.status, std::move(r.out)};
}

const std::string kHarness = R"(<harness name="h" units="mm">
  <attributes>
    <cable id="C1"><electrical><port id="J1"/><port id="J2"/></electrical>
      <physical type="t" color="red" diameter="2" min_bend_radius="10"/></cable>
  </attributes>
  <structure>
    <port id="J1" x="-20" y="5" z="5" dx="1" dy="0" dz="0"/>
    <port id="J2" x="30" y="5" z="5" dx="-1" dy="0" dz="0"/>
    <segment from="J1" to="J2"/>
  </structure>
</harness>
)";

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return at == std::string::npos ? text : text.replace(at, from.size(), to);
}

const std::string kPlyTriangle =
    "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
    "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n";

// Assimp's PLY reader passes a negative face index on; its post-processing (triangulate,
// join vertices) then read the vertex array out of bounds: SIGSEGV in `loom info`.
TEST(Regression, PlyFaceIndexBeyondTheVerticesCrashedAssimp) {
  const fs::path d = scratch();
  write(d / "m.ply", kPlyTriangle + "3 0 1 -5\n");
  const std::string e = input_error([&] { loom::read_mesh_file(d / "m.ply"); });
  EXPECT_NE(e.find("m.ply:13: element face instance 0: vertex index -5 is not one of the 3 vertices (0..2)"),
            std::string::npos)
      << e;
}

// Assimp's OFF reader replaced a face index beyond the vertices by the last vertex (an error
// in a log nobody sees): `loom info` showed a part of one triangle that is not in the file.
TEST(Regression, OffFaceIndexBeyondTheVerticesWasClampedSilently) {
  const fs::path d = scratch();
  write(d / "m.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 77\n");
  const std::string e = input_error([&] { loom::read_mesh_file(d / "m.off"); });
  EXPECT_NE(e.find("m.off:6: face 0: vertex index 77 is not one of the 3 vertices (0..2)"), std::string::npos) << e;
}

// Assimp reads COLLADA <node> hierarchies recursively: 20,000 nested nodes (a 260 kB file)
// overflowed the stack (SIGSEGV); glTF node chains did the same at 20,000.
TEST(Regression, DeepMeshNodeNestingOverflowedTheStack) {
  const fs::path d = scratch();
  std::string dae = R"(<?xml version="1.0"?><COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" )"
                    R"(version="1.4.1"><library_visual_scenes><visual_scene id="s">)";
  for (int i = 0; i < 20000; ++i) dae += "<node>";
  for (int i = 0; i < 20000; ++i) dae += "</node>";
  dae += R"(</visual_scene></library_visual_scenes><scene><instance_visual_scene url="#s"/></scene></COLLADA>)";
  write(d / "deep.dae", dae);
  std::string e = input_error([&] { loom::read_mesh_file(d / "deep.dae"); });
  EXPECT_NE(e.find("deep.dae:1: <node>: nested more than 1000 levels deep"), std::string::npos) << e;
  std::string nodes;
  for (int i = 0; i < 25000; ++i) nodes += "{\"children\":[" + std::to_string(i + 1) + "]},";
  write(d / "deep.gltf", R"({"asset":{"version":"2.0"},"nodes":[)" + nodes +
                             R"({}],"scenes":[{"nodes":[0]}],"scene":0})");
  e = input_error([&] { loom::read_mesh_file(d / "deep.gltf"); });
  EXPECT_NE(e.find("nested more than 1000 levels deep"), std::string::npos) << e;
}

// A PLY header declaring 4e9 vertices in a 200-byte file: Assimp allocated them up front
// (48 GB; "cannot read mesh: std::bad_alloc" where memory ran short, and a machine with
// that much memory was swept clean). The counts are checked against the file's size.
TEST(Regression, MeshHeaderCountsWereAllocatedUnchecked) {
  const fs::path d = scratch();
  write(d / "m.ply", replaced(kPlyTriangle, "element vertex 3", "element vertex 4000000000") + "3 0 1 2\n");
  const std::string e = input_error([&] { loom::read_mesh_file(d / "m.ply"); });
  EXPECT_NE(e.find("m.ply:3: element vertex: declares 4000000000 instances"), std::string::npos) << e;
}

// A PLY face whose list length field says 10⁸ (or 4·10⁹) in a 100-byte file: Assimp
// allocated the list before reading it (830 MB; "cannot read mesh: std::bad_alloc" for
// 4·10⁹, naming no element). Every list length is checked against the bytes left.
TEST(Regression, PlyListLengthWasAllocatedUnchecked) {
  const fs::path d = scratch();
  std::string bin = replaced(replaced(kPlyTriangle, "ascii", "binary_little_endian"), "0 0 0\n1 0 0\n0 1 0\n", "");
  bin += std::string(36, '\0');                   // three vertices at the origin
  bin += std::string("\x00\xe1\xf5\x05", 4);       // uint 100,000,000, little endian
  bin += std::string(12, '\0');                   // the three indices actually there
  write(d / "m.ply", replaced(bin, "property list uchar int", "property list uint int"));
  const std::string e = input_error([&] { loom::read_mesh_file(d / "m.ply"); });
  EXPECT_NE(e.find("m.ply:7: element face instance 0: list length 100000000 is more than the 12 bytes left"),
            std::string::npos)
      << e;
}

// A tessellation cache entry whose vertex count was corrupt (2^32: a truncated write, a
// flipped bit) sized its arrays from it: 96 GB, "loom: error: std::bad_alloc" on every run
// of every scene with that STEP file until the cache was deleted by hand.
TEST(Regression, CorruptTessellationCacheEntryFailedEveryRun) {
  const fs::path d = scratch();
  const fs::path step = fs::path(LOOM_SOURCE_DIR) / "examples/wing-section/spar.step";
  ::setenv("LOOM_CACHE_DIR", (d / "cache").c_str(), 1);
  loom::TessellationParams tp;
  tp.linear_deflection = 1.0;
  const auto fresh = loom::read_cad_file_cached(step, tp, true);
  const fs::path entry = d / "cache" / (loom::tessellation_cache_key(step, tp, true) + ".tess");
  std::string bytes = slurp(entry);
  std::uint64_t name_length = 0;  // after the magic (8) and the mesh count (8)
  std::memcpy(&name_length, bytes.data() + 16, 8);
  const std::uint64_t corrupt = std::uint64_t{1} << 32;  // the vertex count, after the name and B-rep faces (4)
  std::memcpy(bytes.data() + 24 + name_length + 4, &corrupt, 8);
  write(entry, bytes);
  bool hit = true;
  const auto again = loom::read_cad_file_cached(step, tp, true, &hit);
  ::unsetenv("LOOM_CACHE_DIR");
  EXPECT_FALSE(hit);
  ASSERT_EQ(again.size(), fresh.size());
  EXPECT_EQ(again[0].mesh.triangles, fresh[0].mesh.triangles);
}

// loom's own PLY reader skipped the instances of the elements before the vertex element one
// by one: a binary element without properties declaring 1e18 instances looped for ever.
TEST(Regression, PointCloudPlyElementWithoutPropertiesHung) {
  std::string bytes =
      "ply\nformat binary_little_endian 1.0\nelement junk 1000000000000000000\nelement vertex 2\n"
      "property float x\nproperty float y\nproperty float z\nend_header\n";
  bytes += std::string(24, '\0');
  const std::string e = input_error([&] { loom::parse_point_cloud(bytes, "c.ply"); });
  EXPECT_NE(e.find("c.ply:3: element junk: declares 1000000000000000000 instances"), std::string::npos) << e;
}

// PCD header numbers were multiplied and summed unchecked: a COUNT of 2^64-1 wrapped the
// values per point to 2, and the ASCII reader indexed 2^64-1 into a line's 3 values.
TEST(Regression, PcdCountOverflowIndexedPastTheLine) {
  const std::string bytes =
      "VERSION 0.7\nFIELDS pad x y z\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 18446744073709551615 1 1 1\n"
      "WIDTH 2\nHEIGHT 1\nPOINTS 2\nDATA ascii\n0 0 0\n1 0 0\n";
  const std::string e = input_error([&] { loom::parse_point_cloud(bytes, "c.pcd"); });
  EXPECT_NE(e.find("COUNT: field 'pad' has COUNT 18446744073709551615: the size of one point overflows"),
            std::string::npos)
      << e;
}

// Point counts of PLY and PCD headers were reserved before any data was read: 4e9 points
// asked for 96 GB and ended in std::bad_alloc (exit 2 naming no file); a compressed PCD
// block claiming 4 GB from 4 bytes was allocated and zeroed.
TEST(Regression, PointCloudHeaderCountsWereReservedUnchecked) {
  const std::string ply = "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\n"
                          "property float y\nproperty float z\nend_header\n" + std::string(24, '\0');
  std::string e = input_error([&] { loom::parse_point_cloud(ply, "c.ply"); });
  EXPECT_NE(e.find("c.ply:3: element vertex: declares 4000000000 instances"), std::string::npos) << e;
  std::string pcd = "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nPOINTS 357913941\nDATA binary_compressed\n";
  const std::uint32_t sizes[2] = {4u, 4294967292u};  // compressed, uncompressed (little endian)
  pcd.append(reinterpret_cast<const char*>(sizes), sizeof sizes);
  pcd += std::string(4, '\0');
  e = input_error([&] { loom::parse_point_cloud(pcd, "c.pcd"); });
  EXPECT_NE(e.find("c.pcd:6: POINTS: declares 357913941 points"), std::string::npos) << e;
}

// Harness and point cloud files were opened as they came: a directory read as an empty file
// ("malformed XML: No document element found"; the point cloud reader threw
// basic_filebuf::underflow naming nothing), and a device such as /dev/zero was read until
// memory ran out (4 GB before std::bad_alloc).
TEST(Regression, InputThatIsNoRegularFileWasReadAsOne) {
  const fs::path d = scratch();
  std::string e = input_error([&] { loom::read_harness_xml(d); });
  EXPECT_NE(e.find(d.string() + ": not a regular file"), std::string::npos) << e;
  e = input_error([&] { loom::read_point_cloud(d); });
  EXPECT_NE(e.find(d.string() + ": not a regular file"), std::string::npos) << e;
}

// A harness attribute that is not UTF-8 (a Latin-1 colour in a file declaring no encoding)
// was read; the audit then ran and failed writing its report with nlohmann's
// "[json.exception.type_error.316] invalid UTF-8 byte", naming neither file nor line.
TEST(Regression, NonUtf8HarnessTextBrokeTheReports) {
  const std::string text = replaced(kHarness, R"(color="red")", "color=\"r\xf6" "d\"");
  const std::string e = input_error([&] { loom::parse_harness_xml(text, "h.xml"); });
  EXPECT_NE(e.find("h.xml:4: <physical>: attribute 'color' is not valid UTF-8"), std::string::npos) << e;
}

// A file name that is not UTF-8 (a Latin-1 "c\xff.xyz") reached report.json: nlohmann's
// dump() threw type_error 316 after `scan` had written centerline.xml and tube.ply, exit 2
// with a message naming nothing. Reports carry U+FFFD for the bad bytes, and scan makes
// every output's text before it writes the first.
TEST(Regression, NonUtf8FileNameBrokeTheReports) {
  const fs::path d = scratch();
  std::string cloud;
  for (int i = 0; i < 600; ++i)
    for (int k = 0; k < 12; ++k) {
      const double a = 2.0 * M_PI * k / 12.0 + 0.37 * i;
      cloud += std::to_string(0.1 * i) + " " + std::to_string(std::cos(a)) + " " + std::to_string(std::sin(a)) + "\n";
    }
  write(d / "c\xff.xyz", cloud);
  const auto [status, out] = loom("scan '" + (d / "c\xff.xyz").string() + "' --quiet --out " + (d / "o").string());
  EXPECT_EQ(status, 0) << out;
  EXPECT_NE(slurp(d / "o" / "report.json").find("\"cloud\": \"" + (d / "c\xef\xbf\xbd.xyz").string()),
            std::string::npos);
}

// A <bspline> whose knots span [0, 1e-300] was read; its derivatives overflowed, the
// positions came out infinite and the audit stopped in an internal check
// ("overlapping_box_pairs: box 0 is unset"), naming neither file nor element.
TEST(Regression, VanishingKnotDomainGaveNonFiniteCurves) {
  const std::string text =
      replaced(kHarness, R"(<segment from="J1" to="J2"/>)",
               R"(<segment from="J1" to="J2"><bspline degree="3" knots="0 0 0 0 1e-300 1e-300 1e-300 1e-300">)"
               R"(<cp x="-20" y="5" z="5"/><cp x="0" y="25" z="5"/><cp x="10" y="25" z="5"/>)"
               R"(<cp x="30" y="5" z="5"/></bspline></segment>)");
  const std::string e = input_error([&] { loom::parse_harness_xml(text, "h.xml"); });
  EXPECT_NE(e.find("h.xml:9: <bspline>: the knots span the domain [0, 1e-300]"), std::string::npos)
      << e;
}

// Only the audit turned a route that makes no curve into an error naming the harness file
// and cable; render, the view and scan --compare met std::invalid_argument
// ("Centerline::interpolate: need at least 2 distinct key points") and said only that.
TEST(Regression, RouteCurveErrorsNamedNoFileOutsideTheAudit) {
  loom::Harness h = loom::parse_harness_xml(replaced(kHarness, R"(x="30" y="5")", R"(x="-20" y="5")"), "h.xml");
  const loom::HarnessTopology topo(h);
  const std::string e = input_error([&] { loom::cable_centerline(topo, 0); });
  EXPECT_NE(e.find("h.xml:3: cable C1: its route does not make a curve: Centerline::interpolate"), std::string::npos)
      << e;
}

// A scene section given as anything but a table was skipped: `harness = "h.xml"` (for
// `[harness] file = "h.xml"`) loaded a scene without its harness, and `audit` reported
// "nothing to audit", exit 0.
TEST(Regression, SceneSectionOfTheWrongTypeWasIgnored) {
  const fs::path d = scratch();
  write(d / "h.xml", kHarness);
  write(d / "s.toml", "harness = 'h.xml'\n[scene]\nname = 's'\n");
  const std::string e = input_error([&] { loom::load_scene(d / "s.toml"); });
  EXPECT_NE(e.find("s.toml:1: harness: expected a table [harness]"), std::string::npos) << e;
}

// routing.seed = 4294967296 passed (a non-negative integer) and was cast to the planner's
// unsigned 32-bit seed: 0, another seed than the one asked for (and undefined behaviour
// beyond).
TEST(Regression, SceneSeedBeyondThirtyTwoBitsWasCut) {
  const fs::path d = scratch();
  write(d / "s.toml", "[scene]\nname = 's'\n[routing]\nseed = 4294967296\n");
  const std::string e = input_error([&] { loom::load_scene(d / "s.toml"); });
  EXPECT_NE(e.find("s.toml:4: routing.seed: must be an integer in 0..4294967295"), std::string::npos) << e;
}

// `--threads -1` and `--threads 0` ran (all cores), and `route --seed 5000000000` ran with
// the seed cut to 32 bits: bad given values silently replaced.
TEST(Regression, ThreadsAndSeedOptionsTookBadValues) {
  const fs::path d = scratch();
  const std::string audit = std::string(LOOM_SOURCE_DIR) + "/tests/data/audit/clean.toml";
  const std::string route = std::string(LOOM_SOURCE_DIR) + "/tests/data/route/around.toml";
  for (const std::string& cmd : {"audit " + audit + " --threads -1", "audit " + audit + " --threads 0",
                                 "route " + route + " --seed 5000000000 --time-limit 0.2"}) {
    const auto [status, out] = loom(cmd + " --quiet --out " + (d / "o").string());
    EXPECT_EQ(status, 2) << cmd << "\n" << out;
    EXPECT_NE(out.find("must be a whole number in"), std::string::npos) << cmd << "\n" << out;
  }
}

// `render --report` with `"clashes": 5` drew no markers and exit 0; with `"kind": 5` it
// failed with "[json.exception.type_error.302] type must be string", naming nothing.
TEST(Regression, RenderReportOfTheWrongShapeWasTakenOrNamedNothing) {
  const fs::path d = scratch();
  const std::string scene = std::string(LOOM_SOURCE_DIR) + "/tests/data/audit/clash.toml";
  write(d / "a.json", R"({"clashes": 5})");
  write(d / "b.json", R"({"clashes": [{"kind": 5, "point": [0, 0, 0]}]})");
  for (const auto& [file, message] : {std::pair<std::string, std::string>{"a.json", "a.json: clashes: expected an array"},
                                      {"b.json", "b.json: clashes[0].kind: expected a string"}}) {
    const auto [status, out] =
        loom("render " + scene + " --quiet --report " + (d / file).string() + " --out " + (d / "x.png").string());
    EXPECT_EQ(status, 2) << out;
    EXPECT_NE(out.find(message), std::string::npos) << out;
  }
}

// --- special files, links and cache entries as inputs --------------------------------------

// A STEP part that is a FIFO, or a link to /dev/zero, hung `loom info` for ever: the
// tessellation cache hashed the file's bytes for its key before the reader checked that it
// was a regular file (a FIFO blocks the open, /dev/zero never ends).
TEST(Regression, CadCacheHashedADeviceBeforeCheckingIt) {
  const fs::path d = scratch();
  setenv("LOOM_CACHE_DIR", (d / "cache").c_str(), 1);
  fs::create_symlink("/dev/zero", d / "zero.step");
  ASSERT_EQ(mkfifo((d / "pipe.step").c_str(), 0600), 0);
  for (const char* name : {"zero.step", "pipe.step"}) {
    const std::string e = input_error([&] { loom::read_cad_file_cached(d / name, loom::TessellationParams{}, true); });
    EXPECT_NE(e.find(name + std::string(": not a regular file")), std::string::npos) << e;
  }
  unsetenv("LOOM_CACHE_DIR");
}

// Assimp opens the files a mesh refers to itself: a glTF buffer uri naming a FIFO blocked
// `loom info` for ever (an OBJ's mtllib naming one too). Only regular files are opened;
// the glTF is refused naming the reference, the OBJ loads without its materials.
TEST(Regression, MeshReferenceToAFifoHung) {
  const fs::path d = scratch();
  ASSERT_EQ(mkfifo((d / "pipe.bin").c_str(), 0600), 0);
  write(d / "m.gltf", R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],
"meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],
"buffers":[{"uri":"pipe.bin","byteLength":36}],
"bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":36}],
"accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","max":[1,1,0],"min":[0,0,0]}]})");
  const std::string e = input_error([&] { loom::read_mesh_file(d / "m.gltf"); });
  EXPECT_NE(e.find("m.gltf: cannot read mesh: GLTF: could not open referenced file \"pipe.bin\""), std::string::npos)
      << e;
  write(d / "m.obj", "mtllib pipe.bin\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  EXPECT_EQ(loom::read_mesh_file(d / "m.obj").triangle_count(), 1u);
}

// pugixml reads elements after the root: a second <harness> (say two files concatenated)
// was ignored without a word.
TEST(Regression, HarnessSecondRootElementWasIgnored) {
  const std::string e = input_error([&] { loom::parse_harness_xml(kHarness + "<harness name=\"h2\"/>\n", "h.xml"); });
  EXPECT_NE(e.find("h.xml:12: <harness>: a second root element"), std::string::npos) << e;
}

// pugixml keeps both attributes of `<cable id="C1" id="C2">` and a lookup finds the first:
// the second value was dropped without a word.
TEST(Regression, HarnessDuplicateAttributeWasIgnored) {
  const std::string text = replaced(kHarness, R"(diameter="2")", R"(diameter="2" diameter="20")");
  const std::string e = input_error([&] { loom::parse_harness_xml(text, "h.xml"); });
  EXPECT_NE(e.find("h.xml:4: <physical>: duplicate attribute 'diameter'"), std::string::npos) << e;
}

// pugixml skips a DOCTYPE and leaves references it does not know as text: an entity declared
// in it (a "billion laughs" file among them) gave the cable the id "&lol9;", and `&#0;` cut
// "C&#0;1" to "C". Both are refused, naming the line; the predefined entities and character
// references to XML characters still read as XML says.
TEST(Regression, HarnessDtdAndUnknownReferencesWereReadAsText) {
  std::string dtd = "<?xml version=\"1.0\"?>\n<!DOCTYPE h [\n<!ENTITY lol \"lol\">\n";
  for (int k = 1; k <= 9; ++k) {
    dtd += "<!ENTITY lol" + std::to_string(k) + " \"";
    for (int i = 0; i < 10; ++i) dtd += "&lol" + (k == 1 ? std::string() : std::to_string(k - 1)) + ";";
    dtd += "\">\n";
  }
  dtd += "]>\n";
  std::string e = input_error(
      [&] { loom::parse_harness_xml(dtd + replaced(kHarness, R"(id="C1")", R"(id="&lol9;")"), "h.xml"); });
  EXPECT_NE(e.find("h.xml:2: a document type declaration (<!DOCTYPE ...>) is not supported"), std::string::npos) << e;
  e = input_error([&] { loom::parse_harness_xml(replaced(kHarness, R"(id="C1")", R"(id="&lol9;")"), "h.xml"); });
  EXPECT_NE(e.find("h.xml:3: <cable>: attribute 'id': unsupported reference '&lol9;'"), std::string::npos) << e;
  e = input_error([&] { loom::parse_harness_xml(replaced(kHarness, R"(id="C1")", R"(id="C&#0;1")"), "h.xml"); });
  EXPECT_NE(e.find("h.xml:3: <cable>: attribute 'id': unsupported reference '&#0;'"), std::string::npos) << e;
  e = input_error([&] { loom::parse_harness_xml(replaced(kHarness, R"(color="red")", R"(color="R&D")"), "h.xml"); });
  EXPECT_NE(e.find("h.xml:4: <physical>: attribute 'color': unsupported reference '&D'"), std::string::npos) << e;
  const loom::Harness ok = loom::parse_harness_xml(
      replaced(kHarness, R"(color="red")", R"(color="R&amp;D &lt;&gt;&quot;&apos; &#65;&#x1F600;")"), "h.xml");
  EXPECT_EQ(ok.cables[0].physical.color, "R&D <>\"' A\xF0\x9F\x98\x80");
}

// A port direction such as (1e-200, 0, 0) was refused as "zero length": its squared length
// underflows. A direction is zero only if every component is.
TEST(Regression, TinyPortDirectionWasCalledZero) {
  const loom::Harness h =
      loom::parse_harness_xml(replaced(kHarness, R"(dx="1" dy="0" dz="0")", R"(dx="1e-200" dy="0" dz="-1e-200")"), "h.xml");
  EXPECT_NEAR(h.ports[0].direction.x(), std::sqrt(0.5), 1e-15);
  EXPECT_NEAR(h.ports[0].direction.z(), -std::sqrt(0.5), 1e-15);
}

// A symbolic link loop was reported as "scene file not found", sending the user to look for a
// file that is there.
TEST(Regression, SymlinkLoopWasReportedAsMissing) {
  const fs::path d = scratch();
  fs::create_symlink(d / "b.toml", d / "a.toml");
  fs::create_symlink(d / "a.toml", d / "b.toml");
  const std::string e = input_error([&] { loom::load_scene(d / "a.toml"); });
  EXPECT_NE(e.find("a.toml: cannot access scene file: Too many levels of symbolic links"), std::string::npos) << e;
}

// `name = ""` in a [[part]] was taken: clashes were reported against part "" and its simplify
// output became "part.stl".
TEST(Regression, EmptyPartNameWasAccepted) {
  const fs::path d = scratch();
  write(d / "m.ply", kPlyTriangle + "3 0 1 2\n");
  write(d / "s.toml", "[scene]\nname = 's'\n[[part]]\nname = ''\nfile = 'm.ply'\n");
  const std::string e = input_error([&] { loom::load_scene(d / "s.toml"); });
  EXPECT_NE(e.find("s.toml:4: part[1].name: must not be empty"), std::string::npos) << e;
}

// `[harness]` without `file` named no line of the scene.
TEST(Regression, HarnessTableWithoutFileNamedNoLine) {
  const fs::path d = scratch();
  write(d / "s.toml", "[scene]\nname = 's'\n\n[harness]\n");
  const std::string e = input_error([&] { loom::load_scene(d / "s.toml"); });
  EXPECT_NE(e.find("s.toml:4: harness.file: missing harness file name"), std::string::npos) << e;
}

// A STEP assembly whose product names look like loom's own suffixes ("bolt" placed six times,
// and a product named "bolt#2") gave two pieces the name "bolt#2": the scene then refused a
// valid file ("duplicate part name 'as1/bolt#2'"), every run, since the cache kept the names.
TEST(Regression, StepProductNamedLikeASuffixClashed) {
  const fs::path as1 = loom::testing::shared_data("stepcode/as1-oc-214.stp");
  LOOM_SHARED_DATA_OR_SKIP(as1);
  const fs::path d = scratch();
  const std::string text = replaced(slurp(as1), "PRODUCT('l-bracket','l-bracket'", "PRODUCT('bolt#2','bolt#2'");
  write(d / "as1.stp", text);
  loom::TessellationParams tp;
  tp.linear_deflection = 0.5;
  const auto pieces = loom::read_cad_file(d / "as1.stp", tp, true);
  std::set<std::string> names;
  for (const auto& p : pieces) names.insert(p.name);
  EXPECT_EQ(pieces.size(), 18u);
  EXPECT_EQ(names.size(), pieces.size());
  EXPECT_EQ(names.count("bolt#2"), 1u);
}

// `<physical color="red" colour="blue">` took "red" and dropped "blue" without a word.
TEST(Regression, ColorAndColourTogetherDroppedOne) {
  const std::string text = replaced(kHarness, R"(color="red")", R"(color="red" colour="blue")");
  const std::string e = input_error([&] { loom::parse_harness_xml(text, "h.xml"); });
  EXPECT_NE(e.find("h.xml:4: <physical>: both 'color' and 'colour' given"), std::string::npos) << e;
}

// A segment given diameter="0.2" while carrying a 2 mm cable was taken: the router planned
// a tube a tenth of the cable's width (typically a unit slip in the file).
TEST(Regression, SegmentThinnerThanItsCableWasTaken) {
  const std::string text =
      replaced(kHarness, R"(<segment from="J1" to="J2"/>)", R"(<segment from="J1" to="J2" diameter="0.2"/>)");
  const std::string e = input_error([&] { loom::parse_harness_xml(text, "h.xml"); });
  EXPECT_NE(e.find("h.xml:9: segment J1 -> J2: diameter 0.20000000000000001 is less than the diameter 2 of cable 'C1'"),
            std::string::npos)
      << e;
  // Equal to the cable's is valid.
  EXPECT_NO_THROW(loom::parse_harness_xml(
      replaced(kHarness, R"(<segment from="J1" to="J2"/>)", R"(<segment from="J1" to="J2" diameter="2"/>)"), "h.xml"));
}

// TOML's "\u0000" escape put a NUL into a string: file = "m.ply\u0000.stl" passed the .stl
// extension check and then opened "m.ply" (every OS call stops at the NUL).
TEST(Regression, TomlNulInAFileNameReadAnotherFile) {
  const fs::path d = scratch();
  write(d / "m.ply", kPlyTriangle + "3 0 1 2\n");
  write(d / "s.toml", "[scene]\nname = 's'\n[[part]]\nfile = \"m.ply\\u0000.stl\"\n");
  const std::string e = input_error([&] { loom::load_scene(d / "s.toml"); });
  EXPECT_NE(e.find("s.toml:4: part[1].file: must not contain a NUL character"), std::string::npos) << e;
}

}  // namespace
