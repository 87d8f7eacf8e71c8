#pragma once
/// A sharded audit (DESIGN §4, docs/audit.md "Sharding"): the scene's parts are divided
/// among shards — MPI ranks — each of which loads, indexes and checks only the parts it
/// owns, against every cable. Findings against a part are its owner's alone, so the merge is
/// a union: clashes, clearance violations and motion clashes are concatenated, each cable's
/// smallest clearance is the least over the shards, and each clamp holds on the nearest
/// structure any shard found. One shard (the first, rank 0) also runs the passes that need
/// no part (cable–cable, self, bend, segregation) and owns every moving part, so that pairs
/// of moving parts stay on one shard.

#include "routing/audit/audit.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace loom {

/// What one shard of a sharded audit checks.
struct AuditShard {
  /// Global id (index into the whole scene's parts) of each of the shard scene's parts, in
  /// the shard scene's order.
  std::vector<int> part_ids;
  /// This shard also runs the cable–cable, self, bend and segregation passes (exactly one
  /// shard of a run does: merge_audit_shards takes them from the first).
  bool cable_passes = false;
};

/// A part of the whole scene as every shard knows it (the merged report names parts).
struct ShardPart {
  std::string name;
  bool keep_out = false;
  std::size_t triangles = 0;
};

/// Rewrites the part ids of a shard's report (clashes, violations, clamps, motion clashes,
/// scanned parts) from the shard scene's order to global ids. Throws std::out_of_range for a
/// part id the shard does not have.
void globalise_part_ids(AuditReport& rep, const std::vector<int>& part_ids);

/// Merges shard reports — part ids already global, the cable-pass shard first — into the
/// report of the whole audit: `parts` is the global part list, `h` and `routing` the
/// audited harness and the scene's routing settings (for the unsupported spans, which
/// follow from the merged clamps). Timings are the slowest shard's.
AuditReport merge_audit_shards(std::vector<AuditReport> shards, const std::vector<ShardPart>& parts, const Harness& h,
                               const RoutingSettings& routing);

/// A shard's report as bytes for the wire (CBOR: doubles bit for bit, infinities kept).
/// Segregation findings are not included (only the cable-pass shard has them, and it is
/// the one that merges).
std::vector<std::uint8_t> shard_report_bytes(const AuditReport& rep);

/// The report shard_report_bytes wrote. Throws std::runtime_error for bytes that are not
/// one (a rank of another loom version).
AuditReport shard_report_from_bytes(const std::vector<std::uint8_t>& bytes);

}  // namespace loom
