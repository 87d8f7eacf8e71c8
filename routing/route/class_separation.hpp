#pragma once
/// Cable classes in planning (DESIGN §3, §5): a segment is planned away from the bundles of
/// other classes by their [routing.separation] on top of the routing clearance, so the
/// segregation audit of the routed harness finds nothing where the topology keeps the
/// classes in separate segments. Where it does not (one segment carrying two separated
/// classes, or segments of two separated classes meeting at a node) planning cannot help:
/// those places are named before planning.

#include "core/harness_topology.hpp"
#include "core/scene.hpp"

#include <set>
#include <string>
#include <vector>

namespace loom {

/// The classes of the cables each segment carries (index = segment; cables without a class
/// add nothing).
std::vector<std::set<std::string>> segment_classes(const HarnessTopology& topo);

/// The largest separation [routing.separation] requires between any class of `a` and any
/// class of `b` (scene units; 0 when none is given or either set is empty).
double class_gap(const RoutingSettings& routing, const std::set<std::string>& a, const std::set<std::string>& b);

/// One line per place where the topology itself breaks a separation, before any planning: a
/// segment carrying two classes that must be kept apart ("segment A -> B carries classes
/// power and signal, which [routing.separation] keeps 50 apart"), and a node where segments
/// of two such classes meet. Empty when the harness has no such place.
std::vector<std::string> separation_conflicts(const HarnessTopology& topo, const RoutingSettings& routing,
                                              const std::vector<std::set<std::string>>& classes);

}  // namespace loom
