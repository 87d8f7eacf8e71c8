#pragma once
/// Reading meshes and CAD files into world-frame Parts.
/// Meshes (STL ascii/binary, OBJ, PLY, OFF, glTF/GLB, DAE) through Assimp; STEP and IGES
/// through OpenCASCADE, tessellated with a deflection derived from the scene.

#include "core/mesh.hpp"

#include <cstddef>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace loom {

/// A named piece of geometry read from a file (a STEP product occurrence, a solid, or the
/// whole mesh file), in the file's own frame and units converted to the requested unit.
struct NamedMesh {
  std::string name;
  Mesh mesh;
  int brep_faces = 0;  ///< B-rep faces tessellated (CAD files only)
  int leaf = -1;       ///< CAD files read split: the leaf product's place among the file's leaves
};

/// How CAD files are tessellated.
struct TessellationParams {
  double linear_deflection = 0.1;  ///< scene units
  double angular_deflection_deg = 20.0;
  double unit_in_mm = 1.0;         ///< target unit (STEP lengths are converted to it)
};

/// True for extensions handled by OpenCASCADE (.step .stp .iges .igs).
bool is_cad_file(const std::filesystem::path& p);
/// True for extensions handled by Assimp (.stl .obj .ply .off .gltf .glb .dae).
bool is_mesh_file(const std::filesystem::path& p);

/// Reads a mesh file as one mesh (all of its meshes merged, node transforms applied,
/// identical vertices welded). Throws InputError for a missing/unreadable/empty file or
/// non-finite coordinates.
Mesh read_mesh_file(const std::filesystem::path& path);

/// The OBJ text that read_mesh_file hands to Assimp: `o` and `usemtl` statements turned into
/// comments, byte for byte (same size, same lines; a line continuing the one before it with
/// a backslash is left alone). Why: Assimp's OBJ parser looks each object and material name
/// up in a list of those seen before, quadratic in their number (40,000 one-triangle objects
/// took 4.7 s, 100,000 28 s; 40,000 materials 27 s). loom merges every object into one mesh
/// and reads no materials, so the names change nothing it reads.
std::string obj_text_for_assimp(std::string text);

/// The shapes of a STEP/IGES file as OpenCASCADE transferred them (its leaf products in the
/// assembly frame, with their names): all that meshing needs. Defined in mesh_read.cpp.
struct CadShapes;

/// Transferred CAD files by path, kept for the life of one load so that a file is parsed
/// once however often it is meshed (tessellation by need meshes a file coarse, then some of
/// its leaves fine: the second parse was the whole of its overhead). Not thread-safe.
class CadShapeStore {
 public:
  CadShapeStore();
  ~CadShapeStore();
  CadShapeStore(const CadShapeStore&) = delete;
  CadShapeStore& operator=(const CadShapeStore&) = delete;
  /// The shapes of `path` if this store holds them, else null.
  std::shared_ptr<CadShapes> find(const std::filesystem::path& path) const;
  /// Keeps the shapes of `path`.
  void add(const std::filesystem::path& path, std::shared_ptr<CadShapes> shapes);
  /// Files held.
  std::size_t size() const { return files_.size(); }

 private:
  std::map<std::string, std::shared_ptr<CadShapes>> files_;
};

/// Reads a STEP/IGES file. With `split` true, one NamedMesh per leaf product occurrence
/// (name = product name, "#k" appended to repeated names); otherwise one compound mesh.
/// `only_leaves` (split only; ascending leaf indices): tessellate just those leaves, the
/// others are skipped (names stay those of the whole file's reading). With a `store`, the
/// file's transferred shapes are taken from it when it holds them (the meshes are those of a
/// fresh reading) and added to it otherwise.
std::vector<NamedMesh> read_cad_file(const std::filesystem::path& path, const TessellationParams& tp,
                                     bool split, const std::vector<int>* only_leaves = nullptr,
                                     CadShapeStore* store = nullptr);

/// Removes OpenCASCADE's console printers from its default messenger, for the whole
/// process: its STEP/IGES readers and writers otherwise print transfer statistics on stdout,
/// which the command line keeps for its own output. Call once at start-up, before any
/// thread uses OpenCASCADE.
void silence_opencascade_console();

}  // namespace loom
