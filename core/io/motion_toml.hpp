#pragma once
/// Reading part motions from a scene file (DESIGN §3, docs/FORMATS.md "Moving parts"):
/// named `[[motion]]` tables shared by several parts, and a part's `motion` key (an inline
/// table, or the name of a `[[motion]]`). Used by the scene loader only (needs toml++).

#include "core/motion.hpp"

#include <toml++/toml.h>

#include <map>
#include <string>

namespace loom {

/// The `[[motion]]` array of a scene document (absent: none), keyed by name. Each entry is
/// `name = "..."` plus exactly one of `rotate = { axis_point, axis, from_deg, to_deg }` or
/// `translate = { direction, from, to }`. Throws InputError naming `file`, the line and
/// the entry for a missing or duplicate name, an unknown key or a bad value.
std::map<std::string, Motion> read_named_motions(const toml::table& doc, const std::string& file);

/// A part's `motion` value `n`: `{ rotate = {...} }` / `{ translate = {...} }`, or a string
/// naming one of `named`. `part` names the part in messages ("part 'flap-arm'"). Throws
/// InputError naming `file`, the line and the part.
Motion read_part_motion(const toml::node& n, const std::map<std::string, Motion>& named, const std::string& file,
                        const std::string& part);

}  // namespace loom
