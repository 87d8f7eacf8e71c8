#pragma once
/// Loading a whole scene: the TOML file, every part file (meshes and CAD), the harness,
/// and the derived settings (DESIGN §3, §7).

#include "core/progress.hpp"
#include "core/scene.hpp"

#include <filesystem>
#include <string>
#include <vector>

namespace loom {

class CadShapeStore;  // core/io/mesh_read.hpp

/// What load_scene() should do.
struct SceneLoadOptions {
  bool load_parts = true;    ///< false: only TOML + harness (fast, for tests of settings)
  bool use_cache = true;     ///< cache CAD tessellations keyed by file hash and deflection
  /// Stage "load": part files ([[part]] entries) read and triangulated, from the calling thread.
  ProgressFn progress;
  /// Which [[part]] entries to load, by their order in the file (empty: all). An entry not
  /// selected is validated like the others but yields no part (a shard of a sharded audit
  /// loads only its own; duplicate names across entries are then the caller's to check).
  std::vector<bool> entries;
  /// Honour `[tessellation] by_need`: CAD parts meshed at its coarse deflection (the caller
  /// refines what cables come near: retessellate_parts). False: every CAD part at the fine
  /// deflection, and a note when the scene asks for tessellation by need.
  bool tessellate_by_need = false;
  /// With tessellate_by_need and a scene that asks for it: transferred CAD files to read
  /// from and keep (read_cad_file) for the refinement (retessellate_parts). Null: none kept.
  CadShapeStore* cad_shapes = nullptr;
};

/// What loading took and noticed.
struct SceneLoadReport {
  double load_ms = 0.0;
  std::vector<std::string> notes;  ///< e.g. "part 'skin' is open: surface checks only"
  /// The [[part]] entry (0-based, file order) each loaded part came from: a CAD file may
  /// yield several parts, a skipped entry (SceneLoadOptions::entries) none.
  std::vector<int> part_entries;
};

/// Reads and validates a scene file. Relative paths in it are relative to its directory.
/// Throws InputError (file, line, key, reason) for every malformed input.
Scene load_scene(const std::filesystem::path& toml, const SceneLoadOptions& opt = {},
                 SceneLoadReport* report = nullptr);

/// Tessellates the given CAD parts of a loaded scene (indices into scene.parts) again at
/// `deflection` (scene units) from their files, each with its leaf and entry transform,
/// through the tessellation cache (keyed by the leaves too); meshes, closedness and
/// deflection replaced. Throws InputError naming the file.
void retessellate_parts(Scene& scene, const std::vector<int>& parts, double deflection,
                        CadShapeStore* cad_shapes = nullptr);

/// Replaces the scene's harness by a routed harness XML (`--routes`). Throws InputError
/// naming the routes file for a unit mismatch or any harness error.
void apply_routes(Scene& scene, const std::filesystem::path& routes);

}  // namespace loom
