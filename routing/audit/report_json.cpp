// report.json of `loom audit` (DESIGN §4).
#include "routing/audit/report_json.hpp"

#include "core/io/atomic_file.hpp"
#include "core/io/json_text.hpp"

#include <cmath>

namespace loom {

namespace {

using nlohmann::json;

json vec_json(const Vec3& v) {
  // Points come from finite geometry; a non-finite coordinate would be a bug upstream, but
  // the report never carries one: clamp to 0 and the caller's note says so.
  return json::array({std::isfinite(v.x()) ? v.x() : 0.0, std::isfinite(v.y()) ? v.y() : 0.0,
                      std::isfinite(v.z()) ? v.z() : 0.0});
}

/// Sets j[key] = v when finite; otherwise leaves it out and sets j[key + "_note"] = why.
void put(json& j, const std::string& key, double v, const std::string& why) {
  if (std::isfinite(v))
    j[key] = v;
  else
    j[key + "_note"] = why;
}

/// report.json "clamps": each clamp with the part it is fixed to (null: no structure within
/// reach), the segment it holds as FROM/TO (null: none) and the bundle's diameter.
json clamps_json(const AuditReport& rep) {
  json out = json::array();
  for (const ClampLoad& c : rep.supports.clamps) {
    json o;
    o["id"] = c.id;
    o["point"] = vec_json(c.point);
    o["part"] = c.part >= 0 ? json(rep.part_names.at(static_cast<std::size_t>(c.part))) : json(nullptr);
    if (c.part >= 0) o["distance"] = c.distance;
    o["segment"] = c.segment >= 0 ? json(rep.segment_names.at(static_cast<std::size_t>(c.segment))) : json(nullptr);
    o["bundle_diameter"] = c.bundle_diameter;
    o["placed"] = c.placed;
    out.push_back(o);
  }
  return out;
}

}  // namespace

json audit_report_json(const AuditReport& rep) {
  const ClashResult& r = rep.result;
  json j;
  j["scene"] = rep.scene;
  j["units"] = rep.units;
  j["method"] = clash_method_name(rep.method);
  if (rep.method == ClashMethod::Certified) {
    put(j, "tolerance", r.tolerance, "tolerance could not be derived");
    j["tolerance_source"] = r.tolerance_source;
    j["chord_error"] = r.chord_error;
    j["free_space_rel_error"] = r.distance_rel_error;
  } else {
    j["tolerance_note"] = "discrete method: sampled, not certified (obstacles between samples can be missed)";
    if (r.spacing > 0.0) j["spacing"] = r.spacing;
    else j["spacing_note"] = "each cable sampled at its diameter 2r (the paper's rule)";
  }
  j["index"] = rep.index_name;
  j["index_accuracy"] = rep.index_accuracy;
  if (!rep.scanned_parts.empty()) {
    json scanned = json::array();
    for (const ScannedPartBound& b : rep.scanned_parts)
      scanned.push_back({{"part", rep.part_names.at(static_cast<std::size_t>(b.part))},
                         {"voxel", b.voxel_edge},
                         {"accuracy", b.accuracy},
                         {"unknown", b.unknown_occupied ? "occupied" : "free"}});
    j["scanned_parts"] = scanned;
  }

  json clashes = json::array();
  for (const ClashEntry& e : r.clashes) {
    json c;
    c["kind"] = clash_kind_name(e.kind);
    c["cable"] = rep.check_ids.at(static_cast<std::size_t>(e.cable));
    if (e.kind == ClashKind::CableStructure) {
      c["part"] = rep.part_names.at(static_cast<std::size_t>(e.part));
      c["keep_out"] = e.keep_out;
      c["inside"] = e.inside;
    } else if (e.kind == ClashKind::CableCable) {
      c["other"] = rep.check_ids.at(static_cast<std::size_t>(e.other));
    }
    put(c, "clearance", e.clearance, "unbounded");
    if (e.kind == ClashKind::CableStructure)
      if (const ScannedPartBound* b = find_scanned_part(rep.scanned_parts, e.part))
        c["voxel"] = voxel_finding_name(e.clearance, 0.0, b->accuracy);
    c["point"] = vec_json(e.point);
    c["s"] = e.s;
    if (e.kind != ClashKind::CableStructure) c["s_other"] = e.s_other;
    c["s_begin"] = e.s_begin;
    c["s_end"] = e.s_end;
    clashes.push_back(c);
  }
  for (const MotionClash& m : rep.motion.clashes) {
    json c;
    c["kind"] = "cable-motion";
    c["cable"] = rep.check_ids.at(static_cast<std::size_t>(m.cable));
    c["part"] = rep.part_names.at(static_cast<std::size_t>(m.part));
    c["clearance"] = m.clearance;
    c["pose"] = m.pose;
    c["pose_unit"] = m.motion == MotionKind::Rotate ? "deg" : rep.units;
    c["motion"] = motion_kind_name(m.motion);
    c["inside"] = m.inside;
    c["point"] = vec_json(m.point);
    c["s"] = m.s;
    clashes.push_back(c);
  }
  j["clashes"] = clashes;
  if (rep.motion.pose_tolerance > 0.0)
    j["motion"] = {{"pose_tolerance", rep.motion.pose_tolerance},
                   {"chord_error", rep.motion.chord_error},
                   {"poses", rep.motion.poses},
                   {"distance_queries", rep.motion.distance_queries}};

  json violations = json::array();
  for (const Violation& v : r.violations) {
    json o;
    o["kind"] = violation_kind_name(v.kind);
    o["cable"] = rep.check_ids.at(static_cast<std::size_t>(v.cable));
    if (v.kind == ViolationKind::BendRadius) {
      o["radius"] = v.value;  // finite: smaller than a finite minimum
      o["min"] = v.limit;
    } else {
      o["part"] = rep.part_names.at(static_cast<std::size_t>(v.part));
      o["clearance"] = v.value;
      o["required"] = v.limit;
      if (const ScannedPartBound* b = find_scanned_part(rep.scanned_parts, v.part))
        o["voxel"] = voxel_finding_name(v.value, v.limit, b->accuracy);
    }
    o["s"] = v.s;
    o["point"] = vec_json(v.point);
    violations.push_back(o);
  }
  for (const UnsupportedSpan& sp : rep.supports.spans) {
    json o;
    o["kind"] = "unsupported-span";
    o["cable"] = rep.cables.at(static_cast<std::size_t>(sp.cable)).id;
    o["from_s"] = sp.from_s;
    o["to_s"] = sp.to_s;
    o["length"] = sp.to_s - sp.from_s;
    o["spacing"] = sp.spacing;
    o["point"] = vec_json(sp.point);
    violations.push_back(o);
  }
  for (const SegregationFinding& f : rep.segregation) {
    json o;
    o["kind"] = "segregation";
    o["cable"] = rep.check_ids.at(static_cast<std::size_t>(f.cable));
    o["other"] = rep.check_ids.at(static_cast<std::size_t>(f.other));
    o["distance"] = f.distance;
    o["required"] = f.required;
    o["s"] = f.s;
    o["s_other"] = f.s_other;
    o["point"] = vec_json(f.point);
    if (f.segment >= 0) o["segment"] = rep.segment_names.at(static_cast<std::size_t>(f.segment));
    violations.push_back(o);
  }
  j["violations"] = violations;
  j["clamps"] = clamps_json(rep);
  j["supports_checked"] = rep.supports_checked;

  json cables = json::array();
  for (const AuditCable& c : rep.cables) {
    json o;
    o["id"] = c.id;
    o["routed"] = c.routed;
    if (c.routed) {
      const CableCheckSummary& s = r.cables.at(static_cast<std::size_t>(c.check_index));
      o["length"] = s.length;
      put(o, "min_clearance", s.min_clearance, "no part within the audited distance of this cable");
      if (std::isfinite(s.min_clearance)) o["min_clearance_exact"] = s.min_clearance_exact;
      put(o, "min_bend_radius", s.min_bend_radius, "straight: no curvature anywhere");
    } else {
      o["reason"] = c.reason;
    }
    cables.push_back(o);
  }
  j["cables"] = cables;
  j["timing_ms"] = {{"load", rep.load_ms}, {"index", rep.index_ms}, {"route", 0.0}, {"check", rep.check_ms}};
  j["counters"] = {{"distance_queries", r.counters.distance_queries},
                   {"inside_queries", r.counters.inside_queries},
                   {"pair_tests", r.counters.pair_tests},
                   {"samples", r.counters.samples}};
  j["triangles"] = rep.triangles;
  if (rep.tessellation.used) {
    const TessellationByNeed& t = rep.tessellation;
    json refined = json::array();
    for (const int q : t.refined) refined.push_back(rep.part_names.at(static_cast<std::size_t>(q)));
    j["tessellation"] = {{"policy", "by-need"},           {"coarse_deflection", t.coarse_deflection},
                         {"fine_deflection", t.fine_deflection}, {"refined", refined},
                         {"coarse_parts", t.coarse_parts}, {"ms", t.ms}};
  }
  j["notes"] = rep.notes;
  return j;
}

std::set<std::string> unrouted_cable_ids(const nlohmann::json& report) {
  std::set<std::string> ids;
  if (!report.is_object() || !report.contains("cables") || !report["cables"].is_array()) return ids;
  for (const auto& c : report["cables"])
    if (c.is_object() && c.contains("id") && c["id"].is_string() && c.contains("routed") && c["routed"] == false)
      ids.insert(c["id"].get<std::string>());
  return ids;
}

void write_audit_report(const AuditReport& report, const std::filesystem::path& path) {
  write_file_atomic(path, json_text(audit_report_json(report), 2) + "\n");
}

}  // namespace loom
