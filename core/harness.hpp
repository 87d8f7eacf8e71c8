#pragma once
/// The harness model of the parametric-model patent (seed: cable-assembly-parametric-
/// model-xml): four sets — physical attributes, electrical attributes, structure
/// (ports and branch points) and branch paths (ordered path points per segment). The
/// patent's branch points join exactly three nodes; here a node joins any number (two: a
/// pass-through point). Lengths in Harness::units.

#include "core/geometry.hpp"
#include "core/units.hpp"

#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace loom {

/// Physical attributes of one cable (patent: type id, colour, diameter, min bend radius).
struct CablePhysical {
  std::string type;            ///< cable type id, e.g. "AWG20"
  std::string color;           ///< free text colour name
  double diameter = 0.0;       ///< outer diameter (> 0), harness units
  double min_bend_radius = 0.0;  ///< smallest allowed centerline bend radius (≥ 0; 0 = unchecked)
  double cross_section = 0.0;  ///< conductor cross-section, harness units squared (0 = not given)
  /// Segregation class, e.g. "power" or "signal" (empty: none); the scene's
  /// [routing.separation] gives the least distance between two classes.
  std::string cable_class;
};

/// One core of a multicore cable: it runs inside the cable's jacket from end to end.
struct CableCore {
  std::string id;          ///< e.g. the core's wire number
  CablePhysical physical;  ///< its own type, colour, diameter (0 = not given), cross-section
};

/// One cable: an electrical connection between two ports.
struct Cable {
  std::string id;
  std::string ports[2];  ///< the two port ids it connects (electrical attributes)
  CablePhysical physical;  ///< of the whole cable (a multicore: its jacket)
  std::vector<CableCore> cores;  ///< a multicore's cores (empty for a single wire)
  int line = 0;          ///< line in the source file (0 if built in code)
  /// Radius of the cable (diameter / 2).
  double radius() const { return 0.5 * physical.diameter; }
};

/// A connector pin or cable end: a fixed position with the direction a cable leaves it.
struct Port {
  std::string id;
  Vec3 position = Vec3::Zero();
  Vec3 direction = Vec3::UnitX();  ///< unit exit direction
  int line = 0;
  /// False for a port of a file without 3D geometry (KBL formboard, VEC topology) until the
  /// scene's [harness.place] gives its position and direction.
  bool placed = true;
};

/// A branch point of the harness tree, joined to any number of nodes (3 in the patent, 2
/// for a pass-through point). The position may be absent on input, in which case the
/// router places it.
struct BranchPoint {
  std::string id;
  std::optional<Vec3> position;
  int line = 0;
};

/// How the path points of a segment become a curve.
enum class Interp { BSpline, Polyline };

/// An exact cubic (or other degree) B-spline as stored in routed XML.
struct BSplineData {
  int degree = 3;
  std::vector<double> knots;
  std::vector<Vec3> control_points;
};

/// A branch path between two nodes (ports or branch points): ordered interior path
/// points, how to interpolate them, and optionally the exact routed spline.
struct Segment {
  std::string from;   ///< start node id (a port or a branch point)
  std::string to;     ///< end node id
  std::vector<Vec3> path;  ///< interior path points, from → to (may be empty)
  Interp interp = Interp::BSpline;
  std::optional<BSplineData> bspline;  ///< exact routed curve from → to, if any
  std::optional<double> diameter;      ///< bundle diameter given in the file, if any
  /// Length the file gives for the segment (KBL Physical_length, a formboard Virtual_length,
  /// VEC segment length): what the harness maker cuts, harness units.
  std::optional<double> nominal_length;
  /// Id of the branch element this segment was written under (empty: top level), kept
  /// so that writing the file back reproduces its structure.
  std::string parent_branch;
  int line = 0;
};

/// A fixed support of the harness (a clip or fixing): the bundle is held at this point.
struct Clamp {
  std::string id;
  Vec3 position = Vec3::Zero();  ///< on the bundle's centreline, harness units
  int segment = -1;  ///< index into Harness::segments of the segment it holds (−1: not given)
  std::string part;  ///< the structure part it is fixed to, as last measured (empty: not known)
  double bundle_diameter = 0.0;  ///< diameter of the bundle it holds, harness units (0: not known)
  bool placed = false;  ///< true: placed by the router, false: given by the input file
  int line = 0;
};

struct KblOrigin;  // core/io/kbl_read.hpp

/// The harness as read from a file: four sets plus the order elements appeared in.
struct Harness {
  std::string name;
  Unit units = Unit::Millimetre;
  std::vector<Cable> cables;
  std::vector<Port> ports;
  std::vector<BranchPoint> branches;
  std::vector<Segment> segments;
  std::vector<Clamp> clamps;  ///< fixed supports given by the file
  std::string source_file;  ///< the file it was read from (for messages)
  /// Set when the harness was read from a KBL file: that file's text, the KBL ids of loom's
  /// nodes, segments and cables, and what the reader did not use (writing back: kbl_write).
  std::shared_ptr<const KblOrigin> kbl;

  /// Index of a port by id, or -1.
  int find_port(const std::string& id) const;
  /// Index of a branch point by id, or -1.
  int find_branch(const std::string& id) const;
  /// Position of a node (port or branch point) by id; nullopt for an unknown id or an
  /// unplaced branch point.
  std::optional<Vec3> node_position(const std::string& id) const;
  /// Index of a cable by id, or -1.
  int find_cable(const std::string& id) const;
  /// Smallest cable diameter (0 if there are no cables).
  double smallest_diameter() const;
};

}  // namespace loom
