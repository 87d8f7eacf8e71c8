// Arc-length bookkeeping of the certified audit's observations (stretch_tracker.hpp).
#include "routing/audit/stretch_tracker.hpp"

#include <algorithm>
#include <stdexcept>

namespace loom::audit {

bool is_attached(const std::vector<PartAttachment>& attachments, int part, double s, bool inside, double tolerance) {
  return std::any_of(attachments.begin(), attachments.end(), [&](const PartAttachment& a) {
    return a.part == part && s >= a.s_begin && s <= a.s_end && (!inside || holds_port(a, tolerance));
  });
}

void StretchTracker::step(const std::vector<PartObservation>& all, double s0, double s1) {
  const std::vector<PartObservation>* seen_obs = &all;
  if (!attachments_.empty()) {
    kept_.clear();  // reused: steps are the checker's inner loop
    for (const auto& o : all)
      if (!is_attached(attachments_, o.part, o.s, o.inside, tolerance_)) kept_.push_back(o);
    seen_obs = &kept_;
  }
  const std::vector<PartObservation>& obs = *seen_obs;
  for (auto it = open_.begin(); it != open_.end();) {
    const bool seen = std::any_of(obs.begin(), obs.end(), [&](const PartObservation& o) { return o.part == it->first; });
    if (!seen) {
      close(it->second);
      it = open_.erase(it);
    } else {
      ++it;
    }
  }
  for (const auto& o : obs) {
    Open& st = open_[o.part];
    st.band.take(o);
    if (!st.started) {
      st.started = true;
      st.band.s_begin = s0;
    }
    st.band.s_end = s1;
    int contact = -1;
    if (o.key < 0.0) {
      if (!st.contact_open) {
        st.contacts.emplace_back();
        st.contacts.back().s_begin = s0;
        st.contact_open = true;
      }
      Stretch& c = st.contacts.back();
      c.take(o);
      c.s_end = s1;
      contact = static_cast<int>(st.contacts.size()) - 1;
    } else {
      st.contact_open = false;
    }
    // A deferred observation may turn out the deepest of its band or contact stretch
    // only if its lower bound reaches that stretch's smallest upper bound so far.
    if (o.deferred && (o.key_lower <= st.band.deepest.key ||
                       (contact >= 0 && o.key_lower <= st.contacts[static_cast<std::size_t>(contact)].deepest.key)))
      st.candidates.push_back({o, contact});
  }
}

void StretchTracker::flush() {
  for (auto& kv : open_) close(kv.second);
  open_.clear();
}

void StretchTracker::settle(Open& st) {
  // No candidate: no deferred observation was ever a deepest, so the deepest are exact.
  if (st.candidates.empty()) return;
  std::vector<double> contact_upper;
  for (const Stretch& c : st.contacts) contact_upper.push_back(c.deepest.key);
  for (Candidate& c : st.candidates) {
    const std::size_t k = static_cast<std::size_t>(c.contact);
    if (c.obs.key_lower > st.band.deepest.key && (c.contact < 0 || c.obs.key_lower > contact_upper[k])) continue;
    if (!resolve_) throw std::logic_error("clash check: a deferred observation without a resolver");
    resolve_(c.obs);
    st.band.fold(c.obs);
    if (c.contact >= 0) st.contacts[k].fold(c.obs);
  }
  // Every observation not measured has a lower bound above a measured key (the smallest
  // upper bound's own observation was measured), so the exact deepest is the deepest.
  st.band.deepest = st.band.exact;
  for (Stretch& c : st.contacts) c.deepest = c.exact;
}

void StretchTracker::close(Open& st) {
  settle(st);
  min_key = std::min(min_key, st.band.deepest.key);
  for (const Stretch& c : st.contacts) {
    const PartObservation& d = c.deepest;
    ClashEntry e;
    e.kind = ClashKind::CableStructure;
    e.cable = cable_;
    e.part = d.part;
    e.other = -1;
    e.clearance = std::max(d.key, -radius_);  // dist is 0 inside a closed part
    e.point = d.point;
    e.s = d.s;
    e.s_begin = c.s_begin;
    e.s_end = c.s_end;
    e.keep_out = parts_[d.part].keep_out;
    e.inside = d.inside;
    clashes.push_back(e);
  }
  const PartObservation& d = st.band.deepest;
  if (st.contacts.empty() && d.part >= 0 && d.key < parts_[d.part].required) {
    Violation v;
    v.kind = ViolationKind::Clearance;
    v.cable = cable_;
    v.part = d.part;
    v.value = std::max(d.key, 0.0);
    v.limit = parts_[d.part].required;
    v.s = d.s;
    v.s_begin = st.band.s_begin;
    v.s_end = st.band.s_end;
    v.point = d.point;
    violations.push_back(v);
  }
}

}  // namespace loom::audit
