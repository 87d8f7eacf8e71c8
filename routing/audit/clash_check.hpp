#pragma once
/// Clash checking of cables against structure, each other and themselves (DESIGN §4–§6;
/// seed: cable-interference-discrete-point-distance).
///
/// Two methods:
///  * Discrete — the paper, faithfully: each centerline is sampled at its diameter l = 2r
///    (l = r₁ + r₂ for two cables of equal radius); a sample inside a closed part or closer
///    than r to a face is a cable–structure clash; two cables clash when their minimum
///    pairwise sample distance is below r₁ + r₂; a cable interferes with itself when two
///    non-adjacent samples are closer than 2r, or a sample is closer than 2r to the
///    midpoint of two other adjacent samples. With an index the queries go through it (and
///    sample pairs through a uniform grid); without (`use_index = false`) every sample is
///    compared with every triangle and every other sample — the O(n·m) baseline. Both give
///    the same answers. Obstacles passing between samples are missed.
///  * Certified — exact up to `tolerance`: distance is 1-Lipschitz along arc length, so the
///    stretch between samples h apart with distances dₐ, d_b is proven clear when
///    (dₐ + d_b − h)/2 ≥ r + band; free space is crossed in steps of 2(d − r − band)
///    (sphere tracing, each query bounded by the Lipschitz upper bound); only stretches that
///    cannot be proven clear are flattened into chords within `chord_error` of the curve
///    and measured with exact segment–mesh distances. Cable–cable and self contacts go
///    through a sweep-and-prune broad phase over B-spline span hulls (convex-hull property)
///    and exact segment–segment distances between chords.
///
/// Coordinates are world frame, scene units; s is arc length from the cable's first port.

