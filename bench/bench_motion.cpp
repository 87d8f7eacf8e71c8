// Moving parts on the wing section: the bundled demo scene with an actuator arm added in
// bay 2 (a 20 × 20 × 115 mm link hanging from a hinge at (560, 380, 195), rotating ±30°
// about Y), across the way from the trunk to the actuator's receptacle. Measures:
//  - the audit of each routed harness with the arm's motion against the same audit with the
//    arm fixed at rest (process CPU time of run_audit, one thread, prebuilt Embree index,
//    runs interleaved, best of N);
//  - cable-motion clashes after routing around the swept envelope, and after routing
//    around the rest pose only (what a one-pose check would have let through);
//  - FCL's continuous collision (conservative advancement, screw motion from −30° to +30°)
//    of each cable's swept tube against the arm, beside the branch and bound: agreement on
//    contact, the first-contact pose, and time; and FCL's naive solver (100 discrete poses).
// Writes bench/results/motion.csv and motion_cables.csv. Usage: bench_motion [REPS] [ITERATIONS]
#include "audit_timing.hpp"
#include "core/io/scene_load.hpp"
#include "index/embree_index.hpp"
#include "routing/audit/audit.hpp"
#include "routing/curve/sweep.hpp"
#include "routing/route/motion_envelope.hpp"
#include "routing/route/route_pipeline.hpp"

#include <fcl/geometry/bvh/BVH_model.h>
#include <fcl/math/bv/OBBRSS.h>
#include <fcl/narrowphase/continuous_collision.h>

#include <cstdlib>
#include <fstream>
#include <iostream>

namespace loom {
namespace {

constexpr double kDeg = M_PI / 180.0;

/// The arm: a closed box, rest pose hanging down from the hinge, with its motion.
Part actuator_arm() {
  Part p;
  p.name = "actuator-arm";
  const Vec3 lo(550, 370, 90), hi(570, 390, 205);
  for (int k = 0; k < 8; ++k)
    p.mesh.vertices.push_back(Vec3(k & 1 ? hi.x() : lo.x(), k & 2 ? hi.y() : lo.y(), k & 4 ? hi.z() : lo.z()));
  const std::uint32_t q[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& f : q) {
    p.mesh.triangles.push_back({f[0], f[1], f[2]});
    p.mesh.triangles.push_back({f[0], f[2], f[3]});
  }
  p.closed = true;
  Motion m;
  m.name = "arm";
  m.kind = MotionKind::Rotate;
  m.axis_point = Vec3(560, 380, 195);
  m.axis = Vec3::UnitY();
  m.from = -30;
  m.to = 30;
  p.motion = m;
  return p;
}

struct AuditTime {
  AuditReport rep;
  double ms = 1e300;   ///< wall clock of the whole run_audit, best run
  double cpu = 1e300;  ///< process CPU time of it (one thread), best run
};

/// One run_audit (one thread, prebuilt index), kept in t if it is the fastest by CPU time.
void audit_once(const Scene& s, const ObstacleIndex& index, AuditTime& t) {
  AuditOptions o;
  o.index = &index;
  o.check.threads = 1;
  const double w0 = bench::now_ms(), c0 = bench::cpu_ms();
  AuditReport r = run_audit(s, o);
  const double w = bench::now_ms() - w0, c = bench::cpu_ms() - c0;
  if (c < t.cpu) t.cpu = c, t.ms = w, t.rep = std::move(r);
}

/// The audit of `moving` and of `fixed` (the same harness, the arm at rest), runs
/// interleaved so that load on the machine falls on both alike; best of `reps` each.
std::pair<AuditTime, AuditTime> timed_pair(const Scene& moving, const Scene& fixed, const ObstacleIndex& index,
                                           int reps) {
  std::pair<AuditTime, AuditTime> t;
  for (int i = 0; i < reps; ++i) {
    audit_once(moving, index, t.first);
    audit_once(fixed, index, t.second);
  }
  return t;
}

using Model = fcl::BVHModel<fcl::OBBRSSd>;

std::shared_ptr<Model> fcl_model(const Mesh& m) {
  auto out = std::make_shared<Model>();
  out->beginModel();
  for (const auto& t : m.triangles) out->addTriangle(m.vertices[t[0]], m.vertices[t[1]], m.vertices[t[2]]);
  out->endModel();
  return out;
}

}  // namespace
}  // namespace loom

