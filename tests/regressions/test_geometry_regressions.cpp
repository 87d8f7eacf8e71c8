// Regressions of the curve geometry (centerline, fairing, sweep, tube validity,
// cable geometry): one test per bug, inputs written out.
#include "core/centerline.hpp"
#include "core/error.hpp"
#include "core/harness_topology.hpp"
#include "core/io/harness_xml.hpp"
#include "core/mesh.hpp"
#include "core/part.hpp"
#include "index/brute_force_index.hpp"
#include "routing/curve/cable_geometry.hpp"
#include "routing/curve/sweep.hpp"
#include "routing/route/tube_validity.hpp"

#include <ompl/base/spaces/RealVectorStateSpace.h>

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

using loom::Centerline;
using loom::Vec3;

namespace {

/// Facets of the tube's side whose winding normal points toward the nearest point of the
/// centerline (dense samples): the mesh is turned inside out there.
std::size_t inverted_side_facets(const Centerline& c, const loom::SweepResult& res) {
  const std::size_t ring_vertices = static_cast<std::size_t>(res.rings) * res.circumferential;
  std::vector<Vec3> axis;
  for (int k = 0; k <= 4000; ++k) axis.push_back(c.position(c.u_min() + (c.u_max() - c.u_min()) * k / 4000.0));
  std::size_t bad = 0;
  for (std::size_t t = 0; t < res.mesh.triangles.size(); ++t) {
    const auto& f = res.mesh.triangles[t];
    if (f[0] >= ring_vertices || f[1] >= ring_vertices || f[2] >= ring_vertices) continue;
    const auto q = res.mesh.corners(t);
    const Vec3 n = (q[1] - q[0]).cross(q[2] - q[0]);
    const Vec3 g = (q[0] + q[1] + q[2]) / 3.0;
    Vec3 nearest = axis.front();
    for (const Vec3& a : axis)
      if ((a - g).squaredNorm() < (nearest - g).squaredNorm()) nearest = a;
    if (n.dot(g - nearest) < 0.0) ++bad;
  }
  return bad;
}

/// Dense points on a circle arc of radius R in the XY plane (angle 0..sweep), with its end
/// tangents.
Centerline arc(double R, double sweep) {
  std::vector<Vec3> p;
  const int n = 200;
  for (int i = 0; i <= n; ++i) p.emplace_back(R * std::cos(sweep * i / n), R * std::sin(sweep * i / n), 0);
  loom::InterpolationOptions o;
  o.start_tangent = Vec3(0, 1, 0);
  o.end_tangent = Vec3(-std::sin(sweep), std::cos(sweep), 0);
  return Centerline::interpolate(p, o);
}

/// Closed, outward 12-triangle box mesh as a closed part.
loom::Part box_part(const Vec3& lo, const Vec3& hi) {
  loom::Part part;
  part.name = "block";
  part.closed = true;
  for (int i = 0; i < 8; ++i)
    part.mesh.vertices.emplace_back((i & 1) ? hi.x() : lo.x(), (i & 2) ? hi.y() : lo.y(), (i & 4) ? hi.z() : lo.z());
  const int quads[6][4] = {{0, 2, 6, 4}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 5, 7, 6}};
  const Vec3 c = 0.5 * (lo + hi);
  for (const auto& q : quads)
    for (const auto& t : {std::array<int, 3>{q[0], q[1], q[2]}, std::array<int, 3>{q[0], q[2], q[3]}}) {
      const Vec3 a = part.mesh.vertices[t[0]], b = part.mesh.vertices[t[1]], d = part.mesh.vertices[t[2]];
      const bool outward = (b - a).cross(d - a).dot((a + b + d) / 3.0 - c) > 0.0;
      part.mesh.triangles.push_back(outward ? std::array<std::uint32_t, 3>{std::uint32_t(t[0]), std::uint32_t(t[1]),
                                                                           std::uint32_t(t[2])}
                                            : std::array<std::uint32_t, 3>{std::uint32_t(t[0]), std::uint32_t(t[2]),
                                                                           std::uint32_t(t[1])});
    }
  return part;
}

}  // namespace

