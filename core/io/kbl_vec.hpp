#pragma once
/// VEC files (.vec, the prostep ivip Vehicle Electric Container, KBL's successor): what loom
/// reads of them. A VEC's harness topology (TopologyNode, TopologySegment, Routing) is read
/// and counted; its 3D geometry is not read yet, so every VEC is refused with a message that
/// says what the file holds and what loom would need (3D node positions and segment curves,
/// which loom reads from KBL). World frame, millimetres.

#include "core/harness.hpp"

#include <filesystem>
#include <string>

namespace loom {

/// Reads a VEC file: always throws InputError naming the file and the <vec:VecContent>
/// line, saying what the file holds (its version, topology nodes and segments, routings,
/// wire elements) and what is missing for loom (3D geometry, or loom's reader for it).
Harness read_harness_vec(const std::filesystem::path& path);
/// Same, from text; `name_for_errors` stands in for the file name in messages.
Harness parse_harness_vec(const std::string& text, const std::string& name_for_errors);

}  // namespace loom
