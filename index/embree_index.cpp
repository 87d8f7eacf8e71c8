#include "index/embree_index.hpp"

#include "core/stopwatch.hpp"
#include "core/error.hpp"
#include "index/box_tree.hpp"
#include "index/triangle_distance.hpp"

#include <embree3/rtcore.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <exception>
#include <stdexcept>
#include <string>
#include <utility>

#if defined(__SSE__) || defined(__x86_64__)
#include <xmmintrin.h>
#define LOOM_HAVE_MXCSR 1
#endif

namespace loom {

namespace {

/// Relative rounding of a float (2^-24) inflated ×16 to cover the query point's rounding,
/// Embree's own box arithmetic and the radius conversion: the culling pad per unit extent.
constexpr double kFloatPadRel = 16.0 / 16777216.0;
/// Barycentric margin under which a ray is said to graze an edge or vertex of a triangle
/// it crosses; such a ray is discarded from the inside vote.
constexpr double kGrazeBary = 1e-6;
/// A winding number above 0.5 by this much counts as inside where the winding number
/// decides (it passes 0.5 only within rounding of the surface, where p counts as on it).
constexpr double kWindingMargin = 1e-6;
/// A closed part whose box diagonal is below this many times the float rounding of a ray
/// at its distance from the centre is decided by the winding number, not by rays.
constexpr double kRayResolvedParts = 1000.0;
/// Directions of the inside-test rays: fixed, irrational-looking, pairwise far apart, so
/// that no axis-aligned CAD edge is parallel to any of them.
const Vec3 kInsideDirs[] = {
    Vec3(0.5773, 0.5831, 0.5714), Vec3(-0.6207, 0.2931, 0.7270), Vec3(0.3139, -0.8467, 0.4297),
    Vec3(-0.4523, -0.5174, -0.7264), Vec3(0.8123, 0.1451, -0.5651), Vec3(-0.1031, 0.9154, -0.3892),
    Vec3(0.6617, -0.4327, -0.6123), Vec3(-0.8832, -0.2123, 0.4184), Vec3(0.0737, 0.0813, 0.9940)};
constexpr int kMaxInsideDirs = 9;
/// A segment is split into at most this many pieces for sphere point queries.
constexpr int kMaxSegmentPieces = 256;
/// Target piece length as a fraction of the scene diagonal for segment_closest.
constexpr double kSegmentPieceRel = 1.0 / 128.0;
/// closest_on_part with a search radius up to this fraction of the scene's half extent
/// searches the main BVH, skipping other parts' triangles, instead of building (once) a
/// BVH of the part alone: within such a ball the other parts' leaves are few, while the
/// part's own BVH costs a build over all its triangles on first use.
constexpr double kFilteredPartRadiusRel = 1.0 / 32.0;
/// Vertices / triangles per TBB task when converting and classifying the geometry.
constexpr std::size_t kBuildGrain = 16384;
/// From this many triangles on, the automatic build quality is Embree's LOW (Morton
/// builder): on 1M triangles it takes ~3x less build CPU than MEDIUM (SAH), for ~30% slower
/// closest-point queries and 128 instead of 100 bytes per triangle (bench_index,
/// index_build_quality.csv). One build serves an audit's ~10^4 queries, so LOW wins there;
/// query-heavy callers set EmbreeOptions::build_quality = 1.
constexpr std::size_t kLowQualityTriangles = 500000;

/// Sets FTZ/DAZ for the current thread while alive (Embree's recommendation), restoring the
/// caller's MXCSR afterwards.
class FlushDenormals {
 public:
  FlushDenormals() {
#ifdef LOOM_HAVE_MXCSR
    saved_ = _mm_getcsr();
    _mm_setcsr(saved_ | 0x8040u);  // FTZ (bit 15) | DAZ (bit 6)
#endif
  }
  ~FlushDenormals() {
#ifdef LOOM_HAVE_MXCSR
    _mm_setcsr(saved_);
#endif
  }
  FlushDenormals(const FlushDenormals&) = delete;
  FlushDenormals& operator=(const FlushDenormals&) = delete;

