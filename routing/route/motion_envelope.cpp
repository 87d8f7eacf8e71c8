#include "routing/route/motion_envelope.hpp"

#include "core/error.hpp"

namespace loom {

double swept_envelope_gap(double routing_clearance, double smallest_diameter) {
  return routing_clearance > 0.0 ? routing_clearance : 0.5 * smallest_diameter;
}

std::size_t append_swept_envelopes(const std::vector<Part>& parts, double max_gap, const std::string& units,
                                   std::vector<Part>& out, std::vector<std::string>& notes) {
  std::size_t added = 0;
  for (const Part& p : parts) {
    if (!p.motion) continue;
    double gap = 0.0;
    const std::vector<double> poses = pose_samples(*p.motion, p.mesh, max_gap, &gap);
    for (double q : poses) {
      Part copy;
      copy.name = p.name + "@" + full_precision(q) + p.motion->pose_unit(units);
      copy.mesh = posed_mesh(p.mesh, *p.motion, q);
      copy.role = p.role;
      copy.clearance = p.clearance;
      copy.closed = p.closed;
      copy.source_file = p.source_file;
      copy.source_name = p.source_name;
      out.push_back(std::move(copy));
    }
    added += poses.size();
    notes.push_back("moving part '" + p.name + "': planned around its swept envelope, " +
                    std::to_string(poses.size()) + " poses " + full_precision(p.motion->from) + ".." +
                    full_precision(p.motion->to) + " " + p.motion->pose_unit(units) + ", at most " +
                    full_precision(gap) + " apart in point travel");
  }
  return added;
}

void extend_by_swept_envelopes(const std::vector<Part>& parts, double max_gap, AABB& box) {
  for (const Part& p : parts) {
    if (!p.motion) continue;
    double gap = 0.0;
    for (double q : pose_samples(*p.motion, p.mesh, max_gap, &gap)) {
      const AABB b = posed_mesh(p.mesh, *p.motion, q).bounds();
      box.extend(b.min - Vec3::Constant(0.5 * gap));
      box.extend(b.max + Vec3::Constant(0.5 * gap));
    }
  }
}

}  // namespace loom
