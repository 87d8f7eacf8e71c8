#pragma once
/// The port check that the planner and the route pipeline share: a port must lie outside
/// every part, keep radius + clearance from every part it does not sit on, and its straight
/// exit must keep that distance from every part (a part it sits on only past the run that
/// is excused). World frame, scene units.

#include "core/part.hpp"
#include "index/obstacle_index.hpp"
#include "routing/route/path_planner.hpp"

#include <functional>
#include <string>
#include <vector>

namespace loom {

/// A part whose surface comes within the tube's required distance of a port, and how far
/// along the port's straight exit the cable may run closer to it than that.
struct NearPart {
  int part = -1;
  double excused = 0.0;  ///< scene units along the exit from the port
};

/// The parts within `required` of `port` (part_boxes[q]: box of parts[q]). One the port sits
/// on (its connector: any part but a keep-out zone, DESIGN / README "Attached parts") is
/// excused over `excused_on` — the audit does not check the cable against it over the port's
/// straight exit; a keep-out zone never is, but its first `excused_near` cannot be helped
/// (the audit reports it).
std::vector<NearPart> near_port_parts(const ObstacleIndex& index, const std::vector<AABB>& part_boxes,
                                      const std::vector<Part>& parts, const Vec3& port, double required,
                                      double excused_on, double excused_near);

/// One port end and its straight exit, as the port check sees it.
struct PortExit {
  std::string who;               ///< how messages name the port: "port T1", "start port"
  Vec3 port = Vec3::Zero();      ///< the port's position
  Vec3 stub_end = Vec3::Zero();  ///< end of its straight exit (may equal the port)
  bool is_start = true;          ///< the plan's first end (else its second)
  std::vector<NearPart> near;    ///< parts the exit is excused from near the port
  double lift = 0.0;             ///< from this far off the port the exit must be outside every part
};

/// Name of a part id in messages; empty: parts are named by their id.
using PartNameFn = std::function<std::string(int part)>;

/// True if the port and its exit are clear; else writes the reason (start/goal in obstacle,
/// start/goal port blocked), the blocking point and part, and the message into `r`.
/// `part_boxes` (box of each indexed part) is needed only when `e.near` is not empty.
bool check_port_exit(const ObstacleIndex& index, const std::vector<AABB>& part_boxes, const PortExit& e,
                     double required, const PartNameFn& part_name, PlanResult& r);

}  // namespace loom