// Bug: sweeping a tube around a bend tighter than its radius (κ·r > 1) — or a kink of a
// polyline — turned the inner side of the mesh inside out (inverted, crossing facets) and
// said nothing: SweepResult had no way to tell. It reports the fold and where.
TEST(GeometryRegression, TubeFoldingAroundATightBendIsReported) {
  const double r = 2.0;
  const Centerline tight = arc(1.0, 0.5 * M_PI);  // bend radius 1 < r: the tube folds
  const loom::SweepResult folded = loom::sweep_tube(tight, r, {0.01, true});
  ASSERT_GT(inverted_side_facets(tight, folded), 0u);  // the oracle sees the fold
  EXPECT_TRUE(folded.folded);
  EXPECT_GE(folded.fold_s, 0.0);
  EXPECT_LE(folded.fold_s, tight.length());
  EXPECT_EQ(loom::first_non_finite_vertex(folded.mesh), -1);

  // A bend of twice the radius does not fold, and no facet is inverted.
  const Centerline easy = arc(2.0 * r, 0.5 * M_PI);
  const loom::SweepResult fine = loom::sweep_tube(easy, r, {0.01, true});
  EXPECT_EQ(inverted_side_facets(easy, fine), 0u);
  EXPECT_FALSE(fine.folded);

  // A polyline corner (bend radius 0) folds too.
  const Centerline kink = Centerline::polyline({Vec3(0, 0, 0), Vec3(5, 0, 0), Vec3(5, 5, 0)});
  EXPECT_TRUE(loom::sweep_tube(kink, 0.5, {0.01, true}).folded);
}

// Bug: TubeValidityChecker::clearance() returned horizon − required (clear!) for a point
// deep inside a closed part when no surface lay within the clearance horizon, although its
// contract says −required inside a closed part; isValid(s, dist) then called it valid.
TEST(GeometryRegression, ClearanceDeepInsideAClosedPartBeyondTheHorizonIsNegative) {
  const std::vector<loom::Part> parts{box_part(Vec3(0, 0, 0), Vec3(100, 100, 100))};
  const loom::BruteForceIndex index(parts);
  auto space = std::make_shared<ompl::base::RealVectorStateSpace>(3);
  space->setBounds(-10, 110);
  auto si = std::make_shared<ompl::base::SpaceInformation>(space);
  const double required = 3.0, horizon = 10.0 * required;  // the centre is 50 from every face
  loom::configure_tube_space(si, index, required, horizon);
  auto* a = si->allocState();
  loom::set_state_point(a, Vec3(50, 50, 50));
  EXPECT_FALSE(si->isValid(a));
  EXPECT_EQ(si->getStateValidityChecker()->clearance(a), -required);
  double dist = 0.0;
  EXPECT_FALSE(si->getStateValidityChecker()->isValid(a, dist));
  EXPECT_LT(dist, 0.0);
  // Outside, off a corner: clear by its distance to the corner.
  loom::set_state_point(a, Vec3(-10, -10, -10));
  EXPECT_TRUE(si->isValid(a));
  EXPECT_NEAR(si->getStateValidityChecker()->clearance(a), std::sqrt(300.0) - required, 1e-9);
  si->freeState(a);
}