 private:
  unsigned saved_ = 0;
};

float to_float_up(double v) {
  if (!(v < static_cast<double>(std::numeric_limits<float>::max()))) return std::numeric_limits<float>::infinity();
  const float f = static_cast<float>(v);
  return static_cast<double>(f) >= v ? f : std::nextafter(f, std::numeric_limits<float>::infinity());
}

void check_part_id(int part, std::size_t n) {
  if (part < 0 || static_cast<std::size_t>(part) >= n)
    throw std::out_of_range("embree index: part id " + std::to_string(part) + " out of range");
}

Vec3 unit_dir(const Vec3& dir) {
  const double n = dir.norm();
  if (!(n > 0.0) || !std::isfinite(n)) throw std::invalid_argument("embree index: ray direction is zero or not finite");
  return dir / n;
}

enum class Mode { Closest, AnyWithin, Segment, SegmentAny };

/// State of one point query, passed as userPtr to the callback.
struct QueryState {
  const std::vector<EmbreeIndex::PartData>* parts = nullptr;
  Mode mode = Mode::Closest;
  int only_part = -1;    ///< part scenes: the part id (geomID there is 0)
  int filter_part = -1;  ///< main scene: only this part's triangles count (-1: all parts)
  Vec3 p = Vec3::Zero();
  Vec3 a = Vec3::Zero(), b = Vec3::Zero();  ///< segment piece
  double s0 = 0.0, s1 = 1.0;                ///< piece parameters on the whole segment
  double r2 = 0.0;                          ///< any-within threshold²
  double best2 = std::numeric_limits<double>::infinity();
  double best_s = 0.0;
  double radius_offset = 0.0;  ///< added to the best distance when shrinking (piece half length)
  double shrink = 1.0;         ///< the search radius shrinks to shrink·best (< 1: approximate)
  double pad = 0.0;
  ClosestHit hit;
  bool done = false;
};

bool point_query_callback(RTCPointQueryFunctionArguments* args) {
  auto* q = static_cast<QueryState*>(args->userPtr);
  if (q->done) return false;
  const int part = q->only_part >= 0 ? q->only_part : static_cast<int>(args->geomID);
  if (q->filter_part >= 0 && part != q->filter_part) return false;
  const EmbreeIndex::PartData& pd = (*q->parts)[part];
  const auto c = pd.corners(args->primID);
  // Cheap rejection first: the triangle's box is farther than what we already have (or
  // than the any-within threshold). Both are lower bounds, so results stay exact.
  double limit2 = q->mode == Mode::Closest || q->mode == Mode::Segment ? q->best2 : q->r2;
  // An approximate segment query skips what cannot beat best / (1 + rel_error) once it has
  // a best (until then best2 is the caller's radius, whose answer must stay exact). Point
  // queries do not: Embree culls their leaves by the shrunk sphere, and shrinking the box
  // test too was measured to save nothing (the exact point–triangle test costs what the
  // box test does).
  if (q->mode == Mode::Segment && q->hit.part >= 0) limit2 *= q->shrink * q->shrink;
  const Vec3 lo = c[0].cwiseMin(c[1]).cwiseMin(c[2]), hi = c[0].cwiseMax(c[1]).cwiseMax(c[2]);
  double d2;
  Vec3 point;
  double s = 0.0;
  if (q->mode == Mode::Closest || q->mode == Mode::AnyWithin) {
    if (point_box_dist2(q->p, lo, hi) > limit2) return false;
    const bool degenerate = pd.degenerate[args->primID] != 0;  // read only past the box test
    const TrianglePointResult r = closest_point_on_triangle(q->p, c[0], c[1], c[2], degenerate);
    d2 = r.dist2;
    point = r.point;
  } else {
    if (segment_box_dist2_lower(q->a, q->b, lo, hi) > limit2) return false;
    const bool degenerate = pd.degenerate[args->primID] != 0;
    // The plane is as cheap again and much tighter on a finely tessellated curved surface
    // along the segment (the triangles beside the nearest have boxes within the limit).
    if (segment_triangle_dist2_lower(q->a, q->b, c[0], c[1], c[2], degenerate) > limit2) return false;
    const SegmentTriangleResult r = closest_segment_triangle(q->a, q->b, c[0], c[1], c[2], degenerate);
    d2 = r.dist2;
    point = r.triangle_point;
    s = q->s0 + r.s * (q->s1 - q->s0);
  }
  if (q->mode == Mode::AnyWithin || q->mode == Mode::SegmentAny) {
    if (d2 <= q->r2) {
      q->done = true;
      args->query->radius = 0.0f;
      return true;
    }
    return false;
  }
  // Equal to the caller's radius with nothing found yet counts as found (a radius of 0
  // leaves no slack: a segment through a surface is at distance 0 ≤ 0).
  if (d2 < q->best2 || (d2 == q->best2 && (q->hit.part < 0 || part < q->hit.part || (part == q->hit.part &&
                                                                   static_cast<std::int64_t>(args->primID) < q->hit.triangle)))) {
    q->best2 = d2;
    q->best_s = s;
    q->hit.point = point;
    q->hit.part = part;
    q->hit.triangle = args->primID;
    const float nr = to_float_up(std::sqrt(d2) * q->shrink + q->radius_offset + q->pad);
    if (nr < args->query->radius) {
      args->query->radius = nr;
      return true;
    }
  }
  return false;
}

/// Collects every hit along a ray (rejecting each so that traversal continues).
struct CollectContext {
  RTCIntersectContext ctx;  // must be first: Embree passes &ctx back to the filter
  std::vector<std::pair<unsigned, unsigned>>* hits;
};

void collect_filter(const RTCFilterFunctionNArguments* args) {
  const auto* cc = reinterpret_cast<const CollectContext*>(args->context);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] == 0) continue;
    cc->hits->emplace_back(RTCHitN_geomID(args->hit, args->N, i), RTCHitN_primID(args->hit, args->N, i));
    args->valid[i] = 0;
  }
}

