#pragma once
/// A disk cache of CAD tessellations keyed by file content hash and tessellation
/// parameters (DESIGN §7: tessellating finer than needed costs minutes; repeated runs
/// should not pay twice). Location: $LOOM_CACHE_DIR, else $XDG_CACHE_HOME/loom, else
/// $HOME/.cache/loom. A cache that cannot be written only costs time, never correctness.

#include "core/io/mesh_read.hpp"

#include <filesystem>
#include <string>
#include <vector>

namespace loom {

/// The cache directory in use (may not exist yet); empty if no location is available.
std::filesystem::path tessellation_cache_dir();

/// Key of a tessellation: 64-bit FNV-1a of the file bytes and of the parameters (and of
/// the leaves asked for, when only some are), as hex.
std::string tessellation_cache_key(const std::filesystem::path& file, const TessellationParams& tp, bool split,
                                   const std::vector<int>* only_leaves = nullptr);

/// read_cad_file() through the cache: a hit returns the stored meshes, a miss tessellates
/// and stores. `hit` (if given) tells which happened. A path that is not a readable regular
/// file is an InputError before anything is hashed (require_input_file). A miss reads
/// through `shapes` (read_cad_file's store).
std::vector<NamedMesh> read_cad_file_cached(const std::filesystem::path& path, const TessellationParams& tp,
                                            bool split, bool* hit = nullptr,
                                            const std::vector<int>* only_leaves = nullptr,
                                            CadShapeStore* shapes = nullptr);

}  // namespace loom
