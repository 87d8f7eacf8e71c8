#pragma once
/// EmbreeIndex: exact obstacle queries over the parts' triangles, culled by an Embree 3
/// float BVH (DESIGN §6, §9). One RTCScene holds one triangle geometry per part
/// (geomID = part id) over loom's own vertex/index arrays; vertices are re-centred on the
/// scene centre before rounding to float. Every reported distance is computed in double
/// on the original world-frame triangles inside the rtcPointQuery callback; the float BVH
/// only culls, with its search radius padded by a bound on the float rounding, so
/// distances are exact up to double rounding. Inside the callback a triangle is first
/// rejected by its box (a lower bound, so still exact), and its zero-area flag, stored at
/// build, spares the exact kernel its degeneracy test. Inside tests cast several lines
/// (majority vote) through each candidate closed part's whole box and count its crossings,
/// each decided in double; for that part a line is discarded if a crossing lies within the
/// float rounding of Embree's ray test of an edge or vertex (Embree may report it on the
/// neighbouring triangle, or on neither) or if the count is odd (a closed part crosses a
/// line an even number of times: a crossing nobody reported, or a hole); if every line is
/// — or the part is too small for float rays at its distance from the centre — the
/// generalized winding number decides, in double (a point on the surface is not inside).

#include "core/part.hpp"
#include "index/obstacle_index.hpp"

#include <array>
#include <atomic>
#include <cstddef>
#include <memory>
#include <mutex>
#include <vector>

namespace loom {

/// Build settings of the Embree BVH.
struct EmbreeOptions {
  /// Embree build quality: 0 = low (fastest build), 1 = medium, 2 = high (spatial splits);
  /// -1 = automatic: medium, low from 500k triangles on (~3x faster build, ~30% slower
  /// closest queries: the right trade when one build serves one audit).
  int build_quality = -1;
  /// Lines cast per candidate part for an inside test; the answer is the majority of the
  /// lines that cross the part cleanly (no edge or vertex grazed, an even count; odd, ≥ 1).
  /// One is exact on a watertight mesh unless Embree misses two crossings on one line; the
  /// majority guards that and real meshes with holes.
  int inside_rays = 3;
};

/// Exact point/segment/ray queries accelerated by Embree; see ObstacleIndex for the
/// contract of each method.
class EmbreeIndex : public ObstacleIndex {
 public:
  /// Builds the BVH over all parts (meshes in world frame). Throws InputError if a
  /// triangle indexes a missing vertex or a vertex is not finite.
  explicit EmbreeIndex(const std::vector<Part>& parts, const EmbreeOptions& opt = {});
  ~EmbreeIndex() override;
  EmbreeIndex(const EmbreeIndex&) = delete;
  EmbreeIndex& operator=(const EmbreeIndex&) = delete;

  std::string name() const override { return "embree"; }
  IndexAccuracy accuracy() const override;
  int part_count() const override { return static_cast<int>(parts_.size()); }

  ClosestHit closest(const Vec3& p, double max_radius = std::numeric_limits<double>::infinity()) const override;
  /// Stops at the first surface point within (1 + rel_error) of every unvisited leaf: the
  /// search radius shrinks to D / (1 + rel_error) (+ the float pad) at each hit D.
  ClosestHit closest_approx(const Vec3& p, double max_radius, double rel_error) const override;
  ClosestHit closest_on_part(const Vec3& p, int part,
                             double max_radius = std::numeric_limits<double>::infinity()) const override;
  bool inside(const Vec3& p, int* part = nullptr) const override;
  void inside_parts(const Vec3& p, std::vector<int>& out) const override;
  std::optional<AABB> part_bounds(int part) const override;
  RayHit ray(const Vec3& origin, const Vec3& dir,
             double t_max = std::numeric_limits<double>::infinity()) const override;
  bool any_within(const Vec3& p, double r) const override;
  bool segment_within(const Vec3& a, const Vec3& b, double r) const override;
  ClosestHit segment_closest(const Vec3& a, const Vec3& b,
                             double max_radius = std::numeric_limits<double>::infinity(),
                             double* segment_param = nullptr) const override;
  ClosestHit segment_closest_approx(const Vec3& a, const Vec3& b, double max_radius, double rel_error,
                                    double* segment_param = nullptr) const override;
  ClosestHit segment_closest_on_part(const Vec3& a, const Vec3& b, int part, double max_radius,
                                     double* segment_param = nullptr) const override;