int main(int argc, char** argv) {
  using namespace loom;
  const int reps = argc > 1 ? std::atoi(argv[1]) : 3;
  const long long iterations = argc > 2 ? std::atoll(argv[2]) : 3000;
  Scene scene = load_scene(std::string(LOOM_SOURCE_DIR) + "/examples/wing-section/scene.toml");
  scene.parts.push_back(actuator_arm());
  Scene fixed = scene;
  fixed.parts.back().motion.reset();

  RouteOptions ro;
  ro.seed = 1;
  ro.iterations = iterations;
  ro.time_limit = 30.0;  // the iteration budget ends each plan: reproducible
  ro.threads = 1;
  const double r0 = bench::now_ms();
  const RouteReport around_envelope = route_scene(scene, ro);
  const double route_envelope_ms = bench::now_ms() - r0;
  const double r1 = bench::now_ms();
  const RouteReport around_rest = route_scene(fixed, ro);
  const double route_rest_ms = bench::now_ms() - r1;

  // The harness routed around the envelope, audited with and without the arm's motion.
  Scene routed = scene;
  routed.harness = around_envelope.routed;
  Scene routed_fixed = fixed;
  routed_fixed.harness = around_envelope.routed;
  const EmbreeIndex index(scene.parts);
  const auto [full, stat] = timed_pair(routed, routed_fixed, index, reps);
  // The harness routed around the rest pose only, audited over the motion (it crosses the
  // sweep: the motion check has work to do here).
  Scene rest_routed = scene;
  rest_routed.harness = around_rest.routed;
  Scene rest_routed_fixed = fixed;
  rest_routed_fixed.harness = around_rest.routed;
  const auto [missed, missed_static] = timed_pair(rest_routed, rest_routed_fixed, index, reps);

  // FCL continuous collision of each cable's tube against the arm, screw motion −30° → +30°.
  const Part& arm = scene.parts.back();
  const auto arm_model = fcl_model(arm.mesh);
  AABB swept;  // the arm's swept box: cables whose tube box misses it are not asked
  extend_by_swept_envelopes({arm}, 1.0, swept);
  std::vector<AuditCable> cables;
  int ccd_contacts = 0, naive_contacts = 0, bb_contacts = 0, agree = 0;
  double ccd_ms = 0.0, naive_ms = 0.0;
  int ccd_checked = 0;
  std::ofstream per(std::string(LOOM_SOURCE_DIR) + "/bench/results/motion_cables.csv");
  per << "routing,cable,bb_clearance_mm,bb_pose_deg,ccd_contact,ccd_first_contact_deg,ccd_ms,naive_contact,"
         "naive_first_contact_deg,naive_ms\n";
  for (const auto* which : {&rest_routed, &routed}) {
    const AuditTime& a = which == &routed ? full : missed;
    const std::vector<CableInput> inputs = audit_cable_inputs(which->harness, cables);
    for (std::size_t c = 0; c < inputs.size(); ++c) {
      AABB tube_box;
      for (const auto& sp : inputs[c].curve.sample_by_arc_length(inputs[c].radius)) tube_box.extend(sp.second);
      const Vec3 grow = Vec3::Constant(2.0 * inputs[c].radius);
      if (((tube_box.min - grow).array() > swept.max.array()).any() ||
          ((tube_box.max + grow).array() < swept.min.array()).any())
        continue;
      ++ccd_checked;
      SweepOptions so;
      so.chord_tolerance = 0.05;
      const auto tube = fcl_model(sweep_tube(inputs[c].curve, inputs[c].radius, so).mesh);
      fcl::ContinuousCollisionRequestd req;
      req.num_max_iterations = 100;
      req.toc_err = 1e-4;
      req.ccd_motion_type = fcl::CCDM_SCREW;
      req.ccd_solver_type = fcl::CCDC_CONSERVATIVE_ADVANCEMENT;
      fcl::ContinuousCollisionResultd res;
      const fcl::Transform3d from = arm.motion->pose(arm.motion->from), to = arm.motion->pose(arm.motion->to);
      const double t0 = bench::now_ms();
      fcl::continuousCollide(arm_model.get(), from, to, tube.get(), fcl::Transform3d::Identity(),
                             fcl::Transform3d::Identity(), req, res);
      const double dt = bench::now_ms() - t0;
      ccd_ms += dt;
      // FCL's naive solver: discrete collision at num_max_iterations evenly spaced poses.
      fcl::ContinuousCollisionRequestd nreq = req;
      nreq.ccd_solver_type = fcl::CCDC_NAIVE;
      fcl::ContinuousCollisionResultd nres;
      const double t1 = bench::now_ms();
      fcl::continuousCollide(arm_model.get(), from, to, tube.get(), fcl::Transform3d::Identity(),
                             fcl::Transform3d::Identity(), nreq, nres);
      const double ndt = bench::now_ms() - t1;
      naive_ms += ndt;
      naive_contacts += nres.is_collide;
      const double naive_deg = arm.motion->from + nres.time_of_contact * (arm.motion->to - arm.motion->from);
      double bb_clear = 0.0, bb_pose = 0.0;
      bool bb = false;
      for (const auto& m : a.rep.motion.clashes)
        if (a.rep.check_ids[static_cast<std::size_t>(m.cable)] == inputs[c].id) bb = true, bb_clear = m.clearance, bb_pose = m.pose;
      const double toc_deg = arm.motion->from + res.time_of_contact * (arm.motion->to - arm.motion->from);
      ccd_contacts += res.is_collide;
      bb_contacts += bb;
      agree += res.is_collide == bb;
      per << (which == &routed ? "envelope" : "rest") << "," << inputs[c].id << "," << (bb ? bb_clear : 0.0) << ","
          << (bb ? bb_pose : 0.0) << "," << res.is_collide << "," << (res.is_collide ? toc_deg : 0.0) << "," << dt
          << "," << nres.is_collide << "," << (nres.is_collide ? naive_deg : 0.0) << "," << ndt << "\n";
    }
  }
  std::ofstream csv(std::string(LOOM_SOURCE_DIR) + "/bench/results/motion.csv");
  csv << "measure,value\n"
      << "cables," << routed.harness.cables.size() << "\n"
      << "audit_static_cpu_ms," << stat.cpu << "\n"
      << "audit_motion_cpu_ms," << full.cpu << "\n"
      << "audit_ratio," << full.cpu / stat.cpu << "\n"
      << "motion_poses," << full.rep.motion.poses << "\n"
      << "rest_routed_audit_static_cpu_ms," << missed_static.cpu << "\n"
      << "rest_routed_audit_motion_cpu_ms," << missed.cpu << "\n"
      << "rest_routed_audit_ratio," << missed.cpu / missed_static.cpu << "\n"
      << "rest_routed_motion_poses," << missed.rep.motion.poses << "\n"
      << "rest_routed_motion_distance_queries," << missed.rep.motion.distance_queries << "\n"
      << "motion_pose_tolerance_mm," << full.rep.motion.pose_tolerance << "\n"
      << "cable_motion_clashes_routed_around_envelope," << full.rep.motion.clashes.size() << "\n"
      << "unrouted_around_envelope," << around_envelope.unrouted.size() << "\n"
      << "cable_motion_clashes_routed_around_rest_pose," << missed.rep.motion.clashes.size() << "\n"
      << "static_clashes_routed_around_rest_pose," << missed.rep.result.clashes.size() << "\n"
      << "route_envelope_ms," << route_envelope_ms << "\n"
      << "route_rest_ms," << route_rest_ms << "\n"
      << "ccd_contacts," << ccd_contacts << "\n"
      << "branch_and_bound_contacts," << bb_contacts << "\n"
      << "ccd_agrees," << agree << "\n"
      << "ccd_total_ms," << ccd_ms << "\n"
      << "ccd_naive_contacts," << naive_contacts << "\n"
      << "ccd_naive_total_ms," << naive_ms << "\n"
      << "cables_near_arm_checked_by_ccd," << (ccd_checked) << "\n";
  std::cout << "audit CPU: static " << stat.cpu << " ms, with motion " << full.cpu << " ms (x" << full.cpu / stat.cpu
            << "); routed around the rest pose: static " << missed_static.cpu << " ms, with motion " << missed.cpu
            << " ms (x" << missed.cpu / missed_static.cpu << "); cable-motion clashes: " << full.rep.motion.clashes.size() << " routed around the envelope, "
            << missed.rep.motion.clashes.size() << " routed around the rest pose; FCL CCD contacts " << ccd_contacts
            << ", naive " << naive_contacts << " vs branch and bound " << bb_contacts << " (agree " << agree << "), CCD " << ccd_ms
            << " ms; wrote bench/results/motion.csv\n";
  return 0;
}
