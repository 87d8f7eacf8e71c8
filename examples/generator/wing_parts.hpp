#pragma once
/// The solids of the wing-section example, built with OpenCASCADE primitives and Booleans.
/// Each builder returns one solid in its model frame (mm); the scene places repeated parts
/// (ribs, boxes, spars, connector brackets) with transforms, see scene_text().

#include <TopoDS_Shape.hxx>

#include <string>
#include <vector>

namespace loom::examples {

/// One STEP file of the example: its file name, the product name stored in it, the solid.
struct PartShape {
  std::string file;     ///< file name inside the output directory, e.g. "rib.step"
  std::string product;  ///< STEP product name
  TopoDS_Shape shape;   ///< one solid, model frame, mm
};

/// Front spar (C-section, flanges pointing aft) with rivet holes, world frame. The rear
/// spar is the same solid turned 180° about Z and moved by (kSpan, kChord, 0).
TopoDS_Shape make_spar();
/// Rib at x = 0 (web, caps, three lightening holes, rivet holes); placed at kRibX[i].
TopoDS_Shape make_rib();
/// Avionics box centred on x = 0 with two receptacles on its −Y face, cooling slots and a
/// mounting bracket to the rear spar; placed at kBoxX[i].
TopoDS_Shape make_avionics_box();
/// Actuator in world frame: slotted body, threaded-looking rod, rod-end eye, receptacle,
/// mounting bracket to the rear spar.
TopoDS_Shape make_actuator();
/// The actuator's swept envelope (a box), world frame: the keep-out zone.
TopoDS_Shape make_actuator_envelope();
/// Root connector bracket (plate on the front spar web with a receptacle facing +X),
/// world frame; the tip bracket is the same solid turned 180° about Y, moved by (kSpan, 0, kDepth).
TopoDS_Shape make_connector_bracket();

/// All example STEP files, in a fixed order.
std::vector<PartShape> make_wing_parts();

}  // namespace loom::examples
