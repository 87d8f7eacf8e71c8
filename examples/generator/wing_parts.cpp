#include "examples/generator/wing_parts.hpp"

#include "examples/generator/wing_layout.hpp"

#include <BRepAlgoAPI_Cut.hxx>
#include <BRepAlgoAPI_Fuse.hxx>
#include <BRepBuilderAPI_Transform.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <BRepPrimAPI_MakeSphere.hxx>
#include <ShapeUpgrade_UnifySameDomain.hxx>
#include <TopExp_Explorer.hxx>
#include <TopTools_ListOfShape.hxx>
#include <TopoDS.hxx>
#include <gp_Ax2.hxx>
#include <gp_Ax3.hxx>
#include <gp_Trsf.hxx>

#include <stdexcept>

namespace loom::examples {

using namespace layout;

namespace {

/// Positive bodies (fused) and negative bodies (cut) of a solid under construction.
struct Body {
  std::vector<TopoDS_Shape> add;
  std::vector<TopoDS_Shape> cut;
};

TopoDS_Shape box(double x0, double y0, double z0, double x1, double y1, double z1) {
  return BRepPrimAPI_MakeBox(gp_Pnt(x0, y0, z0), gp_Pnt(x1, y1, z1)).Shape();
}

TopoDS_Shape cylinder(const gp_Pnt& base, const gp_Dir& axis, double r, double h) {
  return BRepPrimAPI_MakeCylinder(gp_Ax2(base, axis), r, h).Shape();
}

/// A flat ring (annulus) of radii r0 < r1 and height h on `axis` from `base`.
TopoDS_Shape ring(const gp_Pnt& base, const gp_Dir& axis, double r0, double r1, double h) {
  BRepAlgoAPI_Cut op(cylinder(base, axis, r1, h), cylinder(base, axis, r0, h));
  if (op.HasErrors()) throw std::runtime_error("wing example: ring Boolean failed");
  return op.Shape();
}

TopTools_ListOfShape as_list(const std::vector<TopoDS_Shape>& v, std::size_t from) {
  TopTools_ListOfShape l;
  for (std::size_t i = from; i < v.size(); ++i) l.Append(v[i]);
  return l;
}

/// The single solid of `s`; throws if the Booleans produced anything else.
TopoDS_Shape single_solid(const TopoDS_Shape& s, const char* what) {
  TopoDS_Shape solid;
  int n = 0;
  for (TopExp_Explorer e(s, TopAbs_SOLID); e.More(); e.Next(), ++n) solid = e.Current();
  if (n != 1)
    throw std::runtime_error(std::string("wing example: ") + what + " is " + std::to_string(n) +
                             " solids, expected 1");
  return solid;
}

/// Fuses the positive bodies, cuts the negative ones, merges coplanar faces, and
/// returns the one solid. Sequential Booleans (deterministic output).
TopoDS_Shape build(const Body& b, const char* what) {
  if (b.add.empty()) throw std::logic_error("wing example: empty body");
  TopoDS_Shape s = b.add.front();
  if (b.add.size() > 1) {
    BRepAlgoAPI_Fuse fuse;
    fuse.SetArguments(as_list({s}, 0));
    fuse.SetTools(as_list(b.add, 1));
    fuse.SetRunParallel(false);
    fuse.Build();
    if (fuse.HasErrors()) throw std::runtime_error(std::string("wing example: fuse failed for ") + what);
    s = fuse.Shape();
  }
  if (!b.cut.empty()) {
    BRepAlgoAPI_Cut cut;
    cut.SetArguments(as_list({s}, 0));
    cut.SetTools(as_list(b.cut, 0));
    cut.SetRunParallel(false);
    cut.Build();
    if (cut.HasErrors()) throw std::runtime_error(std::string("wing example: cut failed for ") + what);
    s = cut.Shape();
  }
  ShapeUpgrade_UnifySameDomain unify(s, true, true, false);
  unify.Build();
  return single_solid(unify.Shape(), what);
}

TopoDS_Shape moved(const TopoDS_Shape& s, const gp_Trsf& t) {
  return BRepBuilderAPI_Transform(s, t, true).Shape();
}

/// Adds a receptacle standing on a face at `base` with outward axis `out` (`xdir` fixes
/// the roll): shell, coupling ring, bore with a polarising key groove and, optionally, a
/// square flange with four mounting holes. `embed` sinks the shell into the body.
void add_receptacle(Body& body, const gp_Pnt& base, const gp_Dir& out, const gp_Dir& xdir,
                    const ReceptacleSpec& s, double embed, bool flange) {
  Body local;
  const gp_Dir z(0, 0, 1);
  local.add.push_back(cylinder(gp_Pnt(0, 0, -embed), z, s.r_out, s.length + embed));
  constexpr double kRingH = 4.0, kRingStep = 1.5, kRingFromMouth = 10.0;  // coupling nut ring
  local.add.push_back(cylinder(gp_Pnt(0, 0, s.length - kRingFromMouth), z, s.r_out + kRingStep, kRingH));
  local.cut.push_back(cylinder(gp_Pnt(0, 0, s.length - s.bore_depth), z, s.r_in, s.bore_depth + 1.0));
  constexpr double kKeyHalfW = 1.0, kKeyDepth = 1.5;  // polarising key groove in the bore
  local.cut.push_back(box(-kKeyHalfW, s.r_in - 1.0, s.length - s.bore_depth, kKeyHalfW,
                          s.r_in + kKeyDepth, s.length + 1.0));
  if (flange) {
    constexpr double kFlangeMargin = 5.0, kFlangeT = 3.0, kHoleR = 1.5;
    const double h = s.r_out + kFlangeMargin;
    local.add.push_back(box(-h, -h, 0.0, h, h, kFlangeT));
    const double c = s.r_out + 1.5;
    for (int i = 0; i < 4; ++i) {
      const double sx = (i & 1) ? c : -c, sy = (i & 2) ? c : -c;
      local.cut.push_back(cylinder(gp_Pnt(sx, sy, -2.0), z, kHoleR, kFlangeT + 3.0));
    }
  }
  gp_Trsf t;
  t.SetDisplacement(gp_Ax3(), gp_Ax3(base, out, xdir));
  for (const auto& a : local.add) body.add.push_back(moved(a, t));
  for (const auto& c : local.cut) body.cut.push_back(moved(c, t));
}

}  // namespace

TopoDS_Shape make_spar() {
  Body b;
  const double fy0 = kSparInnerY, fy1 = kSparInnerY + kSparFlangeW;
  b.add.push_back(box(0, kSparWebY0, 0, kSpan, kSparInnerY, kDepth));
  b.add.push_back(box(0, fy0, 0, kSpan, fy1, kSparFlangeT));
  b.add.push_back(box(0, fy0, kDepth - kSparFlangeT, kSpan, fy1, kDepth));
  const gp_Dir z(0, 0, 1), y(0, 1, 0);
  // Flange rivets, symmetric about the mid-span so that the turned copy matches.
  const int n = static_cast<int>(kSpan / kSparRivetPitch);
  for (int k = 0; k < n; ++k) {
    const double x = 0.5 * kSparRivetPitch + k * kSparRivetPitch;
    const double yc = 0.5 * (fy0 + fy1);
    b.cut.push_back(cylinder(gp_Pnt(x, yc, -1.0), z, kRivetR, kSparFlangeT + 2.0));
    b.cut.push_back(cylinder(gp_Pnt(x, yc, kDepth - kSparFlangeT - 1.0), z, kRivetR, kSparFlangeT + 2.0));
  }
  // Web rivets at the rib stations (rib attachment clips), both sides of each rib.
  constexpr double kClipDX = 8.0, kWebRivetZ0 = 25.0, kWebRivetDZ = 25.0;
  constexpr int kWebRivets = 7;
  for (double xr : kRibX)
    for (double sx : {-kClipDX, kClipDX})
      for (int k = 0; k < kWebRivets; ++k)
        b.cut.push_back(cylinder(gp_Pnt(xr + sx, kSparWebY0 - 1.0, kWebRivetZ0 + k * kWebRivetDZ), y, kRivetR,
                                 kSparWebT + 2.0));
  return build(b, "spar");
}

TopoDS_Shape make_rib() {
  Body b;
  const double y0 = kSparInnerY, y1 = kRearSparInnerY;
  const double z0 = kSparFlangeT, z1 = kDepth - kSparFlangeT;
  const double hw = 0.5 * kRibT, hc = 0.5 * kRibCapW;
  b.add.push_back(box(-hw, y0, z0, hw, y1, z1));
  b.add.push_back(box(-hc, y0, z0, hc, y1, z0 + kRibCapT));
  b.add.push_back(box(-hc, y0, z1 - kRibCapT, hc, y1, z1));
  const gp_Dir x(1, 0, 0), z(0, 0, 1);
  // Lightening holes with a stiffening lip (a ring around each hole on both faces).
  constexpr double kLipWidth = 5.0, kLipHalfLen = 4.0;
  for (double yc : kLighteningY) {
    b.add.push_back(cylinder(gp_Pnt(-kLipHalfLen, yc, kLighteningZ), x, kLighteningR + kLipWidth, 2 * kLipHalfLen));
    b.cut.push_back(cylinder(gp_Pnt(-kLipHalfLen - 1.0, yc, kLighteningZ), x, kLighteningR, 2 * kLipHalfLen + 2.0));
  }
  // Cap rivets: one row each side of the web, top and bottom caps.
  constexpr double kCapRivetDX = 9.0, kFirstRivet = 20.0;
  for (double yr = y0 + kFirstRivet; yr < y1 - 0.5 * kFirstRivet; yr += kRibRivetPitch)
    for (double sx : {-kCapRivetDX, kCapRivetDX}) {
      b.cut.push_back(cylinder(gp_Pnt(sx, yr, z0 - 1.0), z, kRivetR, kRibCapT + 2.0));
      b.cut.push_back(cylinder(gp_Pnt(sx, yr, z1 - kRibCapT - 1.0), z, kRivetR, kRibCapT + 2.0));
    }
  // Web rivets where the rib meets the spars.
  constexpr double kEdgeRivetDY = 10.0, kWebRivetZ0 = 25.0, kWebRivetDZ = 25.0;
  constexpr int kWebRivets = 7;
  for (double yr : {y0 + kEdgeRivetDY, y1 - kEdgeRivetDY})
    for (int k = 0; k < kWebRivets; ++k)
      b.cut.push_back(cylinder(gp_Pnt(-hw - 1.0, yr, kWebRivetZ0 + k * kWebRivetDZ), x, kRivetR, kRibT + 2.0));
  return build(b, "rib");
}

TopoDS_Shape make_avionics_box() {
  Body b;
  b.add.push_back(box(-kBoxHalfW, kBoxY0, kBoxZ0, kBoxHalfW, kBoxY1, kBoxZ1));
  // Mounting shelf to the rear spar web, with two bolt holes.
  constexpr double kShelfHalfW = 60.0, kShelfT = 6.0, kBoltR = 3.0, kBoltDX = 40.0, kBoltFromSpar = 25.0;
  b.add.push_back(box(-kShelfHalfW, kBoxY1 - 1.0, kBoxZ0, kShelfHalfW, kRearSparInnerY, kBoxZ0 + kShelfT));
  const gp_Dir z(0, 0, 1), my(0, -1, 0), x(1, 0, 0);
  for (double sx : {-kBoltDX, kBoltDX})
    b.cut.push_back(cylinder(gp_Pnt(sx, kRearSparInnerY - kBoltFromSpar, kBoxZ0 - 1.0), z, kBoltR, kShelfT + 2.0));
  // Cooling slots on the lid (3 mm grooves, 2.5 mm deep): detail that α-SIM removes.
  constexpr int kSlots = 9;
  constexpr double kSlotW = 3.0, kSlotPitch = 16.0, kSlotDepth = 2.5, kSlotMargin = 20.0;
  const double first = -0.5 * (kSlots - 1) * kSlotPitch;
  for (int j = 0; j < kSlots; ++j) {
    const double xs = first + j * kSlotPitch - 0.5 * kSlotW;
    b.cut.push_back(box(xs, kBoxY0 + kSlotMargin, kBoxZ1 - kSlotDepth, xs + kSlotW, kBoxY1 - kSlotMargin, kBoxZ1 + 1.0));
  }
  for (double sx : {-kBoxReceptacleDX, kBoxReceptacleDX})
    add_receptacle(b, gp_Pnt(sx, kBoxY0, kBoxReceptacleZ), my, x, kBoxReceptacle, 1.0, true);
  return build(b, "avionics box");
}

TopoDS_Shape make_actuator() {
  Body b;
  const gp_Dir x(1, 0, 0), y(0, 1, 0), z(0, 0, 1), my(0, -1, 0);
  const gp_Pnt axis0(kActBodyX0, kActAxisY, kActAxisZ);
  b.add.push_back(cylinder(axis0, x, kActBodyR, kActBodyX1 - kActBodyX0));
  // Stepped end cap and clevis lug (with its pin hole) towards rib 2.
  constexpr double kCapR = 30.0, kCapLen = 10.0, kLugX0 = 458.0, kLugHalfY = 8.0, kLugHalfZ = 15.0, kPinR = 4.0;
  b.add.push_back(cylinder(gp_Pnt(kActBodyX0 - kCapLen, kActAxisY, kActAxisZ), x, kCapR, kCapLen + 1.0));
  b.add.push_back(box(kLugX0, kActAxisY - kLugHalfY, kActAxisZ - kLugHalfZ, kActBodyX0 - kCapLen + 1.0,
                      kActAxisY + kLugHalfY, kActAxisZ + kLugHalfZ));
  b.cut.push_back(cylinder(gp_Pnt(kLugX0 + 7.0, kActAxisY - kLugHalfY - 1.0, kActAxisZ), y, kPinR, 2 * kLugHalfY + 2.0));
  // Rod with a threaded look: thin rings.
  b.add.push_back(cylinder(gp_Pnt(kActBodyX1 - 1.0, kActAxisY, kActAxisZ), x, kActRodR, kActRodX1 - kActBodyX1 + 1.0));
  constexpr int kThreadRings = 20;
  constexpr double kThreadX0 = 656.0, kThreadPitch = 3.0, kThreadH = 1.2, kThreadDepth = 1.0;
  for (int k = 0; k < kThreadRings; ++k)
    b.add.push_back(cylinder(gp_Pnt(kThreadX0 + k * kThreadPitch, kActAxisY, kActAxisZ), x, kActRodR + kThreadDepth,
                             kThreadH));
  // Rod-end eye with its pin bore.
  const double eye_x = kActRodX1 + kActEyeR - 4.0;
  b.add.push_back(BRepPrimAPI_MakeSphere(gp_Pnt(eye_x, kActAxisY, kActAxisZ), kActEyeR).Shape());
  b.cut.push_back(cylinder(gp_Pnt(eye_x, kActAxisY, kActAxisZ - kActEyeR - 1.0), z, kPinR, 2 * kActEyeR + 2.0));
  // Slots along the top and bottom of the body and three circumferential grooves.
  constexpr double kSlotX0 = 560.0, kSlotX1 = 630.0, kSlotHalfW = 1.5, kSlotDepth = 4.0;
  b.cut.push_back(box(kSlotX0, kActAxisY - kSlotHalfW, kActAxisZ + kActBodyR - kSlotDepth, kSlotX1,
                      kActAxisY + kSlotHalfW, kActAxisZ + kActBodyR + 1.0));
  b.cut.push_back(box(kSlotX0, kActAxisY - kSlotHalfW, kActAxisZ - kActBodyR - 1.0, kSlotX1,
                      kActAxisY + kSlotHalfW, kActAxisZ - kActBodyR + kSlotDepth));
  constexpr double kGrooveDepth = 2.0, kGrooveW = 2.0;
  for (double gx : {590.0, 600.0, 610.0})
    b.cut.push_back(ring(gp_Pnt(gx, kActAxisY, kActAxisZ), x, kActBodyR - kGrooveDepth, kActBodyR + 1.0, kGrooveW));
  // Bracket to the rear spar web with two bolt holes.
  constexpr double kBrX0 = 560.0, kBrX1 = 610.0, kBrHalfZ = 12.0, kBoltR = 3.0, kBoltFromSpar = 24.0;
  b.add.push_back(box(kBrX0, kActAxisY, kActAxisZ - kBrHalfZ, kBrX1, kRearSparInnerY, kActAxisZ + kBrHalfZ));
  for (double bx : {kBrX0 + 12.0, kBrX1 - 12.0})
    b.cut.push_back(cylinder(gp_Pnt(bx, kRearSparInnerY - kBoltFromSpar, kActAxisZ - kBrHalfZ - 1.0), z, kBoltR,
                             2 * kBrHalfZ + 2.0));
  // Receptacle on the −Y side of the body, sunk into the curved wall.
  constexpr double kEmbed = 12.0;
  add_receptacle(b, gp_Pnt(kActReceptacleX, kActAxisY - kActBodyR, kActAxisZ), my, x, kActReceptacle, kEmbed, false);
  return build(b, "actuator");
}

TopoDS_Shape make_actuator_envelope() {
  const double* e = kActEnvelope;
  return single_solid(box(e[0], e[1], e[2], e[3], e[4], e[5]), "actuator envelope");
}

TopoDS_Shape make_connector_bracket() {
  Body b;
  const double x1 = kConnPlateX0 + kConnPlateT;
  b.add.push_back(box(kConnPlateX0, kSparInnerY, kConnPlateZ0, x1, kConnPlateY1, kConnPlateZ1));
  // Foot riveted to the spar web.
  constexpr double kFootLen = 30.0, kFootT = 6.0, kFootRivetDX = 20.0;
  b.add.push_back(box(kConnPlateX0, kSparInnerY, kConnPlateZ0, kConnPlateX0 + kFootLen, kSparInnerY + kFootT,
                      kConnPlateZ1));
  const gp_Dir x(1, 0, 0), y(0, 1, 0);
  for (double zr : {kConnPlateZ0 + 15.0, kConnPlateZ1 - 15.0})
    b.cut.push_back(cylinder(gp_Pnt(kConnPlateX0 + kFootRivetDX, kSparInnerY - 1.0, zr), y, kRivetR, kFootT + 2.0));
  add_receptacle(b, gp_Pnt(x1, kTrunkY, kTrunkZ), x, y, kTrunkReceptacle, 1.0, true);
  return build(b, "connector bracket");
}

std::vector<PartShape> make_wing_parts() {
  std::vector<PartShape> parts;
  parts.push_back({"spar.step", "spar", make_spar()});
  parts.push_back({"rib.step", "rib", make_rib()});
  parts.push_back({"avionics-box.step", "avionics-box", make_avionics_box()});
  parts.push_back({"actuator.step", "actuator", make_actuator()});
  parts.push_back({"actuator-envelope.step", "actuator-envelope", make_actuator_envelope()});
  parts.push_back({"connector-bracket.step", "connector-bracket", make_connector_bracket()});
  return parts;
}

}  // namespace loom::examples
