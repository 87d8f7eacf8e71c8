#pragma once
/// KBL 2.3 / 2.4 harness files (VDA 4964, prostep ivip) read into loom's harness model:
/// Nodes (Cartesian points) become ports where a wire ends or a connector, ring terminal or
/// component box sits, branch points elsewhere (any degree); Segments keep their centre
/// curves (kbl_curve.hpp: several per segment joined into one, a curve that overruns its
/// node trimmed there) and their cross-section as a nominal bundle diameter; wires and
/// multicores (a jacket with its cores) become cables between the ports of their
/// connections' contact points, each checked against its Routing; fixings become clamps.
/// A file whose nodes have no 3D position (a formboard drawing: 2D points, or none) is read
/// as topology only: ports unplaced (Port::placed false, the scene's [harness.place] places
/// them), branch points left to the router, 2D curves not read, each segment's
/// Physical_length or drawing Virtual_length kept as its nominal length.
/// Lengths in millimetres (the file's units converted), world frame of the file.
/// What loom does not use is named and counted in KblOrigin, never dropped silently.

#include "core/harness.hpp"

#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace loom {

/// What a KBL file held around loom's harness model, kept with the Harness read from it.
struct KblOrigin {
  std::string version;                      ///< the container's version_id, e.g. "2.3 SR-1"
  std::shared_ptr<const std::string> text;  ///< the file as read (written back with new geometry)
  std::map<std::string, std::string> node_ids;  ///< loom node id (port or branch point) → KBL Node id
  std::vector<std::string> segment_ids;         ///< per loom segment: the KBL Segment id
  /// Per loom segment: its curve as read (the writer leaves the file's own curves where
  /// loom's is still this one).
  std::vector<std::optional<BSplineData>> segment_curves;
  /// Per loom cable: the KBL wire, core or multicore occurrences whose length it gives.
  std::map<std::string, std::vector<std::string>> wire_ids;
  /// What was understood, in print order: ("wires", 12), ("connectors", 5), ...
  std::vector<std::pair<std::string, int>> counts;
  /// Elements with an id that loom does not use, by element name (e.g. "Module": 1).
  std::map<std::string, int> ignored;
  /// What the reader noticed: wires it could not place, diameters smaller than the wires
  /// need, lengths and tangents that disagree with the curves, ... (one line each).
  std::vector<std::string> notes;
};

/// Largest distance, mm, between a centre curve and the node it must reach (an end of the
/// curve, or where it passes a node it overruns). KBL coordinates carry 6 decimals and CAD
/// systems join curves to ~1e-3 mm; a curve farther than this from its node is not on it.
constexpr double kKblNodeGap = 0.01;

/// Reads a KBL file (.kbl). Throws InputError naming the file, line and element for every
/// fault: malformed XML, a reference to a missing id, a 2D point among 3D nodes, a port
/// without a position in a 3D file, a curve far from its nodes, a number that is not finite, a wire without an
/// outside diameter, a Routing that differs from the tree path between its wire's ends, a
/// cycle.
Harness read_harness_kbl(const std::filesystem::path& path);
/// Same, from text; `name_for_errors` stands in for the file name in messages.
Harness parse_harness_kbl(std::string text, const std::string& name_for_errors);

}  // namespace loom
