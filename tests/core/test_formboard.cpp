// Harnesses without 3D geometry: a formboard (2D) KBL and a VEC topology read as topology
// only (ports and branch points unplaced, nominal segment lengths kept), and the scene's
// [harness.place] table that places the ports. The oracle is the files' own text.
#include "core/error.hpp"
#include "core/io/kbl_read.hpp"
#include "core/io/kbl_vec.hpp"
#include "core/io/kbl_write.hpp"
#include "core/io/scene_load.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <unistd.h>
#include <vector>

namespace loom {
namespace {

/// The scene file and its harness, no part file (nor the tessellation cache) read.
SceneLoadOptions settings_only() {
  SceneLoadOptions o;
  o.load_parts = false;
  o.use_cache = false;
  return o;
}

namespace fs = std::filesystem;

const std::string kData = std::string(LOOM_TEST_DATA) + "/formboard/";
const std::string kMini = kData + "mini-2d.kbl";
const std::string kVecSample = std::string(LOOM_SHARED_DATA) + "/kbl/routing-examples.vec";

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

int line_of(const std::string& text, const std::string& needle) {
  int line = 1;
  for (std::size_t i = 0; i < text.find(needle); ++i) line += text[i] == '\n';
  return line;
}

/// The InputError `f` throws (fails the test if it throws none).
template <class F>
std::string refusal(F f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected an InputError";
  return {};
}

void expect_all(const std::string& text, const std::vector<std::string>& needles) {
  for (const auto& n : needles) EXPECT_NE(text.find(n), std::string::npos) << n << "\n" << text;
}

// ---- reading ----------------------------------------------------------------------

TEST(FormboardKbl, ReadsAsTopologyWithTheDrawingsLengths) {
  const Harness h = read_harness_kbl(kMini);
  ASSERT_EQ(h.ports.size(), 3u);
  for (const auto& p : h.ports) EXPECT_FALSE(p.placed) << p.id;
  EXPECT_GE(h.find_port("X1"), 0);
  EXPECT_GE(h.find_port("X2"), 0);
  EXPECT_GE(h.find_port("X3"), 0);
  ASSERT_EQ(h.branches.size(), 1u);
  EXPECT_EQ(h.branches[0].id, "N2");
  EXPECT_FALSE(h.branches[0].position);
  ASSERT_EQ(h.segments.size(), 3u);
  const double nominal[3] = {200, 260, 260};  // the Virtual_length of S1, S2, S3
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_FALSE(h.segments[k].bspline);
    ASSERT_TRUE(h.segments[k].nominal_length);
    EXPECT_DOUBLE_EQ(*h.segments[k].nominal_length, nominal[k]);
  }
  EXPECT_EQ(h.segments[0].from, "X1");
  EXPECT_EQ(h.segments[0].to, "N2");
  ASSERT_EQ(h.cables.size(), 2u);
  EXPECT_EQ(h.cables[1].id, "W2");
  EXPECT_EQ(h.cables[1].ports[1], "X3");
  EXPECT_DOUBLE_EQ(h.cables[1].physical.diameter, 2.5);
  EXPECT_DOUBLE_EQ(h.cables[1].physical.min_bend_radius, 10.0);
  // The fixing's placement is on the drawing: not taken as a 3D position.
  EXPECT_TRUE(h.clamps.empty());
  bool said = false;
  for (const auto& n : h.kbl->notes) said = said || n.find("fixing 'K1'") != std::string::npos;
  EXPECT_TRUE(said);
}

// Written back with its ports placed but its branch point still open (what `loom audit`
// of an unrouted scene writes): the file reads as 3D, the branch point open, the drawing's
// lengths kept.
TEST(FormboardKbl, PlacedPortsWriteBackAs3DWithTheBranchPointOpen) {
  Harness h = read_harness_kbl(kMini);
  for (std::size_t i = 0; i < h.ports.size(); ++i) {
    h.ports[i].position = Vec3(100.0 * static_cast<double>(i), 5.0, 50.0);
    h.ports[i].placed = true;
  }
  const Harness back = parse_harness_kbl(harness_to_kbl(h), "written.kbl");
  for (std::size_t i = 0; i < h.ports.size(); ++i) {
    EXPECT_TRUE(back.ports[i].placed);
    EXPECT_EQ(back.ports[i].position, h.ports[i].position);
  }
  EXPECT_FALSE(back.branches[0].position);
  for (const auto& s : back.segments) EXPECT_FALSE(s.bspline);
  // Unrouted segments keep their Virtual_length; in a 3D file that is no nominal length.
  const std::string text = harness_to_kbl(h);
  EXPECT_NE(text.find("<Value_component>260</Value_component>"), std::string::npos);
  // Nothing placed: the drawing is written back as it was read.
  const Harness again = parse_harness_kbl(harness_to_kbl(read_harness_kbl(kMini)), "again.kbl");
  for (const auto& p : again.ports) EXPECT_FALSE(p.placed);
  EXPECT_DOUBLE_EQ(*again.segments[1].nominal_length, 260.0);
}

TEST(FormboardKbl, A2DPointAmong3DOnesIsRefusedAtThatPoint) {
  const std::string text = slurp(kMini);
  // Every node in 3D but N3: its 2D point has no 3D position to take.
  std::string t = text;
  for (const char* p : {"P1", "P2", "P4"})
    t = replaced(t, std::string("<Cartesian_point id=\"") + p + "\"><Coordinates>", std::string("<Cartesian_point id=\"") + p +
                                                                                       "\"><Coordinates>0</Coordinates><Coordinates>");
  const std::string e = refusal([&] { parse_harness_kbl(t, "mini.kbl"); });
  expect_all(e, {"mini.kbl:" + std::to_string(line_of(t, "<Cartesian_point id=\"P3\"")) + ":", "2D (formboard) point of node 'N3'",
                 "3 other nodes have 3D"});
}

TEST(FormboardKbl, AWireWithoutItsDiameterIsRefusedNamingIt) {
  const std::string t = replaced(slurp(kMini),
                                 "<Outside_diameter id=\"OD\"><Unit_component>U_mm</Unit_component><Value_component>2.5</"
                                 "Value_component></Outside_diameter>",
                                 "");
  expect_all(refusal([&] { parse_harness_kbl(t, "mini.kbl"); }),
             {"mini.kbl:" + std::to_string(line_of(t, "<General_wire id=\"GW\"")) + ":", "<Outside_diameter>", "WO1"});
}

TEST(FormboardKbl, ANonPositiveLengthIsRefused) {
  const std::string t = replaced(slurp(kMini), "<Value_component>260</Value_component></Virtual_length>",
                                 "<Value_component>-5</Value_component></Virtual_length>");
  expect_all(refusal([&] { parse_harness_kbl(t, "mini.kbl"); }),
             {"mini.kbl:" + std::to_string(line_of(t, "<Virtual_length id=\"VL2\"")) + ":", "must be positive"});
}

TEST(VecTopology, TheGuidelineSampleIsRefusedNamingTheWireWithoutDiameter) {
  const std::string text = slurp(kVecSample);
  expect_all(refusal([&] { read_harness_vec(kVecSample); }),
             {"routing-examples.vec:" + std::to_string(line_of(text, "<WireElementReference id=\"WireElementReference_00093\"")) + ":",
              "wire 'W1'", "has no <OutsideDiameter>"});
}

TEST(VecTopology, BothVariantsTogetherAreACycleSaidAtASegment) {
  const std::string t = replaced(slurp(kVecSample), "<ConductorSpecification>",
                                 "<OutsideDiameter id=\"OD\"><ValueComponent>1.6</ValueComponent></OutsideDiameter>\n"
                                 "      <ConductorSpecification>");
  const std::string e = refusal([&] { parse_harness_vec(t, "both.vec"); });
  expect_all(e, {"both.vec:", "<TopologySegment id=\"TopologySegment_000", "cycle", "2 variant configurations"});
}

TEST(VecTopology, OneVariantReadsAsTopologyWithItsLengths) {
  const Harness h = read_harness_vec(kData + "routing-examples-rl.vec");
  ASSERT_EQ(h.ports.size(), 3u);
  for (const char* id : {"A1", "A2", "A3"}) {
    const int p = h.find_port(id);
    ASSERT_GE(p, 0) << id;
    EXPECT_FALSE(h.ports[static_cast<std::size_t>(p)].placed);
  }
  ASSERT_EQ(h.branches.size(), 4u);
  for (const char* id : {"ND-2", "ND-4", "ND-5", "ND-6"}) {
    const int b = h.find_branch(id);
    ASSERT_GE(b, 0) << id;
    EXPECT_FALSE(h.branches[static_cast<std::size_t>(b)].position);
  }
  // Segments as the file lists them (SEG-2, SEG-1, SEG-3 .. SEG-6) with their adapted lengths.
  ASSERT_EQ(h.segments.size(), 6u);
  const double nominal[6] = {150, 150, 200, 120, 120, 150};
  for (std::size_t k = 0; k < 6; ++k) {
    ASSERT_TRUE(h.segments[k].nominal_length) << k;
    EXPECT_DOUBLE_EQ(*h.segments[k].nominal_length, nominal[k]);
  }
  EXPECT_EQ(h.segments[0].from, "A1");
  EXPECT_EQ(h.segments[0].to, "ND-2");
  ASSERT_EQ(h.cables.size(), 3u);
  for (const auto& c : h.cables) {
    EXPECT_DOUBLE_EQ(c.physical.diameter, 1.6) << c.id;
    EXPECT_DOUBLE_EQ(c.physical.min_bend_radius, 8.0) << c.id;
    EXPECT_EQ(c.ports[0], "A1");
  }
  EXPECT_EQ(h.cables[h.find_cable("W2")].ports[1], "A3");
  // Lines are the VEC file's, where each element is (not those of its KBL reading).
  const std::string text = slurp(kData + "routing-examples-rl.vec");
  EXPECT_EQ(h.ports[static_cast<std::size_t>(h.find_port("A1"))].line, line_of(text, "<TopologyNode id=\"TopologyNode_00024\""));
  EXPECT_EQ(h.branches[static_cast<std::size_t>(h.find_branch("ND-4"))].line, line_of(text, "<TopologyNode id=\"TopologyNode_00027\""));
  EXPECT_EQ(h.segments[3].line, line_of(text, "<TopologySegment id=\"TopologySegment_00035\""));
  EXPECT_EQ(h.cables[h.find_cable("W2")].line, line_of(text, "<WireElementReference id=\"WireElementReference_00098\""));
  bool loop = false;
  for (const auto& n : h.kbl->notes) loop = loop || n.find("routing 'W3'") != std::string::npos;
  EXPECT_TRUE(loop);
}

// ---- the scene places the ports -----------------------------------------------------

/// A scene file beside the test data naming `harness` and holding `extra` TOML.
struct TempScene {
  fs::path dir;
  fs::path file;
  TempScene(const std::string& name, const std::string& harness, const std::string& extra) {
    dir = fs::temp_directory_path() / ("loom_formboard_" + name + "_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    file = dir / "scene.toml";
    std::ofstream(file) << "[scene]\nname = \"" << name << "\"\nunits = \"mm\"\n\n[harness]\nfile = \"" << harness << "\"\n"
                        << extra;
  }
  ~TempScene() { fs::remove_all(dir); }
};

const char* kPlaceAll =
    "\n[harness.place]\n"
    "X1 = { at = [0.0, 0.0, 50.0], dir = [2.0, 0.0, 0.0] }\n"
    "N3 = { at = [440.0, 100.0, 50.0], dir = [-1.0, 0.0, 0.0] }\n"
    "X3 = { at = [440.0, -100.0, 50.0], dir = [0.0, 0.0, -3.0] }\n";

TEST(FormboardScene, PlacedPortsTakeTheTablesPositionsAndDirections) {
  TempScene s("placed", kMini, kPlaceAll);
  SceneLoadReport rep;
  const Scene scene = load_scene(s.file, settings_only(), &rep);
  const Harness& h = scene.harness;
  const auto& x1 = h.ports[static_cast<std::size_t>(h.find_port("X1"))];
  const auto& x2 = h.ports[static_cast<std::size_t>(h.find_port("X2"))];  // placed by its Node id N3
  const auto& x3 = h.ports[static_cast<std::size_t>(h.find_port("X3"))];
  for (const auto* p : {&x1, &x2, &x3}) EXPECT_TRUE(p->placed);
  EXPECT_EQ(x1.position, Vec3(0, 0, 50));
  EXPECT_EQ(x1.direction, Vec3(1, 0, 0));
  EXPECT_EQ(x2.position, Vec3(440, 100, 50));
  EXPECT_EQ(x3.direction, Vec3(0, 0, -1));
  EXPECT_FALSE(h.branches[0].position);  // the router's
  bool said = false;
  for (const auto& n : rep.notes)
    said = said || n.find("no 3D geometry: topology only, 3 nodes to be placed by the scene, 1 by the router") != std::string::npos;
  EXPECT_TRUE(said);
}

TEST(FormboardScene, MissingPlacementsAreAllNamedWithTheTable) {
  TempScene s("missing", kMini, "\n[harness.place]\nX1 = { at = [0.0, 0.0, 50.0], dir = [1.0, 0.0, 0.0] }\n");
  const std::string text = slurp(kMini);
  const std::string e = refusal([&] { load_scene(s.file, settings_only()); });
  expect_all(e, {kMini + ":" + std::to_string(line_of(text, "<Node id=\"N3\"")) + ":", "2 ports have no position",
                 "X2 (line " + std::to_string(line_of(text, "<Node id=\"N3\"")) + ")",
                 "X3 (line " + std::to_string(line_of(text, "<Node id=\"N4\"")) + ")", "[harness.place]",
                 s.file.string()});
  EXPECT_EQ(e.find("X1 (line"), std::string::npos) << e;
  // No table at all: all three.
  TempScene none("none", kMini, "");
  expect_all(refusal([&] { load_scene(none.file, settings_only()); }), {"3 ports have no position", "X1 (line"});
}

TEST(FormboardScene, ABadPlacementIsNamedAtItsKey) {
  const std::string head = "\n[harness.place]\n";
  const std::vector<std::pair<std::string, std::vector<std::string>>> cases{
      {"N2 = { at = [1.0, 2.0, 3.0], dir = [1.0, 0.0, 0.0] }\n", {"harness.place.N2", "is a branch point", "the router places"}},
      {"X9 = { at = [1.0, 2.0, 3.0], dir = [1.0, 0.0, 0.0] }\n", {"harness.place.X9", "is no port of harness file"}},
      {"X1 = { at = [1.0, 2.0, 3.0], dir = [0.0, 0.0, 0.0] }\n", {"harness.place.X1.dir", "must not be zero"}},
      {"X1 = { at = [1.0, 2.0], dir = [1.0, 0.0, 0.0] }\n", {"harness.place.X1.at", "3 numbers"}},
      {"X1 = { at = [1.0, 2.0, 3.0] }\n", {"harness.place.X1", "needs both 'at'"}},
      {"X1 = { at = [1.0, 2.0, 3.0], dir = [1.0, 0.0, 0.0], up = 1 }\n", {"harness.place.X1.up", "unknown key"}},
      {"X1 = [1.0, 2.0, 3.0]\n", {"harness.place.X1", "expected an inline table"}}};
  for (const auto& [toml, needles] : cases) {
    TempScene s("bad", kMini, head + toml);
    std::vector<std::string> all = needles;
    all.push_back(s.file.string() + ":9:");  // the key's line: 6 lines of [scene] and [harness] above
    expect_all(refusal([&] { load_scene(s.file, settings_only()); }), all);
  }
}

TEST(FormboardScene, APlacementMovesA3DPortAndFreesItsSegments) {
  const std::string gen = std::string(LOOM_SOURCE_DIR) + "/examples/kbl-generator/generator.kbl";
  const Harness file = read_harness_kbl(gen);
  ASSERT_FALSE(file.ports.empty());
  const std::string id = file.ports[0].id;
  TempScene s("moved", gen, "\n[harness.place]\n\"" + id + "\" = { at = [1.0, 2.0, 3.0], dir = [0.0, 1.0, 0.0] }\n");
  SceneLoadReport rep;
  const Scene scene = load_scene(s.file, settings_only(), &rep);
  const Harness& h = scene.harness;
  EXPECT_EQ(h.ports[0].position, Vec3(1, 2, 3));
  int freed = 0, kept = 0;
  for (std::size_t k = 0; k < h.segments.size(); ++k) {
    const bool touches = h.segments[k].from == id || h.segments[k].to == id;
    EXPECT_EQ(h.segments[k].bspline.has_value(), !touches && file.segments[k].bspline.has_value()) << k;
    (touches ? freed : kept) += 1;
  }
  EXPECT_GE(freed, 1);
  std::string notes;
  for (const auto& n : rep.notes) notes += n + "\n";
  expect_all(notes, {"port '" + id + "': the scene's [harness.place] moves it", "the router plans it"});
}

}  // namespace
}  // namespace loom