/// How the line p + t·u (any t) meets a triangle, in double.
struct LineCrossing {
  enum Status { Miss, Through, Grazing } status = Miss;
  double t = 0.0;
};

/// Classifies the line's crossing of triangle abc: Grazing when the crossing point lies
/// within `margin` (absolute, scene units) of an edge line of the triangle, or within
/// kGrazeBary of one in barycentric terms, or the line lies in the triangle's plane;
/// otherwise Through or Miss. `margin` bounds the float rounding of Embree's ray test
/// across the ray: a crossing closer than that to an edge may be reported on the
/// neighbouring triangle or on neither, so the ray cannot count it.
LineCrossing line_crossing(const Vec3& p, const Vec3& u, const Vec3& a, const Vec3& b, const Vec3& c,
                           double margin) {
  LineCrossing out;
  const Vec3 e1 = b - a, e2 = c - a;
  const Vec3 pv = u.cross(e2);
  const double det = e1.dot(pv);
  const double scale = e1.norm() * e2.norm();
  if (!(std::abs(det) > 1e-12 * scale)) {
    // Parallel: a line in the plane of a real triangle is ambiguous; degenerate ones are ignored.
    const Vec3 n = e1.cross(e2);
    if (n.squaredNorm() > 0.0 && std::abs(n.normalized().dot(p - a)) <= 1e-12 * std::sqrt(scale))
      out.status = LineCrossing::Grazing;
    return out;
  }
  const double inv = 1.0 / det;
  const Vec3 tv = p - a;
  const double bu = tv.dot(pv) * inv;
  const Vec3 qv = tv.cross(e1);
  const double bv = u.dot(qv) * inv;
  const double bw = 1.0 - bu - bv;
  out.t = e2.dot(qv) * inv;
  // Distance of the crossing point from each edge line: its barycentric coordinate times
  // the altitude onto that edge, 2·area / edge length.
  const double twice_area = e1.cross(e2).norm();
  const double du = bu * twice_area / e2.norm();        // from edge ca (opposite b)
  const double dv = bv * twice_area / e1.norm();        // from edge ab (opposite c)
  const double dw = bw * twice_area / (c - b).norm();   // from edge bc (opposite a)
  const double m = std::min({bu, bv, bw}), d = std::min({du, dv, dw});
  // A rounding of `margin` across the ray moves the crossing by margin / |cos| within the
  // plane, |cos| = |u · n| = |det| / (2·area): a ray at a glancing angle grazes sooner.
  margin *= twice_area / std::abs(det);
  if (m >= kGrazeBary && d > margin)
    out.status = LineCrossing::Through;
  else if (m < -kGrazeBary && d < -margin)
    out.status = LineCrossing::Miss;
  else
    out.status = LineCrossing::Grazing;
  return out;
}

/// Distance along the unit direction u from p, inside box b, to where the ray leaves b.
double box_exit_distance(const AABB& b, const Vec3& p, const Vec3& u) {
  double t = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 3; ++k) {
    if (u[k] > 0.0) t = std::min(t, (b.max[k] - p[k]) / u[k]);
    else if (u[k] < 0.0) t = std::min(t, (b.min[k] - p[k]) / u[k]);
  }
  return std::max(0.0, t);
}

bool memory_monitor(void* ptr, ssize_t bytes, bool /*post*/) {
  static_cast<std::atomic<long long>*>(ptr)->fetch_add(bytes);
  return true;
}

}  // namespace

struct EmbreeIndex::Impl {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  std::vector<RTCGeometry> geoms;            // per part (null for empty parts)
  mutable std::vector<RTCScene> part_scenes;  // lazily built, one per part
  mutable std::unique_ptr<std::once_flag[]> part_once;
  std::atomic<long long> embree_bytes{0};
  std::string last_error;
  /// Boxes of the closed parts with triangles (others empty), indexed by part id: the
  /// candidates of an inside test without a pass over every part.
  std::unique_ptr<BoxTree> closed_boxes;
};

