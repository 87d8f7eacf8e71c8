// Regressions of resource limits that fired too late or named no file: one test per finding
// of the fuzzing campaign, inputs written out in the test. Refusals are checked by their
// message (what the user sees) and, where the old path allocated gigabytes first, on inputs
// small enough that the old path shows its failure cheaply.
#include "core/error.hpp"
#include "core/io/harness_xml.hpp"
#include "core/scene.hpp"
#include "index/brute_force_index.hpp"
#include "index/simplify/alpha_sim.hpp"
#include "routing/audit/clash_check.hpp"
#include "routing/curve/cable_limit.hpp"
#include "routing/scan/scan_centerline.hpp"
#include "routing/scan/scan_oracle.hpp"
#include "routing/view/render.hpp"

#include "common/run_loom.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

namespace {

namespace fs = std::filesystem;
using namespace loom;
using loom::testing::run_loom;

/// An empty scratch directory of this test process.
fs::path scratch(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("loom_limit_reg_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

std::string read_text(const fs::path& p) {
  std::ifstream in(p);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

/// The closed box [0, 10]³ as OBJ.
const char* const kBoxObj =
    "v 0 0 0\nv 10 0 0\nv 0 10 0\nv 10 10 0\nv 0 0 10\nv 10 0 10\nv 0 10 10\nv 10 10 10\n"
    "f 1 3 2\nf 2 3 4\nf 5 6 7\nf 6 8 7\nf 1 2 5\nf 2 6 5\nf 3 7 4\nf 4 7 8\nf 1 5 3\nf 3 5 7\nf 2 4 6\nf 4 8 6\n";

/// A harness of one cable C1 (its <cable> element on line 5) of `diameter` between ports J1
/// (-20, 5, 30) and J2 (30, 5, 30) over one polyline segment through `path` (<pt .../>
/// elements; empty: straight, 50 long, 20 above the box).
std::string one_cable_harness(const std::string& diameter, const std::string& path) {
  return "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
         "<!-- one cable -->\n"
         "<harness name=\"h\" units=\"mm\">\n"
         "  <attributes>\n"
         "    <cable id=\"C1\">\n"
         "      <electrical><port id=\"J1\"/><port id=\"J2\"/></electrical>\n"
         "      <physical type=\"AWG20\" color=\"red\" diameter=\"" +
         diameter +
         "\" min_bend_radius=\"0\"/>\n"
         "    </cable>\n"
         "  </attributes>\n"
         "  <structure>\n"
         "    <port id=\"J1\" x=\"-20\" y=\"5\" z=\"30\" dx=\"1\" dy=\"0\" dz=\"0\"/>\n"
         "    <port id=\"J2\" x=\"30\" y=\"5\" z=\"30\" dx=\"-1\" dy=\"0\" dz=\"0\"/>\n"
         "    <segment from=\"J1\" to=\"J2\"><path interp=\"polyline\">" +
         path +
         "</path></segment>\n"
         "  </structure>\n"
         "</harness>\n";
}

/// DIR/scene.toml with the box and DIR/harness.xml; returns the scene path.
fs::path write_scene(const fs::path& dir, const std::string& harness) {
  std::ofstream(dir / "box.obj") << kBoxObj;
  std::ofstream(dir / "harness.xml") << harness;
  std::ofstream(dir / "scene.toml") << "[scene]\nname = \"s\"\nunits = \"mm\"\n[[part]]\nname = \"box\"\n"
                                       "file = \"box.obj\"\n[harness]\nfile = \"harness.xml\"\n";
  return dir / "scene.toml";
}

/// A straight cable of radius r from a to b.
CableInput straight_cable(const std::string& id, const Vec3& a, const Vec3& b, double r) {
  CableInput c;
  c.id = id;
  c.curve = Centerline::polyline({a, b});
  c.radius = r;
  return c;
}

// audit-discrete-spacing-memory-before-limit: `--method discrete --spacing 1e-6` on a 50 mm
// cable took 5·10⁷ samples (under the sample limit) and grew past 3.5 GB before the
// sample-pair limit, counted from the samples' grid, refused it. The pairs are now bounded
// before any sample is taken: each sample meets at least the samples of its own cable
// within half a grid cell (r) of arc length, 2·m·min(m, ⌊r/h⌋ + 1) pairs for m samples h
// apart (each with its midpoint) — here m = 500001, h = 1e-4, r = 1: 10001020002 > 4·10⁹.
// (At 1e-4 the old path still refused, after 5·10⁵ samples and their grid, with another
// message: the figure is what tells the paths apart without gigabytes.)
TEST(LimitRegression, DiscreteSamplePairsAreBoundedBeforeSampling) {
  const std::vector<Part> parts;
  const BruteForceIndex idx(parts);
  ClashRequest req;
  req.method = ClashMethod::Discrete;
  req.spacing = 1e-4;
  const CableInput c = straight_cable("C1", {-20, 5, 30}, {30, 5, 30}, 1.0);
  const double intervals = std::ceil(c.curve.length() / 1e-4), h = c.curve.length() / intervals;
  const double m = intervals + 1.0, near = std::floor(1.0 / h) + 1.0;  // 500001, 10001
  try {
    check_clashes({c}, parts, &idx, req);
    FAIL() << "accepted";
  } catch (const std::invalid_argument& e) {
    const std::string why = e.what();
    EXPECT_NE(why.find("cable 'C1': sample spacing 0.0001 (--spacing)"), std::string::npos) << why;
    EXPECT_NE(why.find("at least " + full_precision(2.0 * m * near) + " pairs of samples"), std::string::npos) << why;
  }
  // Fifty times coarser the bound (about 4·10⁶) passes and the audit runs (nothing near).
  req.spacing = 5e-3;
  EXPECT_NO_THROW(check_clashes({c}, parts, &idx, req));

  // The command line names the harness file and the cable's line.
  const fs::path dir = scratch("discrete");
  const fs::path scene = write_scene(dir, one_cable_harness("2", ""));
  const auto r = run_loom("audit " + scene.string() + " --method discrete --spacing 1e-4 --quiet --out " +
                          (dir / "out").string());
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("harness.xml:5: cable 'C1': sample spacing 0.0001 (--spacing) puts samples so close"),
            std::string::npos)
      << r.out;
  EXPECT_FALSE(fs::exists(dir / "out" / "report.json"));
}

// audit-limit-error-names-no-file: limits hit inside check_clashes printed
// "check_clashes: cable 'C1' would need 99999999995 chords ..." without the harness file or
// line (the cause, a path point at x = 1e11, is in the harness). Every refusal of a cable now
// names the file (the harness, or the --routes file that replaced it) and the cable's line.
TEST(LimitRegression, AuditLimitsNameTheHarnessFileAndTheCablesLine) {
  const fs::path dir = scratch("named");
  const fs::path scene = write_scene(dir, one_cable_harness("2", "<pt x=\"1e11\" y=\"5\" z=\"30\"/>"));
  const std::string out = " --quiet --out " + (dir / "out").string();
  auto r = run_loom("audit " + scene.string() + out);
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("harness.xml:5: cable 'C1' would need 99999999995 chords"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("check_clashes"), std::string::npos) << r.out;
  // The discrete method's sample count (a point at 1e12: 10¹² samples at the diameter 2).
  std::ofstream(dir / "harness.xml") << one_cable_harness("2", "<pt x=\"1e12\" y=\"5\" z=\"30\"/>");
  r = run_loom("audit " + scene.string() + " --method discrete" + out);
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("harness.xml:5: cable 'C1': sample spacing 2 (its diameter) gives"), std::string::npos)
      << r.out;
  // A --routes file that replaces a clean harness is the file named.
  std::ofstream(dir / "harness.xml") << one_cable_harness("2", "");
  std::ofstream(dir / "routes.xml") << one_cable_harness("2", "<pt x=\"1e11\" y=\"5\" z=\"30\"/>");
  r = run_loom("audit " + scene.string() + " --routes " + (dir / "routes.xml").string() + out);
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("routes.xml:5: cable 'C1' would need"), std::string::npos) << r.out;
  // The route's audit: a cable of diameter 1e-9 needs at least 170 / 1e-9 chords between its
  // ports whatever its route; refused before any planning, at its element (the route around
  // the box of tests/data/route, which the old path planned in a few seconds first).
  const std::string route_data = std::string(LOOM_TEST_DATA) + "/route";
  fs::copy_file(route_data + "/box.obj", dir / "route_box.obj");
  std::string toml = read_text(route_data + "/around.toml"), xml = read_text(route_data + "/harness_around.xml");
  toml.replace(toml.find("\"box.obj\""), 9, "\"route_box.obj\"");
  xml.replace(xml.find("diameter=\"2\""), 12, "diameter=\"1e-9\"");
  std::ofstream(dir / "around.toml") << toml;
  std::ofstream(dir / "harness_around.xml") << xml;
  r = run_loom("route " + (dir / "around.toml").string() + " --iterations 200" + out);
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("harness_around.xml:5: cable 'C1': its ports J1 and J2 are 170 apart"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("at least 170000000000 chords"), std::string::npos) << r.out;
}

// The same finding, for tubes: `render: cable 'C1': sweep_tube: ... more than 4194304 rings`
// named no file. A tube refused (its rings, its triangles, the output's budget) is now a
// CableLimitError for the cable, which the commands turn into an error at its element.
TEST(LimitRegression, TubeRefusalsNameTheCablesElement) {
  const Harness h = parse_harness_xml(one_cable_harness("2", ""), "tubes.xml");
  Scene scene;
  scene.harness = h;
  scene.has_harness = true;
  RenderOptions opt;
  opt.width = opt.height = 16;
  opt.max_tube_triangles = 10;  // fewer than any tube
  try {
    render_scene(scene, h, nlohmann::json::object(), opt);
    FAIL() << "accepted";
  } catch (const CableLimitError& e) {
    EXPECT_EQ(e.cable(), "C1");
    const InputError named = cable_input_error(h, e);
    EXPECT_EQ(named.where().file, "tubes.xml");
    EXPECT_EQ(named.where().line, 5);
    EXPECT_EQ(std::string(named.what()).rfind("tubes.xml:5: render: cable 'C1': ", 0), 0u) << named.what();
  }
  // A sweep's refusal gives its figures at full precision ("chord tolerance 0.000000" was
  // all the scan's said).
  SweepOptions tiny;
  tiny.chord_tolerance = 1e-30;
  try {
    sweep_tube(Centerline::polyline({Vec3(0, 0, 0), Vec3(0, 0, 1)}), 1.0, tiny);
    FAIL() << "accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("chord tolerance 7.5000000000000006e-31"), std::string::npos) << e.what();
  }
}

// scan-axis-tiny-diameter-unnamed-error: `scan --method axis --diameter 1e-300` on a 2 mm
// tube worked 10 s and 1 GB (sweeping a tube at a chord tolerance of 1e-302), then failed
// in sweep_tube without the cloud's name. The axis method's block fits never moved from a
// start radius that small (their steps scale with it) and "agreed" with the given diameter
// while every point lay a millimetre off; a fit whose points lie farther from its surface
// than its radius measures nothing now, and the extraction refuses the diameter at once, as
// the graph method (the oracle here) and smaller mistakes did.
TEST(LimitRegression, AxisMethodRefusesADiameterFarBelowTheCloudsAtOnce) {
  using namespace scan_test;
  const TrueAxis axis = make_axis([](double u) { return Vec3(60.0 * u, 0.0, 0.0); });
  ScanSpec spec;
  spec.radius = 1.0;
  spec.points = 1500;
  const std::vector<Vec3> cloud = scan_tube(axis, spec);
  ScanOptions o;
  o.method = ScanMethod::Axis;
  o.diameter = 2.0;
  ASSERT_EQ(extract_centerline(cloud, o).status, ScanStatus::Ok);
  for (const double d : {1e-300, 1e-100, 1e-30}) {
    o.diameter = d;
    o.method = ScanMethod::Graph;
    EXPECT_NE(extract_centerline(cloud, o).status, ScanStatus::Ok) << d;
    o.method = ScanMethod::Axis;
    const ScanResult r = extract_centerline(cloud, o);
    EXPECT_EQ(r.status, ScanStatus::NotATube) << d << ": " << r.message;
    EXPECT_NE(r.message.find("is the given diameter " + full_precision(d) + " right?"), std::string::npos)
        << r.message;
  }
}

// simplify-json-inf-text: at --dim-pre 1e-300 the sample estimate overflowed to +inf and
// simplify.json said "needs about inf points". No output of loom holds inf or nan text.
TEST(LimitRegression, SimplifyJsonHoldsNoInfOrNanText) {
  const fs::path dir = scratch("inf");
  const fs::path scene = write_scene(dir, one_cable_harness("2", ""));
  const auto r = run_loom("simplify " + scene.string() + " --dim-pre 1e-300 --quiet --out " + (dir / "out").string());
  ASSERT_EQ(r.status, 0) << r.out;
  const std::string text = read_text(dir / "out" / "simplify.json");
  const auto json = nlohmann::json::parse(text);
  EXPECT_EQ(json["parts"][0]["status"], "too_fine");
  EXPECT_NE(json["parts"][0]["reason"].get<std::string>().find("needs more than 4000000 points"), std::string::npos);
  // No word "inf", "infinity" or "nan" anywhere (numbers, keys and reasons alike).
  std::string word;
  for (const char ch : text + " ") {
    if (std::isalpha(static_cast<unsigned char>(ch))) {
      word += static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
      continue;
    }
    EXPECT_TRUE(word != "inf" && word != "infinity" && word != "nan") << text;
    word.clear();
  }
}

/// simplify-open-sparse-mesh-memory's three open triangles (one sheet at x = 2100, two small
/// ones about 2 m away), scaled by `k`.
Part three_triangles(double k) {
  Part p;
  p.name = "p";
  p.mesh.vertices = {{2100.0, -375.0, -1125.0},    {2100.0, -450.0, -675.0},   {2100.0, -450.0, -1575.0},
                     {173.3075, -852.5635, -675.0}, {272.5454, -826.2076, -675.0}, {249.0341, -770.7672, -675.0},
                     {49.70588, -808.4735, -675.0}, {71.65557, -867.0441, -675.0}, {150.5551, -795.8851, -675.0}};
  for (auto& v : p.mesh.vertices) v *= k;
  p.mesh.triangles = {{0, 1, 2}, {3, 4, 5}, {6, 7, 8}};
  p.closed = false;
  return p;
}

// simplify-open-sparse-mesh-memory: α-SIM on three open triangles spread far apart (few
// samples, a projection hull of 2 m) grew past 7.7 GB: the α-shapes fell back to their hulls,
// whose Delaunay triangles across the emptiness were each listed over their box in a grid.
// The guard now also counts the lattice of each projection's convex hull, before any sample
// is taken. Shown at a quarter of the size with the limit lowered to 500,000 (the old path
// ran there, to a hull fallback): the XZ hull spans about 9.2·10⁵ lattice points at
// L_max = 0.25 while the samples are about 3.5·10⁴.
TEST(LimitRegression, OpenTrianglesFarApartAreTooFineBeforeSampling) {
  AlphaSimOptions o;
  o.dim_pre = 0.5;
  o.max_cloud_points = 500000;
  const AlphaSimPart sp = simplify_part(three_triangles(0.25), o);
  EXPECT_EQ(sp.result.status, AlphaSimStatus::TooFine) << sp.result.reason;
  EXPECT_EQ(sp.result.fallback, AlphaSimFallback::Original);
  EXPECT_NE(sp.result.reason.find("the convex hull of a projection spans about"), std::string::npos)
      << sp.result.reason;
  EXPECT_TRUE(sp.result.projections.empty());  // refused before any plane was sampled
  EXPECT_EQ(sp.mesh.triangles, three_triangles(0.25).mesh.triangles);
  // A closed box fills its projections: hull and samples agree, and one within the limit
  // is simplified as before.
  Part box;
  box.name = "box";
  std::istringstream obj(kBoxObj);
  for (std::string t; obj >> t;) {
    if (t == "v") {
      double x, y, z;
      obj >> x >> y >> z;
      box.mesh.vertices.emplace_back(x, y, z);
    } else {
      std::uint32_t a, b, c;
      obj >> a >> b >> c;
      box.mesh.triangles.push_back({a - 1, b - 1, c - 1});
    }
  }
  box.closed = true;
  const AlphaSimPart sb = simplify_part(box, o);
  EXPECT_NE(sb.result.status, AlphaSimStatus::TooFine) << sb.result.reason;
}

// simplify-step-stale-output: `simplify --step` into a directory holding an earlier run's
// p.step left it there when p fell back to its original (no STEP): a mixed set. A target the
// run does not write is removed with the new set in place, and simplify.json says so.
TEST(LimitRegression, SimplifyStepLeavesNoEarlierRunsFile) {
  const fs::path dir = scratch("step");
  const fs::path scene = write_scene(dir, one_cable_harness("2", ""));
  const std::string out = (dir / "out").string();
  auto r = run_loom("simplify " + scene.string() + " --step --quiet --out " + out);
  ASSERT_EQ(r.status, 0) << r.out;
  ASSERT_TRUE(fs::exists(dir / "out" / "box.step"));
  auto json = nlohmann::json::parse(read_text(dir / "out" / "simplify.json"));
  EXPECT_EQ(json["parts"][0]["step_file"], "box.step");
  EXPECT_TRUE(json["removed"].empty());
  // The same part 1e-8 across: thin, its original kept, no STEP solid.
  std::ofstream(dir / "box.obj") << "v 0 0 0\nv 1e-8 0 0\nv 0 1e-8 0\nv 1e-8 1e-8 0\nv 0 0 1e-8\nv 1e-8 0 1e-8\n"
                                    "v 0 1e-8 1e-8\nv 1e-8 1e-8 1e-8\n"
                                 << std::string(kBoxObj).substr(std::string(kBoxObj).find("f "));
  r = run_loom("simplify " + scene.string() + " --step --quiet --out " + out);
  ASSERT_EQ(r.status, 0) << r.out;
  json = nlohmann::json::parse(read_text(dir / "out" / "simplify.json"));
  EXPECT_EQ(json["parts"][0]["status"], "thin");
  EXPECT_EQ(json["parts"][0]["step_file"], "");
  EXPECT_EQ(json["removed"], nlohmann::json::array({"box.step"}));
  EXPECT_FALSE(fs::exists(dir / "out" / "box.step"));
  EXPECT_TRUE(fs::exists(dir / "out" / "box.stl"));
}

}  // namespace
