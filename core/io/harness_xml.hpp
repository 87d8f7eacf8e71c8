#pragma once
/// Harness XML (DESIGN §3, after the parametric-model patent): read with line-accurate
/// errors, written back losslessly (read → write → read gives the same model).

#include "core/harness.hpp"

#include <filesystem>
#include <string>

namespace loom {

/// Reads and validates a harness file (elements, attributes, numbers, ids). Structural
/// checks that need the whole tree (cycles, disconnected cables) are done
/// by HarnessTopology, which this calls too. Throws InputError naming file, line, element.
Harness read_harness_xml(const std::filesystem::path& path);
/// Same, from text; `name_for_errors` stands in for the file name in messages.
Harness parse_harness_xml(const std::string& text, const std::string& name_for_errors);
/// Serialises a harness (including routed <bspline> data) to XML text.
std::string harness_to_xml(const Harness& h);
/// Writes harness_to_xml(h) atomically.
void write_harness_xml(const Harness& h, const std::filesystem::path& path);

}  // namespace loom