namespace {
void device_error(void* user, RTCError code, const char* str) {
  auto* impl = static_cast<EmbreeIndex::Impl*>(user);
  impl->last_error = "embree error " + std::to_string(static_cast<int>(code)) + ": " + (str ? str : "");
}

/// Copies one part's mesh into pd, checks its indices and vertices, and sets its box.
void copy_part(const Part& part, EmbreeIndex::PartData& pd) {
  const Mesh& m = part.mesh;
  pd.closed = part.closed;
  pd.vertices = m.vertices;
  pd.triangles = m.triangles;
  for (std::size_t t = 0; t < pd.triangles.size(); ++t)
    for (std::uint32_t v : pd.triangles[t]) {
      if (v >= pd.vertices.size())
        throw InputError({part.source_file, 0, part.name},
                         "triangle " + std::to_string(t) + " references vertex " + std::to_string(v) +
                             " but the mesh has " + std::to_string(pd.vertices.size()));
      if (!pd.vertices[v].allFinite())
        throw InputError({part.source_file, 0, part.name}, "vertex " + std::to_string(v) + " is not finite");
      pd.bounds.extend(pd.vertices[v]);
    }
}

/// Fills pd.vertices_f (re-centred on `centre`, rounded to float, + Embree's padding) and
/// pd.degenerate, in parallel chunks.
void prepare_part(EmbreeIndex::PartData& pd, const Vec3& centre) {
  if (pd.triangles.empty()) return;
  pd.vertices_f.assign(3 * pd.vertices.size() + 4, 0.0f);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, pd.vertices.size(), kBuildGrain),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t v = r.begin(); v != r.end(); ++v) {
                        const Vec3 d = pd.vertices[v] - centre;
                        for (int k = 0; k < 3; ++k) pd.vertices_f[3 * v + k] = static_cast<float>(d[k]);
                      }
                    });
  pd.degenerate.assign(pd.triangles.size(), 0);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, pd.triangles.size(), kBuildGrain),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t t = r.begin(); t != r.end(); ++t) {
                        const auto c = pd.corners(t);
                        pd.degenerate[t] = triangle_is_degenerate(c[0], c[1], c[2]) ? 1 : 0;
                      }
                    });
}
}  // namespace

EmbreeIndex::EmbreeIndex(const std::vector<Part>& parts, const EmbreeOptions& opt)
    : impl_(std::make_unique<Impl>()), parts_(parts.size()), opt_(opt) {
  if (opt_.inside_rays < 1) opt_.inside_rays = 1;
  if (opt_.inside_rays > kMaxInsideDirs) opt_.inside_rays = kMaxInsideDirs;
  if (opt_.inside_rays % 2 == 0) ++opt_.inside_rays;
  // Copy the geometry and validate it, parts in parallel; the first error in part order
  // is reported, so the message does not depend on scheduling.
  std::vector<std::exception_ptr> errors(parts.size());
  tbb::parallel_for(std::size_t(0), parts.size(), [&](std::size_t i) {
    try {
      copy_part(parts[i], parts_[i]);
    } catch (...) {
      errors[i] = std::current_exception();
    }
  });
  AABB all;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    if (errors[i]) std::rethrow_exception(errors[i]);
    all.extend(parts_[i].bounds);
    triangle_count_ += parts_[i].triangles.size();
  }
  centre_ = all.center();
  if (!all.empty()) half_extent_ = (all.max - centre_).cwiseAbs().cwiseMax((all.min - centre_).cwiseAbs()).maxCoeff();

  Impl& im = *impl_;
  im.device = rtcNewDevice(nullptr);
  if (!im.device) throw std::runtime_error("embree index: rtcNewDevice failed");
  rtcSetDeviceErrorFunction(im.device, device_error, &im);
  rtcSetDeviceMemoryMonitorFunction(im.device, memory_monitor, &im.embree_bytes);

  const Stopwatch t0;
  FlushDenormals ftz;
  // Float re-centred vertices for Embree and the per-triangle degenerate flags, in parallel.
  tbb::parallel_for(std::size_t(0), parts_.size(), [&](std::size_t i) { prepare_part(parts_[i], centre_); });
  im.scene = rtcNewScene(im.device);
  rtcSetSceneFlags(im.scene, RTC_SCENE_FLAG_ROBUST | RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION);
  const int quality = opt_.build_quality >= 0 ? opt_.build_quality
                      : triangle_count_ >= kLowQualityTriangles ? 0
                                                                : 1;
  const RTCBuildQuality q = quality <= 0   ? RTC_BUILD_QUALITY_LOW
                            : quality == 1 ? RTC_BUILD_QUALITY_MEDIUM
                                           : RTC_BUILD_QUALITY_HIGH;
  rtcSetSceneBuildQuality(im.scene, q);
  im.geoms.assign(parts_.size(), nullptr);
  for (std::size_t i = 0; i < parts_.size(); ++i) {
    PartData& pd = parts_[i];
    if (pd.triangles.empty()) continue;
    RTCGeometry g = rtcNewGeometry(im.device, RTC_GEOMETRY_TYPE_TRIANGLE);
    rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, pd.vertices_f.data(), 0,
                               3 * sizeof(float), pd.vertices.size());
    rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, pd.triangles.data(), 0,
                               3 * sizeof(std::uint32_t), pd.triangles.size());
    rtcSetGeometryBuildQuality(g, q);
    rtcCommitGeometry(g);
    rtcAttachGeometryByID(im.scene, g, static_cast<unsigned>(i));
    im.geoms[i] = g;
  }
  rtcCommitScene(im.scene);
  build_seconds_ = t0.seconds();
  if (rtcGetDeviceError(im.device) != RTC_ERROR_NONE || !im.last_error.empty())
    throw std::runtime_error("embree index: build failed: " + im.last_error);
  im.part_scenes.assign(parts_.size(), nullptr);
  im.part_once.reset(new std::once_flag[parts_.size()]);
  std::vector<AABB> closed(parts_.size());
  for (std::size_t i = 0; i < parts_.size(); ++i)
    if (parts_[i].closed && !parts_[i].triangles.empty()) closed[i] = parts_[i].bounds;
  im.closed_boxes = std::make_unique<BoxTree>(std::move(closed));
}

