// Shard reports of a sharded audit: global part ids, the merge, and the wire format.
#include "routing/audit/audit_shard.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <limits>
#include <set>
#include <stdexcept>
#include <tuple>

namespace loom {

namespace {

int global_id(int local, const std::vector<int>& ids) {
  return local < 0 ? local : ids.at(static_cast<std::size_t>(local));
}

/// Appends the notes of `from` not yet in `to`, in their order (every shard says the
/// harness's notes; each part's are its owner's).
void merge_notes(std::vector<std::string>& to, const std::vector<std::string>& from) {
  std::set<std::string> seen(to.begin(), to.end());
  for (const std::string& n : from)
    if (seen.insert(n).second) to.push_back(n);
}

/// The order check_clashes gives: by cable, then s (ties, which one process leaves in
/// its own order, by kind and obstacle so that the merge is deterministic).
bool clash_before(const ClashEntry& a, const ClashEntry& b) {
  return std::tie(a.cable, a.s, a.kind, a.part, a.other) < std::tie(b.cable, b.s, b.kind, b.part, b.other);
}
bool violation_before(const Violation& a, const Violation& b) {
  return std::tie(a.cable, a.s, a.kind, a.part) < std::tie(b.cable, b.s, b.kind, b.part);
}

/// A cable's smallest clearance over two shards: the smaller value, exact if either shard's
/// equal value is.
void merge_summary(CableCheckSummary& to, const CableCheckSummary& from) {
  if (from.min_clearance < to.min_clearance) {
    to.min_clearance = from.min_clearance;
    to.min_clearance_exact = from.min_clearance_exact;
  } else if (from.min_clearance == to.min_clearance) {
    to.min_clearance_exact = to.min_clearance_exact || from.min_clearance_exact;
  }
}

/// A clamp holds on the nearest structure any shard found within its reach (ties, which
/// one index breaks by its own traversal, by the lower part id).
void merge_clamp(ClampLoad& to, const ClampLoad& from) {
  if (from.part < 0) return;
  if (to.part < 0 || from.distance < to.distance || (from.distance == to.distance && from.part < to.part)) {
    to.part = from.part;
    to.distance = from.distance;
  }
}

void add_counters(ClashCounters& to, const ClashCounters& from) {
  to.distance_queries += from.distance_queries;
  to.inside_queries += from.inside_queries;
  to.pair_tests += from.pair_tests;
  to.samples += from.samples;
  to.deferred_chords += from.deferred_chords;
  to.deferred_measured += from.deferred_measured;
  to.block_overlaps_estimate += from.block_overlaps_estimate;
  to.block_pairs += from.block_pairs;
  to.pair_contacts += from.pair_contacts;
}

}  // namespace

void globalise_part_ids(AuditReport& rep, const std::vector<int>& ids) {
  for (ClashEntry& e : rep.result.clashes)
    if (e.kind == ClashKind::CableStructure) e.part = global_id(e.part, ids);
  for (Violation& v : rep.result.violations)
    if (v.kind == ViolationKind::Clearance) v.part = global_id(v.part, ids);
  for (ClampLoad& c : rep.supports.clamps) c.part = global_id(c.part, ids);
  for (MotionClash& m : rep.motion.clashes) m.part = global_id(m.part, ids);
  for (ScannedPartBound& b : rep.scanned_parts) b.part = global_id(b.part, ids);
}

AuditReport merge_audit_shards(std::vector<AuditReport> shards, const std::vector<ShardPart>& parts, const Harness& h,
                               const RoutingSettings& routing) {
  if (shards.empty()) throw std::invalid_argument("merge_audit_shards: no shard");
  AuditReport out = std::move(shards.front());
  out.part_names.clear();
  out.part_keep_out.clear();
  out.triangles = 0;
  for (const ShardPart& p : parts) {
    out.part_names.push_back(p.name);
    out.part_keep_out.push_back(p.keep_out);
    out.triangles += p.triangles;
  }
  ClashResult& r = out.result;
  for (std::size_t k = 1; k < shards.size(); ++k) {
    const AuditReport& s = shards[k];
    if (s.result.cables.size() != r.cables.size())
      throw std::invalid_argument("merge_audit_shards: shard " + std::to_string(k) + " checked " +
                                  std::to_string(s.result.cables.size()) + " cables, the first " +
                                  std::to_string(r.cables.size()));
    r.clashes.insert(r.clashes.end(), s.result.clashes.begin(), s.result.clashes.end());
    r.violations.insert(r.violations.end(), s.result.violations.begin(), s.result.violations.end());
    for (std::size_t c = 0; c < r.cables.size(); ++c) merge_summary(r.cables[c], s.result.cables[c]);
    add_counters(r.counters, s.result.counters);
    merge_notes(r.notes, s.result.notes);
    merge_notes(out.notes, s.notes);
    out.scanned_parts.insert(out.scanned_parts.end(), s.scanned_parts.begin(), s.scanned_parts.end());
    for (std::size_t c = 0; c < out.supports.clamps.size() && c < s.supports.clamps.size(); ++c)
      merge_clamp(out.supports.clamps[c], s.supports.clamps[c]);
    out.motion.clashes.insert(out.motion.clashes.end(), s.motion.clashes.begin(), s.motion.clashes.end());
    out.motion.poses += s.motion.poses;
    out.motion.distance_queries += s.motion.distance_queries;
    merge_notes(out.motion.notes, s.motion.notes);
    out.load_ms = std::max(out.load_ms, s.load_ms);
    out.index_ms = std::max(out.index_ms, s.index_ms);
    out.check_ms = std::max(out.check_ms, s.check_ms);
  }
  std::sort(r.clashes.begin(), r.clashes.end(), clash_before);
  std::sort(r.violations.begin(), r.violations.end(), violation_before);
  std::sort(out.scanned_parts.begin(), out.scanned_parts.end(),
            [](const ScannedPartBound& a, const ScannedPartBound& b) { return a.part < b.part; });
  std::sort(out.motion.clashes.begin(), out.motion.clashes.end(), [](const MotionClash& a, const MotionClash& b) {
    return std::tie(a.cable, a.part) < std::tie(b.cable, b.part);
  });
  if (out.supports_checked)
    out.supports.spans = unsupported_spans(h, out.supports.clamps, routing.clamp_spacing.value);
  return out;
}

// ---- wire format ----------------------------------------------------------------------

namespace {

using nlohmann::json;

json vec(const Vec3& v) { return json::array({v.x(), v.y(), v.z()}); }
Vec3 vec(const json& j) { return {j.at(0).get<double>(), j.at(1).get<double>(), j.at(2).get<double>()}; }

json to_wire(const ClashEntry& e) {
  return json::array({static_cast<int>(e.kind), e.cable, e.part, e.other, e.clearance, vec(e.point), e.s, e.s_other,
                      e.s_begin, e.s_end, e.keep_out, e.inside});
}
void from_wire(const json& j, ClashEntry& e) {
  e.kind = static_cast<ClashKind>(j.at(0).get<int>());
  e.cable = j.at(1), e.part = j.at(2), e.other = j.at(3), e.clearance = j.at(4), e.point = vec(j.at(5));
  e.s = j.at(6), e.s_other = j.at(7), e.s_begin = j.at(8), e.s_end = j.at(9), e.keep_out = j.at(10);
  e.inside = j.at(11);
}
json to_wire(const Violation& v) {
  return json::array({static_cast<int>(v.kind), v.cable, v.part, v.value, v.limit, v.s, vec(v.point), v.s_begin,
                      v.s_end});
}
void from_wire(const json& j, Violation& v) {
  v.kind = static_cast<ViolationKind>(j.at(0).get<int>());
  v.cable = j.at(1), v.part = j.at(2), v.value = j.at(3), v.limit = j.at(4), v.s = j.at(5), v.point = vec(j.at(6));
  v.s_begin = j.at(7), v.s_end = j.at(8);
}
json to_wire(const CableCheckSummary& c) {
  return json::array({c.length, c.min_clearance, c.min_clearance_exact, c.min_bend_radius, c.min_bend_s});
}
void from_wire(const json& j, CableCheckSummary& c) {
  c.length = j.at(0), c.min_clearance = j.at(1), c.min_clearance_exact = j.at(2), c.min_bend_radius = j.at(3);
  c.min_bend_s = j.at(4);
}
json to_wire(const ClashCounters& c) {
  return json::array({c.distance_queries, c.inside_queries, c.pair_tests, c.samples, c.deferred_chords,
                      c.deferred_measured, c.block_overlaps_estimate, c.block_pairs, c.pair_contacts});
}
void from_wire(const json& j, ClashCounters& c) {
  c.distance_queries = j.at(0), c.inside_queries = j.at(1), c.pair_tests = j.at(2), c.samples = j.at(3);
  c.deferred_chords = j.at(4), c.deferred_measured = j.at(5), c.block_overlaps_estimate = j.at(6);
  c.block_pairs = j.at(7), c.pair_contacts = j.at(8);
}
json to_wire(const ClampLoad& c) {
  return json::array({c.id, vec(c.point), c.segment, c.part, c.distance, c.bundle_diameter, c.placed, c.segment_s});
}
void from_wire(const json& j, ClampLoad& c) {
  c.id = j.at(0), c.point = vec(j.at(1)), c.segment = j.at(2), c.part = j.at(3), c.distance = j.at(4);
  c.bundle_diameter = j.at(5), c.placed = j.at(6), c.segment_s = j.at(7);
}
json to_wire(const MotionClash& m) {
  return json::array({m.cable, m.part, m.clearance, m.pose, vec(m.point), m.s, m.inside, static_cast<int>(m.motion)});
}
void from_wire(const json& j, MotionClash& m) {
  m.cable = j.at(0), m.part = j.at(1), m.clearance = j.at(2), m.pose = j.at(3), m.point = vec(j.at(4));
  m.s = j.at(5), m.inside = j.at(6), m.motion = static_cast<MotionKind>(j.at(7).get<int>());
}
json to_wire(const ScannedPartBound& b) { return json::array({b.part, b.voxel_edge, b.accuracy, b.unknown_occupied}); }
void from_wire(const json& j, ScannedPartBound& b) {
  b.part = j.at(0), b.voxel_edge = j.at(1), b.accuracy = j.at(2), b.unknown_occupied = j.at(3);
}

template <class T>
json list(const std::vector<T>& xs) {
  json a = json::array();
  for (const T& x : xs) a.push_back(to_wire(x));
  return a;
}
template <class T>
void unlist(const json& a, std::vector<T>& xs) {
  xs.clear();
  for (const json& j : a) from_wire(j, xs.emplace_back());
}

/// Tells a shard report from other bytes (and from one of another layout).
constexpr const char* kWireFormat = "loom-audit-shard-1";

}  // namespace

std::vector<std::uint8_t> shard_report_bytes(const AuditReport& rep) {
  const ClashResult& r = rep.result;
  json j;
  j["format"] = kWireFormat;
  j["clashes"] = list(r.clashes);
  j["violations"] = list(r.violations);
  j["cables"] = list(r.cables);
  j["counters"] = to_wire(r.counters);
  j["result_notes"] = r.notes;
  j["notes"] = rep.notes;
  j["scanned"] = list(rep.scanned_parts);
  j["clamps"] = list(rep.supports.clamps);
  j["supports_checked"] = rep.supports_checked;
  j["motion"] = list(rep.motion.clashes);
  j["motion_counts"] = json::array({rep.motion.poses, rep.motion.distance_queries});
  j["motion_notes"] = rep.motion.notes;
  j["ms"] = json::array({rep.load_ms, rep.index_ms, rep.check_ms});
  j["triangles"] = rep.triangles;
  return json::to_cbor(j);
}

AuditReport shard_report_from_bytes(const std::vector<std::uint8_t>& bytes) {
  AuditReport rep;
  try {
    const json j = json::from_cbor(bytes);
    if (j.at("format") != kWireFormat) throw std::runtime_error("format " + j.at("format").dump());
    ClashResult& r = rep.result;
    unlist(j.at("clashes"), r.clashes);
    unlist(j.at("violations"), r.violations);
    unlist(j.at("cables"), r.cables);
    from_wire(j.at("counters"), r.counters);
    r.notes = j.at("result_notes").get<std::vector<std::string>>();
    rep.notes = j.at("notes").get<std::vector<std::string>>();
    unlist(j.at("scanned"), rep.scanned_parts);
    unlist(j.at("clamps"), rep.supports.clamps);
    rep.supports_checked = j.at("supports_checked");
    unlist(j.at("motion"), rep.motion.clashes);
    rep.motion.poses = j.at("motion_counts").at(0), rep.motion.distance_queries = j.at("motion_counts").at(1);
    rep.motion.notes = j.at("motion_notes").get<std::vector<std::string>>();
    rep.load_ms = j.at("ms").at(0), rep.index_ms = j.at("ms").at(1), rep.check_ms = j.at("ms").at(2);
    rep.triangles = j.at("triangles");
  } catch (const std::exception& e) {
    throw std::runtime_error(std::string("not a loom audit shard report: ") + e.what());
  }
  return rep;
}

}  // namespace loom