#include "core/centerline.hpp"
#include "core/part.hpp"
#include "core/progress.hpp"
#include "index/obstacle_index.hpp"

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace loom {

/// Which algorithm checks the cables.
enum class ClashMethod {
  Certified,  ///< exact to the tolerance (default)
  Discrete,   ///< the seed paper's sampled method
};

/// "certified" | "discrete".
const char* clash_method_name(ClashMethod m);

/// A stretch [s0, s1) of a cable's centerline that runs in one harness segment.
struct CableSegmentRange {
  int segment = -1;  ///< index into Harness::segments
  double s0 = 0.0;   ///< arc length where the cable enters it
  double s1 = 0.0;   ///< arc length where the cable leaves it
};

/// A harness node (port or branch point) on a cable's route, around which cables that
/// share it are allowed to touch (they leave or join a bundle there).
struct CableJunction {
  std::string node;     ///< node id (shared ids identify the same junction)
  Vec3 position = Vec3::Zero();
  double radius = 0.0;  ///< contacts with both points within this distance of the node are excused
  /// The cable passes through the node between two of its segments (not one of its ends):
  /// its own contacts within `radius` of it are its turn there, judged as a bend (NodeTurn).
  bool passes = false;
};

/// Where a cable passes a node between two harness segments, at any node degree. The
/// wires splay inside the node's breakout, so the direction change between the segments is
/// not a kink of one cable; it is a bend that the breakout takes up: the tightest arc
/// tangent to both directions within `reach` of the node has radius reach / tan(turn / 2).
/// A turn of up to 90° always fits (the breakout is at least the largest bend radius); a
/// fold back through the node does not, and is reported as a bend, not a self clash.
struct NodeTurn {
  std::string node;         ///< node id
  double s = 0.0;           ///< arc length of the node along the cable, scene units
  Vec3 point = Vec3::Zero();  ///< the node's position on the centerline
  double turn = 0.0;        ///< angle between the arriving and the leaving tangent, radians
  double radius = 0.0;      ///< reach / tan(turn / 2), scene units (infinity for no turn)
};

/// A part a cable end is attached to: the connector (or the box it is mounted on) that its
/// port sits on. Contacts and clearance shortfalls with that part over the port's straight
/// exit are the connector's own, not findings. The centerline inside the part is excused
/// only where the port itself lies inside it, deeper than the audit tolerance (a connector
/// modelled solid, which the exit leaves; holds_port): a port on a face whose exit runs
/// into the part goes through it, a clash.
struct PartAttachment {
  int part = -1;         ///< index into the checked parts
  double s_begin = 0.0;  ///< arc-length range of the cable over which the part is excused
  double s_end = 0.0;
  std::string port;      ///< the port id, for the report
  double port_depth = 0.0;  ///< how deep the port lies inside the (closed) part; 0 outside or on it
};

/// True if the attachment's part holds its port: deeper inside it than `tolerance` (scene
/// units), so that a port on a face, up to rounding and the tolerance, is on the face.
inline bool holds_port(const PartAttachment& a, double tolerance) { return a.port_depth > tolerance; }

/// One cable as the checker sees it.
struct CableInput {
  std::string id;
  Centerline curve;              ///< from its first port to its second
  double radius = 0.0;           ///< r = diameter / 2, scene units
  double min_bend_radius = 0.0;  ///< smallest allowed 1/κ (0 = unchecked)
  std::vector<CableSegmentRange> segments;  ///< the harness segments it runs through, in order
  std::vector<CableJunction> junctions;     ///< nodes on its route (for junction excuses)
  /// Pieces over which bends are judged: (arc length where the piece starts, its curve).
  /// Empty: the whole `curve`. Where two harness segments meet at a node the wires splay
  /// inside the breakout, so the direction change there is judged as a NodeTurn instead.
  /// Each is `curve` over [start, start + its length]; cables whose pieces are equal (one
  /// harness segment's curve) are checked together at the bundle level (ClashRequest).
  std::vector<std::pair<double, Centerline>> bend_pieces;
  /// The direction changes between bend pieces, one per node the cable passes (NodeTurn).
  std::vector<NodeTurn> node_turns;
  /// Parts its ports sit on (never keep-out parts): not checked against over the ranges given.
  std::vector<PartAttachment> attachments;
};

/// Work the cable–cable and self passes may take on before it refuses the audit
/// (CableLimitError naming a cable, exit 2) instead of running for hours or out of memory. Routed
/// harnesses stay far below them (the bench's 10× scene, 1,000 cables: 6·10⁴ overlapping
/// block pairs and at most 1.6·10⁴ contacts); a route that folds back on itself or over
/// another cable thousands of times reaches them (2,000 zigzags of a 50 mm route on the
/// wing harness ran out of 24 GB before them, and is refused in 0.7 s with them).
struct ClashLimits {
  /// Most overlapping pairs of chord-block boxes (8 chords each) the broad phase may have
  /// to enumerate, estimated before it runs from a fixed-seed sample of the blocks (the
  /// enumeration itself cannot be stopped).
  std::size_t max_block_overlaps = 50'000'000;
  /// Most block pairs kept for the narrow phase (64 exact segment distances each).
  std::size_t max_block_pairs = 5'000'000;
  /// Most chord (certified) or sample (discrete, also without an index) pairs in contact
  /// kept for grouping into stretches (~112 bytes each).
  std::size_t max_pair_contacts = 4'000'000;
  /// Discrete method with an index: most sample pairs its grid may hand to the distance
  /// test (a few ns each): bounded from below by each cable's length and spacing before any
  /// sample is taken, then counted from the grid's occupancy before testing. The
  /// brute-force baseline (no index) compares every pair by design and is not limited.
  std::size_t max_sample_pairs = 4'000'000'000;
};

/// Everything the checker needs to know. Tolerances are named, documented and derived
/// from the cables when left at 0 (DESIGN §7).
struct ClashRequest {
  ClashMethod method = ClashMethod::Certified;
  /// false: the brute-force discrete baseline (every sample against every triangle).
  bool use_index = true;
  /// Certified accuracy: no clash deeper than −tolerance is missed, none shallower than
  /// +tolerance reported (also applies to clearances). ≤ 0: smallest cable radius / 100.
  double tolerance = 0.0;
  /// Discrete sample spacing; ≤ 0: the paper's rule (the cable diameter 2r).
  double spacing = 0.0;
  /// Required gap between cable surface and every part ([routing] clearance); each part
  /// adds its own Part::clearance.
  double routing_clearance = 0.0;
  /// Longest sphere-tracing step (bounds the query radius). ≤ 0: 50 · cable radius.
  double max_step = 0.0;
  /// Certified: a sample's closest-point query stops at the distance its decisions need
  /// (far from every surface that saves the BVH leaves around the nearest one; the value is
  /// found later only if a decision or the cable's smallest sampled clearance needs it).
  /// The report is the same either way; false queries every sample to its full radius (the
  /// reference the tests compare with).
  bool cut_short_queries = true;
  /// Certified: relative error ε allowed in the sphere trace's free-space distance queries
  /// (ObstacleIndex::closest_approx). Those samples only need a lower bound on the distance,
  /// and D / (1 + ε) is one; it costs steps (1 + ε) shorter at most but spares the BVH
  /// leaves around the nearest surface, whose number grows with the tessellation. Chords
  /// near contact take the same (1 + ε) distance first and are measured exactly only where
  /// [D / (1 + ε), D] leaves a decision open or the chord can be the deepest point of its
  /// stretch. Where a short stretch's bounds fall short of a proof, its samples are asked
  /// again at ε/8 rather than exactly. Contact decisions, reported distances and the
  /// smallest clearance stay exact to the tolerance;
  /// sample positions, and so the last digits of a report, depend on ε. 0 = exact queries
  /// (then cut_short_queries changes nothing in the report). Must be finite and ≥ 0.
  double distance_rel_error = 0.25;
  /// Certified: check every cable on its own (the reference), not at the bundle level.
  /// The bundle level (false) takes the pieces several cables share (their bend pieces:
  /// harness segments) once for all of them — structure proofs as a tube of the largest
  /// radius, one chord set, bends once per curve — and works per cable only where a piece
  /// cannot decide: near a part, where cables part at a node or meet another piece. Its
  /// findings are this reference's within the tolerance; a harness whose cables share no
  /// piece is checked per cable either way.
  bool per_cable = false;
  /// Work limits of the cable–cable and self passes (see ClashLimits).
  ClashLimits limits;
  /// Worker threads (≤ 0: all cores).
  int threads = 0;
  bool check_structure = true;    ///< cable–structure clashes and clearance violations
  bool check_cable_cable = true;  ///< clashes between different cables
  bool check_self = true;         ///< self-interference
  bool check_bend = true;         ///< bend-radius violations
  /// Stage "audit": cables checked (done = total once the cable pairs are checked too);
  /// called one at a time, from worker threads. May be empty.
  ProgressFn progress;
};

/// What kind of clash.
enum class ClashKind { CableStructure, CableCable, Self };
/// "cable-structure" | "cable-cable" | "self".
const char* clash_kind_name(ClashKind k);

/// One contiguous stretch of a centerline in contact with one obstacle, at its deepest point.
struct ClashEntry {
  ClashKind kind = ClashKind::CableStructure;
  int cable = -1;      ///< index into the cable list
  int part = -1;       ///< cable-structure: index into the part list
  int other = -1;      ///< cable-cable: the other cable (self: == cable)
  double clearance = 0.0;  ///< < 0: surface distance minus radii (−r when the axis is inside a closed part)
  Vec3 point = Vec3::Zero();  ///< deepest point: on the centerline (structure), midway between axes (cables)
  double s = 0.0;          ///< arc length of the deepest point on `cable`
  double s_other = 0.0;    ///< arc length on `other` (cable-cable, self)
  double s_begin = 0.0;    ///< start of the stretch on `cable` (to one chord, ≤ 2r)
  double s_end = 0.0;      ///< end of the stretch on `cable` (to one chord, ≤ 2r)
  bool keep_out = false;   ///< the part is a keep-out zone
  bool inside = false;     ///< the centerline runs inside the (closed) part here
};

/// What kind of violation.
enum class ViolationKind { BendRadius, Clearance };
/// "bend-radius" | "clearance".
const char* violation_kind_name(ViolationKind k);

/// A bend tighter than allowed, or a stretch closer to a part than required.
struct Violation {
  ViolationKind kind = ViolationKind::Clearance;
  int cable = -1;
  int part = -1;           ///< clearance: index into the part list
  double value = 0.0;      ///< bend: radius 1/κ; clearance: the smallest clearance (≥ 0)
  double limit = 0.0;      ///< bend: min_bend_radius; clearance: required
  double s = 0.0;          ///< arc length where it is worst
  Vec3 point = Vec3::Zero();  ///< centerline point there
  double s_begin = 0.0;    ///< clearance: start of the band stretch (to one chord, ≤ 2r); bend: s
  double s_end = 0.0;      ///< clearance: end of the band stretch (to one chord, ≤ 2r); bend: s
};

/// Per-cable summary.
struct CableCheckSummary {
  double length = 0.0;          ///< arc length of the centerline
  /// Smallest clearance to any part found; exact (to tolerance) when `min_clearance_exact`,
  /// otherwise the smallest sampled value — an upper bound, the true value being ≥ the
  /// band the audit watches (required clearance). Infinity when no part was seen at all.
  double min_clearance = 0.0;
  bool min_clearance_exact = false;
  double min_bend_radius = 0.0;  ///< smallest 1/κ (infinity for a straight cable)
  double min_bend_s = 0.0;       ///< where
};

/// Work done.
struct ClashCounters {
  std::int64_t distance_queries = 0;  ///< point and segment distance queries against structure
  std::int64_t inside_queries = 0;    ///< point-in-part tests
  std::int64_t pair_tests = 0;        ///< exact segment–segment (or sample–sample) distances
  std::int64_t samples = 0;           ///< centerline points evaluated
  /// Certified, approximate queries: chords whose distance was first known within (1 + ε)
  /// only, and how many of them were then measured exactly (the rest could not be the
  /// deepest point of their stretch). Not in report.json.
  std::int64_t deferred_chords = 0;
  std::int64_t deferred_measured = 0;
  /// Certified cable–cable and self pass, against ClashLimits: the estimated overlapping
  /// chord-block pairs, the block pairs kept for the narrow phase, the chord pairs in
  /// contact. Not in report.json.
  std::int64_t block_overlaps_estimate = 0;
  std::int64_t block_pairs = 0;
  std::int64_t pair_contacts = 0;
};

/// The outcome of check_clashes().
struct ClashResult {
  std::vector<ClashEntry> clashes;       ///< sorted by cable, then s
  std::vector<Violation> violations;     ///< sorted by cable, then s
  std::vector<CableCheckSummary> cables; ///< one per input cable
  ClashCounters counters;
  double tolerance = 0.0;          ///< the certified accuracy used (discrete: 0 = not certified)
  std::string tolerance_source;    ///< "request" or the derivation rule
  double chord_error = 0.0;        ///< max distance between the measured chords and the curve
  double distance_rel_error = 0.0; ///< certified: ε of the free-space and first chord queries (ClashRequest)
  double spacing = 0.0;            ///< discrete: sample spacing used (0 = per cable 2r)
  bool bundle_level = false;       ///< certified: checked at the bundle level (ClashRequest::per_cable)
  std::vector<std::string> notes;  ///< what the user should know (open parts, …)
};

/// Checks every cable against the parts, each other and itself. `index` indexes exactly
/// `parts` (same order); it may be null only when use_index is false. Throws
/// std::invalid_argument for a cable without a curve or a non-positive radius, and
/// CableLimitError (routing/curve/cable_limit.hpp) naming a cable whose audit would pass a
/// limit: more than kMaxCertifiedChords chords, more samples or sample pairs than the
/// discrete method takes, or the ClashLimits.
ClashResult check_clashes(const std::vector<CableInput>& cables, const std::vector<Part>& parts,
                          const ObstacleIndex* index, const ClashRequest& request);

/// Most chords the certified audit flattens one cable into. A routed cable (bends of at
/// least a few radii) needs a few thousand at the default tolerance, a 100 m cable at a 1 µm
/// tolerance ~10⁶; beyond this the route wiggles on the scale of the tolerance (200,000 key
/// points 1 µm apart), is thousands of kilometres long, or the cable is far thinner than the
/// scene's scale, and flattening it would not end: check_clashes refuses it before any chord
/// is made (CableLimitError).
constexpr double kMaxCertifiedChords = 1e7;

/// Fewest chords the certified audit needs for a centerline `length` long of radius
/// `radius` (scene units): its chords are at most 2r long. A cable whose ports are farther
/// apart than kMaxCertifiedChords of them cannot be audited, whatever its route.
double fewest_certified_chords(double length, double radius);

/// The derived default tolerance: smallest cable radius / 100 (and its rule as text).
double default_clash_tolerance(const std::vector<CableInput>& cables, std::string* source = nullptr);

}  // namespace loom
