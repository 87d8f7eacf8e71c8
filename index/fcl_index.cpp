#include "index/fcl_index.hpp"

#include "core/error.hpp"
#include "index/brute_force_index.hpp"
#include "index/triangle_distance.hpp"

#include <fcl/geometry/bvh/BVH_model.h>
#include <fcl/math/bv/OBBRSS.h>
#include <fcl/math/bv/utility.h>
#include <fcl/narrowphase/collision.h>
#include <fcl/narrowphase/distance.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace loom {

namespace {

using Model = fcl::BVHModel<fcl::OBBRSSd>;

/// FCL's triangle distance skips its face test when |normal|² ≤ 1e-15 (an absolute
/// threshold); triangles with |normal|² below this margin are answered by our kernels.
constexpr double kFclFaceTestNormal2 = 1e-13;
/// Upper bound on contacts gathered for a ray's candidate triangles per part.
constexpr std::size_t kMaxRayContacts = 1u << 20;

/// One-triangle model for segment ab (a == b: a point), with its leaf BV refitted from
/// the one or two distinct points.
std::shared_ptr<Model> query_model(const Vec3& a, const Vec3& b) {
  auto m = std::make_shared<Model>();
  m->beginModel(1, 3);
  m->addTriangle(a, b, b);
  m->endModel();
  const fcl::Vector3d pts[2] = {a, b};
  fcl::OBBRSSd bv;
  fcl::fit(pts, a == b ? 1 : 2, bv);
  m->getBV(0).bv = bv;
  return m;
}

Vec3 unit_dir(const Vec3& dir) {
  const double n = dir.norm();
  if (!(n > 0.0) || !std::isfinite(n)) throw std::invalid_argument("fcl index: ray direction is zero or not finite");
  return dir / n;
}

}  // namespace

struct FclIndex::Impl {
  std::vector<PartTriangles> parts;                    // exact corners, bounds, closed flag
  std::vector<std::shared_ptr<Model>> models;          // null when every triangle is direct
  std::vector<std::vector<std::int64_t>> model_to_mesh;  // FCL triangle id → mesh triangle id
  std::vector<std::vector<std::int64_t>> direct;       // triangles checked by our kernels
};

FclIndex::FclIndex(const std::vector<Part>& parts) : impl_(std::make_unique<Impl>()) {
  Impl& im = *impl_;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const Mesh& m = parts[i].mesh;
    for (std::size_t t = 0; t < m.triangle_count(); ++t)
      for (std::uint32_t v : m.triangles[t]) {
        if (v >= m.vertices.size())
          throw InputError({parts[i].source_file, 0, parts[i].name},
                           "triangle " + std::to_string(t) + " references vertex " + std::to_string(v) +
                               " but the mesh has " + std::to_string(m.vertices.size()));
        if (!m.vertices[v].allFinite())
          throw InputError({parts[i].source_file, 0, parts[i].name}, "vertex " + std::to_string(v) + " is not finite");
      }
  }
  im.parts = extract_part_triangles(parts);
  im.models.resize(parts.size());
  im.model_to_mesh.resize(parts.size());
  im.direct.resize(parts.size());
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const Mesh& m = parts[i].mesh;
    std::vector<fcl::Vector3d> verts(m.vertices.begin(), m.vertices.end());
    std::vector<fcl::Triangle> tris;
    for (std::size_t t = 0; t < m.triangle_count(); ++t) {
      const auto c = m.corners(t);
      const double n2 = (c[1] - c[0]).cross(c[2] - c[0]).squaredNorm();
      if (triangle_is_degenerate(c[0], c[1], c[2]) || n2 <= kFclFaceTestNormal2) {
        im.direct[i].push_back(static_cast<std::int64_t>(t));
        continue;
      }
      tris.emplace_back(m.triangles[t][0], m.triangles[t][1], m.triangles[t][2]);
      im.model_to_mesh[i].push_back(static_cast<std::int64_t>(t));
    }
    if (tris.empty()) continue;
    auto model = std::make_shared<Model>();
    model->beginModel(static_cast<int>(tris.size()), static_cast<int>(verts.size()));
    model->addSubModel(verts, tris);
    model->endModel();
    im.models[i] = std::move(model);
  }
}

FclIndex::~FclIndex() = default;

int FclIndex::part_count() const { return static_cast<int>(impl_->parts.size()); }

