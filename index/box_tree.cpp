// Box BVH with Embree user geometry: point queries for overlap, rtcCollide for pairs.
#include "index/box_tree.hpp"

#include <atomic>

#include <embree3/rtcore.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>

namespace loom {

namespace {

/// Smallest outward move of a corner (in the re-centred frame, scene units). Why: Embree
/// runs with denormals flushed, so a point box at the centre would round to a zero-size
/// float box, and its builder asserts (Debian's build keeps asserts) on a set whose bounds
/// have no extent — two equal point boxes abort the process. 1e-20 is a normal float, far
/// below any length loom measures, and only ever widens a candidate test.
constexpr double kMinPad = 1e-20;
/// Relative outward move before rounding: covers the re-centring subtraction's rounding
/// and float's 2^-24 with room to spare.
constexpr double kRelPad = 0x1p-20;

float round_down(double x) {
  const double moved = x - std::max(std::abs(x) * kRelPad, kMinPad);
  return std::nextafter(static_cast<float>(moved), -std::numeric_limits<float>::infinity());
}
float round_up(double x) {
  const double moved = x + std::max(std::abs(x) * kRelPad, kMinPad);
  return std::nextafter(static_cast<float>(moved), std::numeric_limits<float>::infinity());
}

/// Throws std::invalid_argument("box tree: <what> ...") with the box at full precision
/// unless b is unset or a finite box with min ≤ max.
void check_box(const AABB& b, const std::string& what) {
  if (box_is_unset(b)) return;
  if (!b.min.allFinite() || !b.max.allFinite() || !(b.min.array() <= b.max.array()).all()) {
    std::ostringstream os;
    os.precision(17);
    os << "box tree: " << what << " is neither unset nor a finite box: min (" << b.min.transpose() << "), max ("
       << b.max.transpose() << ")";
    throw std::invalid_argument(os.str());
  }
}

void device_error(void* user, RTCError code, const char* str) {
  auto* msg = static_cast<std::string*>(user);
  if (msg->empty()) *msg = "embree error " + std::to_string(static_cast<int>(code)) + ": " + (str ? str : "");
}

}  // namespace

struct BoxTree::Impl {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  std::string error;  ///< first Embree error (reported by the call that raised it)
  Vec3 centre = Vec3::Zero();
  std::vector<std::uint32_t> ids;  ///< Embree primitive → box index (unset boxes left out)
  std::vector<float> lo, hi;       ///< 3 floats per primitive: re-centred, rounded outwards
  std::vector<AABB> boxes;         ///< as given