EmbreeIndex::~EmbreeIndex() {
  if (!impl_) return;
  for (RTCScene s : impl_->part_scenes)
    if (s) rtcReleaseScene(s);
  for (RTCGeometry g : impl_->geoms)
    if (g) rtcReleaseGeometry(g);
  if (impl_->scene) rtcReleaseScene(impl_->scene);
  if (impl_->device) rtcReleaseDevice(impl_->device);
}

void* EmbreeIndex::part_scene(int part) const {
  Impl& im = *impl_;
  std::call_once(im.part_once[part], [&] {
    if (!im.geoms[part]) return;
    FlushDenormals ftz;
    RTCScene s = rtcNewScene(im.device);
    rtcSetSceneFlags(s, RTC_SCENE_FLAG_ROBUST);
    rtcAttachGeometryByID(s, im.geoms[part], 0);
    rtcCommitScene(s);
    im.part_scenes[part] = s;
  });
  return im.part_scenes[part];
}

std::size_t EmbreeIndex::memory_bytes() const {
  std::size_t b = static_cast<std::size_t>(std::max<long long>(0, impl_->embree_bytes.load()));
  for (const PartData& pd : parts_)
    b += pd.vertices.capacity() * sizeof(Vec3) + pd.triangles.capacity() * sizeof(pd.triangles[0]) +
         pd.vertices_f.capacity() * sizeof(float) + pd.degenerate.capacity();
  return b;
}

double EmbreeIndex::float_pad(const Vec3& p, double radius) const {
  const double far = (p - centre_).cwiseAbs().maxCoeff();
  const double r = std::isfinite(radius) ? radius : 0.0;
  return kFloatPadRel * (half_extent_ + far + r) + std::numeric_limits<float>::min();
}

double EmbreeIndex::distance_rounding() const {
  return 16.0 * std::numeric_limits<double>::epsilon() * (centre_.cwiseAbs().maxCoeff() + half_extent_);
}

IndexAccuracy EmbreeIndex::accuracy() const {
  IndexAccuracy a;
  a.exact = true;
  a.abs_error = distance_rounding();
  a.description = "embree float BVH re-centred on (" + full_precision(centre_.x()) + ", " +
                  full_precision(centre_.y()) + ", " + full_precision(centre_.z()) +
                  "), culling radius padded by " + full_precision(kFloatPadRel * half_extent_) +
                  " (float rounding); distances exact in double: <= " + full_precision(a.abs_error) +
                  " scene units; inside/ray origins rounded to float: <= " +
                  full_precision(half_extent_ / 16777216.0) + " scene units";
  return a;
}

namespace {
/// One Embree point query: `rel` is the world point minus the index centre, `radius` the
/// search radius already padded for float rounding; the callback accumulates into q.
void run_point_query(RTCScene scene, const Vec3& rel, double radius, QueryState& q) {
  RTCPointQuery pq;
  pq.x = static_cast<float>(rel.x());
  pq.y = static_cast<float>(rel.y());
  pq.z = static_cast<float>(rel.z());
  pq.time = 0.0f;
  pq.radius = to_float_up(radius);
  RTCPointQueryContext ctx;
  rtcInitPointQueryContext(&ctx);
  rtcPointQuery(scene, &pq, &ctx, point_query_callback, &q);
}

ClosestHit finish_closest(QueryState& q, double max_radius) {
  ClosestHit h = q.hit;
  if (h.found()) {
    h.distance = std::sqrt(q.best2);
    if (h.distance > max_radius) h = ClosestHit{};
  }
  return h;
}
}  // namespace

ClosestHit EmbreeIndex::closest(const Vec3& p, double max_radius) const {
  if (triangle_count_ == 0 || !(max_radius >= 0.0)) return {};
  return closest_in(impl_->scene, -1, -1, p, max_radius);
}

ClosestHit EmbreeIndex::closest_approx(const Vec3& p, double max_radius, double rel_error) const {
  if (!(rel_error >= 0.0) || !std::isfinite(rel_error))
    throw std::invalid_argument("embree index: rel_error must be finite and >= 0, got " + full_precision(rel_error));
  if (triangle_count_ == 0 || !(max_radius >= 0.0)) return {};
  return closest_in(impl_->scene, -1, -1, p, max_radius, 1.0 / (1.0 + rel_error));
}

