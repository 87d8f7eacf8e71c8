#pragma once
/// Sweeping a sphere along a centerline: tubes (constant r) and canal surfaces (variable
/// r(s)) with a rotation-minimising frame (seed: cable-scan-centerline-and-sphere-sweep §4).

#include "core/centerline.hpp"
#include "core/mesh.hpp"

#include <functional>
#include <limits>
#include <string>
#include <vector>

namespace loom {

/// Resolution of a swept surface, derived from a chord tolerance.
/// Most triangles of all cable tubes of one harness output (render.png, cables.ply):
/// ~1 GB as a mesh, ~6 GB with a ray-casting BVH. A harness of 1,000 cables of a few metres
/// needs a few million; routes folding back on themselves thousands of times need more.
constexpr std::size_t kHarnessTubeTriangleBudget = 40'000'000;

struct SweepOptions {
  double chord_tolerance = 0.01;  ///< max distance between the mesh and the true surface, scene units
  bool end_caps = true;           ///< close both ends (watertight)
  /// Most triangles the mesh may have; past it the sweep throws std::invalid_argument
  /// after placing the rings and before allocating the mesh. A caller meshing many tubes
  /// passes what is left of its own budget.
  std::size_t max_triangles = std::numeric_limits<std::size_t>::max();
};

/// One cross-section of a sweep: a circle in the plane normal to `tangent` (world
/// coordinates, scene units). Mesh ring i places vertex j at
/// centre + radius·(cos φ · normal + sin φ · tangent × normal), φ = 2π(j + (i mod 2)/2)/n:
/// odd rings are rotated by half a step, so the facets are near-equilateral.
struct SweepSection {
  double u = 0.0;       ///< curve parameter
  double s = 0.0;       ///< arc length from the start
  Vec3 point;           ///< C(u)
  Vec3 centre;          ///< circle centre M (eq. 7; = point for a tube)
  Vec3 tangent;         ///< unit tangent of the centerline
  Vec3 normal;          ///< first in-plane axis of the rotation-minimising frame
  double radius = 0.0;  ///< circle radius R (eq. 8; = r for a tube)
};

/// What sweeping produced and the resolution it chose.
struct SweepResult {
  Mesh mesh;                 ///< the swept surface (world coordinates, scene units)
  int circumferential = 0;  ///< vertices per ring
  int rings = 0;            ///< rings along the curve
  double max_frame_turn = 0.0;  ///< largest angle between adjacent frames (radians)
  /// True if the tube folds over itself between two neighbouring rings: the centerline
  /// bends there more tightly than the tube's radius (κ·r > 1 at the ring spacing; kinks
  /// and folds of the centerline included), so part of one ring lies behind the plane of
  /// the next and the facets between them cross, turned inside out. The mesh is still
  /// closed; it is not a valid tube surface there.
  bool folded = false;
  double fold_s = 0.0;  ///< arc length of the ring where the first fold starts (0 if none)
  /// The cross-section of each ring, in order: ring i's vertices are
  /// mesh.vertices[i·circumferential, (i + 1)·circumferential) (empty for a junction).
  std::vector<SweepSection> sections;
};

/// Tube of constant radius r around the centerline. A centerline of zero length (all its
/// control points one point) gives the ball of radius r there, as sweep_junction does.
SweepResult sweep_tube(const Centerline& c, double radius, const SweepOptions& opt = {});
/// Canal surface of radius r(s), s = arc length from the start (the ball of radius r(0)
/// for a centerline of zero length).
SweepResult sweep_canal(const Centerline& c, const std::function<double(double)>& radius_of_s,
                        const SweepOptions& opt = {});
/// sweep_tube into `out`, which it overwrites (the same result as the returning form). The
/// storage of out's vectors is reused: a caller that sweeps many cables through one
/// SweepResult (one per thread) allocates, and page-faults, its mesh memory once, not once
/// per cable. If it throws, out's contents are unspecified.
void sweep_tube(const Centerline& c, double radius, const SweepOptions& opt, SweepResult& out);
/// sweep_canal into `out`, reusing its storage as sweep_tube(c, radius, opt, out) does.
void sweep_canal(const Centerline& c, const std::function<double(double)>& radius_of_s, const SweepOptions& opt,
                 SweepResult& out);

/// Sweeps the tubes of many cables within one triangle budget: each sweep may use what the
/// earlier ones left (SweepOptions::max_triangles), so the budget is judged before each
/// mesh is allocated. Not thread-safe (one per output).
class TubeBudget {
 public:
  /// `owner` prefixes refusals (e.g. "render", "cables.ply").
  explicit TubeBudget(std::string owner, std::size_t total = kHarnessTubeTriangleBudget);
  /// sweep_tube(c, radius, opt) within what is left. Past it, or for any refusal of the
  /// sweep, throws CableLimitError (cable_limit.hpp) for `cable`, naming the owner, the
  /// cable and, when the cables before it took some, their share of the budget.
  SweepResult sweep(const Centerline& c, double radius, SweepOptions opt, const std::string& cable);
  /// Triangles of the tubes swept so far.
  std::size_t used() const { return used_; }

 private:
  std::string owner_;
  std::size_t total_ = 0;
  std::size_t used_ = 0;
  std::size_t cables_ = 0;
};

/// The cross-sections sweep_tube places (their spacing keeps the sagitta along the tube
/// within half the chord tolerance), with rotation-minimising frames.
std::vector<SweepSection> tube_sections(const Centerline& c, double radius, const SweepOptions& opt = {});
/// The cross-sections sweep_canal places.
std::vector<SweepSection> canal_sections(const Centerline& c, const std::function<double(double)>& radius_of_s,
                                         const SweepOptions& opt = {});
/// Vertices per ring that keep the polygon within `tolerance` of a circle of radius r.
int circumferential_resolution(double radius, double tolerance);

/// Closed sphere mesh around a branch junction: circumscribes the ball of radius r about
/// `centre` (no point of the ball lies outside it) and stays within opt.chord_tolerance of
/// its sphere. With tubes whose end caps meet at `centre`, it fills the wedges between
/// them, so the union has no gap. `rings` = latitude rings, `circumferential` = longitudes.
SweepResult sweep_junction(const Vec3& centre, double radius, const SweepOptions& opt = {});

}  // namespace loom
