// loom's certified audit against the pipeline a user would build from FCL 0.7, side by side
// on the seed paper's "complex" scene (bench/audit_scenes.hpp: 200 closed parts, ~1M
// triangles, 100 cables of 1–3 m, d = 2–10 mm; bench_audit's paper scale) and the same work:
// cable–part clashes and clearance violations (routing clearance 3 mm plus each part's own)
// and cable–cable clashes, no self or bend checks.
//
// The FCL pipeline: each cable flattened into chords whose sag stays within loom's
// tolerance (r/100), each chord a capsule of the cable's radius; a broad phase
// (DynamicAABBTree managers) on the capsules widened by the clearance band; fcl::collide for
// the candidates, and fcl::distance only for the pairs within the band but not in contact;
// one TBB task per cable. Findings are compared as sets: (cable, part) pairs in contact,
// (cable, part) pairs closer than required, (cable, cable) pairs in contact.
//
// Writes bench/results/fcl_peer.csv: index build, check time on 1 and 2 threads for both
// (best of REPS, wall and process CPU), and whether the findings agree.
// Usage: bench_fcl_peer [REPS] [TRIS_PER_PART]
#include "bench/audit_scenes.hpp"
#include "bench/audit_timing.hpp"
#include "index/embree_index.hpp"
#include "routing/audit/clash_check.hpp"

#include <fcl/broadphase/broadphase_dynamic_AABB_tree.h>
#include <fcl/geometry/bvh/BVH_model.h>
#include <fcl/geometry/shape/capsule.h>
#include <fcl/math/bv/OBBRSS.h>
#include <fcl/narrowphase/collision.h>
#include <fcl/narrowphase/distance.h>

#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

namespace {

using namespace loom;
using Model = fcl::BVHModel<fcl::OBBRSSd>;
using Object = fcl::CollisionObjectd;
/// (cable, part or other cable).
using Pair = std::pair<int, int>;

constexpr double kRoutingClearance = 3.0;  ///< mm, as bench_audit

/// The findings compared: contact and near (closer than required) cable–part pairs, contact
/// cable–cable pairs (lower index first).
struct Findings {
  std::set<Pair> part_contact, part_near, cable_contact;
  bool operator==(const Findings& o) const {
    return part_contact == o.part_contact && part_near == o.part_near && cable_contact == o.cable_contact;
  }
};

Findings of(const ClashResult& r) {
  Findings f;
  for (const auto& c : r.clashes) {
    if (c.kind == ClashKind::CableStructure) {
      f.part_contact.insert({c.cable, c.part});
      f.part_near.insert({c.cable, c.part});
    } else if (c.kind == ClashKind::CableCable) {
      f.cable_contact.insert({std::min(c.cable, c.other), std::max(c.cable, c.other)});
    }
  }
  for (const auto& v : r.violations)
    if (v.kind == ViolationKind::Clearance) f.part_near.insert({v.cable, v.part});
  return f;
}

/// A cable as chords: end points, each chord's sag within `tol` of the curve.
std::vector<Vec3> chords(const CableInput& c, double tol) {
  const double bend = std::max(c.curve.min_bend_radius().radius, c.radius);
  const double len = std::min(2.0 * c.radius, std::sqrt(8.0 * bend * tol));
  std::vector<Vec3> pts;
  for (const auto& sp : c.curve.sample_by_arc_length(len)) pts.push_back(sp.second);
  return pts;
}

/// An FCL capsule object of radius r along ab (FCL's capsule axis is z, centred).
std::unique_ptr<Object> capsule(const Vec3& a, const Vec3& b, double r) {
  const Vec3 d = b - a;
  const double len = d.norm();
  fcl::Transform3d t = fcl::Transform3d::Identity();
  t.translation() = 0.5 * (a + b);
  if (len > 0.0) t.linear() = Eigen::Quaterniond::FromTwoVectors(Vec3::UnitZ(), d / len).toRotationMatrix();
  return std::make_unique<Object>(std::make_shared<fcl::Capsuled>(r, len), t);
}

/// The FCL side: part models (built once) and the check.
class FclPipeline {
 public:
  explicit FclPipeline(const std::vector<Part>& parts) : parts_(parts) {
    for (const Part& p : parts) {
      auto m = std::make_shared<Model>();
      m->beginModel();
      for (std::size_t t = 0; t < p.mesh.triangle_count(); ++t) {
        const auto c = p.mesh.corners(t);
        m->addTriangle(c[0], c[1], c[2]);
      }
      m->endModel();
      objects_.push_back(std::make_unique<Object>(m));
      objects_.back()->computeAABB();
      objects_.back()->setUserData(reinterpret_cast<void*>(static_cast<std::intptr_t>(objects_.size() - 1)));
    }
    std::vector<Object*> raw;
    for (auto& o : objects_) raw.push_back(o.get());
    manager_.registerObjects(raw);
    manager_.setup();
  }

