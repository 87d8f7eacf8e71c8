#pragma once
/// The whole wing-section example: STEP files, harness.xml and scene.toml, written
/// deterministically (same bytes on every run with the same OpenCASCADE).

#include <filesystem>
#include <string>
#include <vector>

namespace loom::examples {

/// Writes every file of the wing-section example into `outdir` (created if missing) and
/// returns their names, in the order written. Throws std::runtime_error on a modelling or
/// file failure.
std::vector<std::string> generate_wing_section(const std::filesystem::path& outdir);

}  // namespace loom::examples
