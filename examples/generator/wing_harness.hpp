#pragma once
/// The harness of the wing-section example: ports on the receptacles (positions and exit
/// directions computed from the same layout as the solids), a tree of branch points (each
/// joined to exactly three nodes) with a trunk along the span through the rib lightening
/// holes and a breakout to every box, and 24 cables.

#include <array>
#include <string>
#include <vector>

namespace loom::examples {

/// A harness port: cable end at a receptacle mouth, world frame (mm), unit exit direction.
struct PortSpec {
  std::string id;
  std::array<double, 3> position;
  std::array<double, 3> direction;
};

/// A branch point; `has_position` false leaves it for the router to place.
struct BranchSpec {
  std::string id;
  bool has_position;
  std::array<double, 3> position;
  std::vector<std::string> segments_to;  ///< segments written under this branch element
};

/// One cable: two ports and the patent's physical attributes.
struct CableSpec {
  std::string id, port_a, port_b, type, color;
  double diameter;         ///< mm
  double min_bend_radius;  ///< mm
};

/// Ports of the example, in file order.
std::vector<PortSpec> wing_ports();
/// Branch points and the tree's segments, in file order.
std::vector<BranchSpec> wing_branches();
/// Cables, in file order.
std::vector<CableSpec> wing_cables();
/// The harness XML text (DESIGN §3) of the example.
std::string wing_harness_xml();

}  // namespace loom::examples