  Findings check(const std::vector<CableInput>& cables, double tol) const {
    std::vector<std::vector<Vec3>> pts(cables.size());
    tbb::parallel_for(std::size_t(0), cables.size(), [&](std::size_t c) { pts[c] = chords(cables[c], tol); });
    Findings f;
    std::mutex m;
    tbb::parallel_for(std::size_t(0), cables.size(), [&](std::size_t c) {
      Findings local = check_parts(static_cast<int>(c), cables[c], pts[c]);
      const std::lock_guard<std::mutex> lock(m);
      f.part_contact.insert(local.part_contact.begin(), local.part_contact.end());
      f.part_near.insert(local.part_near.begin(), local.part_near.end());
    });
    f.cable_contact = check_cables(cables, pts);
    return f;
  }

 private:
  /// One cable against the parts: broad phase on band-widened capsules, then collide and
  /// distance on the candidates.
  Findings check_parts(int c, const CableInput& cable, const std::vector<Vec3>& pts) const {
    struct Query {
      const Object* self = nullptr;  ///< the widened capsule asked about
      std::vector<int> candidates;
    };
    double widest = 0.0;
    for (const Part& p : parts_) widest = std::max(widest, p.clearance);
    Findings f;
    for (std::size_t i = 0; i + 1 < pts.size(); ++i) {
      const auto wide = capsule(pts[i], pts[i + 1], cable.radius + kRoutingClearance + widest);
      wide->computeAABB();
      Query q;
      q.self = wide.get();
      manager_.collide(wide.get(), &q, [](Object* o1, Object* o2, void* data) {
        // The manager calls back with its own object and the query, in either order.
        auto& query = *static_cast<Query*>(data);
        const Object* part = o1 == query.self ? o2 : o1;
        query.candidates.push_back(static_cast<int>(reinterpret_cast<std::intptr_t>(part->getUserData())));
        return false;
      });
      if (q.candidates.empty()) continue;
      const auto tube = capsule(pts[i], pts[i + 1], cable.radius);
      for (int part : q.candidates) {
        const Object& obj = *objects_[static_cast<std::size_t>(part)];
        if (f.part_contact.count({c, part})) continue;
        fcl::CollisionRequestd creq;
        fcl::CollisionResultd cres;
        if (fcl::collide(tube.get(), &obj, creq, cres) > 0) {
          f.part_contact.insert({c, part});
          f.part_near.insert({c, part});
          continue;
        }
        if (f.part_near.count({c, part})) continue;
        fcl::DistanceRequestd dreq;
        dreq.enable_nearest_points = false;
        fcl::DistanceResultd dres;
        fcl::distance(tube.get(), &obj, dreq, dres);
        if (dres.min_distance < kRoutingClearance + parts_[static_cast<std::size_t>(part)].clearance)
          f.part_near.insert({c, part});
      }
    }
    return f;
  }

  /// Cable–cable contact: every chord capsule of every cable in one manager, pairs of
  /// different cables whose capsules collide.
  static std::set<Pair> check_cables(const std::vector<CableInput>& cables, const std::vector<std::vector<Vec3>>& pts) {
    std::vector<std::unique_ptr<Object>> caps;
    for (std::size_t c = 0; c < cables.size(); ++c)
      for (std::size_t i = 0; i + 1 < pts[c].size(); ++i) {
        caps.push_back(capsule(pts[c][i], pts[c][i + 1], cables[c].radius));
        caps.back()->computeAABB();
        caps.back()->setUserData(reinterpret_cast<void*>(static_cast<std::intptr_t>(c)));
      }
    fcl::DynamicAABBTreeCollisionManagerd manager;
    std::vector<Object*> raw;
    for (auto& o : caps) raw.push_back(o.get());
    manager.registerObjects(raw);
    manager.setup();
    std::set<Pair> out;
    manager.collide(&out, [](Object* o1, Object* o2, void* data) {
      const int a = static_cast<int>(reinterpret_cast<std::intptr_t>(o1->getUserData()));
      const int b = static_cast<int>(reinterpret_cast<std::intptr_t>(o2->getUserData()));
      auto& found = *static_cast<std::set<Pair>*>(data);
      if (a == b || found.count({std::min(a, b), std::max(a, b)})) return false;
      fcl::CollisionRequestd req;
      fcl::CollisionResultd res;
      if (fcl::collide(o1, o2, req, res) > 0) found.insert({std::min(a, b), std::max(a, b)});
      return false;
    });
    return out;
  }