ClosestHit EmbreeIndex::closest_on_part(const Vec3& p, int part, double max_radius) const {
  check_part_id(part, parts_.size());
  const PartData& pd = parts_[part];
  if (pd.triangles.empty() || !(max_radius >= 0.0)) return {};
  if (point_box_dist2(p, pd.bounds.min, pd.bounds.max) > max_radius * max_radius) return {};
  // A bounded search stays in the main BVH (skipping other parts); an unbounded or wide
  // one uses the part's own BVH, built on first use.
  if (max_radius <= kFilteredPartRadiusRel * half_extent_) return closest_in(impl_->scene, -1, part, p, max_radius);
  return closest_in(part_scene(part), part, -1, p, max_radius);
}

std::optional<AABB> EmbreeIndex::part_bounds(int part) const {
  check_part_id(part, parts_.size());
  return parts_[part].bounds;
}

ClosestHit EmbreeIndex::closest_in(void* scene, int only_part, int filter_part, const Vec3& p,
                                   double max_radius, double shrink) const {
  FlushDenormals ftz;
  QueryState q;
  q.parts = &parts_;
  q.only_part = only_part;
  q.filter_part = filter_part;
  q.shrink = shrink;
  q.p = p;
  q.pad = float_pad(p, max_radius);
  if (std::isfinite(max_radius)) q.best2 = max_radius * max_radius * (1.0 + 1e-15);
  run_point_query(static_cast<RTCScene>(scene), p - centre_, max_radius + q.pad, q);
  return finish_closest(q, max_radius);
}

bool EmbreeIndex::any_within(const Vec3& p, double r) const {
  if (triangle_count_ == 0 || !(r >= 0.0)) return false;
  FlushDenormals ftz;
  QueryState q;
  q.parts = &parts_;
  q.mode = Mode::AnyWithin;
  q.p = p;
  q.r2 = r * r;
  run_point_query(impl_->scene, p - centre_, r + float_pad(p, r), q);
  return q.done;
}

bool EmbreeIndex::segment_within(const Vec3& a, const Vec3& b, double r) const {
  if (triangle_count_ == 0 || !(r >= 0.0)) return false;
  FlushDenormals ftz;
  const double len = (b - a).norm();
  const double target = std::max(4.0 * r, 2.0 * half_extent_ * kSegmentPieceRel);
  const int n = target > 0.0 ? std::clamp(static_cast<int>(std::ceil(len / target)), 1, kMaxSegmentPieces) : 1;
  QueryState q;
  q.parts = &parts_;
  q.mode = Mode::SegmentAny;
  q.r2 = r * r;
  for (int k = 0; k < n && !q.done; ++k) {
    q.a = a + (b - a) * (static_cast<double>(k) / n);
    q.b = a + (b - a) * (static_cast<double>(k + 1) / n);
    const Vec3 mid = 0.5 * (q.a + q.b);
    const double half = 0.5 * (q.b - q.a).norm();
    run_point_query(impl_->scene, mid - centre_, half + r + float_pad(mid, half + r), q);
  }
  return q.done;
}

ClosestHit EmbreeIndex::segment_closest(const Vec3& a, const Vec3& b, double max_radius,
                                        double* segment_param) const {
  return segment_closest_in(a, b, -1, max_radius, segment_param, 1.0);
}

ClosestHit EmbreeIndex::segment_closest_approx(const Vec3& a, const Vec3& b, double max_radius, double rel_error,
                                               double* segment_param) const {
  if (!(rel_error >= 0.0) || !std::isfinite(rel_error))
    throw std::invalid_argument("embree index: rel_error must be finite and >= 0, got " + full_precision(rel_error));
  return segment_closest_in(a, b, -1, max_radius, segment_param, 1.0 / (1.0 + rel_error));
}

ClosestHit EmbreeIndex::segment_closest_on_part(const Vec3& a, const Vec3& b, int part, double max_radius,
                                                double* segment_param) const {
  check_part_id(part, parts_.size());
  return segment_closest_in(a, b, part, max_radius, segment_param, 1.0);
}

ClosestHit EmbreeIndex::segment_closest_in(const Vec3& a, const Vec3& b, int filter_part, double max_radius,
                                           double* segment_param, double shrink) const {
  if (triangle_count_ == 0 || !(max_radius >= 0.0)) return {};
  FlushDenormals ftz;
  const double len = (b - a).norm();
  const double target = 2.0 * half_extent_ * kSegmentPieceRel;
  const int n = target > 0.0 ? std::clamp(static_cast<int>(std::ceil(len / target)), 1, kMaxSegmentPieces) : 1;
  QueryState q;
  q.parts = &parts_;
  q.mode = Mode::Segment;
  q.filter_part = filter_part;
  q.shrink = shrink;
  q.best2 = std::isfinite(max_radius) ? max_radius * max_radius * (1.0 + 1e-15) : q.best2;
  // Pieces in order: the shrinking radius carries over from one to the next.
  for (int k = 0; k < n; ++k) {
    q.s0 = static_cast<double>(k) / n;
    q.s1 = static_cast<double>(k + 1) / n;
    q.a = a + (b - a) * q.s0;
    q.b = a + (b - a) * q.s1;
    const Vec3 mid = 0.5 * (q.a + q.b);
    const double half = 0.5 * (q.b - q.a).norm();
    q.radius_offset = half;
    // Shrunk only once something was found: until then best2 is the caller's radius, and a
    // "nothing within max_radius" answer must stay exact.
    const double cur = !std::isfinite(q.best2) ? std::numeric_limits<double>::infinity()
                                                : std::sqrt(q.best2) * (q.hit.part >= 0 ? shrink : 1.0);
    q.pad = float_pad(mid, half + (std::isfinite(cur) ? cur : 0.0));
    run_point_query(impl_->scene, mid - centre_, half + cur + q.pad, q);
  }
  ClosestHit h = finish_closest(q, max_radius);
  if (h.found() && segment_param) *segment_param = q.best_s;
  return h;
}

