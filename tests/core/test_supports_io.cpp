// Supports and cable classes on input: <clamp> and class="..." in the harness XML (read,
// written, read again; each bad value named by line), and [routing] clamp_spacing,
// clamp_reach and [routing.separation] in the scene.
#include "core/error.hpp"
#include "core/io/harness_xml.hpp"
#include "core/io/scene_load.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

namespace loom {
namespace {

namespace fs = std::filesystem;

/// A harness of two cables through branch B, with `extra` inserted into <structure> and
/// `cls` as the first cable's class attribute text.
std::string harness(const std::string& extra, const std::string& cls = " class=\"power\"") {
  return R"(<harness name="H" units="mm">
  <attributes>
    <cable id="C1"><electrical><port id="A"/><port id="B"/></electrical>
      <physical type="t" color="c" diameter="2" min_bend_radius="20")" +
         cls + R"(/></cable>
    <cable id="C2"><electrical><port id="A2"/><port id="B"/></electrical>
      <physical type="t" color="c" diameter="4" min_bend_radius="20"/></cable>
  </attributes>
  <structure>
    <port id="A" x="0" y="0" z="0" dx="1" dy="0" dz="0"/>
    <port id="A2" x="0" y="10" z="0" dx="1" dy="0" dz="0"/>
    <port id="B" x="100" y="0" z="0" dx="-1" dy="0" dz="0"/>
)" + extra + R"(
    <branch id="J" x="50" y="5" z="0"><segment to="A"/><segment to="A2"/><segment to="B"/></branch>
  </structure>
</harness>
)";
}

