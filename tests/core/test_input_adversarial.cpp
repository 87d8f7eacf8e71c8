// Adversarial inputs to loom's readers (scene TOML, harness XML, mesh files), through the
// library and the command line. The oracle is DESIGN §3–§4: every bad input is exit
// status 2 with a message naming the file, the line or element and what is wrong, and nothing
// half-written; valid edge values (BOM, CRLF, comments, unicode, predefined entities, UTF-16,
// hex floats in TOML) keep working. Each defect such inputs exposed has its regression test
// in tests/regressions/test_input_regressions.cpp; this file keeps the broader catalogue.
#include "core/error.hpp"
#include "core/harness_topology.hpp"
#include "core/io/harness_xml.hpp"
#include "core/io/mesh_read.hpp"
#include "core/io/scene_load.hpp"
#include "common/run_loom.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <sys/stat.h>

namespace loom {
namespace {

namespace fs = std::filesystem;

const std::string kHarness = R"(<harness name="h" units="mm">
  <attributes>
    <cable id="C1"><electrical><port id="J1"/><port id="J2"/></electrical>
      <physical type="t" color="red" diameter="2" min_bend_radius="10"/></cable>
  </attributes>
  <structure>
    <port id="J1" x="-20" y="5" z="30" dx="1" dy="0" dz="0"/>
    <port id="J2" x="30" y="5" z="30" dx="-1" dy="0" dz="0"/>
    <segment from="J1" to="J2"/>
  </structure>
</harness>
)";

/// A closed box [0,10]^3 as OBJ.
const std::string kBoxObj =
    "v 0 0 0\nv 10 0 0\nv 0 10 0\nv 10 10 0\nv 0 0 10\nv 10 0 10\nv 0 10 10\nv 10 10 10\n"
    "f 1 3 2\nf 2 3 4\nf 5 6 7\nf 6 8 7\nf 1 2 5\nf 2 6 5\nf 3 7 4\nf 4 7 8\nf 1 5 3\nf 3 5 7\nf 2 4 6\nf 4 8 6\n";

const std::string kScene = "[scene]\nname = 's'\n[[part]]\nname = 'box'\nfile = 'box.obj'\n[harness]\nfile = 'h.xml'\n";

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return at == std::string::npos ? text : text.replace(at, from.size(), to);
}

class InputAdversarial : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("loom_input_adversarial_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    write("box.obj", kBoxObj);
    write("h.xml", kHarness);
  }
  void TearDown() override { fs::remove_all(dir_); }

  void write(const std::string& name, const std::string& bytes) {
    std::ofstream(dir_ / name, std::ios::binary) << bytes;
  }
  /// The InputError message of loading `toml` as the scene (with `harness` as h.xml), or ""
  /// with a failure if it loads.
  std::string scene_error(const std::string& toml, const std::string& harness = kHarness) {
    write("s.toml", toml);
    write("h.xml", harness);
    try {
      load_scene(dir_ / "s.toml");
      ADD_FAILURE() << "no InputError for:\n" << toml << "\n" << harness;
    } catch (const InputError& e) {
      return e.what();
    }
    return {};
  }
  /// Loads `toml` (with `harness` as h.xml), which must be valid.
  Scene scene_ok(const std::string& toml, const std::string& harness = kHarness) {
    write("s.toml", toml);
    write("h.xml", harness);
    return load_scene(dir_ / "s.toml");
  }
  std::string harness_error(const std::string& text) {
    try {
      parse_harness_xml(text, "h.xml");
      ADD_FAILURE() << "no InputError for:\n" << text;
    } catch (const InputError& e) {
      return e.what();
    }
    return {};
  }
  fs::path dir_;
};

/// Expects `needle` in the message `text` (evaluated once).
#define EXPECT_HAS(text, needle)                                              \
  do {                                                                        \
    const std::string loom_message_ = (text);                                 \
    EXPECT_NE(loom_message_.find(needle), std::string::npos) << loom_message_; \
  } while (0)

