#pragma once
/// Whether two certified audits of one scene found the same (the bundle level against the
/// per-cable reference, in the harness-audit bench and the bundle tests).
///
/// Stretch ends are known to one chord (≤ 2r): where the clearance leaves the band (or the
/// contact) for less than a chord, one audit's chords may see the gap and the other's not.
/// One audit then reports two stretches where the other reports one, or a clearance
/// violation where the other's band stretch runs on into a contact (a clash, and no
/// violation). So findings of one kind, cable and part (or other cable) are grouped, over
/// both audits, into runs of stretches less than a chord (2r + 2·tolerance) apart. The
/// audits agree when
///  * every run has findings in both, the smallest clearances of a run agree within twice
///    the tolerance (each is within it of the truth), and each audit's deepest point of a
///    run lies in the run (runs with more stretches in one audit count as splits);
///  * a run found by one audit only has its smallest clearance within twice the tolerance
///    of the finding's threshold (0 for a clash, the required clearance for a violation;
///    counted as edges), or is a violation next to a clash of the same cable and part in the
///    other audit with the clearance between them (the truth, from `oracle`) in the band
///    but for gaps shorter than a chord (counted as joins);
///  * bend violations are equal (the same curves give the same results), and per cable the
///    lengths and bend radii are equal and the smallest clearances agree where exact.
/// World frame, scene units.
#include "routing/audit/clash_check.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <string>
#include <tuple>
#include <vector>