/// The message of the InputError that parsing `text` throws ("" if none).
std::string parse_error(const std::string& text) {
  try {
    parse_harness_xml(text, "h.xml");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(HarnessClamps, ReadWrittenAndReadAgain) {
  const Harness h = parse_harness_xml(
      harness(R"(<clamp id="K1" x="70" y="2" z="0" segment="B/J"/>
    <clamp id="K2" x="20" y="1" z="0" segment="J/A" part="rib" placed="true"/>
    <clamp id="K3" x="1" y="2" z="3"/>)"),
      "h.xml");
  ASSERT_EQ(h.clamps.size(), 3u);
  EXPECT_EQ(h.clamps[0].id, "K1");
  EXPECT_EQ(h.clamps[0].position, Vec3(70, 2, 0));
  ASSERT_GE(h.clamps[0].segment, 0);
  const Segment& s0 = h.segments[static_cast<std::size_t>(h.clamps[0].segment)];
  EXPECT_EQ(s0.from + s0.to, "JB");  // either end first names the same segment
  EXPECT_FALSE(h.clamps[0].placed);
  EXPECT_EQ(h.clamps[0].line, 12);
  EXPECT_EQ(h.clamps[1].part, "rib");
  EXPECT_TRUE(h.clamps[1].placed);
  EXPECT_EQ(h.clamps[2].segment, -1);
  EXPECT_EQ(h.cables[0].physical.cable_class, "power");
  EXPECT_EQ(h.cables[1].physical.cable_class, "");

  const Harness again = parse_harness_xml(harness_to_xml(h), "again.xml");
  ASSERT_EQ(again.clamps.size(), h.clamps.size());
  for (std::size_t k = 0; k < h.clamps.size(); ++k) {
    EXPECT_EQ(again.clamps[k].id, h.clamps[k].id);
    EXPECT_EQ(again.clamps[k].position, h.clamps[k].position);
    EXPECT_EQ(again.clamps[k].segment, h.clamps[k].segment);
    EXPECT_EQ(again.clamps[k].part, h.clamps[k].part);
    EXPECT_EQ(again.clamps[k].placed, h.clamps[k].placed);
  }
  EXPECT_EQ(again.cables[0].physical.cable_class, "power");
  EXPECT_EQ(again.cables[1].physical.cable_class, "");
}

TEST(HarnessClamps, BadClampsAreNamedByLine) {
  struct Case {
    std::string clamp, needle;
  };
  const Case cases[] = {
      {R"(<clamp id="K" x="1" y="2" z="3" segment="J/Q"/>)", "unknown segment 'J/Q'"},
      {R"(<clamp id="K" x="1" y="2" z="3" segment=""/>)", "'segment' is empty"},
      {R"(<clamp id="K" x="nan" y="2" z="3"/>)", "not finite"},
      {R"(<clamp id="K" y="2" z="3"/>)", "missing attribute 'x'"},
      {R"(<clamp x="1" y="2" z="3"/>)", "missing attribute 'id'"},
      {R"(<clamp id="K" x="1" y="2" z="3" placed="yes"/>)", "placed must be 'true' or 'false'"},
      {R"(<clamp id="K" x="1" y="2" z="3" load="5"/>)", "unknown attribute 'load'"},
      {R"(<clamp id="K" x="1" y="2" z="3"/><clamp id="K" x="1" y="2" z="4"/>)", "duplicate clamp id"},
      {R"(<clamp id="K" x="1" y="2" z="3"><pt x="0" y="0" z="0"/></clamp>)", "unexpected element <pt>"},
  };
  for (const Case& c : cases) {
    const std::string msg = parse_error(harness(c.clamp));
    EXPECT_NE(msg.find("h.xml:12"), std::string::npos) << c.clamp << " → " << msg;
    EXPECT_NE(msg.find(c.needle), std::string::npos) << c.clamp << " → " << msg;
  }
  EXPECT_NE(parse_error(harness("", " class=\"\"")).find("'class' is empty"), std::string::npos);
}

/// A scratch directory with the clamp-free harness and a scene file written per test.
class SupportScene : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("loom_supports_io_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::create_directories(dir_);
    std::ofstream(dir_ / "h.xml") << harness("");
  }
  void TearDown() override { fs::remove_all(dir_); }
  Scene load(const std::string& routing, const std::string& units = "mm") {
    std::ofstream(dir_ / "s.toml") << "[scene]\nname='s'\nunits='" << units << "'\n[harness]\nfile='h.xml'\n" << routing;
    return load_scene(dir_ / "s.toml");
  }
  std::string error(const std::string& routing) {
    try {
      load(routing);
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  }
  fs::path dir_;
};

TEST_F(SupportScene, DefaultsAreInSceneUnitsAndLeaveSupportsUnchecked) {
  const Scene mm = load("");
  EXPECT_DOUBLE_EQ(mm.routing.clamp_spacing.value, 450.0);
  EXPECT_DOUBLE_EQ(mm.routing.clamp_reach.value, 25.0);
  EXPECT_FALSE(mm.routing.supports);
  EXPECT_TRUE(mm.routing.separation.empty());
  std::ofstream(dir_ / "h.xml") << R"(<harness name="H" units="m"/>)";
  const Scene m = load("", "m");
  EXPECT_DOUBLE_EQ(m.routing.clamp_spacing.value, 0.45);
  EXPECT_DOUBLE_EQ(m.routing.clamp_reach.value, 0.025);
}

TEST_F(SupportScene, GivenSpacingReachAndSeparation) {
  const Scene s = load("[routing]\nclamp_spacing = 300\nclamp_reach = 10.5\n[routing.separation]\npower.signal = 50.0\n"
                       "signal.power = 50\nsignal.signal = 2\n");
  EXPECT_TRUE(s.routing.supports);
  EXPECT_DOUBLE_EQ(s.routing.clamp_spacing.value, 300.0);
  EXPECT_DOUBLE_EQ(s.routing.clamp_reach.value, 10.5);
  EXPECT_DOUBLE_EQ(s.routing.separation_between("power", "signal"), 50.0);
  EXPECT_DOUBLE_EQ(s.routing.separation_between("signal", "power"), 50.0);
  EXPECT_DOUBLE_EQ(s.routing.separation_between("signal", "signal"), 2.0);
  EXPECT_DOUBLE_EQ(s.routing.separation_between("power", "power"), 0.0);
  EXPECT_DOUBLE_EQ(s.routing.separation_between("", "signal"), 0.0);
}

TEST_F(SupportScene, BadValuesAreNamed) {
  struct Case {
    std::string routing, needle;
  };
  const Case cases[] = {
      {"[routing]\nclamp_spacing = 0\n", "routing.clamp_spacing"},
      {"[routing]\nclamp_spacing = -5\n", "must be positive"},
      {"[routing]\nclamp_reach = nan\n", "routing.clamp_reach"},
      {"[routing]\nclamp_reach = inf\n", "finite"},
      {"[routing]\nclamp_spacing = 'far'\n", "expected a number"},
      {"[routing]\nseparation = 5\n", "expected a table [routing.separation]"},
      {"[routing.separation]\npower = 5\n", "expected CLASS.CLASS = distance"},
      {"[routing.separation]\npower.signal = 'x'\n", "routing.separation.power.signal"},
      {"[routing.separation]\npower.signal = -1\n", "must be positive"},
      {"[routing.separation]\npower.signal = 50\nsignal.power = 40\n", "symmetric"},
  };
  for (const Case& c : cases) {
    const std::string msg = error(c.routing);
    EXPECT_NE(msg.find("s.toml:"), std::string::npos) << c.routing << " → " << msg;
    EXPECT_NE(msg.find(c.needle), std::string::npos) << c.routing << " → " << msg;
  }
}

}  // namespace
}  // namespace loom