TEST_F(InputAdversarial, TomlDuplicatesAndUnrepresentableNumbersAreMalformed) {
  EXPECT_HAS(scene_error("[scene]\nname = 'a'\nname = 'b'\n"), "s.toml:3: malformed TOML");
  EXPECT_HAS(scene_error("[scene]\nname = 'a'\n[scene]\nunits = 'm'\n"), "s.toml:3: malformed TOML");
  EXPECT_HAS(scene_error("[scene]\n[routing]\nclearance = 1e400\n"), "s.toml:3: malformed TOML");
  EXPECT_HAS(scene_error("[scene]\n[routing]\nseed = 99999999999999999999\n"), "s.toml:3: malformed TOML");
  EXPECT_HAS(scene_error("[scene]\n[routing]\nclearance = nan\n"), "s.toml:3: routing.clearance: must be finite");
  EXPECT_HAS(scene_error("[scene]\n[routing]\nclearance = -inf\n"), "s.toml:3: routing.clearance: must be finite");
  EXPECT_HAS(scene_error("[scene]\n[routing]\nclearance = '3'\n"), "routing.clearance: expected a number");
  EXPECT_HAS(scene_error("[scene]\n[routing]\nclearance = -1\n"), "routing.clearance: must not be negative");
  EXPECT_HAS(scene_error("[scene]\nunits = 'MM'\n"), "scene.units: unknown unit 'MM'");
  EXPECT_HAS(scene_error("[scene]\nunits = 1\n"), "scene.units: expected a string");
  EXPECT_HAS(scene_error(""), "missing [scene] table");
}

TEST_F(InputAdversarial, TomlPartEntriesAreChecked) {
  const std::string head = "[scene]\nname = 's'\n[[part]]\nfile = 'box.obj'\n";
  EXPECT_HAS(scene_error(kScene + "[[part]]\nname = 'box'\nfile = 'box.obj'\n"), "duplicate part name 'box'");
  EXPECT_HAS(scene_error(head + "transform = { scale = 0 }\n"), "transform.scale: must be positive");
  EXPECT_HAS(scene_error(head + "transform = { scale = -1.0 }\n"), "transform.scale: must be positive");
  EXPECT_HAS(scene_error(head + "transform = { translate = ['1', 0, 0] }\n"), "translate: expected numbers");
  EXPECT_HAS(scene_error(head + "transform = { translate = [1, 0] }\n"), "expected an array of 3 numbers");
  EXPECT_HAS(scene_error(head + "transform = { rotate_deg = [nan, 0, 0] }\n"), "rotate_deg: must be finite");
  EXPECT_HAS(scene_error(head + "transform = { matrix = 1 }\n"), "transform.matrix: unknown key");
  EXPECT_HAS(scene_error(head + "transform = 'identity'\n"), "expected an inline table");
  EXPECT_HAS(scene_error(head + "transform = { scale = 1e12 }\n"), "beyond ±1000000000000 scene units");
  EXPECT_HAS(scene_error(head + "clearance = -1\n"), "part 'box'.clearance: must not be negative");
  EXPECT_HAS(scene_error(head + "role = 'Structure'\n"), "role must be 'structure' or 'keep_out'");
  EXPECT_HAS(scene_error(head + "compound = 'yes'\n"), "compound: expected true or false");
  EXPECT_HAS(scene_error("[scene]\n[[part]]\nname = 'x'\n"), "s.toml:2: part[1]: missing 'file'");
  EXPECT_HAS(scene_error("[scene]\n[part]\nfile = 'box.obj'\n"), "part: expected [[part]] tables");
  EXPECT_HAS(scene_error("[scene]\n[[part]]\nfile = 'box.txt'\n"), "unknown file extension '.txt'");
  EXPECT_HAS(scene_error("[scene]\n[[part]]\nfile = 'absent.stl'\n"), "absent.stl: file not found");
  EXPECT_HAS(scene_error("[scene]\n[harness]\nfile = 3\n"), "s.toml:3: harness.file: expected a string");
  EXPECT_HAS(scene_error("[scene]\n[harness]\nfile = ''\n"), "harness.file: empty file name");
}

