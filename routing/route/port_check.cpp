#include "routing/route/port_check.hpp"

#include "core/error.hpp"
#include "index/box_tree.hpp"

#include <algorithm>

namespace loom {

namespace {

std::string part_label(const PartNameFn& part_name, int part) {
  if (part < 0) return "part ?";
  return part_name ? "part '" + part_name(part) + "'" : "part " + std::to_string(part);
}

const NearPart* find_near(const std::vector<NearPart>& near, int part) {
  const auto it = std::find_if(near.begin(), near.end(), [part](const NearPart& n) { return n.part == part; });
  return it == near.end() ? nullptr : &*it;
}

/// The nearest part, other than those in e.near, within `required` of the port.
ClosestHit too_close(const ObstacleIndex& index, const std::vector<AABB>& part_boxes, const PortExit& e,
                     double required) {
  if (e.near.empty()) return index.closest(e.port, required);
  ClosestHit best;
  for (std::size_t q = 0; q < part_boxes.size(); ++q) {
    const int id = static_cast<int>(q);
    if (find_near(e.near, id) || !part_boxes[q].inflated(required).contains(e.port)) continue;
    const ClosestHit hit = index.closest_on_part(e.port, id, required);
    if (hit.found() && hit.distance < best.distance) best = hit;
  }
  return best;
}

/// The nearest part that the straight exit port → stub_end comes within `required` of
/// (found() == false if none). A part near the port is measured only past its excused run,
/// and over that run (from `lift` off the port, where the port's own surface is left behind)
/// it must not be entered; every other part is measured over the whole exit. An exit lifted
/// off the port inside a part meets it at distance 0 there.
ClosestHit exit_obstacle(const ObstacleIndex& index, const std::vector<AABB>& part_boxes, const PortExit& e,
                         double required) {
  ClosestHit best;
  const double len = (e.stub_end - e.port).norm();
  if (!(len > 0.0)) return best;
  const Vec3 dir = (e.stub_end - e.port) / len;
  // Lifted off the port, the exit must be outside every part (a segment that starts inside
  // a part need not touch its surface).
  const Vec3 lifted = e.port + std::min(e.lift, len) * dir;
  int inside_part = -1;
  if (index.inside(lifted, &inside_part)) {
    best.distance = 0.0;
    best.point = lifted;
    best.part = inside_part;
    return best;
  }
  if (e.near.empty()) return index.segment_closest(e.port, e.stub_end, required);
  AABB exit_box;
  exit_box.extend(e.port);
  exit_box.extend(e.stub_end);
  auto measure = [&](int q, double from, double to, double need) {
    if (!(to > from)) return;
    const ClosestHit hit = index.segment_closest_on_part(e.port + from * dir, e.port + to * dir, q, need);
    if (hit.found() && hit.distance <= best.distance) best = hit;
  };
  for (std::size_t q = 0; q < part_boxes.size(); ++q) {
    if (!boxes_overlap(exit_box.inflated(required), part_boxes[q])) continue;
    const int id = static_cast<int>(q);
    if (const NearPart* n = find_near(e.near, id)) {
      const double excused = std::min(n->excused, len);
      measure(id, std::min(e.lift, len), excused, 0.0);  // not into it
      measure(id, excused, len, required);
    } else {
      measure(id, 0.0, len, required);
    }
  }
  return best;
}

}  // namespace

std::vector<NearPart> near_port_parts(const ObstacleIndex& index, const std::vector<AABB>& part_boxes,
                                      const std::vector<Part>& parts, const Vec3& port, double required,
                                      double excused_on, double excused_near) {
  std::vector<NearPart> near;
  for (std::size_t q = 0; q < parts.size(); ++q)
    if (part_boxes[q].inflated(required).contains(port) &&
        index.closest_on_part(port, static_cast<int>(q), required).found())
      near.push_back({static_cast<int>(q), parts[q].role == PartRole::KeepOut ? excused_near : excused_on});
  return near;
}

bool check_port_exit(const ObstacleIndex& index, const std::vector<AABB>& part_boxes, const PortExit& e,
                     double required, const PartNameFn& part_name, PlanResult& r) {
  const std::string at = e.who + " at " + full_precision(e.port);
  int inside_part = -1;
  const bool inside = index.inside(e.port, &inside_part);
  const ClosestHit close = inside ? ClosestHit{} : too_close(index, part_boxes, e, required);
  if (inside || close.found()) {
    r.reason = e.is_start ? NoPathReason::StartInObstacle : NoPathReason::GoalInObstacle;
    r.blocked_at = e.port;
    r.blocking_part = inside ? inside_part : close.part;
    r.message = at + (inside ? " is inside " + part_label(part_name, inside_part)
                             : " is " + full_precision(close.distance) + " from " + part_label(part_name, close.part) +
                                   ", closer than radius + clearance = " + full_precision(required));
    return false;
  }
  // Every part is kept `required` away from the whole exit, but a part the port sits on only
  // past its excused run; the planner starts at the exit's end.
  ClosestHit hit;
  if (index.segment_within(e.port, e.stub_end, required)) hit = exit_obstacle(index, part_boxes, e, required);
  const ClosestHit at_end = hit.found() ? ClosestHit{} : index.closest(e.stub_end, required);
  if (!hit.found() && !at_end.found()) return true;
  const ClosestHit& w = hit.found() ? hit : at_end;
  r.reason = e.is_start ? NoPathReason::StartPortBlocked : NoPathReason::GoalPortBlocked;
  r.blocked_at = w.point;
  r.blocking_part = w.part;
  r.message = at + " faces a wall: its straight exit of length " + full_precision((e.stub_end - e.port).norm()) +
              (hit.found() ? " comes" : " ends") + " within " + full_precision(w.distance) + " of " +
              part_label(part_name, w.part) + " (needs " + full_precision(required) + ")";
  return false;
}

}  // namespace loom