RayHit EmbreeIndex::ray(const Vec3& origin, const Vec3& dir, double t_max) const {
  const Vec3 u = unit_dir(dir);
  if (triangle_count_ == 0 || !(t_max >= 0.0)) return {};
  FlushDenormals ftz;
  const Vec3 oc = origin - centre_;
  const double pad = float_pad(origin, 0.0);
  RTCRayHit rh;
  rh.ray.org_x = static_cast<float>(oc.x());
  rh.ray.org_y = static_cast<float>(oc.y());
  rh.ray.org_z = static_cast<float>(oc.z());
  rh.ray.dir_x = static_cast<float>(u.x());
  rh.ray.dir_y = static_cast<float>(u.y());
  rh.ray.dir_z = static_cast<float>(u.z());
  rh.ray.tnear = 0.0f;
  rh.ray.tfar = to_float_up(t_max + pad);
  rh.ray.time = 0.0f;
  rh.ray.mask = 0xFFFFFFFFu;
  rh.ray.id = 0;
  rh.ray.flags = 0;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  rtcIntersect1(impl_->scene, &ctx, &rh);
  RayHit out;
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return out;
  const int part = static_cast<int>(rh.hit.geomID);
  const auto c = parts_[part].corners(rh.hit.primID);
  // Refine t in double on the exact triangle; keep Embree's t if the double test misses
  // (the ray grazes an edge within float rounding).
  const RayTriangleResult r = intersect_ray_triangle(origin, u, c[0], c[1], c[2]);
  const double t = r.hit ? r.t : static_cast<double>(rh.ray.tfar);
  if (t > t_max) return out;
  out.t = t;
  out.part = part;
  out.triangle = rh.hit.primID;
  const Vec3 n = (c[1] - c[0]).cross(c[2] - c[0]);
  out.normal = n.norm() > 0.0 ? Vec3(n.normalized()) : Vec3(-u);
  return out;
}

bool EmbreeIndex::inside(const Vec3& p, int* part) const {
  std::vector<int> held;
  inside_scan(p, true, held);
  if (held.empty()) return false;
  if (part) *part = held.front();
  return true;
}

void EmbreeIndex::inside_parts(const Vec3& p, std::vector<int>& out) const {
  inside_scan(p, false, out);
  std::sort(out.begin(), out.end());
}

