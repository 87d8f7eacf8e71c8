#pragma once
/// view.html: one self-contained page (three.js r111 inlined, no network) showing a scene's
/// parts, the harness cables coloured per cable, clashes (red) and violations (bend radius
/// orange, clearance yellow) from a report.json, with a side list that flies the camera to
/// an item, orbit/pan/zoom and part visibility toggles.

#include "core/harness.hpp"
#include "core/mesh.hpp"
#include "core/scene.hpp"
#include "routing/view/render.hpp"

#include <nlohmann/json.hpp>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

namespace loom {

/// What the page may contain.
struct ViewOptions {
  /// Most part triangles the page carries (all parts together); larger parts are decimated
  /// by vertex clustering in proportion to their triangle count. Keeps the page interactive.
  std::size_t triangle_budget = 300000;
  /// Coordinate rounding (scene units); 0 = derived: min(0.01 unit, 1e-5 × scene diagonal).
  double quantum = 0.0;
  /// Most centerline samples per cable (the spacing is length / this, or finer).
  std::size_t max_cable_samples = 400;
  std::string title;  ///< page title; empty = "loom — <scene name>"
};

/// What was written.
struct ViewStats {
  std::size_t part_triangles = 0;   ///< triangles of the scene's parts
  std::size_t shown_triangles = 0;  ///< part triangles carried by the page (≤ budget)
  std::size_t cables_drawn = 0;     ///< cables with a centerline (routed)
  std::size_t clashes = 0;          ///< report.json clashes[] shown as markers
  std::size_t violations = 0;       ///< report.json violations[] shown as markers
  std::size_t clamps = 0;           ///< report.json clamps[] shown as markers (cubes)
  double quantum = 0.0;             ///< coordinate rounding used (scene units)
  std::uintmax_t bytes = 0;         ///< size of the page
};

/// Vertex-clustering decimation: vertices are merged per cubic grid cell (at the cell's mean),
/// triangles that collapse or repeat are dropped; the cell grows until at most max_triangles
/// remain. Returns the mesh unchanged if it already fits. Same frame and units as `mesh`.
Mesh decimate_vertex_clustering(const Mesh& mesh, std::size_t max_triangles);

/// The page's data as JSON text (parts, cables, clashes, violations; coordinates as integers
/// in units of stats->quantum). `harness` is the routed (or given) harness drawn as cables;
/// `report` is a report.json of `loom route` or `loom audit` (clashes[], violations[]).
std::string view_data_json(const Scene& scene, const Harness& harness, const nlohmann::json& report,
                           const ViewOptions& opt, ViewStats* stats = nullptr);

/// Writes view.html (atomically) and returns what it holds.
ViewStats write_view_html(const std::filesystem::path& file, const Scene& scene, const Harness& harness,
                          const nlohmann::json& report, const ViewOptions& opt = {});

/// The files write_view_outputs() writes into `dir` (view.html, render.png).
std::vector<std::filesystem::path> view_output_files(const std::filesystem::path& dir);

/// What `loom route` and `loom audit` write beside report.json: DIR/view.html and
/// DIR/render.png (routing/render.hpp; size, camera and progress from `render`). Returns the
/// page's stats. The picture is made first: if render_scene throws, neither file is written.
ViewStats write_view_outputs(const std::filesystem::path& dir, const Scene& scene, const Harness& harness,
                             const nlohmann::json& report, const RenderOptions& render = {});

}  // namespace loom
