#pragma once
/// Clearance of cables to moving parts over the parts' whole motion (DESIGN §5: "moving
/// parts: clearance is the minimum over the whole motion"). The cables are static; each
/// moving part sweeps its range of poses (core/motion.hpp). For a cable and a part,
/// f(q) = distance from the cable's centerline to the part at pose q is L-Lipschitz in q,
/// L = the motion's largest point speed over the part (Motion::max_point_speed): between
/// two poses a, b the minimum is at least (f(a) + f(b) − L·|b − a|)/2. A branch and bound
/// over the pose range (Piyavskii) splits the interval with the lowest bound until every
/// bound is within `pose tolerance` of the best sampled value or above the cable radius;
/// each f(q) is exact: the centerline flattened into chords within `chord error`
/// (chord_plan.hpp) and moved into the part's rest frame, FCL segment–mesh distances
/// (FclIndex), 0 inside a closed part. pose tolerance + chord error = the audit tolerance,
/// so a cable–motion clash deeper than −tolerance is never missed and none shallower than
/// +tolerance is reported. World frame, scene units; poses in degrees or scene units.

#include "routing/audit/chord_plan.hpp"
#include "routing/audit/clash_check.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace loom {

class FclIndex;

/// A cable closer to a moving part than its radius at some pose: the worst pose.
struct MotionClash {
  int cable = -1;             ///< index into the checked cables
  int part = -1;              ///< index into the scene's parts
  double clearance = 0.0;     ///< < 0: least surface distance − r over the motion (−r: axis inside the part)
  double pose = 0.0;          ///< where it is least: degrees (rotate) or scene units (translate)
  Vec3 point = Vec3::Zero();  ///< the centerline point closest to the part at that pose
  double s = 0.0;             ///< arc length of `point` from the cable's first port
  bool inside = false;        ///< the centerline runs inside the (closed) part at that pose
  MotionKind motion = MotionKind::Rotate;  ///< how the part moves (the unit of `pose`)
};

/// The least distance from a polyline to one moving part over its motion.
struct MotionExtremum {
  double distance = 0.0;  ///< least centerline distance found (capped: see motion_min_distance)
  double pose = 0.0;      ///< pose where it was found
  std::size_t chord = 0;  ///< chord of the polyline closest there
  double t = 0.0;         ///< parameter on that chord, 0..1
  bool inside = false;    ///< the polyline lies inside the part there
  std::int64_t poses = 0;    ///< poses evaluated
  std::int64_t queries = 0;  ///< segment–mesh distance queries
};

/// Least distance over the poses of `motion` between the chords `ch` (world frame, static)
/// and part `part` of `fcl` (indexed in its rest pose), to within `pose_tol` below the
/// value returned, or proof that it is at least `cutoff` (then `distance` ≥ cutoff − pose_tol
/// and may be any value there). `closed`: the part has an inside (distance 0 there).
/// `speed` = motion.max_point_speed of the part's mesh. Chords whose distance to the part's
/// swept hull exceeds `cutoff` are skipped; the caller passes them all.
MotionExtremum motion_min_distance(const Chords& ch, const FclIndex& fcl, int part, bool closed, const Motion& motion,
                                   double speed, const Mesh& mesh, double pose_tol, double cutoff);

/// Everything the motion audit found.
struct MotionAudit {
  std::vector<MotionClash> clashes;  ///< sorted by cable, part
  double pose_tolerance = 0.0;       ///< share of the tolerance left to the pose bound
  double chord_error = 0.0;          ///< share left to the chords
  std::int64_t poses = 0;            ///< poses evaluated over all cable–part pairs
  std::int64_t distance_queries = 0;
  std::vector<std::string> notes;
};

/// Checks every cable against every moving part of `parts` over its motion, at `tolerance`
/// (> 0, scene units; ClashResult::tolerance). A part a cable's port sits on
/// (CableInput::attachments) moves the cable with it and is not checked against that cable
/// (said in the notes). `threads` ≤ 0: all cores. No moving part: nothing is done.
MotionAudit check_motion_clearance(const std::vector<CableInput>& cables, const std::vector<Part>& parts,
                                   double tolerance, int threads);

/// Names of moving parts whose surfaces cross, or one of which holds a vertex of the other,
/// in their rest poses ("'a' and 'b'"), one entry per pair: parts that are drawn through each
/// other move through each other, a modelling error worth a warning.
std::vector<std::string> moving_parts_interpenetrating(const std::vector<Part>& parts);

}  // namespace loom