TEST_F(InputAdversarial, TomlValidEdgesKeepWorking) {
  // BOM, CRLF line endings, comments, unicode names and paths, a hex integer, metres.
  write("bøx ✈.obj", kBoxObj);
  const Scene s = scene_ok(
      "\xEF\xBB\xBF# comment\r\n[scene]\r\nname = \"Flügel ✈\" # trailing comment\r\nunits = \"mm\"\r\n"
      "[[part]]\r\nname = \"rippe-ü\"\r\nfile = \"bøx ✈.obj\"\r\nclearance = 0x2\r\n[harness]\r\nfile = \"h.xml\"\r\n");
  EXPECT_EQ(s.name, "Flügel ✈");
  ASSERT_EQ(s.parts.size(), 1u);
  EXPECT_EQ(s.parts[0].name, "rippe-ü");
  EXPECT_EQ(s.parts[0].clearance, 2.0);
  EXPECT_EQ(s.harness.cables.size(), 1u);
  const Scene m = scene_ok("[scene]\nunits = 'm'\n[harness]\nfile = 'h.xml'\n", replaced(kHarness, "\"mm\"", "\"m\""));
  EXPECT_EQ(m.units, Unit::Metre);
  // The scene unit and the harness unit must agree: a harness without units is in mm.
  EXPECT_HAS(scene_error("[scene]\nunits = 'm'\n[harness]\nfile = 'h.xml'\n",
                         replaced(kHarness, " units=\"mm\"", "")),
             "unit mismatch: the harness is in mm but the scene is in m");
}

TEST_F(InputAdversarial, FilesThatAreNoRegularFilesAreRefused) {
  fs::create_directories(dir_ / "dir.stl");
  fs::create_symlink(dir_ / "loop2.stl", dir_ / "loop1.stl");
  fs::create_symlink(dir_ / "loop1.stl", dir_ / "loop2.stl");
  ASSERT_EQ(mkfifo((dir_ / "pipe.stl").c_str(), 0600), 0);
  ASSERT_EQ(mkfifo((dir_ / "pipe.xml").c_str(), 0600), 0);
  EXPECT_HAS(scene_error("[scene]\n[[part]]\nfile = 'dir.stl'\n"), "dir.stl: not a regular file");
  EXPECT_HAS(scene_error("[scene]\n[[part]]\nfile = 'pipe.stl'\n"), "pipe.stl: not a regular file");
  EXPECT_HAS(scene_error("[scene]\n[[part]]\nfile = 'loop1.stl'\n"), "loop1.stl: cannot access file");
  EXPECT_HAS(scene_error("[scene]\n[harness]\nfile = 'pipe.xml'\n"), "pipe.xml: not a regular file");
  if (fs::exists("/dev/zero")) {
    fs::create_symlink("/dev/zero", dir_ / "zero.stp");
    EXPECT_HAS(scene_error("[scene]\n[[part]]\nfile = 'zero.stp'\n"), "zero.stp: not a regular file");
  }
}

TEST_F(InputAdversarial, MeshesWithoutTrianglesOrWithBadNumbersAreRefused) {
  write("empty.stl", "");
  write("nan.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n");
  write("big.obj", "v 0 0 0\nv 1e400 0 0\nv 0 1 0\nf 1 2 3\n");
  write("points.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n");
  write("degenerate.obj", "v 0 0 0\nv 0 0 0\nv 0 0 0\nf 1 2 3\n");
  write("index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99999999999\n");
  write("empty.step", "");
  for (const auto& [file, needle] : std::vector<std::pair<std::string, std::string>>{
           {"empty.stl", "empty.stl: cannot read mesh"},
           {"nan.obj", "nan.obj: vertex 1 has a NaN or infinite coordinate"},
           {"big.obj", "big.obj: vertex 1 has a NaN or infinite coordinate"},
           {"points.obj", "points.obj: cannot read mesh"},
           {"degenerate.obj", "degenerate.obj: the mesh has no triangles"},
           {"index.obj", "index.obj: cannot read mesh"},
           {"empty.step", "empty.step: cannot parse STEP file"}}) {
    const std::string e = scene_error("[scene]\n\n[[part]]\nfile = '" + file + "'\n");
    EXPECT_HAS(e, needle);
    EXPECT_HAS(e, "s.toml:4 part '");  // the scene entry that named the file
  }
}

TEST_F(InputAdversarial, MeshReferencesOutsideRegularFilesAreRefused) {
  const std::string gltf = R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],
"meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],
"buffers":[{"uri":"URI","byteLength":36}],
"bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":36}],
"accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","max":[1,1,0],"min":[0,0,0]}]})";
  fs::create_directories(dir_ / "sub");
  for (const std::string uri : {"absent.bin", "sub", "/dev/zero", "../../../../../../../../nonexistent.bin"}) {
    write("m.gltf", replaced(gltf, "URI", uri));
    try {
      read_mesh_file(dir_ / "m.gltf");
      ADD_FAILURE() << uri;
    } catch (const InputError& e) {
      EXPECT_HAS(std::string(e.what()), "m.gltf: cannot read mesh: GLTF: could not open referenced file");
    }
  }
}

