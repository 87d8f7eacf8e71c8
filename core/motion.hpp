#pragma once
/// Motion of a moving part (a flap actuator, a gear door, a hinge): a rigid rotation about
/// a fixed axis or a translation along a fixed direction, over a range of its pose
/// parameter. The part's mesh is its rest pose (pose parameter 0, as drawn); pose q moves
/// it by pose(q). Angles are in degrees, offsets and coordinates in scene units, world frame.

#include "core/geometry.hpp"
#include "core/mesh.hpp"

#include <string>
#include <vector>

namespace loom {

/// Kind of rigid motion.
enum class MotionKind {
  Rotate,     ///< about the line through axis_point along axis; pose in degrees
  Translate,  ///< along direction; pose in scene units
};

/// "rotate" | "translate".
const char* motion_kind_name(MotionKind k);

/// Largest |angle| a rotation's range may reach, degrees (one full turn either way).
constexpr double kMaxMotionDegrees = 360.0;

/// One rigid motion of one or more parts over the pose range [from, to].
struct Motion {
  std::string name;                 ///< the [[motion]] name, or empty for a part's own
  MotionKind kind = MotionKind::Rotate;
  Vec3 axis_point = Vec3::Zero();   ///< rotate: a point on the axis (world frame)
  Vec3 axis = Vec3::UnitZ();        ///< rotate: unit axis; translate: unit direction
  double from = 0.0;                ///< first pose: degrees (rotate) or scene units (translate)
  double to = 0.0;                  ///< last pose, ≥ from

  /// The rigid transform taking the rest pose to pose q (world frame).
  Eigen::Isometry3d pose(double q) const;
  /// Largest distance any point of `m` moves per unit of pose (scene units per degree, or 1
  /// for a translation): the Lipschitz constant of every distance to the moving mesh over
  /// the pose. Rotation: the largest vertex distance from the axis × π/180 (the distance
  /// from a line is convex, so the largest over the hull is at a vertex).
  double max_point_speed(const Mesh& m) const;
  /// "deg" for a rotation, else the scene's unit name `units`.
  std::string pose_unit(const std::string& units) const;
};

/// Throws InputError (file, part) unless the motion is usable: finite values, a non-zero
/// axis (normalised in place), from ≤ to and, for a rotation, |from|, |to| ≤ kMaxMotionDegrees.
/// `where` names the element for the message ("part 'arm'.motion", "motion 'flap'").
void validate_motion(Motion& m, const std::string& file, int line, const std::string& where);

/// The mesh moved to pose q (a copy; world frame).
Mesh posed_mesh(const Mesh& m, const Motion& motion, double q);

/// Poses from..to (both included), evenly spaced so that no point of `m` moves more than
/// `max_gap` between two consecutive ones (one pose when from == to). At most 4096 poses:
/// `gap`, if given, receives the largest point travel between two of them actually reached.
std::vector<double> pose_samples(const Motion& motion, const Mesh& m, double max_gap, double* gap = nullptr);

}  // namespace loom