std::size_t FclIndex::direct_triangle_count() const {
  std::size_t n = 0;
  for (const auto& d : impl_->direct) n += d.size();
  return n;
}

IndexAccuracy FclIndex::accuracy() const {
  IndexAccuracy a;
  a.exact = true;
  double extent = 0.0;
  for (const auto& p : impl_->parts)
    if (!p.bounds.empty()) extent = std::max(extent, p.bounds.min.cwiseAbs().cwiseMax(p.bounds.max.cwiseAbs()).maxCoeff());
  a.abs_error = 64.0 * std::numeric_limits<double>::epsilon() * extent;
  a.description = "FCL 0.7 BVHModel<OBBRSS> mesh-mesh distance (exact triangle distance, double): <= " +
                  full_precision(a.abs_error) + " scene units";
  return a;
}

ClosestHit FclIndex::part_distance(const Vec3& a, const Vec3& b, int part, double* s) const {
  const Impl& im = *impl_;
  ClosestHit best;
  double best_s = 0.0;
  const PartTriangles& pt = im.parts[part];
  if (im.models[part]) {
    const auto q = query_model(a, b);
    fcl::DistanceRequestd req(true);
    fcl::DistanceResultd res;
    const fcl::Transform3d id = fcl::Transform3d::Identity();
    fcl::distance(im.models[part].get(), id, q.get(), id, req, res);
    if (res.b1 >= 0 && static_cast<std::size_t>(res.b1) < im.model_to_mesh[part].size()) {
      const std::int64_t t = im.model_to_mesh[part][res.b1];
      const auto& c = pt.triangles[static_cast<std::size_t>(t)];
      // FCL gives the distance and the triangle; the points and the segment parameter come
      // from the exact kernel on that triangle (FCL leaves them unset when they touch).
      const SegmentTriangleResult r = closest_segment_triangle(a, b, c[0], c[1], c[2]);
      best.distance = std::max(0.0, res.min_distance);
      best.point = r.triangle_point;
      best.part = part;
      best.triangle = t;
      best_s = r.s;
    }
  }
  for (std::int64_t t : im.direct[part]) {
    const auto& c = pt.triangles[static_cast<std::size_t>(t)];
    const SegmentTriangleResult r = closest_segment_triangle(a, b, c[0], c[1], c[2]);
    const double d = std::sqrt(r.dist2);
    if (d < best.distance) {
      best.distance = d;
      best.point = r.triangle_point;
      best.part = part;
      best.triangle = t;
      best_s = r.s;
    }
  }
  if (s) *s = best_s;
  return best;
}

namespace {
/// Parts ordered by the lower bound of the distance from segment ab to their boxes.
std::vector<std::pair<double, int>> parts_by_box(const std::vector<PartTriangles>& parts, const Vec3& a, const Vec3& b) {
  std::vector<std::pair<double, int>> order;
  for (std::size_t i = 0; i < parts.size(); ++i)
    if (!parts[i].triangles.empty())
      order.emplace_back(std::sqrt(segment_box_dist2_lower(a, b, parts[i].bounds.min, parts[i].bounds.max)),
                         static_cast<int>(i));
  std::sort(order.begin(), order.end());
  return order;
}
}  // namespace

ClosestHit FclIndex::segment_closest(const Vec3& a, const Vec3& b, double max_radius, double* segment_param) const {
  ClosestHit best;
  double best_s = 0.0;
  for (const auto& [lower, part] : parts_by_box(impl_->parts, a, b)) {
    if (lower > max_radius || lower > best.distance) break;
    double s = 0.0;
    const ClosestHit h = part_distance(a, b, part, &s);
    if (h.found() && h.distance <= max_radius && h.distance < best.distance) {
      best = h;
      best_s = s;
    }
  }
  if (best.found() && segment_param) *segment_param = best_s;
  return best;
}

ClosestHit FclIndex::closest(const Vec3& p, double max_radius) const { return segment_closest(p, p, max_radius); }

ClosestHit FclIndex::closest_on_part(const Vec3& p, int part, double max_radius) const {
  if (part < 0 || part >= part_count()) throw std::out_of_range("fcl index: part id " + std::to_string(part) + " out of range");
  if (impl_->parts[part].triangles.empty()) return {};
  const ClosestHit h = part_distance(p, p, part, nullptr);
  return h.found() && h.distance <= max_radius ? h : ClosestHit{};
}