  /// The re-centring offset: Embree sees world − centre() (world frame, scene units).
  const Vec3& centre() const { return centre_; }
  /// Largest |coordinate − centre| over all vertices (scene units).
  double half_extent() const { return half_extent_; }
  /// Wall-clock seconds spent building the main BVH: float conversion of the vertices,
  /// per-triangle degenerate flags (both parallel) and Embree's build.
  double build_seconds() const { return build_seconds_; }
  /// Bytes held: Embree's allocations (BVH) plus loom's vertex/index/double arrays.
  std::size_t memory_bytes() const;
  /// Total triangles indexed.
  std::size_t triangle_count() const { return triangle_count_; }

  /// Per-part data (public for the callbacks in the .cpp; not part of the API).
  struct PartData;
  struct Impl;

 private:
  /// Search-radius pad (scene units) that covers float rounding for a query at p.
  double float_pad(const Vec3& p, double radius) const;
  /// Bound on the rounding of an exact distance (scene units; IndexAccuracy::abs_error).
  double distance_rounding() const;
  /// The closed parts holding p strictly inside, into *out (cleared first) in candidate
  /// order; with first_only the scan stops at the first. inside() and inside_parts().
  void inside_scan(const Vec3& p, bool first_only, std::vector<int>& out) const;
  /// Closest point in `scene`: the whole index (only_part = -1; filter_part ≥ 0 keeps that
  /// part's triangles only), or a one-part scene with only_part = its id.
  /// `shrink` = 1 / (1 + rel_error) scales the search radius at each hit (1: exact).
  ClosestHit closest_in(void* scene, int only_part, int filter_part, const Vec3& p, double max_radius,
                        double shrink = 1.0) const;
  /// Closest point on the segment ab's nearest surface in the main scene (filter_part ≥ 0:
  /// that part's triangles only), with the search radius shrinking to shrink·best.
  ClosestHit segment_closest_in(const Vec3& a, const Vec3& b, int filter_part, double max_radius,
                                double* segment_param, double shrink) const;
  /// Lazily built scene holding only one part (for closest_on_part).
  void* part_scene(int part) const;

  std::unique_ptr<Impl> impl_;
  std::vector<PartData> parts_;
  Vec3 centre_ = Vec3::Zero();
  double half_extent_ = 0.0;
  double build_seconds_ = 0.0;
  std::size_t triangle_count_ = 0;
  EmbreeOptions opt_;
};

/// Per-part storage: double vertices (world frame) and indices for the exact kernels, the
/// float re-centred copy Embree reads (padded by one float4 as Embree requires).
struct EmbreeIndex::PartData {
  std::vector<Vec3> vertices;  ///< world frame, double (the exact geometry)
  std::vector<std::array<std::uint32_t, 3>> triangles;  ///< shared with Embree's index buffer
  std::vector<float> vertices_f;  ///< x y z per vertex, re-centred, + 4 padding floats
  std::vector<std::uint8_t> degenerate;  ///< per triangle: 1 if triangle_is_degenerate()
  AABB bounds;                    ///< world-frame box of the referenced vertices
  bool closed = false;            ///< Part::closed: only closed parts have an inside
  /// The three world-frame corners of triangle t.
  std::array<Vec3, 3> corners(std::size_t t) const {
    const auto& f = triangles[t];
    return {vertices[f[0]], vertices[f[1]], vertices[f[2]]};
  }
};

}  // namespace loom