namespace loom::bench {

/// The exact clearance of a cable at arc length s to a part (−r inside a closed part).
using ClearanceOracle = std::function<double(int cable, int part, double s)>;

/// What compare_findings() found.
struct FindingsDiff {
  std::vector<std::string> problems;  ///< empty: the same findings
  int splits = 0;  ///< runs with more stretches in one audit than in the other
  int edges = 0;   ///< runs in one audit only, within the tolerance of the threshold
  int joins = 0;   ///< violations in one audit whose band stretch the other joins to a contact
  double max_clearance_diff = 0.0;  ///< largest |Δ smallest clearance| over runs found by both
  double max_point_diff = 0.0;      ///< largest distance between the two audits' deepest points of a run
};

namespace detail {

/// One stretch of one audit.
struct Stretch {
  double s_begin = 0.0, s_end = 0.0, s = 0.0, value = 0.0;
  Vec3 point = Vec3::Zero();
  bool ref = false;        ///< from the reference audit
  double threshold = 0.0;  ///< a finding below this value (0, or the required clearance)
};

/// Stretches of both audits less than a chord apart.
struct Run {
  double s0 = 0.0, s1 = 0.0;
  const Stretch* deep[2] = {nullptr, nullptr};  ///< deepest of the reference [1] and the other [0]
  int count[2] = {0, 0};
};

inline std::vector<Run> runs_of(std::vector<Stretch>& all, double gap) {
  std::sort(all.begin(), all.end(), [](const Stretch& a, const Stretch& b) { return a.s_begin < b.s_begin; });
  std::vector<Run> out;
  for (const Stretch& x : all) {
    if (out.empty() || x.s_begin > out.back().s1 + gap) out.push_back({x.s_begin, x.s_end, {nullptr, nullptr}, {0, 0}});
    Run& r = out.back();
    r.s1 = std::max(r.s1, x.s_end);
    const Stretch*& d = r.deep[x.ref ? 1 : 0];
    if (!d || x.value < d->value) d = &x;
    ++r.count[x.ref ? 1 : 0];
  }
  return out;
}

/// True if, on cable c between arc lengths a < b, the clearance to `part` stays below
/// `required` + 2·tol but for stretches shorter than `gap` (sampled every tol / 2).
inline bool in_band_between(const ClearanceOracle& oracle, int c, int part, double a, double b, double required,
                            double tol, double gap) {
  const double h = 0.5 * tol;
  double out_since = -1.0;
  for (double s = a; s <= b + 0.5 * h; s += h) {
    const bool out = oracle(c, part, std::min(s, b)) > required + 2.0 * tol;
    if (out && out_since < 0.0) out_since = s;
    if (!out) out_since = -1.0;
    if (out_since >= 0.0 && s - out_since > gap) return false;
  }
  return true;
}

}  // namespace detail

/// Compares `got` with the reference `ref` (see the file comment); `cables` are the audited
/// cables (a chord is at most 2r long); `oracle` may be empty (then a violation found by one
/// audit only is a problem unless it is an edge).
inline FindingsDiff compare_findings(const ClashResult& ref, const ClashResult& got, const std::vector<CableInput>& cables,
                                     const ClearanceOracle& oracle = {}) {
  FindingsDiff diff;
  const double tol = ref.tolerance;
  auto say = [&](const std::string& p) {
    if (diff.problems.size() < 20) diff.problems.push_back(p);
  };
  using Key = std::tuple<int, int, int, int>;  // 0 clash / 1 clearance violation, clash kind, cable, part or other
  std::map<Key, std::vector<detail::Stretch>> stretches;
  for (const ClashResult* r : {&ref, &got}) {
    for (const auto& e : r->clashes)
      stretches[{0, static_cast<int>(e.kind), e.cable, e.kind == ClashKind::CableStructure ? e.part : e.other}].push_back(
          {e.s_begin, e.s_end, e.s, e.clearance, e.point, r == &ref, 0.0});
    for (const auto& v : r->violations)
      if (v.kind == ViolationKind::Clearance)
        stretches[{1, 0, v.cable, v.part}].push_back({v.s_begin, v.s_end, v.s, v.value, v.point, r == &ref, v.limit});
  }
  std::map<Key, std::vector<detail::Run>> runs;
  for (auto& [k, list] : stretches)
    runs[k] = detail::runs_of(list, 2.0 * cables[static_cast<std::size_t>(std::get<2>(k))].radius + 2.0 * tol);
  for (const auto& [k, list] : runs) {
    const int c = std::get<2>(k);
    const double gap = 2.0 * cables[static_cast<std::size_t>(c)].radius + 2.0 * tol;
    const std::string what = std::string(std::get<0>(k) == 0 ? clash_kind_name(static_cast<ClashKind>(std::get<1>(k)))
                                                              : "clearance violation") +
                             " of cable " + cables[static_cast<std::size_t>(c)].id + " with " + std::to_string(std::get<3>(k));
    for (const detail::Run& r : list) {
      const std::string where = what + " over [" + std::to_string(r.s0) + ", " + std::to_string(r.s1) + "]";
      if (r.deep[0] && r.deep[1]) {
        const double dc = std::abs(r.deep[0]->value - r.deep[1]->value);
        diff.max_clearance_diff = std::max(diff.max_clearance_diff, dc);
        diff.max_point_diff = std::max(diff.max_point_diff, (r.deep[0]->point - r.deep[1]->point).norm());
        if (dc > 2.0 * tol)
          say(where + ": deepest " + std::to_string(r.deep[1]->value) + " in the reference, " + std::to_string(r.deep[0]->value));
        if (r.count[0] != r.count[1]) ++diff.splits;
        continue;
      }
      const detail::Stretch& only = r.deep[0] ? *r.deep[0] : *r.deep[1];
      if (only.value >= only.threshold - 2.0 * tol) {
        ++diff.edges;
        continue;
      }
      // A violation the other audit's band stretch may have joined to a contact.
      bool joined = false;
      if (std::get<0>(k) == 1 && oracle) {
        const auto clashes = runs.find({0, static_cast<int>(ClashKind::CableStructure), c, std::get<3>(k)});
        if (clashes != runs.end())
          for (const detail::Run& cr : clashes->second) {
            if (!cr.deep[only.ref ? 0 : 1]) continue;  // the other audit's clash
            // The arc between the violation and the clash (none where they overlap).
            const double a = cr.s1 < r.s0 ? cr.s1 : std::min(r.s1, cr.s0);
            const double b = cr.s1 < r.s0 ? r.s0 : cr.s0;
            if (a > b || detail::in_band_between(oracle, c, std::get<3>(k), a, b, only.threshold, tol, gap)) {
              joined = true;
              break;
            }
          }
      }
      if (joined)
        ++diff.joins;
      else
        say(where + ": " + std::to_string(r.count[1]) + " stretches in the reference, " + std::to_string(r.count[0]) +
            " (deepest " + std::to_string(only.value) + ")");
    }
  }
  // Bend violations: the same curves, the same results.
  std::vector<const Violation*> rb, gb;
  for (const auto& v : ref.violations)
    if (v.kind == ViolationKind::BendRadius) rb.push_back(&v);
  for (const auto& v : got.violations)
    if (v.kind == ViolationKind::BendRadius) gb.push_back(&v);
  if (rb.size() != gb.size()) {
    say(std::to_string(rb.size()) + " bend violations in the reference, " + std::to_string(gb.size()));
  } else {
    for (std::size_t i = 0; i < rb.size(); ++i)
      if (rb[i]->cable != gb[i]->cable || rb[i]->value != gb[i]->value || rb[i]->s != gb[i]->s)
        say("bend violation of cable " + cables[static_cast<std::size_t>(rb[i]->cable)].id + ": " +
            std::to_string(rb[i]->value) + " at s = " + std::to_string(rb[i]->s) + " in the reference, " +
            std::to_string(gb[i]->value) + " at " + std::to_string(gb[i]->s));
  }
  if (ref.cables.size() != got.cables.size()) {
    say("cable summaries: " + std::to_string(ref.cables.size()) + " in the reference, " + std::to_string(got.cables.size()));
    return diff;
  }
  for (std::size_t c = 0; c < ref.cables.size(); ++c) {
    const CableCheckSummary& a = ref.cables[c];
    const CableCheckSummary& b = got.cables[c];
    const std::string who = "cable " + cables[c].id + ": ";
    if (a.length != b.length) say(who + "length " + std::to_string(a.length) + " vs " + std::to_string(b.length));
    if (a.min_bend_radius != b.min_bend_radius || a.min_bend_s != b.min_bend_s)
      say(who + "min bend radius " + std::to_string(a.min_bend_radius) + " vs " + std::to_string(b.min_bend_radius));
    // Exact below the band only: its edge is decided to the tolerance.
    const double dm = std::abs(a.min_clearance - b.min_clearance);
    if ((a.min_clearance_exact || b.min_clearance_exact) && !(dm <= 2.0 * tol))
      say(who + "smallest clearance " + std::to_string(a.min_clearance) + (a.min_clearance_exact ? " (exact)" : "") +
          " vs " + std::to_string(b.min_clearance) + (b.min_clearance_exact ? " (exact)" : ""));
  }
  return diff;
}

}  // namespace loom::bench