ClosestHit FclIndex::segment_closest_on_part(const Vec3& a, const Vec3& b, int part, double max_radius,
                                            double* segment_param) const {
  if (part < 0 || part >= part_count()) throw std::out_of_range("fcl index: part id " + std::to_string(part) + " out of range");
  if (impl_->parts[part].triangles.empty()) return {};
  double s = 0.0;
  const ClosestHit h = part_distance(a, b, part, &s);
  if (!h.found() || !(h.distance <= max_radius)) return {};
  if (segment_param) *segment_param = s;
  return h;
}

ClosestHit FclIndex::capsule_on_part(const Vec3& a, const Vec3& b, double r, int part, double* segment_param) const {
  if (part < 0 || part >= part_count()) throw std::out_of_range("fcl index: part id " + std::to_string(part) + " out of range");
  if (impl_->parts[part].triangles.empty()) return {};
  ClosestHit h = part_distance(a, b, part, segment_param);
  if (h.found()) h.distance -= r;
  return h;
}

bool FclIndex::any_within(const Vec3& p, double r) const { return segment_within(p, p, r); }

bool FclIndex::segment_within(const Vec3& a, const Vec3& b, double r) const {
  if (!(r >= 0.0)) return false;
  for (const auto& [lower, part] : parts_by_box(impl_->parts, a, b)) {
    if (lower > r) break;
    const ClosestHit h = part_distance(a, b, part, nullptr);
    if (h.found() && h.distance <= r) return true;
  }
  return false;
}

bool FclIndex::inside(const Vec3& p, int* part) const {
  std::vector<int> held;
  parts_holding(impl_->parts, p, true, held);
  if (held.empty()) return false;
  if (part) *part = held.front();
  return true;
}

void FclIndex::inside_parts(const Vec3& p, std::vector<int>& out) const { parts_holding(impl_->parts, p, false, out); }

RayHit FclIndex::ray(const Vec3& origin, const Vec3& dir, double t_max) const {
  const Vec3 u = unit_dir(dir);
  const Impl& im = *impl_;
  RayHit best;
  best.t = t_max;
  for (int i = 0; i < part_count(); ++i) {
    const PartTriangles& pt = im.parts[i];
    if (pt.triangles.empty()) continue;
    // Ray clipped to the part's box (grown a little so that faces on the box count).
    const double grow = 1e-9 * (pt.bounds.diagonal() + origin.cwiseAbs().maxCoeff());
    double t0 = 0.0, t1 = best.t;
    for (int k = 0; k < 3 && t0 <= t1; ++k) {
      const double lo = pt.bounds.min[k] - grow, hi = pt.bounds.max[k] + grow;
      if (u[k] == 0.0) {
        if (origin[k] < lo || origin[k] > hi) t0 = t1 + 1;
        continue;
      }
      double ta = (lo - origin[k]) / u[k], tb = (hi - origin[k]) / u[k];
      if (ta > tb) std::swap(ta, tb);
      t0 = std::max(t0, ta);
      t1 = std::min(t1, tb);
    }
    if (!(t0 <= t1)) continue;
    std::vector<std::int64_t> cand(im.direct[i].begin(), im.direct[i].end());
    if (im.models[i]) {
      const auto q = query_model(origin + t0 * u, origin + t1 * u);
      fcl::CollisionRequestd req(kMaxRayContacts, false);
      fcl::CollisionResultd res;
      const fcl::Transform3d id = fcl::Transform3d::Identity();
      fcl::collide(im.models[i].get(), id, q.get(), id, req, res);
      for (std::size_t c = 0; c < res.numContacts(); ++c) {
        const int b1 = res.getContact(c).b1;
        if (b1 >= 0 && static_cast<std::size_t>(b1) < im.model_to_mesh[i].size()) cand.push_back(im.model_to_mesh[i][b1]);
      }
    }
    for (std::int64_t t : cand) {
      const auto& c = pt.triangles[static_cast<std::size_t>(t)];
      const RayTriangleResult r = intersect_ray_triangle(origin, u, c[0], c[1], c[2]);
      if (r.hit && r.t <= best.t && !(r.t == best.t && best.part >= 0 && (i > best.part || t >= best.triangle))) {
        best.t = r.t;
        best.part = i;
        best.triangle = t;
        best.normal = (c[1] - c[0]).cross(c[2] - c[0]).normalized();
      }
    }
  }
  if (!best.found()) best.t = std::numeric_limits<double>::infinity();
  return best;
}

}  // namespace loom
