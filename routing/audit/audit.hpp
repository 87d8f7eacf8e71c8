#pragma once
/// The audit pipeline (DESIGN §4): scene → obstacle index (timed as timing_ms.index) →
/// clash, bend and clearance checks (timed as timing_ms.check) → an AuditReport, which
/// report_json writes as report.json.

#include "core/io/scene_load.hpp"
#include "core/progress.hpp"
#include "core/scene.hpp"
#include "routing/audit/clash_check.hpp"
#include "routing/audit/motion_clearance.hpp"
#include "routing/audit/segregation.hpp"
#include "routing/audit/supports.hpp"
#include "routing/audit/tessellation_need.hpp"
#include "routing/audit/voxel_findings.hpp"

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace loom {

class CadShapeStore;  // core/io/mesh_read.hpp

struct AuditShard;

/// What `loom audit` was asked to do.
struct AuditOptions {
  ClashRequest check;  ///< method, tolerance, spacing, threads, progress, …
  /// A routed harness XML that replaces the scene's harness (nullopt: the scene's own).
  std::optional<std::filesystem::path> routes;
  /// A prebuilt exact index of the scene's parts (e.g. SceneIndices::embree, shared with
  /// planning); null: run_audit builds an EmbreeIndex and times it.
  const ObstacleIndex* index = nullptr;
  /// Stages "load" (audit_scene_file: part files loaded), "index" (when run_audit builds it) and,
  /// unless check.progress is set, "audit" (cables checked). May be empty.
  ProgressFn progress;
  /// One shard of a sharded audit (audit_shard.hpp): the scene holds only the parts the
  /// shard owns, the report's part ids are global, and unsupported spans are left to the
  /// merge. Null: the whole audit.
  const AuditShard* shard = nullptr;
};

/// One cable of the harness as audited.
struct AuditCable {
  std::string id;
  bool routed = false;  ///< false: some segment of its chain has no curve yet (not checked)
  std::string reason;   ///< why it is not routed
  int check_index = -1; ///< index into ClashResult::cables (−1 if not routed)
};

/// Everything report.json says.
struct AuditReport {
  std::string scene;
  std::string units;
  ClashMethod method = ClashMethod::Certified;
  bool use_index = true;
  std::string index_name;        ///< "embree", or "none" for the brute-force baseline
  std::string index_accuracy;    ///< the index's own description of its accuracy
  std::vector<std::string> part_names;
  std::vector<bool> part_keep_out;
  std::vector<ScannedPartBound> scanned_parts;  ///< parts made of voxels, with their bound
  std::vector<AuditCable> cables;       ///< every harness cable, in harness order
  std::vector<std::string> check_ids;   ///< ids of the checked (routed) cables, by check index
  ClashResult result;                   ///< indices refer to check_ids / part_names
  double load_ms = 0.0;
  double index_ms = 0.0;
  double check_ms = 0.0;
  std::size_t triangles = 0;
  std::vector<std::string> notes;
  /// Clamps and unsupported spans; spans are checked only when `supports_checked` (the
  /// scene sets [routing] clamp_spacing), clamps are always listed.
  SupportAudit supports;  ///< span cable indices refer to `cables` (harness order)
  bool supports_checked = false;
  /// Cables of separated classes too close or sharing a bundle (indices refer to check_ids).
  std::vector<SegregationFinding> segregation;
  /// Cables closer to a moving part than their radius at some pose of its motion (cable-motion).
  MotionAudit motion;
  /// Each harness segment as FROM/TO (the spelling of <clamp segment>), by segment index.
  std::vector<std::string> segment_names;
  /// Tessellation by need (audit_scene_file, when the scene asks for it): refined parts
  /// index part_names.
  TessellationByNeed tessellation;

  /// True when any clash or violation was found.
  bool found_problems() const {
    return !result.clashes.empty() || !result.violations.empty() || !supports.spans.empty() ||
           !segregation.empty() || !motion.clashes.empty();
  }
  /// True when some harness cable could not be checked (a segment of its chain has no
  /// curve yet, e.g. an unplaced branch point): see `cables[i].reason`.
  bool any_unchecked() const {
    for (const auto& c : cables)
      if (!c.routed) return true;
    return false;
  }
  /// DESIGN §4 exit status of a completed audit: 0 clean, 1 clashes or violations, 3 some
  /// cable has no route to check (as `route` says of a cable it could not route: an audit
  /// that left cables unchecked is not clean, whatever it found on the others).
  int exit_code() const { return any_unchecked() ? 3 : found_problems() ? 1 : 0; }
};

/// The cables of a harness as the checker sees them (routed ones only): centerlines, radii,
/// the harness segments each runs through and the junctions where bundled cables may touch.
/// `cables` receives one AuditCable per harness cable.
std::vector<CableInput> audit_cable_inputs(const Harness& h, std::vector<AuditCable>& cables);

/// Fills each cable's PartAttachment list: a part (not keep-out) whose surface is within the
/// cable radius + required clearance of one of its ports, or that contains the port, is the
/// connector or box the port sits on, and is excused over the port's straight exit
/// (derived_stub_length: max(min bend radius, 2r), at most half the cable) — except, for a
/// port not inside the part, where the centerline enters it or (past the audit tolerance
/// from the port) touches it. Returns one note per (port, part) pair for the report.
/// Distances through `index` (the audit's, indexing `parts`); null: measured on each
/// candidate part directly.
std::vector<std::string> attach_ports(const Harness& h, const std::vector<Part>& parts, double routing_clearance,
                                      std::vector<CableInput>& inputs, const ObstacleIndex* index = nullptr);

/// Checks that `routes` (read from a --routes file) routes `designed`, the scene's harness:
/// the same cables by id, each joining the same two ports with the same diameter and
/// minimum bend radius (ports and branch points may move: a what-if is a route too). A
/// cable missing from the routes would go unchecked, and one the scene does not have would
/// be checked against the wrong harness: each difference throws InputError naming the
/// routes file, the line and the cable.
void check_routes_match(const Harness& designed, const Harness& routes);

/// apply_routes (the routes file replaces the scene's harness), then check_routes_match
/// against the harness the scene had, if any: what `--routes FILE` does in every command.
void apply_matching_routes(Scene& scene, const std::filesystem::path& routes);

/// Audits a loaded scene (its parts and harness). Builds the index unless the request is
/// the brute-force baseline (use_index = false, discrete). Throws InputError for an
/// inconsistent harness, and for a cable whose audit would pass a limit (check_clashes'
/// CableLimitError), naming the harness file and the cable's line.
AuditReport run_audit(const Scene& scene, const AuditOptions& opt);

/// The scene an audit of `scene_file` checks: load_scene with `load`, then --routes
/// (apply_matching_routes) and the check of a requested tolerance, as audit_scene_file does.
Scene load_audit_scene(const std::filesystem::path& scene_file, const AuditOptions& opt, const SceneLoadOptions& load,
                       SceneLoadReport* report = nullptr);

/// Tessellation by need for an audit of `scene` (loaded with tessellate_by_need): the
/// coarse CAD parts its routed cables come within reach of are meshed at the fine
/// deflection (tessellate_by_need, at the audit's tolerance). Nothing when the scene does
/// not ask for it; without a harness every part stays coarse (nothing is checked).
TessellationByNeed refine_for_audit(Scene& scene, const AuditOptions& opt, CadShapeStore* cad_shapes = nullptr);

/// Loads the scene file (timed as timing_ms.load), applies --routes (apply_matching_routes),
/// and audits it. Throws InputError (exit 2)
/// for bad input, and for a requested certified tolerance that is not below the thinnest
/// cable's radius (it could miss a cable lying on a part's surface). `loaded`, if given, receives the audited scene
/// (parts and the harness actually checked), e.g. to draw it.
AuditReport audit_scene_file(const std::filesystem::path& scene_file, const AuditOptions& opt,
                             Scene* loaded = nullptr);

}  // namespace loom