TEST_F(InputAdversarial, HarnessIdsAndReferencesAreChecked) {
  const std::string cable2 = R"(<cable id="C2"><electrical><port id="J1"/><port id="J2"/></electrical>
      <physical diameter="3"/></cable></attributes>)";
  EXPECT_HAS(harness_error(replaced(kHarness, "</attributes>", R"(<cable id="C1"><electrical><port id="J1"/>)"
                                                              R"(<port id="J2"/></electrical><physical diameter="3"/></cable></attributes>)")),
             "cable 'C1': duplicate cable id");
  EXPECT_HAS(harness_error(replaced(kHarness, "<segment", R"(<port id="J1" x="0" y="0" z="0" dx="1" dy="0" dz="0"/><segment)")),
             "port 'J1': duplicate node id");
  EXPECT_HAS(harness_error(replaced(kHarness, "<segment", R"(<branch id="J2"/><segment)")), "branch 'J2': duplicate node id");
  EXPECT_HAS(harness_error(replaced(kHarness, R"(to="J2"/>)", R"(to="J9"/>)")), "unknown node id 'J9'");
  EXPECT_HAS(harness_error(replaced(kHarness, R"(to="J2"/>)", R"(to="J1"/>)")), "joins a node to itself");
  EXPECT_HAS(harness_error(replaced(kHarness, R"(<segment from="J1" to="J2"/>)",
                                    R"(<segment from="J1" to="J2"/><segment from="J2" to="J1"/>)")),
             "duplicate segment between the same two nodes");
  EXPECT_HAS(harness_error(replaced(kHarness, R"(<segment from="J1" to="J2"/>)", "")), "are not connected");
  EXPECT_HAS(harness_error(replaced(kHarness, R"(<port id="J2"/></electrical>)", R"(<port id="J1"/></electrical>)")),
             "both ends are the same port");
  EXPECT_HAS(harness_error(replaced(kHarness, R"(<cable id="C1">)", R"(<cable id="">)")), "attribute 'id' is empty");
  // A cable may share its ports with another (two cables in one bundle): that is valid.
  EXPECT_EQ(parse_harness_xml(replaced(kHarness, "</attributes>", cable2), "h.xml").cables.size(), 2u);
}

TEST_F(InputAdversarial, HarnessNumbersAreChecked) {
  for (const auto& [from, to, needle] : std::vector<std::tuple<std::string, std::string, std::string>>{
           {R"(diameter="2")", R"(diameter="-2")", "diameter must be positive"},
           {R"(diameter="2")", R"(diameter="0")", "diameter must be positive"},
           {R"(diameter="2")", R"(diameter="1e-400")", "diameter must be positive"},  // underflows to 0
           {R"(diameter="2")", R"(diameter="nan")", "'diameter' is not finite"},
           {R"(diameter="2")", R"(diameter="1e400")", "'diameter' is not finite"},
           {R"(diameter="2")", R"(diameter="2mm")", "'diameter' is not a number: '2mm'"},
           {R"(diameter="2")", R"(diameter="2,5")", "'diameter' is not a number"},
           {R"(diameter="2")", R"(diameter="")", "'diameter' is empty"},
           {R"(diameter="2")", R"(diameter="1e13")", "is beyond ±1000000000000"},
           {R"(min_bend_radius="10")", R"(min_bend_radius="-1")", "min_bend_radius must not be negative"},
           {R"(min_bend_radius="10")", R"(min_bend_radius="inf")", "not finite"},
           {R"(x="-20")", R"(x="abc")", "'x' is not a number"},
           {R"(dx="1" dy="0" dz="0")", R"(dx="0" dy="-0" dz="0")", "has zero length"},
           {R"(<segment from="J1" to="J2"/>)", R"(<segment from="J1" to="J2" diameter="-1"/>)",
            "diameter must be positive"},
           {R"(<segment from="J1" to="J2"/>)", R"(<segment from="J1" to="J2"><path><pt x="1" y="2"/></path></segment>)",
            "missing attribute 'z'"},
           {R"(units="mm")", R"(units="furlong")", "unknown units 'furlong'"}}) {
    EXPECT_HAS(harness_error(replaced(kHarness, from, to)), needle);
  }
}

