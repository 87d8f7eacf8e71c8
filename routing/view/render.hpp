#pragma once
/// render.png: a picture of a scene ray-cast on the CPU with Embree: parts and
/// cable tubes (swept from the cable centerlines) Lambert-shaded, clashes and violations of a
/// report.json drawn as discs at their projected points, from a camera framing the harness.

#include "core/geometry.hpp"
#include "core/harness.hpp"
#include "core/progress.hpp"
#include "core/scene.hpp"
#include "routing/curve/sweep.hpp"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <filesystem>
#include <optional>
#include <vector>

namespace loom {

/// A pinhole camera (world frame, scene units).
struct RenderCamera {
  Vec3 eye = Vec3(1, -1, 1);
  Vec3 target = Vec3::Zero();
  Vec3 up = Vec3::UnitZ();
  double fov_deg = 40.0;  ///< vertical field of view
};

/// What to render.
struct RenderOptions {
  int width = 1200;   ///< pixels
  int height = 800;   ///< pixels
  std::optional<RenderCamera> camera;  ///< nullopt: frame_camera() on the harness (or scene)
  /// Radius of a clash/violation disc in pixels; 0 = derived: max(4, min(width, height) / 120).
  double marker_radius_px = 0.0;
  /// Stage "render": image rows ray-cast, one call at a time from TBB workers. May be empty.
  ProgressFn progress;
  /// Most triangles of all cable tubes together (~150 bytes each with the ray-casting
  /// BVH); past it render_scene throws std::invalid_argument naming the cable (routes
  /// folding back on themselves thousands of times ran the machine out of memory).
  std::size_t max_tube_triangles = kHarnessTubeTriangleBudget;
};

/// An 8-bit RGB picture, rows top to bottom.
struct Image {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgb;  ///< width × height × 3
  /// Colour of pixel (x, y), x right, y down.
  std::array<std::uint8_t, 3> at(int x, int y) const;
};

/// What rendering did.
struct RenderStats {
  std::size_t rays = 0;            ///< primary rays cast (one per pixel)
  std::size_t tube_triangles = 0;  ///< triangles of the swept cable tubes
  std::size_t markers = 0;         ///< clash/violation/clamp discs drawn (in view)
  /// Share of the cable tubes' points the framing camera sees unhidden by parts (1 when
  /// the camera was given or there are no parts).
  double visible_cable_share = 1.0;
  double ms = 0.0;                 ///< wall time of index build + ray casting
};

/// A camera looking at `box` from the front-right-above so that all of it is in view for the
/// given width/height aspect ratio.
RenderCamera frame_camera(const AABB& box, double aspect);
/// The same framing from direction `view_from` (target → eye, any length > 0).
RenderCamera frame_camera(const AABB& box, double aspect, const Vec3& view_from);

/// Pixel coordinates (x right, y down, pixel centres at +0.5) of a world point, or nullopt if
/// it is behind the camera.
std::optional<Eigen::Vector2d> project_to_pixel(const RenderCamera& cam, int width, int height, const Vec3& p);

/// Ray-casts the scene's parts and the harness's routed cables; draws the report's clashes
/// (red), violations (bend radius orange, clearance yellow) and clamps (small teal discs,
/// counted in RenderStats::markers). Without opt.camera the camera
/// frames the harness from whichever of eight diagonal directions hides the least of it
/// behind parts, and structure in front of a cable is drawn see-through (45 % cable colour).
/// Throws InputError for a size below 1×1.
Image render_scene(const Scene& scene, const Harness& harness, const nlohmann::json& report,
                   const RenderOptions& opt = {}, RenderStats* stats = nullptr);

/// Writes the image as an 8-bit RGB PNG (libpng), atomically.
void write_png(const std::filesystem::path& file, const Image& image);

/// Parses "WxH" (e.g. "1600x900") into opt.width/height; throws InputError naming `flag`.
void parse_render_size(const std::string& text, const std::string& flag, RenderOptions& opt);

/// The colour render_scene and view.html give cable i (hue steps by the golden angle).
std::array<std::uint8_t, 3> cable_colour(std::size_t i);

}  // namespace loom
