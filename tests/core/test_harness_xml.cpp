// Harness XML: lossless round trip and the bad-input catalogue (each error names the line).
#include "core/error.hpp"
#include "core/geometry.hpp"
#include "core/harness_topology.hpp"
#include "core/io/harness_xml.hpp"

#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <filesystem>
#include <fstream>

namespace loom {
namespace {

const char* kSample = R"(<?xml version="1.0"?>
<harness name="W1" units="mm">
  <attributes>
    <cable id="C1">
      <electrical><port id="J1.1"/><port id="J3.4"/></electrical>
      <physical type="AWG20" color="red" diameter="1.8" min_bend_radius="18"/>
    </cable>
    <cable id="C2">
      <electrical><port id="J2.1"/><port id="J3.4"/></electrical>
      <physical type="AWG22" color="blue" diameter="1.2" min_bend_radius="12"/>
    </cable>
    <cable id="C3">
      <electrical><port id="J4.1"/><port id="J4.2"/></electrical>
      <physical type="AWG22" color="white" diameter="1.2" min_bend_radius="12"/>
    </cable>
  </attributes>
  <structure>
    <segment from="J4.1" to="J4.2">
      <path interp="polyline"><pt x="0" y="5" z="0"/><pt x="0.1" y="5" z="0.25"/></path>
    </segment>
    <port id="J1.1" x="0" y="0" z="0" dx="1" dy="0" dz="0"/>
    <port id="J2.1" x="0" y="100" z="0" dx="1" dy="0" dz="0"/>
    <port id="J3.4" x="300" y="50" z="0" dx="-1" dy="0" dz="0"/>
    <port id="J4.1" x="0" y="0" z="50" dx="0" dy="0" dz="1"/>
    <port id="J4.2" x="0" y="10" z="50" dx="0" dy="0" dz="1"/>
    <branch id="B1" x="120" y="40" z="10">
      <segment to="J1.1">
        <path interp="bspline"><pt x="60" y="10" z="5"/></path>
      </segment>
      <segment to="J2.1"/>
      <segment to="J3.4" diameter="3.5">
        <bspline degree="3" knots="0 0 0 0 1 1 1 1">
          <cp x="120" y="40" z="10"/><cp x="180" y="45" z="8"/><cp x="240" y="50" z="2"/><cp x="300" y="50" z="0"/>
        </bspline>
      </segment>
    </branch>
  </structure>
</harness>
)";

void expect_same(const Harness& a, const Harness& b) {
  EXPECT_EQ(a.name, b.name);
  EXPECT_EQ(a.units, b.units);
  ASSERT_EQ(a.cables.size(), b.cables.size());
  for (std::size_t i = 0; i < a.cables.size(); ++i) {
    EXPECT_EQ(a.cables[i].id, b.cables[i].id);
    EXPECT_EQ(a.cables[i].ports[0], b.cables[i].ports[0]);
    EXPECT_EQ(a.cables[i].ports[1], b.cables[i].ports[1]);
    EXPECT_EQ(a.cables[i].physical.type, b.cables[i].physical.type);
    EXPECT_EQ(a.cables[i].physical.color, b.cables[i].physical.color);
    EXPECT_EQ(a.cables[i].physical.diameter, b.cables[i].physical.diameter);
    EXPECT_EQ(a.cables[i].physical.min_bend_radius, b.cables[i].physical.min_bend_radius);
  }
  ASSERT_EQ(a.ports.size(), b.ports.size());
  for (std::size_t i = 0; i < a.ports.size(); ++i) {
    EXPECT_EQ(a.ports[i].id, b.ports[i].id);
    EXPECT_EQ(a.ports[i].position, b.ports[i].position);
    EXPECT_EQ(a.ports[i].direction, b.ports[i].direction);
  }
  ASSERT_EQ(a.branches.size(), b.branches.size());
  for (std::size_t i = 0; i < a.branches.size(); ++i) {
    EXPECT_EQ(a.branches[i].id, b.branches[i].id);
    EXPECT_EQ(a.branches[i].position.has_value(), b.branches[i].position.has_value());
    if (a.branches[i].position && b.branches[i].position) {
      EXPECT_EQ(*a.branches[i].position, *b.branches[i].position);
    }
  }
  ASSERT_EQ(a.segments.size(), b.segments.size());
  for (std::size_t i = 0; i < a.segments.size(); ++i) {
    const auto &x = a.segments[i], &y = b.segments[i];
    EXPECT_EQ(x.from, y.from);
    EXPECT_EQ(x.to, y.to);
    EXPECT_EQ(x.path, y.path);
    EXPECT_EQ(x.interp, y.interp);
    EXPECT_EQ(x.diameter, y.diameter);
    EXPECT_EQ(x.parent_branch, y.parent_branch);
    ASSERT_EQ(x.bspline.has_value(), y.bspline.has_value());
    if (x.bspline) {
      EXPECT_EQ(x.bspline->degree, y.bspline->degree);
      EXPECT_EQ(x.bspline->knots, y.bspline->knots);
      EXPECT_EQ(x.bspline->control_points, y.bspline->control_points);
    }
  }
}

TEST(HarnessXml, ReadsEveryField) {
  Harness h = parse_harness_xml(kSample, "sample.xml");
  EXPECT_EQ(h.name, "W1");
  ASSERT_EQ(h.cables.size(), 3u);
  EXPECT_EQ(h.cables[0].ports[1], "J3.4");
  EXPECT_DOUBLE_EQ(h.cables[0].physical.diameter, 1.8);
  EXPECT_EQ(h.cables[1].physical.color, "blue");
  ASSERT_EQ(h.ports.size(), 5u);
  EXPECT_EQ(h.ports[2].direction, Vec3(-1, 0, 0));
  ASSERT_EQ(h.branches.size(), 1u);
  EXPECT_EQ(*h.branches[0].position, Vec3(120, 40, 10));
  ASSERT_EQ(h.segments.size(), 4u);
  // Canonical order: nested segments first, then top-level ones.
  EXPECT_EQ(h.segments[0].from, "B1");
  EXPECT_EQ(h.segments[0].path.size(), 1u);
  EXPECT_EQ(h.segments[2].diameter, 3.5);
  ASSERT_TRUE(h.segments[2].bspline.has_value());
  EXPECT_EQ(h.segments[2].bspline->control_points.size(), 4u);
  EXPECT_EQ(h.segments[3].interp, Interp::Polyline);
  EXPECT_EQ(h.segments[3].from, "J4.1");
  EXPECT_GT(h.cables[0].line, 3);
}

TEST(HarnessXml, RoundTripIsLossless) {
  Harness a = parse_harness_xml(kSample, "sample.xml");
  const std::string text = harness_to_xml(a);
  Harness b = parse_harness_xml(text, "written.xml");
  expect_same(a, b);
  EXPECT_EQ(harness_to_xml(b), text);  // and the writer is a fixed point
}

TEST(HarnessXml, RoundTripThroughFile) {
  Harness a = parse_harness_xml(kSample, "sample.xml");
  const auto path = std::filesystem::temp_directory_path() / "loom_test_roundtrip.xml";
  write_harness_xml(a, path);
  Harness b = read_harness_xml(path);
  expect_same(a, b);
  std::filesystem::remove(path);
}

// Full-precision numbers survive the round trip bit for bit.
RC_GTEST_PROP(HarnessXmlProps, CoordinatesRoundTripExactly, ()) {
  Harness a = parse_harness_xml(kSample, "sample.xml");
  // Any double within the accepted magnitude (fmod keeps every mantissa bit of small ones).
  const auto x = std::fmod(*rc::gen::arbitrary<double>(), kMaxInputMagnitude);
  const auto y = std::fmod(*rc::gen::arbitrary<double>(), kMaxInputMagnitude);
  RC_PRE(std::isfinite(x) && std::isfinite(y));
  a.ports[0].position = Vec3(x, y, x * 0.1);
  a.segments[0].path[0] = Vec3(y, x, 1e-300);
  Harness b = parse_harness_xml(harness_to_xml(a), "w.xml");
  RC_ASSERT(b.ports[0].position == a.ports[0].position);
  RC_ASSERT(b.segments[0].path[0] == a.segments[0].path[0]);
}

RC_GTEST_PROP(HarnessXmlProps, CoordinatesBeyondTheInputMagnitudeAreRefused, ()) {
  Harness a = parse_harness_xml(kSample, "sample.xml");
  const double x = *rc::gen::inRange(1, 1000000) * 1e-3 + 1.0;  // (1, 1001]
  a.ports[0].position = Vec3(0.0, (x > 500.0 ? -1.0 : 1.0) * x * kMaxInputMagnitude, 0.0);
  RC_ASSERT_THROWS_AS(parse_harness_xml(harness_to_xml(a), "w.xml"), InputError);
}

/// Replaces the first occurrence of `from` in the sample and expects an InputError whose
/// message contains every needle (including the line number where given).
void expect_bad(const std::string& from, const std::string& to, std::vector<std::string> needles) {
  std::string text = kSample;
  const auto at = text.find(from);
  ASSERT_NE(at, std::string::npos) << from;
  text.replace(at, from.size(), to);
  try {
    parse_harness_xml(text, "bad.xml");
    FAIL() << "expected an error for: " << to;
  } catch (const InputError& e) {
    for (const auto& n : needles) EXPECT_NE(std::string(e.what()).find(n), std::string::npos) << e.what();
    EXPECT_EQ(e.where().file, "bad.xml");
  }
}

TEST(HarnessXml, UnknownPortId) {
  expect_bad(R"(<port id="J3.4"/></electrical>
      <physical type="AWG20")", R"(<port id="J9.9"/></electrical>
      <physical type="AWG20")", {"bad.xml:4:", "cable 'C1'", "unknown port id 'J9.9'"});
}

// The patent's branch points join exactly 3 nodes; loom reads any degree and notes it.
TEST(HarnessXml, BranchWithFourConnectionsIsReadWithANote) {
  std::string text = kSample;
  const std::string from = R"(<segment to="J2.1"/>)";
  text.replace(text.find(from), from.size(), R"(<segment to="J2.1"/><segment to="J4.1"/>)");
  const Harness h = parse_harness_xml(text, "four.xml");
  const HarnessTopology t(h);
  EXPECT_EQ(t.incident_segments("B1").size(), 4u);
  ASSERT_EQ(t.notes().size(), 1u);
  EXPECT_NE(t.notes()[0].find("branch 'B1' joins 4 nodes"), std::string::npos) << t.notes()[0];
}

TEST(HarnessXml, BranchWithTwoConnectionsIsAPassThroughPoint) {
  // B1 keeps J1.1 and J3.4 only: C1 runs through it; C2 and J2.1 go.
  std::string text = kSample;
  for (const std::string cut : {R"(<segment to="J2.1"/>)", R"(<port id="J2.1" x="0" y="100" z="0" dx="1" dy="0" dz="0"/>)"})
    text.erase(text.find(cut), cut.size());
  const auto c2 = text.find(R"(<cable id="C2">)");
  text.erase(c2, text.find("</cable>", c2) + 8 - c2);
  const Harness h = parse_harness_xml(text, "two.xml");
  const HarnessTopology t(h);
  EXPECT_EQ(t.incident_segments("B1").size(), 2u);
  EXPECT_EQ(t.cable_chain(h.find_cable("C1")).size(), 2u);
  ASSERT_EQ(t.notes().size(), 1u);
  EXPECT_NE(t.notes()[0].find("two.xml:"), std::string::npos) << t.notes()[0];
  EXPECT_NE(t.notes()[0].find("branch 'B1' joins 2 nodes: a pass-through point"), std::string::npos) << t.notes()[0];
}

TEST(HarnessXml, Cycle) {
  expect_bad(R"(<segment from="J4.1" to="J4.2">)", R"(<segment from="J4.1" to="J4.2"></segment><segment from="J4.2" to="J1.1"></segment><segment from="J4.1" to="J2.1">)",
             {"cycle"});
}

TEST(HarnessXml, DisconnectedCable) {
  expect_bad(R"(<port id="J4.2"/>)", R"(<port id="J1.1"/>)", {"cable 'C3'", "not connected"});
}

TEST(HarnessXml, DuplicateIds) {
  expect_bad(R"(<cable id="C2">)", R"(<cable id="C1">)", {"duplicate cable id"});
  expect_bad(R"(<port id="J2.1" x)", R"(<port id="J1.1" x)", {"duplicate node id"});
}

TEST(HarnessXml, NonPositiveDiameter) {
  expect_bad(R"(diameter="1.8")", R"(diameter="0")", {"bad.xml:6:", "<physical>", "diameter must be positive"});
  expect_bad(R"(diameter="1.8")", R"(diameter="-2")", {"diameter must be positive"});
}

TEST(HarnessXml, NanAndInfCoordinates) {
  expect_bad(R"(x="300")", R"(x="nan")", {"<port id=\"J3.4\">", "not finite"});
  expect_bad(R"(x="60")", R"(x="inf")", {"<pt>", "not finite"});
  expect_bad(R"(x="300")", R"(x="3e400")", {"not finite"});
  expect_bad(R"(x="300")", R"(x="abc")", {"not a number"});
}

TEST(HarnessXml, ZeroLengthPortDirection) {
  expect_bad(R"(dx="-1" dy="0" dz="0")", R"(dx="0" dy="0" dz="0")", {"J3.4", "zero length"});
}

TEST(HarnessXml, MalformedXmlNamesLine) {
  expect_bad("</attributes>", "</attribute>", {"bad.xml:", "malformed XML"});
}

TEST(HarnessXml, UnknownElementAndAttribute) {
  expect_bad("<attributes>", "<attributes><wire/>", {"unexpected element <wire>"});
  expect_bad(R"(color="red")", R"(colr="red")", {"unknown attribute 'colr'"});
}

TEST(HarnessXml, BadSplines) {
  expect_bad(R"(knots="0 0 0 0 1 1 1 1")", R"(knots="0 0 0 1 1 1 1")", {"expected 8 knots"});
  expect_bad(R"(knots="0 0 0 0 1 1 1 1")", R"(knots="0 0 0 0 1 0.5 1 1")", {"must not decrease"});
  expect_bad(R"(interp="polyline")", R"(interp="spline")", {"interp must be"});
}

// Attribute values travel into report.json and view.html, which are UTF-8: a byte that is
// not valid UTF-8 is refused where it is read, naming the line, element and attribute.
TEST(HarnessXml, AttributeValuesMustBeUtf8) {
  expect_bad(R"(color="red")", "color=\"r\xff\xfe" "d\"", {"bad.xml:6:", "<physical>", "'color'", "not valid UTF-8"});
  expect_bad(R"(<cable id="C2">)", "<cable id=\"C\xc3\x28" "2\">", {"bad.xml:8:", "'id'", "not valid UTF-8"});
  expect_bad(R"(color="red")", "color=\"\xed\xa0\x80\"", {"not valid UTF-8"});  // a UTF-16 surrogate
  expect_bad(R"(color="red")", "color=\"\xc0\xaf\"", {"not valid UTF-8"});      // an overlong '/'
  // Valid multi-byte text, and a file that declares its encoding, are read as they are.
  std::string text = kSample;
  text.replace(text.find(R"(color="red")"), 11, "color=\"\xe7\xba\xa2\xf0\x9f\x94\xb4\"");
  EXPECT_EQ(parse_harness_xml(text, "u.xml").cables[0].physical.color, "\xe7\xba\xa2\xf0\x9f\x94\xb4");
  std::string latin1 = kSample;
  latin1.replace(0, std::string(R"(<?xml version="1.0"?>)").size(), R"(<?xml version="1.0" encoding="ISO-8859-1"?>)");
  latin1.replace(latin1.find(R"(color="red")"), 11, "color=\"r\xf6" "d\"");
  EXPECT_EQ(parse_harness_xml(latin1, "l.xml").cables[0].physical.color, "r\xc3\xb6" "d");
}

// A <bspline>'s knots must span a domain (its derivatives scale as 1/width^k): an empty or
// vanishing one is refused at the element, not met later as NaN positions.
TEST(HarnessXml, BsplineKnotDomainMustNotVanish) {
  const std::string knots = R"(knots="0 0 0 0 1 1 1 1")";
  expect_bad(knots, R"(knots="0 0 0 0 0 0 0 0")", {"bad.xml:32:", "<bspline>", "domain [0, 0]", "not a curve"});
  expect_bad(knots, R"(knots="0 0 0 0 1e-300 1e-300 1e-300 1e-300")", {"<bspline>", "narrower than 1e-12"});
  expect_bad(knots, R"(knots="1e6 1e6 1e6 1e6 1000000.0000001 1000000.0000001 1000000.0000001 1000000.0000001")",
             {"<bspline>", "narrower than 1e-12"});
  // The domain is [knot 3, knot 4] of 8: clamping knots outside it may coincide.
  std::string text = kSample;
  text.replace(text.find(knots), knots.size(), R"(knots="-5 -5 -5 0 1e-6 7 7 7")");
  EXPECT_NO_THROW(parse_harness_xml(text, "ok.xml"));
}

// A directory, a device or a pipe is not a harness file (a device such as /dev/zero would be
// read without end until memory runs out).
TEST(HarnessXml, NonRegularFileIsRefused) {
  const auto dir = std::filesystem::temp_directory_path() / "loom_harness_dir.xml";
  std::filesystem::create_directories(dir);
  for (const std::filesystem::path& p : {dir, std::filesystem::path("/dev/zero")}) {
    if (!std::filesystem::exists(p)) continue;
    try {
      read_harness_xml(p);
      ADD_FAILURE() << p;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(p.string() + ": not a regular file"), std::string::npos) << e.what();
    }
  }
  std::filesystem::remove_all(dir);
}

TEST(HarnessXml, CableWithThreePorts) {
  expect_bad(R"(<port id="J3.4"/></electrical>)", R"(<port id="J3.4"/><port id="J2.1"/></electrical>)",
             {"exactly two ports"});
}

TEST(HarnessXml, MissingFileIsNamed) {
  try {
    read_harness_xml("/nonexistent/harness.xml");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/harness.xml"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("not found"), std::string::npos);
  }
}

}  // namespace
}  // namespace loom
