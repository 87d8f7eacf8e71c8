#pragma once
/// JSON documents as text, for every report and file loom writes.

#include <nlohmann/json.hpp>

#include <string>

namespace loom {

/// `j` as text (indented by `indent`, or compact if < 0). A string that is not valid UTF-8
/// — a file or part name taken from the file system; harness data is checked when read —
/// gets U+FFFD for its bad bytes, where nlohmann's dump() would throw type_error 316 (a
/// message naming nothing, after some outputs were already written).
std::string json_text(const nlohmann::json& j, int indent = -1);

}  // namespace loom
