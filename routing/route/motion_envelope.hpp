#pragma once
/// The swept envelope of moving parts as planning obstacles: each moving part is posed at
/// evenly spaced poses over its motion, close enough that no point of it moves more than
/// `max_gap` between two of them, so that every point of the swept volume lies within
/// max_gap / 2 of some posed copy. A route planned clear of the copies by the routing
/// clearance c, with max_gap ≤ c, keeps at least c / 2 from the part at every pose: no
/// cable-motion clash. The audit that follows is exact (routing/audit/motion_clearance.hpp);
/// this envelope serves planning only. World frame, scene units.

#include "core/part.hpp"

#include <string>
#include <vector>

namespace loom {

/// The largest point travel between two posed copies: the routing clearance, or half the
/// smallest cable diameter when the clearance is 0 (then the copies are a radius apart).
double swept_envelope_gap(double routing_clearance, double smallest_diameter);

/// Appends to `out` one fixed copy of every moving part of `parts` per pose of
/// pose_samples(motion, mesh, max_gap) (named "<part>@<pose><unit>", role and clearance
/// of the part, no motion) and one note per moving part; returns how many were appended.
/// `units` is the scene's unit name (for translations' poses).
std::size_t append_swept_envelopes(const std::vector<Part>& parts, double max_gap, const std::string& units,
                                   std::vector<Part>& out, std::vector<std::string>& notes);

/// Grows `box` to hold every moving part of `parts` at every pose of
/// pose_samples(motion, mesh, max_gap), grown by max_gap / 2 (the planning space must
/// reach around the envelope).
void extend_by_swept_envelopes(const std::vector<Part>& parts, double max_gap, AABB& box);

}  // namespace loom
