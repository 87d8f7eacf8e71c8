#pragma once
/// Sweeping a sphere along a centerline: tubes (constant r) and canal surfaces (variable
/// r(s)) with a rotation-minimising frame (seed: cable-scan-centerline-and-sphere-sweep §4).

#include "core/centerline.hpp"
#include "core/mesh.hpp"

#include <functional>

namespace loom {

/// Resolution of a swept surface, derived from a chord tolerance.
struct SweepOptions {
  double chord_tolerance = 0.01;  ///< max distance between the mesh and the true surface, scene units
  bool end_caps = true;           ///< close both ends (watertight)
};

/// What sweeping produced and the resolution it chose.
struct SweepResult {
  Mesh mesh;
  int circumferential = 0;  ///< vertices per ring
  int rings = 0;            ///< rings along the curve
  double max_frame_turn = 0.0;  ///< largest angle between adjacent frames (radians)
};

/// Tube of constant radius r around the centerline.
SweepResult sweep_tube(const Centerline& c, double radius, const SweepOptions& opt = {});
/// Canal surface of radius r(s), s = arc length from the start.
SweepResult sweep_canal(const Centerline& c, const std::function<double(double)>& radius_of_s,
                        const SweepOptions& opt = {});

}  // namespace loom