// Bug: a cable whose chain holds an exact <bspline> with an unclamped knot vector (the
// harness reader accepts any non-decreasing knots) was joined as if clamped: join() drops
// the first control point of the next piece and the first four knots, so the cable's curve
// left its segments (here it started ~100 mm away from port A) while each piece on its own
// was right.
TEST(GeometryRegression, CableThroughAnUnclampedExactSplineFollowsItsSegments) {
  const char* xml = R"(<harness name="H" units="mm">
  <attributes>
    <cable id="C1"><electrical><port id="A"/><port id="B"/></electrical>
      <physical type="t" color="c" diameter="2" min_bend_radius="10"/></cable>
  </attributes>
  <structure>
    <port id="A" x="0" y="0" z="0" dx="1" dy="0" dz="0"/>
    <port id="B" x="200" y="0" z="0" dx="-1" dy="0" dz="0"/>
    <port id="D" x="100" y="-100" z="0" dx="0" dy="1" dz="0"/>
    <branch id="J" x="100" y="10" z="0">
      <segment to="A"><bspline degree="3" knots="0 1 2 3 4 5 6 7">
        <cp x="260" y="20" z="0"/><cp x="80" y="10" z="0"/><cp x="20" y="0" z="0"/><cp x="-160" y="-10" z="0"/>
      </bspline></segment>
      <segment to="B"><path interp="polyline"><pt x="150" y="10" z="0"/></path></segment>
      <segment to="D"/>
    </branch>
  </structure>
</harness>
)";
  // The uniform cubic's one piece runs from (P0 + 4P1 + P2)/6 = J to (P1 + 4P2 + P3)/6 = A.
  const loom::Harness h = loom::parse_harness_xml(xml, "h.xml");
  const loom::HarnessTopology topo(h);
  const std::vector<loom::CablePiece> pieces = loom::cable_pieces(topo, 0);
  ASSERT_EQ(pieces.size(), 2u);
  const std::optional<Centerline> cable = loom::cable_centerline(topo, 0);
  ASSERT_TRUE(cable.has_value());
  EXPECT_LE((cable->position(cable->u_min()) - Vec3(0, 0, 0)).norm(), 1e-9);
  EXPECT_LE((cable->position(cable->u_max()) - Vec3(200, 0, 0)).norm(), 1e-9);
  const double expected = pieces[0].curve.length() + pieces[1].curve.length();
  EXPECT_NEAR(cable->length(), expected, 1e-9 * expected);
  // Every point of the cable at arc length s is the piece's point at its own arc length.
  for (int k = 0; k <= 200; ++k) {
    const double s = expected * k / 200.0;
    const loom::CablePiece& p = s < pieces[1].s0 ? pieces[0] : pieces[1];
    const Vec3 want = p.curve.position(p.curve.parameter_at_length(s - p.s0));
    EXPECT_LE((cable->position(cable->parameter_at_length(s)) - want).norm(), 1e-6) << s;
  }
}

// Bug: join() glued consecutive segment curves by dropping the next piece's first control
// point, whatever the gap: an exact <bspline> stopping 5 mm short of its branch point was
// silently bent over to meet the previous piece, so the cable's audited curve was not the
// file's segment. A gap beyond rounding is a clear error naming the harness and cable.
// (The branch point has no position here: with one, the curve's end is checked against it
// first, GeometryRegression.ExactSplineAwayFromItsPortsIsAClearError.)
TEST(GeometryRegression, CableWhoseSegmentsDoNotMeetIsAClearError) {
  const char* xml = R"(<harness name="H" units="mm">
  <attributes>
    <cable id="C1"><electrical><port id="A"/><port id="B"/></electrical>
      <physical type="t" color="c" diameter="2" min_bend_radius="10"/></cable>
  </attributes>
  <structure>
    <port id="A" x="0" y="0" z="0" dx="1" dy="0" dz="0"/>
    <port id="B" x="200" y="0" z="0" dx="-1" dy="0" dz="0"/>
    <port id="D" x="100" y="-100" z="0" dx="0" dy="1" dz="0"/>
    <branch id="J">
      <segment to="A"><bspline degree="3" knots="0 0 0 0 1 1 1 1">
        <cp x="95" y="10" z="0"/><cp x="60" y="8" z="0"/><cp x="30" y="2" z="0"/><cp x="0" y="0" z="0"/>
      </bspline></segment>
      <segment to="B"><bspline degree="1" knots="0 0 1 1">
        <cp x="100" y="10" z="0"/><cp x="200" y="0" z="0"/>
      </bspline></segment>
      <segment to="D"/>
    </branch>
  </structure>
</harness>
)";
  const loom::Harness h = loom::parse_harness_xml(xml, "h.xml");
  const loom::HarnessTopology topo(h);
  try {
    const std::optional<Centerline> c = loom::cable_centerline(topo, 0);
    FAIL() << "joined across a 5 mm gap, length " << (c ? c->length() : 0.0);
  } catch (const loom::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("do not meet"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("C1"), std::string::npos) << e.what();
  }
}

