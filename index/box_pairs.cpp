// Broad phase over boxes with Embree's BVH-against-BVH traversal (rtcCollide).
#include "index/box_pairs.hpp"

#include <embree3/rtcore.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_sort.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>

namespace loom {

namespace {

/// The boxes as Embree sees them: float, re-centred, each corner moved outwards of the
/// double box by at least kMinPad before rounding outwards, so that a float box always
/// contains its double box and never has a zero edge.
struct FloatBoxes {
  std::vector<float> lo, hi;  ///< 3 per box
};

/// Smallest outward move of a corner (in the re-centred frame, metres). Why: Embree runs
/// with denormals flushed, so a point box at the centre would round to a zero-size float
/// box, and its builder asserts (Debian's build keeps asserts) on a set whose bounds have
/// no extent — two equal point boxes abort the process. 1e-20 is a normal float, far
/// below any length loom measures, and only ever widens a candidate test.
constexpr double kMinPad = 1e-20;

float round_down(double x) {
  const double moved = x - std::max(std::abs(x) * 0x1p-20, kMinPad);
  return std::nextafter(static_cast<float>(moved), -std::numeric_limits<float>::infinity());
}
float round_up(double x) {
  const double moved = x + std::max(std::abs(x) * 0x1p-20, kMinPad);
  return std::nextafter(static_cast<float>(moved), std::numeric_limits<float>::infinity());
}

void box_bounds(const RTCBoundsFunctionArguments* args) {
  const auto* fb = static_cast<const FloatBoxes*>(args->geometryUserPtr);
  const std::size_t k = 3 * static_cast<std::size_t>(args->primID);
  RTCBounds* b = args->bounds_o;
  b->lower_x = fb->lo[k];
  b->lower_y = fb->lo[k + 1];
  b->lower_z = fb->lo[k + 2];
  b->upper_x = fb->hi[k];
  b->upper_y = fb->hi[k + 1];
  b->upper_z = fb->hi[k + 2];
}

bool overlap(const AABB& a, const AABB& b) {
  return (a.min.array() <= b.max.array()).all() && (b.min.array() <= a.max.array()).all();
}

/// What the collide callback reads and fills.
struct CollideState {
  const std::vector<AABB>* boxes = nullptr;
  tbb::enumerable_thread_specific<std::vector<BoxPair>> found;
};

void collide_callback(void* user, RTCCollision* collisions, unsigned count) {
  auto* st = static_cast<CollideState*>(user);
  const std::vector<AABB>& boxes = *st->boxes;
  std::vector<BoxPair>& out = st->found.local();
  for (unsigned k = 0; k < count; ++k) {
    const std::uint32_t i = collisions[k].primID0, j = collisions[k].primID1;
    // One scene against itself: Embree visits every ordered pair of overlapping leaves, so
    // (i, j) and (j, i) both arrive; keeping i < j reports each pair once. Leaves pair all
    // their primitives, so most candidates fail the exact box test.
    if (i < j && overlap(boxes[i], boxes[j])) out.emplace_back(i, j);
  }
}

struct DeviceDeleter {
  void operator()(RTCDeviceTy* d) const { rtcReleaseDevice(d); }
};
struct SceneDeleter {
  void operator()(RTCSceneTy* s) const { rtcReleaseScene(s); }
};

void device_error(void* user, RTCError code, const char* str) {
  auto* msg = static_cast<std::string*>(user);
  if (msg->empty()) *msg = "embree error " + std::to_string(static_cast<int>(code)) + ": " + (str ? str : "");
}

}  // namespace

std::vector<BoxPair> overlapping_box_pairs(const std::vector<AABB>& boxes, int threads) {
  AABB all;
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    const AABB& b = boxes[i];
    if (!b.min.allFinite() || !b.max.allFinite() || !(b.min.array() <= b.max.array()).all()) {
      std::ostringstream os;
      os.precision(17);
      os << "overlapping_box_pairs: box " << i << " is not a finite box: min (" << b.min.transpose() << "), max ("
         << b.max.transpose() << ")";
      throw std::invalid_argument(os.str());
    }
    all.extend(b);
  }
  std::vector<BoxPair> pairs;
  if (boxes.size() < 2) return pairs;
  if (boxes.size() > std::numeric_limits<std::uint32_t>::max())
    throw std::invalid_argument("overlapping_box_pairs: more boxes than 32-bit primitive ids");

  // Re-centred before rounding to float so that far-from-origin scenes keep tight boxes.
  const Vec3 centre = all.center();
  FloatBoxes fb;
  fb.lo.resize(3 * boxes.size());
  fb.hi.resize(3 * boxes.size());
  for (std::size_t i = 0; i < boxes.size(); ++i)
    for (int a = 0; a < 3; ++a) {
      fb.lo[3 * i + a] = round_down(boxes[i].min[a] - centre[a]);
      fb.hi[3 * i + a] = round_up(boxes[i].max[a] - centre[a]);
    }

  std::string error;
  std::unique_ptr<RTCDeviceTy, DeviceDeleter> device(rtcNewDevice(nullptr));
  if (!device) throw std::runtime_error("overlapping_box_pairs: rtcNewDevice failed");
  rtcSetDeviceErrorFunction(device.get(), device_error, &error);

  CollideState state;
  state.boxes = &boxes;
  tbb::task_arena arena(threads > 0 ? threads : tbb::task_arena::automatic);
  arena.execute([&] {
    std::unique_ptr<RTCSceneTy, SceneDeleter> scene(rtcNewScene(device.get()));
    // Low quality (Morton) build: the tree is traversed once, so a fast build beats a tight one.
    rtcSetSceneBuildQuality(scene.get(), RTC_BUILD_QUALITY_LOW);
    RTCGeometry g = rtcNewGeometry(device.get(), RTC_GEOMETRY_TYPE_USER);
    rtcSetGeometryUserPrimitiveCount(g, static_cast<unsigned>(boxes.size()));
    rtcSetGeometryUserData(g, &fb);
    rtcSetGeometryBoundsFunction(g, box_bounds, nullptr);
    rtcCommitGeometry(g);
    rtcAttachGeometry(scene.get(), g);
    rtcReleaseGeometry(g);
    rtcCommitScene(scene.get());
    if (error.empty()) rtcCollide(scene.get(), scene.get(), collide_callback, &state);
    if (!error.empty()) return;
    std::size_t total = 0;
    for (const auto& v : state.found) total += v.size();
    pairs.reserve(total);
    for (const auto& v : state.found) pairs.insert(pairs.end(), v.begin(), v.end());
    tbb::parallel_sort(pairs.begin(), pairs.end());
  });
  if (!error.empty()) throw std::runtime_error("overlapping_box_pairs: " + error);
  // Each ordered leaf pair is visited once, so no pair should repeat; unique() makes the
  // contract hold without leaning on that traversal detail.
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  return pairs;
}

}  // namespace loom