  const std::vector<Part>& parts_;
  std::vector<std::unique_ptr<Object>> objects_;
  mutable fcl::DynamicAABBTreeCollisionManagerd manager_;
};

/// The best of several timed runs (by wall clock) and that run's process CPU time.
struct Best {
  double wall = 1e300, cpu = 0.0;
  template <class F>
  void run(F&& f) {
    const double t0 = bench::now_ms(), c0 = bench::cpu_ms();
    f();
    const double dt = bench::now_ms() - t0, dc = bench::cpu_ms() - c0;
    if (dt < wall) {
      wall = dt;
      cpu = dc;
    }
  }
};

void print_difference(const char* what, const std::set<Pair>& a, const std::set<Pair>& b) {
  std::vector<Pair> only_a, only_b;
  std::set_difference(a.begin(), a.end(), b.begin(), b.end(), std::back_inserter(only_a));
  std::set_difference(b.begin(), b.end(), a.begin(), a.end(), std::back_inserter(only_b));
  for (const auto& p : only_a) std::printf("  %s: loom only (%d, %d)\n", what, p.first, p.second);
  for (const auto& p : only_b) std::printf("  %s: FCL only (%d, %d)\n", what, p.first, p.second);
}

}  // namespace

int main(int argc, char** argv) {
  const int reps = argc > 1 ? std::max(1, std::atoi(argv[1])) : 3;
  const int tris = argc > 2 ? std::max(100, std::atoi(argv[2])) : 7500;
  const bench::BenchScene sc = bench::make_scene(200, tris, 100, 1.0, 42);
  double tol = 1e300;
  for (const auto& c : sc.cables) tol = std::min(tol, c.radius / 100.0);

  const double e0 = bench::now_ms(), ec0 = bench::cpu_ms();
  const EmbreeIndex embree(sc.parts);
  const double embree_build = bench::now_ms() - e0, embree_build_cpu = bench::cpu_ms() - ec0;
  const double f0 = bench::now_ms(), fc0 = bench::cpu_ms();
  const FclPipeline fcl_side(sc.parts);
  const double fcl_build = bench::now_ms() - f0, fcl_build_cpu = bench::cpu_ms() - fc0;

  ClashRequest req;
  req.routing_clearance = kRoutingClearance;
  req.check_self = false;
  req.check_bend = false;
  std::ofstream csv(std::string(LOOM_SOURCE_DIR) + "/bench/results/fcl_peer.csv");
  csv << "triangles,cables,threads,loom_build_ms,fcl_build_ms,loom_check_ms,loom_check_cpu_ms,fcl_check_ms,"
         "fcl_check_cpu_ms,speedup,part_contacts,part_near,cable_contacts,identical\n";
  for (int threads : {1, 2}) {
    const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(threads));
    req.threads = threads;
    Best loom_t, fcl_t;
    Findings loom_f, fcl_f;
    for (int r = 0; r < reps; ++r) {  // interleaved, best of reps
      loom_t.run([&] { loom_f = of(check_clashes(sc.cables, sc.parts, &embree, req)); });
      fcl_t.run([&] { fcl_f = fcl_side.check(sc.cables, tol); });
    }
    const bool same = loom_f == fcl_f;
    std::printf("%zu triangles, %d thread(s): loom %.1f ms (cpu %.1f), FCL pipeline %.1f ms (cpu %.1f): %.1fx; "
                "part contacts %zu/%zu, near %zu/%zu, cable contacts %zu/%zu: %s\n",
                sc.triangles, threads, loom_t.wall, loom_t.cpu, fcl_t.wall, fcl_t.cpu, fcl_t.wall / loom_t.wall,
                loom_f.part_contact.size(), fcl_f.part_contact.size(), loom_f.part_near.size(), fcl_f.part_near.size(),
                loom_f.cable_contact.size(), fcl_f.cable_contact.size(), same ? "identical" : "DIFFERENT");
    if (!same) {
      print_difference("part contact", loom_f.part_contact, fcl_f.part_contact);
      print_difference("part near", loom_f.part_near, fcl_f.part_near);
      print_difference("cable contact", loom_f.cable_contact, fcl_f.cable_contact);
    }
    csv << sc.triangles << ',' << sc.cables.size() << ',' << threads << ',' << embree_build << ',' << fcl_build << ','
        << loom_t.wall << ',' << loom_t.cpu << ',' << fcl_t.wall << ',' << fcl_t.cpu << ',' << fcl_t.wall / loom_t.wall
        << ',' << loom_f.part_contact.size() << ',' << loom_f.part_near.size() << ',' << loom_f.cable_contact.size()
        << ',' << (same ? 1 : 0) << '\n';
  }
  std::printf("index build: Embree %.0f ms (cpu %.0f), FCL %.0f ms (cpu %.0f)\n", embree_build, embree_build_cpu,
              fcl_build, fcl_build_cpu);
  return 0;
}
