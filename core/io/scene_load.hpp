#pragma once
/// Loading a whole scene: the TOML file, every part file (meshes and CAD), the harness,
/// and the derived settings (DESIGN §3, §7).

#include "core/progress.hpp"
#include "core/scene.hpp"

#include <filesystem>
#include <string>
#include <vector>

namespace loom {

/// What load_scene() should do.
struct SceneLoadOptions {
  bool load_parts = true;    ///< false: only TOML + harness (fast, for tests of settings)
  bool use_cache = true;     ///< cache CAD tessellations keyed by file hash and deflection
  /// Stage "load": part files ([[part]] entries) read and triangulated, from the calling thread.
  ProgressFn progress;
};

/// What loading took and noticed.
struct SceneLoadReport {
  double load_ms = 0.0;
  std::vector<std::string> notes;  ///< e.g. "part 'skin' is open: surface checks only"
};

/// Sets, for the whole process, the names that a scene's routing.planner may take, so that
/// load_scene refuses any other naming the file and line. Until it is called any name loads
/// (core does not know the planners; loom::route's planner_names() does, and the command
/// line registers them at start-up). Call before any thread loads a scene.
void register_planner_names(std::vector<std::string> names);

/// Reads and validates a scene file. Relative paths in it are relative to its directory.
/// Throws InputError (file, line, key, reason) for every malformed input.
Scene load_scene(const std::filesystem::path& toml, const SceneLoadOptions& opt = {},
                 SceneLoadReport* report = nullptr);

/// Replaces the scene's harness by a routed harness XML (`--routes`). Throws InputError
/// naming the routes file for a unit mismatch or any harness error.
void apply_routes(Scene& scene, const std::filesystem::path& routes);

}  // namespace loom