  ~Impl() {
    if (scene) rtcReleaseScene(scene);
    if (device) rtcReleaseDevice(device);
  }
};

namespace {

void bounds_function(const RTCBoundsFunctionArguments* args) {
  const auto* im = static_cast<const BoxTree::Impl*>(args->geometryUserPtr);
  const std::size_t k = 3 * static_cast<std::size_t>(args->primID);
  RTCBounds* b = args->bounds_o;
  b->lower_x = im->lo[k];
  b->lower_y = im->lo[k + 1];
  b->lower_z = im->lo[k + 2];
  b->upper_x = im->hi[k];
  b->upper_y = im->hi[k + 1];
  b->upper_z = im->hi[k + 2];
}

/// One overlap query: the exact box and what was found.
struct OverlapQuery {
  const BoxTree::Impl* im = nullptr;
  AABB query;
  std::vector<std::uint32_t>* out = nullptr;  ///< null: count only
  std::size_t count = 0;                      ///< boxes found (counting)
  const std::function<bool(std::uint32_t)>* keep = nullptr;  ///< counting: which count as kept
  std::size_t kept = 0;                                       ///< of `count`, those keep accepts
  std::size_t cap = std::numeric_limits<std::size_t>::max();
};

bool overlap_callback(RTCPointQueryFunctionArguments* args) {
  auto* q = static_cast<OverlapQuery*>(args->userPtr);
  if (q->count >= q->cap) return false;
  const std::uint32_t i = q->im->ids[args->primID];
  if (!boxes_overlap(q->im->boxes[i], q->query)) return false;
  if (q->out) {
    q->out->push_back(i);
    return false;  // the search sphere never shrinks: every overlapping box is wanted
  }
  if (!*q->keep || (*q->keep)(i)) ++q->kept;
  if (++q->count < q->cap) return false;
  args->query->radius = 0.0f;  // enough counted: let the traversal end
  return true;
}

/// Runs q over the tree: a point query whose sphere holds q.query.
void run_overlap_query(const BoxTree::Impl& im, OverlapQuery& q) {
  // The sphere around the query's centre through its corners holds the query box; its
  // radius is padded for the float rounding of the centre (relative to the larger of the
  // centre's and the radius' magnitude) so that no overlapping float box is culled.
  const Vec3 c = q.query.center() - im.centre;
  const double half = 0.5 * q.query.diagonal();
  const double pad = 4.0 * kRelPad * (c.cwiseAbs().maxCoeff() + half) + kMinPad;
  RTCPointQuery pq;
  pq.x = static_cast<float>(c.x());
  pq.y = static_cast<float>(c.y());
  pq.z = static_cast<float>(c.z());
  pq.time = 0.0f;
  pq.radius = std::nextafter(static_cast<float>(half + pad), std::numeric_limits<float>::infinity());
  RTCPointQueryContext ctx;
  rtcInitPointQueryContext(&ctx);
  rtcPointQuery(im.scene, &pq, &ctx, overlap_callback, &q);
}

struct CollideState {
  const BoxTree::Impl* im = nullptr;
  const BoxTree::PairFilter* filter = nullptr;
  std::atomic<std::size_t> kept{0};
  std::atomic<bool> overflow{false};
  tbb::enumerable_thread_specific<std::vector<BoxPair>> found;
};

void collide_callback(void* user, RTCCollision* collisions, unsigned count) {
  auto* st = static_cast<CollideState*>(user);
  if (st->overflow.load(std::memory_order_relaxed)) return;  // Embree cannot be stopped: skip
  const BoxTree::Impl& im = *st->im;
  std::vector<BoxPair>& out = st->found.local();
  for (unsigned k = 0; k < count; ++k) {
    const std::uint32_t i = im.ids[collisions[k].primID0], j = im.ids[collisions[k].primID1];
    // One scene against itself: Embree visits every ordered pair of overlapping leaves, so
    // (i, j) and (j, i) both arrive; keeping i < j reports each pair once. Leaves pair all
    // their primitives, so most candidates fail the exact box test.
    if (!(i < j && boxes_overlap(im.boxes[i], im.boxes[j]))) continue;
    if (st->filter->keep && !st->filter->keep(i, j)) continue;
    if (st->kept.fetch_add(1, std::memory_order_relaxed) >= st->filter->max_pairs) {
      st->overflow.store(true, std::memory_order_relaxed);
      return;
    }
    out.emplace_back(i, j);
  }
}

}  // namespace

BoxTree::BoxTree(std::vector<AABB> boxes) : impl_(std::make_unique<Impl>()) {
  Impl& im = *impl_;
  im.boxes = std::move(boxes);
  if (im.boxes.size() > std::numeric_limits<std::uint32_t>::max())
    throw std::invalid_argument("box tree: more boxes than 32-bit ids");
  AABB all;
  for (std::size_t i = 0; i < im.boxes.size(); ++i) {
    check_box(im.boxes[i], "box " + std::to_string(i));
    all.extend(im.boxes[i]);
  }
  // Re-centred before rounding to float so that far-from-origin scenes keep tight boxes.
  im.centre = all.center();
  for (std::size_t i = 0; i < im.boxes.size(); ++i) {
    const AABB& b = im.boxes[i];
    if (box_is_unset(b)) continue;
    im.ids.push_back(static_cast<std::uint32_t>(i));
    for (int a = 0; a < 3; ++a) {
      im.lo.push_back(round_down(b.min[a] - im.centre[a]));
      im.hi.push_back(round_up(b.max[a] - im.centre[a]));
    }
  }
  if (im.ids.empty()) return;  // nothing to index: every query answers nothing
  im.device = rtcNewDevice(nullptr);
  if (!im.device) throw std::runtime_error("box tree: rtcNewDevice failed");
  rtcSetDeviceErrorFunction(im.device, device_error, &im.error);
  im.scene = rtcNewScene(im.device);
  // Low quality (Morton) build: fast, and the queries are few per box.
  rtcSetSceneBuildQuality(im.scene, RTC_BUILD_QUALITY_LOW);
  RTCGeometry g = rtcNewGeometry(im.device, RTC_GEOMETRY_TYPE_USER);
  rtcSetGeometryUserPrimitiveCount(g, static_cast<unsigned>(im.ids.size()));
  rtcSetGeometryUserData(g, &im);
  rtcSetGeometryBoundsFunction(g, bounds_function, nullptr);
  rtcCommitGeometry(g);
  rtcAttachGeometry(im.scene, g);
  rtcReleaseGeometry(g);
  rtcCommitScene(im.scene);
  if (!im.error.empty()) throw std::runtime_error("box tree: " + im.error);
}

BoxTree::~BoxTree() = default;
std::size_t BoxTree::size() const { return impl_->boxes.size(); }
BoxTree::BoxTree(BoxTree&& o) noexcept = default;
BoxTree& BoxTree::operator=(BoxTree&& o) noexcept = default;

void BoxTree::overlapping(const AABB& query, std::vector<std::uint32_t>& out) const {
  out.clear();
  check_box(query, "query");
  const Impl& im = *impl_;
  if (box_is_unset(query) || im.ids.empty()) return;
  OverlapQuery q;
  q.im = &im;
  q.query = query;
  q.out = &out;
  run_overlap_query(im, q);
  // Leaves report their primitives in tree order; callers want a stable, ascending list.
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
}

std::size_t BoxTree::count_overlapping(const AABB& query, std::size_t cap) const {
  return count_overlapping(query, cap, {}).all;
}

BoxTree::OverlapCount BoxTree::count_overlapping(const AABB& query, std::size_t cap,
                                                 const std::function<bool(std::uint32_t)>& keep) const {
  check_box(query, "query");
  const Impl& im = *impl_;
  if (box_is_unset(query) || im.ids.empty() || cap == 0) return {};
  OverlapQuery q;
  q.im = &im;
  q.query = query;
  q.cap = cap;
  q.keep = &keep;
  run_overlap_query(im, q);
  return {std::min(q.count, cap), std::min(q.kept, cap)};
}

std::vector<BoxPair> BoxTree::self_pairs() const { return self_pairs(PairFilter{}); }

std::vector<BoxPair> BoxTree::self_pairs(const PairFilter& filter) const {
  std::vector<BoxPair> pairs;
  const Impl& im = *impl_;
  if (im.ids.size() < 2) return pairs;
  CollideState state;
  state.im = &im;
  state.filter = &filter;
  rtcCollide(im.scene, im.scene, collide_callback, &state);
  if (!im.error.empty()) throw std::runtime_error("box tree: " + im.error);
  if (state.overflow)
    throw std::length_error("box tree: more than " + std::to_string(filter.max_pairs) + " overlapping pairs kept");
  std::size_t total = 0;
  for (const auto& v : state.found) total += v.size();
  pairs.reserve(total);
  for (const auto& v : state.found) pairs.insert(pairs.end(), v.begin(), v.end());
  tbb::parallel_sort(pairs.begin(), pairs.end());
  // Each ordered leaf pair is visited once, so no pair should repeat; unique() makes the
  // contract hold without leaning on that traversal detail.
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  return pairs;
}

}  // namespace loom