void EmbreeIndex::inside_scan(const Vec3& p, bool first_only, std::vector<int>& out) const {
  out.clear();
  // Candidate closed parts whose box contains p.
  if (!p.allFinite()) return;
  std::vector<std::uint32_t> cand;
  AABB at;
  at.extend(p);
  impl_->closed_boxes->overlapping(at, cand);
  if (cand.empty()) return;
  // A part not much larger than the float rounding of a ray at this distance from the
  // centre cannot be crossed reliably (Embree may report none of its triangles, which no
  // test here could notice): the winding number decides it, in double, O(its triangles).
  // So does every candidate when every ray grazed (p on a surface, which is not inside; a
  // winding number of −1 is inside a part oriented inwards, as the rays' parity counts it).
  const double on_surface = distance_rounding();
  auto winding_inside = [&](std::uint32_t c) {
    // On the surface (within the rounding of the exact distance) p is not strictly inside;
    // there the solid angle of the face under p is ±2π by the rounding of a zero.
    if (closest_on_part(p, static_cast<int>(c), on_surface).found()) return false;
    const PartData& pd = parts_[c];
    const double w = triangles_winding_number(p, pd.triangles.size(), [&](std::size_t t) { return pd.corners(t); });
    return std::abs(w) > 0.5 + kWindingMargin;
  };
  std::vector<char> by_winding(cand.size(), 0);
  bool any_by_rays = false;
  for (std::size_t i = 0; i < cand.size(); ++i) {
    const double size = parts_[cand[i]].bounds.diagonal();
    by_winding[i] = size < kRayResolvedParts * float_pad(p, size) ? 1 : 0;
    any_by_rays = any_by_rays || !by_winding[i];
  }
  // Adds candidate i; true when the scan can stop there.
  auto holds = [&](std::size_t i) {
    out.push_back(static_cast<int>(cand[i]));
    return first_only;
  };
  if (!any_by_rays) {
    for (std::size_t i = 0; i < cand.size(); ++i)
      if (winding_inside(cand[i]) && holds(i)) return;
    return;
  }
  FlushDenormals ftz;
  const Vec3 pc = p - centre_;
  std::vector<int> votes_in(cand.size(), 0), valid(cand.size(), 0);
  std::vector<int> ahead(cand.size(), 0), behind(cand.size(), 0);
  std::vector<char> grazed(cand.size(), 0);
  std::vector<std::pair<unsigned, unsigned>> hits;
  // A candidate still short of its rays (the ones the winding number decides need none).
  auto wanting = [&]() {
    for (std::size_t i = 0; i < cand.size(); ++i)
      if (!by_winding[i] && valid[i] < opt_.inside_rays) return true;
    return false;
  };
  for (int k = 0; k < kMaxInsideDirs && wanting(); ++k) {
    const Vec3 u = kInsideDirs[k].normalized();
    // The ray runs along the whole line through p within the candidates' boxes, both
    // ways: a closed part crosses a line an even number of times, so an odd count shows a
    // crossing Embree's float test missed. Embree may report neither of two triangles
    // when the ray passes within its rounding of their common edge (embree issue #387),
    // and a crossing nobody reports cannot be seen as grazing. p lies in each candidate's
    // box, so the line leaves the last of them within `exit` ahead and `back` behind.
    double exit = 0.0, back = 0.0;
    for (std::size_t i = 0; i < cand.size(); ++i)
      if (!by_winding[i]) {
        exit = std::max(exit, box_exit_distance(parts_[cand[i]].bounds, p, u));
        back = std::max(back, box_exit_distance(parts_[cand[i]].bounds, p, -u));
      }
    // Float rounding of the ray test, across the ray, anywhere along it (the bound that
    // pads every culling radius); the ray starts that much farther back and ends farther on.
    const double margin = float_pad(p, std::max(exit, back));
    back += 4.0 * margin;
    const Vec3 org = pc - back * u;
    hits.clear();
    CollectContext cc;
    rtcInitIntersectContext(&cc.ctx);
    cc.ctx.filter = collect_filter;
    cc.hits = &hits;
    RTCRayHit rh;
    rh.ray.org_x = static_cast<float>(org.x());
    rh.ray.org_y = static_cast<float>(org.y());
    rh.ray.org_z = static_cast<float>(org.z());
    rh.ray.dir_x = static_cast<float>(u.x());
    rh.ray.dir_y = static_cast<float>(u.y());
    rh.ray.dir_z = static_cast<float>(u.z());
    rh.ray.tnear = 0.0f;
    rh.ray.tfar = to_float_up(back + exit + 4.0 * margin);
    rh.ray.time = 0.0f;
    rh.ray.mask = 0xFFFFFFFFu;
    rh.ray.id = 0;
    rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(impl_->scene, &cc.ctx, &rh);
    std::sort(hits.begin(), hits.end());
    hits.erase(std::unique(hits.begin(), hits.end()), hits.end());
    std::fill(ahead.begin(), ahead.end(), 0);
    std::fill(behind.begin(), behind.end(), 0);
    std::fill(grazed.begin(), grazed.end(), 0);
    for (const auto& h : hits) {
      const auto it = std::find(cand.begin(), cand.end(), h.first);
      if (it == cand.end() || by_winding[it - cand.begin()]) continue;
      const std::size_t i = static_cast<std::size_t>(it - cand.begin());
      const auto c = parts_[h.first].corners(h.second);
      const LineCrossing x = line_crossing(p, u, c[0], c[1], c[2], margin);
      // Grazing: the ray passes by an edge or vertex, or lies in the plane; t = 0: p on the surface.
      if (x.status == LineCrossing::Grazing || (x.status == LineCrossing::Through && x.t == 0.0)) grazed[i] = 1;
      else if (x.status == LineCrossing::Through) ++(x.t > 0.0 ? ahead[i] : behind[i]);
    }
    // Each candidate counts the ray only if it crossed that part cleanly and an even number
    // of times: another part's edge near the ray says nothing about this one.
    for (std::size_t i = 0; i < cand.size(); ++i) {
      if (by_winding[i] || grazed[i] || (ahead[i] + behind[i]) % 2 != 0) continue;
      ++valid[i];
      votes_in[i] += ahead[i] % 2;
    }
  }
  // In candidate order, as every answer here: first_only stops at the first part that holds p.
  // A candidate no ray crossed cleanly (p on its surface, or a part open in spite of its
  // flag) is decided by the winding number.
  for (std::size_t i = 0; i < cand.size(); ++i) {
    const bool in = by_winding[i] || valid[i] == 0 ? winding_inside(cand[i]) : 2 * votes_in[i] > valid[i];
    if (in && holds(i)) return;
  }
}

}  // namespace loom