// Bug: the tube of a zero-length centerline (an exact <bspline> whose control points
// coincide) was five coincident rings: a closed but flat mesh of zero volume, two discs
// facing away from each other. The cable is the ball of radius r around its one point
// (DESIGN §5); its tube is that ball's sphere mesh (as at a junction).
TEST(GeometryRegression, ZeroLengthCableSweepsToItsBall) {
  const Vec3 p(1, 2, 3);
  const double r = 0.5, tol = 0.01;
  const Centerline c(3, {0, 0, 0, 0, 1, 1, 1, 1}, std::vector<Vec3>(4, p));
  ASSERT_EQ(c.length(), 0.0);
  const loom::SweepResult res = loom::sweep_tube(c, r, {tol, true});
  EXPECT_EQ(loom::first_non_finite_vertex(res.mesh), -1);
  const loom::MeshTopology topo = loom::analyse_topology(res.mesh);
  EXPECT_TRUE(topo.closed);
  EXPECT_EQ(topo.misoriented_edges, 0u);
  EXPECT_EQ(topo.degenerate_triangles, 0u);
  // It holds the ball and stays within the chord tolerance of its sphere.
  const double ball = 4.0 / 3.0 * M_PI * r * r * r;
  EXPECT_GE(res.mesh.signed_volume(), ball * (1 - 1e-12));
  EXPECT_LE(res.mesh.signed_volume(), 4.0 / 3.0 * M_PI * std::pow(r + tol, 3));
  for (const Vec3& v : res.mesh.vertices) EXPECT_LE((v - p).norm(), r + tol);
  // The same for the canal form.
  const loom::SweepResult canal = loom::sweep_canal(c, [r](double) { return r; }, {tol, true});
  EXPECT_GE(canal.mesh.signed_volume(), ball * (1 - 1e-12));
}

// Bug: an exact <bspline> was taken as the segment wherever it lay: one 495 mm away from
// both its ports was audited (exit 0, "clean") as the cable between them. A segment's
// exact curve must start at its from-node and end at its to-node where the file places
// them (within rounding); otherwise the harness is refused naming the file, cable, segment,
// node and gap.
TEST(GeometryRegression, ExactSplineAwayFromItsPortsIsAClearError) {
  const char* xml = R"(<harness name="H" units="mm">
  <attributes>
    <cable id="C1"><electrical><port id="A"/><port id="B"/></electrical>
      <physical type="t" color="c" diameter="2" min_bend_radius="10"/></cable>
  </attributes>
  <structure>
    <port id="A" x="0" y="0" z="0" dx="1" dy="0" dz="0"/>
    <port id="B" x="200" y="0" z="0" dx="-1" dy="0" dz="0"/>
    <segment from="A" to="B"><bspline degree="3" knots="0 0 0 0 1 1 1 1">
      <cp x="0" y="495" z="0"/><cp x="60" y="495" z="0"/><cp x="140" y="495" z="0"/><cp x="200" y="495" z="0"/>
    </bspline></segment>
  </structure>
</harness>
)";
  const loom::Harness h = loom::parse_harness_xml(xml, "h.xml");
  const loom::HarnessTopology topo(h);
  try {
    const std::optional<Centerline> c = loom::cable_centerline(topo, 0);
    FAIL() << "took a curve 495 mm from its ports, length " << (c ? c->length() : 0.0);
  } catch (const loom::InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("h.xml:3"), std::string::npos) << what;
    EXPECT_NE(what.find("C1"), std::string::npos) << what;
    EXPECT_NE(what.find("segment A -> B starts at (0, 495, 0), not at A (0, 0, 0) (gap 495)"), std::string::npos) << what;
  }
  // A curve ending at its ports is the segment (rounding of a written file allowed).
  std::string ok = xml;
  const std::string far = R"(<cp x="0" y="495" z="0"/><cp x="60" y="495" z="0"/><cp x="140" y="495" z="0"/><cp x="200" y="495" z="0"/>)";
  ok.replace(ok.find(far), far.size(),
             R"(<cp x="0" y="1e-13" z="0"/><cp x="60" y="40" z="0"/><cp x="140" y="40" z="0"/><cp x="200" y="0" z="0"/>)");
  const loom::Harness h2 = loom::parse_harness_xml(ok, "h.xml");
  const loom::HarnessTopology topo2(h2);
  EXPECT_NO_THROW(loom::cable_centerline(topo2, 0));
}
