#pragma once
/// VEC files (.vec, the prostep ivip Vehicle Electric Container, KBL's successor): their
/// topology (TopologyNode, TopologySegment with its LengthInformation, components placed on
/// nodes, contact points, wire element references with their wire ends and outside
/// diameters, routings) read into loom's harness model through the KBL reader, as the KBL
/// 2.4 document that says the same: nodes without 3D positions (topology only: the scene
/// places the ports, the router the branch points). A VEC's 3D geometry is not read: a file
/// that has some is refused. Millimetres.
#include "core/harness.hpp"

#include <filesystem>
#include <string>

namespace loom {

/// Reads a VEC file's topology (ports unplaced, Harness::kbl its KBL equivalent). Throws
/// InputError naming the file, line and VEC element for every fault: a missing reference, a
/// wire without an outside diameter, a routing off the tree path, a cycle (variants), 3D
/// geometry it does not read.
Harness read_harness_vec(const std::filesystem::path& path);
/// Same, from text; `name_for_errors` stands in for the file name in messages.
Harness parse_harness_vec(const std::string& text, const std::string& name_for_errors);

}  // namespace loom