TEST_F(InputAdversarial, HarnessXmlValidEdgesKeepWorking) {
  // BOM, CRLF, comments, CDATA and processing instructions beside the elements, '&' inside
  // comments, predefined entities and character references.
  std::string crlf;
  for (char c : replaced(kHarness, R"(color="red")", R"(color="r&amp;d &#x1F600;")")) {
    if (c == '\n') crlf += '\r';
    crlf += c;
  }
  const std::string text = "\xEF\xBB\xBF<?xml version=\"1.0\" encoding=\"UTF-8\"?>\r\n<!-- R&D's harness -->\r\n" + crlf +
                           "<!-- trailing & comment -->\r\n";
  const Harness h = parse_harness_xml(text, "h.xml");
  EXPECT_EQ(h.cables[0].physical.color, "r&d \xF0\x9F\x98\x80");
  // UTF-16 with a byte order mark, an escaped '&' inside.
  const std::string utf8 = replaced(kHarness, R"(color="red")", R"(color="r&amp;d")");
  std::string utf16 = "\xFF\xFE";
  for (char c : utf8) utf16 += std::string{c, '\0'};
  EXPECT_EQ(parse_harness_xml(utf16, "h16.xml").cables[0].physical.color, "r&d");
  // A harness without cables (ports waiting for wiring) is valid.
  EXPECT_TRUE(parse_harness_xml(R"(<harness name="h" units="mm"/>)", "h.xml").cables.empty());
}

TEST_F(InputAdversarial, HarnessMarkupPugixmlWouldMisreadIsRefused) {
  EXPECT_HAS(harness_error(kHarness + "<harness/>"), "a second root element");
  EXPECT_HAS(harness_error(replaced(kHarness, R"(id="C1")", R"(id="C1" id="C2")")), "duplicate attribute 'id'");
  EXPECT_HAS(harness_error("<!DOCTYPE h SYSTEM \"file:///etc/passwd\">\n" + kHarness),
             "h.xml:1: a document type declaration");
  EXPECT_HAS(harness_error(replaced(kHarness, R"(color="red")", R"(color="&#xFFFE;")")), "unsupported reference '&#xFFFE;'");
  EXPECT_HAS(harness_error(replaced(kHarness, R"(color="red")", R"(color="&#x110000;")")), "unsupported reference");
  EXPECT_HAS(harness_error(replaced(kHarness, R"(color="red")", R"(color="&#;")")), "unsupported reference '&#;'");
  EXPECT_HAS(harness_error(replaced(kHarness, R"(color="red")", R"(color="a & b")")), "unsupported reference '& b'");
  // A raw control character is no XML character (the writer would put it back as "&#01;");
  // a tab given as a reference is one, and survives the round trip.
  EXPECT_HAS(harness_error(replaced(kHarness, R"(color="red")", "color=\"r\x01" "d\"")),
             "h.xml:4: <physical>: attribute 'color' holds control character 1");
  const Harness tab = parse_harness_xml(replaced(kHarness, R"(color="red")", R"(color="r&#9;d")"), "h.xml");
  EXPECT_EQ(parse_harness_xml(harness_to_xml(tab), "w.xml").cables[0].physical.color, "r\td");
  // Nesting far deeper than a harness has is an error at the first unknown element, not a crash.
  std::string deep = "<harness name=\"h\"><structure>";
  for (int i = 0; i < 200000; ++i) deep += "<a>";
  for (int i = 0; i < 200000; ++i) deep += "</a>";
  deep += "</structure></harness>";
  EXPECT_HAS(harness_error(deep), "unexpected element <a> inside <structure>");
}

// A large harness (20,000 ports, 10,000 cables, each with its own segment, plus one branch
// joining three more ports) is read with every cable's chain right. Ports are looked up in
// one node table: a linear search per cable end would be quadratic in all (no timing is
// asserted here).
TEST_F(InputAdversarial, LargeHarnessIsReadWithItsChains) {
  constexpr int kPairs = 10000;
  std::string cables, ports, segments;
  for (int i = 0; i < kPairs; ++i) {
    const std::string a = "P" + std::to_string(2 * i), b = "P" + std::to_string(2 * i + 1);
    cables += "<cable id=\"C" + std::to_string(i) + "\"><electrical><port id=\"" + b + "\"/><port id=\"" + a +
              "\"/></electrical><physical diameter=\"1\"/></cable>\n";
    ports += "<port id=\"" + a + "\" x=\"" + std::to_string(i) + "\" y=\"0\" z=\"0\" dx=\"0\" dy=\"1\" dz=\"0\"/>\n";
    ports += "<port id=\"" + b + "\" x=\"" + std::to_string(i) + "\" y=\"9\" z=\"0\" dx=\"0\" dy=\"-1\" dz=\"0\"/>\n";
    segments += "<segment from=\"" + a + "\" to=\"" + b + "\"/>\n";
  }
  cables += R"(<cable id="X"><electrical><port id="Q1"/><port id="Q3"/></electrical><physical diameter="1"/></cable>)";
  ports += R"(<port id="Q1" x="0" y="0" z="50" dx="1" dy="0" dz="0"/><port id="Q2" x="9" y="0" z="50" dx="1" dy="0" dz="0"/>)";
  ports += R"(<port id="Q3" x="0" y="9" z="50" dx="1" dy="0" dz="0"/>)";
  segments += R"(<branch id="B"><segment to="Q1"/><segment to="Q2"/><segment to="Q3"/></branch>)";
  const Harness h = parse_harness_xml("<harness name=\"big\" units=\"mm\"><attributes>" + cables +
                                          "</attributes><structure>" + ports + segments + "</structure></harness>",
                                      "big.xml");
  const HarnessTopology topo(h);
  ASSERT_EQ(h.cables.size(), static_cast<std::size_t>(kPairs) + 1);
  for (int c : {0, kPairs / 2, kPairs - 1}) {
    const auto& chain = topo.cable_chain(c);
    ASSERT_EQ(chain.size(), 1u);
    EXPECT_EQ(h.segments[static_cast<std::size_t>(chain[0].segment)].from, "P" + std::to_string(2 * c));
    EXPECT_TRUE(chain[0].reversed);  // the cable runs from the segment's end to its start
  }
  const auto& x = topo.cable_chain(kPairs);
  ASSERT_EQ(x.size(), 2u);
  EXPECT_EQ(h.segments[static_cast<std::size_t>(x[0].segment)].to, "Q1");
  EXPECT_EQ(h.segments[static_cast<std::size_t>(x[1].segment)].to, "Q3");
}

// The command line: every bad input is exit status 2 naming the file, and a failed audit or
// route writes nothing into --out.
TEST_F(InputAdversarial, CommandLineRefusesBadInputsWithStatusTwoAndWritesNothing) {
  ASSERT_EQ(mkfifo((dir_ / "pipe.step").c_str(), 0600), 0);
  const std::vector<std::pair<std::string, std::string>> cases = {
      {kScene + "[routing]\nclearance = nan\n", "s.toml:9: routing.clearance: must be finite"},
      {"[scene]\n[[part]]\nfile = 'pipe.step'\n", "pipe.step: not a regular file"},
      {kScene + "[[part]]\nname = 'box'\nfile = 'box.obj'\n", "duplicate part name 'box'"},
  };
  for (const auto& [toml, needle] : cases) {
    write("s.toml", toml);
    for (const std::string cmd : {"info", "audit", "route --time-limit 0.2"}) {
      const fs::path out = dir_ / "out";
      const auto r = testing::run_loom(cmd + " '" + (dir_ / "s.toml").string() + "' --quiet" +
                                       (cmd == "info" ? std::string() : " --out '" + out.string() + "'"));
      EXPECT_EQ(r.status, 2) << cmd << "\n" << r.out;
      EXPECT_HAS(r.out, needle);
      EXPECT_FALSE(fs::exists(out / "report.json")) << cmd;
    }
  }
  write("h.xml", replaced(kHarness, R"(id="C1")", R"(id="C1" id="C2")"));
  write("s.toml", kScene);
  const auto r = testing::run_loom("info '" + (dir_ / "s.toml").string() + "' --json");
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_HAS(r.out, "h.xml:3: <cable id=\"C1\">: duplicate attribute 'id'");
}

}  // namespace
}  // namespace loom
