// A harness read from KBL written back as KBL (kbl_write.hpp).
#include "core/io/kbl_write.hpp"

#include "core/error.hpp"
#include "core/harness_topology.hpp"
#include "core/io/atomic_file.hpp"
#include "core/io/kbl_curve.hpp"
#include "core/io/kbl_dom.hpp"
#include "core/io/kbl_read.hpp"

#include <pugixml.hpp>

#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>
#include <unordered_map>

namespace loom {

namespace {

using kbl_dom::child;
using kbl_dom::children;
using kbl_dom::local_name;
std::string text_of(const pugi::xml_node& n) { return kbl_dom::words_text(n); }

/// The shortest decimal text that reads back as exactly v.
std::string number_text(double v) {
  char buf[40];
  for (int digits = 15; digits <= 17; ++digits) {
    std::snprintf(buf, sizeof buf, "%.*g", digits, v);
    if (std::strtod(buf, nullptr) == v) break;
  }
  return buf;
}


class KblWriter {
 public:
  KblWriter(const Harness& h, const KblOrigin& o) : h_(h), o_(o) {}
  std::string write();

 private:
  pugi::xml_node element(const std::string& id) const {
    const auto it = by_id_.find(id);
    return it == by_id_.end() ? pugi::xml_node() : it->second;
  }
  /// A fresh id "<stem>_loom_<n>" that the file does not use.
  std::string fresh_id(const std::string& stem) {
    for (;;) {
      const std::string id = stem + "_loom_" + std::to_string(++serial_);
      if (!by_id_.count(id)) return id;
    }
  }
  static void set_text(pugi::xml_node n, const std::string& v) { n.text().set(v.c_str()); }
  /// Sets a number unless the text already reads as it (unchanged values keep their text).
  static void set_number(pugi::xml_node n, double v) {
    char* end = nullptr;
    const std::string t = text_of(n);
    if (!t.empty() && std::strtod(t.c_str(), &end) == v && *end == '\0') return;
    set_text(n, number_text(v));
  }
  /// A new child `name` of `parent` with a fresh id, after `after` (the first child if empty).
  pugi::xml_node new_object(pugi::xml_node parent, const char* name, const pugi::xml_node& after) {
    pugi::xml_node n = after ? parent.insert_child_after(name, after) : parent.prepend_child(name);
    const std::string id = fresh_id(name);
    n.append_attribute("id") = id.c_str();
    by_id_[id] = n;
    return n;
  }
  /// Sets a numerical value given in mm, in its Unit_component's unit (a new one in mm).
  void set_measure(pugi::xml_node value, double mm) {
    if (!child(value, "Unit_component") && !child(value, "Value_component"))
      set_text(value.append_child("Unit_component"), mm_unit());
    pugi::xml_node v = child(value, "Value_component");
    if (!v) v = value.append_child("Value_component");
    set_number(v, mm / unit_mm(value));
  }
  pugi::xml_node new_point(const Vec3& p);
  void set_point(pugi::xml_node cp, const Vec3& p) {
    auto c = children(cp, "Coordinates");
    while (c.size() < 3) c.push_back(cp.append_child("Coordinates"));
    for (int i = 0; i < 3; ++i) set_number(c[static_cast<std::size_t>(i)], p[i]);
  }
  double unit_mm(const pugi::xml_node& value) const;
  std::string mm_unit();
  /// Sets (or appends after `after`, or first) the three values of a vector element.
  void set_vector(pugi::xml_node seg, const char* name, const Vec3& v, pugi::xml_node after);
  void write_nodes();
  void write_segment(std::size_t k, const Centerline& c);
  void write_lengths(const HarnessTopology& topo);
  void drop_unused_points(const std::set<std::string>& candidates);

  const Harness& h_;
  const KblOrigin& o_;
  pugi::xml_document doc_;
  pugi::xml_node root_;
  std::unordered_map<std::string, pugi::xml_node> by_id_;
  std::set<std::string> dropped_points_;
  std::vector<bool> changed_;  ///< per segment: loom's curve differs from the file's
  int serial_ = 0;
};

pugi::xml_node KblWriter::new_point(const Vec3& p) {
  // Beside the file's own points (the container's elements come in schema order).
  pugi::xml_node last;
  for (auto c : root_.children())
    if (c.type() == pugi::node_element && local_name(c) == "Cartesian_point") last = c;
  pugi::xml_node cp = new_object(root_, "Cartesian_point", last);
  set_point(cp, p);
  return cp;
}

double KblWriter::unit_mm(const pugi::xml_node& value) const {
  const pugi::xml_node u = element(text_of(child(value, "Unit_component")));
  if (!u) return 1.0;
  const std::string prefix = text_of(child(u, "Si_prefix"));
  static const std::map<std::string, double> prefixes{{"", 1000.0}, {"milli", 1.0}, {"centi", 10.0},
                                                      {"deci", 100.0}, {"micro", 1e-3}, {"kilo", 1e6}};
  const auto it = prefixes.find(prefix);
  return text_of(child(u, "Si_unit_name")) == "metre" && it != prefixes.end() ? it->second : 1.0;
}

std::string KblWriter::mm_unit() {
  pugi::xml_node last;
  for (auto u : children(root_, "Unit")) {
    last = u;
    if (text_of(child(u, "Si_unit_name")) == "metre" && text_of(child(u, "Si_prefix")) == "milli" &&
        text_of(child(u, "Si_dimension")).empty())
      return u.attribute("id").value();
  }
  pugi::xml_node u = new_object(root_, "Unit", last);
  set_text(u.append_child("Si_unit_name"), "metre");
  set_text(u.append_child("Si_prefix"), "milli");
  return u.attribute("id").value();
}

void KblWriter::set_vector(pugi::xml_node seg, const char* name, const Vec3& v, pugi::xml_node after) {
  auto parts = children(seg, name);
  if (parts.size() != 3) {
    for (auto p : parts) seg.remove_child(p);
    parts.clear();
    for (int i = 0; i < 3; ++i) {
      after = after ? seg.insert_child_after(name, after) : seg.prepend_child(name);
      parts.push_back(after);
    }
  }
  for (int i = 0; i < 3; ++i) set_number(parts[static_cast<std::size_t>(i)], v[i]);
}

void KblWriter::write_nodes() {
  auto place = [&](const std::string& loom_id, const Vec3& p) {
    const auto it = o_.node_ids.find(loom_id);
    pugi::xml_node node = it == o_.node_ids.end() ? pugi::xml_node() : element(it->second);
    if (!node) throw std::invalid_argument("harness_to_kbl: node '" + loom_id + "' is not a Node of " + h_.source_file);
    const pugi::xml_node ref_el = child(node, "Cartesian_point");
    const pugi::xml_node cp = element(text_of(ref_el));
    if (cp && children(cp, "Coordinates").size() == 3) return set_point(cp, p);
    if (cp) {  // a formboard (2D) point: the node takes a new 3D one, the drawing's goes if unused
      dropped_points_.insert(cp.attribute("id").value());
      return set_text(ref_el, new_point(p).attribute("id").value());
    }
    // A node the router placed: a new point, referenced after the node's Id and Alias_ids.
    pugi::xml_node after;
    for (auto c : node.children())
      if (c.type() == pugi::node_element && (local_name(c) == "Id" || local_name(c) == "Alias_id")) after = c;
    pugi::xml_node ref = after ? node.insert_child_after("Cartesian_point", after) : node.prepend_child("Cartesian_point");
    set_text(ref, new_point(p).attribute("id").value());
  };
  bool placed_any = false;
  for (const auto& p : h_.ports)
    if (p.placed) place(p.id, p.position), placed_any = true;  // an unplaced port keeps the drawing's point
  for (const auto& b : h_.branches)
    if (b.position) place(b.id, *b.position), placed_any = true;
  if (!placed_any) return;
  // A branch point still open in a drawing now partly 3D loses its 2D point: left beside
  // 3D ones it would make the file neither a drawing nor 3D; without one it stays open.
  for (const auto& b : h_.branches) {
    const auto it = o_.node_ids.find(b.id);
    pugi::xml_node node = b.position || it == o_.node_ids.end() ? pugi::xml_node() : element(it->second);
    const pugi::xml_node ref_el = node ? child(node, "Cartesian_point") : pugi::xml_node();
    if (const pugi::xml_node cp = element(text_of(ref_el)); cp && children(cp, "Coordinates").size() == 2) {
      dropped_points_.insert(cp.attribute("id").value());
      node.remove_child(ref_el);
    }
  }
}

void KblWriter::write_segment(std::size_t k, const Centerline& c) {
  pugi::xml_node seg = element(o_.segment_ids[k]);
  // The old curves go (their points with them, unless something else refers to them).
  const auto old = children(seg, "Center_curve");
  pugi::xml_node anchor = old.empty() ? pugi::xml_node() : old.front().previous_sibling();
  if (old.empty())
    for (const char* n : {"Start_node", "End_node"})
      if (const pugi::xml_node e = child(seg, n); e && (!anchor || e.offset_debug() > anchor.offset_debug())) anchor = e;
  for (auto cc : old) {
    for (auto cp : children(cc, "Control_points")) {
      std::istringstream in(cp.child_value());
      for (std::string t; in >> t;) dropped_points_.insert(t);
    }
    seg.remove_child(cc);
  }
  for (const auto& span : kbl_uniform_spans(c)) {
    pugi::xml_node cc = new_object(seg, "Center_curve", anchor);
    anchor = cc;
    set_text(cc.append_child("Degree"), std::to_string(c.degree()));
    std::string refs;
    for (const Vec3& q : span) refs += (refs.empty() ? "" : " ") + std::string(new_point(q).attribute("id").value());
    set_text(cc.append_child("Control_points"), refs);
  }
  // Start and end tangents, and the length, after the segment's Id and Alias_ids.
  pugi::xml_node head;
  for (auto e : seg.children())
    if (e.type() == pugi::node_element && (local_name(e) == "Id" || local_name(e) == "Alias_id")) head = e;
  Vec3 d0[2], d1[2];
  c.evaluate(c.u_min(), 1, d0);
  c.evaluate(c.u_max(), 1, d1, true);
  if (d0[1].norm() > 0.0) set_vector(seg, "Start_vector", d0[1].normalized(), head);
  const auto sv = children(seg, "Start_vector");
  if (d1[1].norm() > 0.0) set_vector(seg, "End_vector", d1[1].normalized(), sv.empty() ? head : sv.back());
  pugi::xml_node vl = child(seg, "Virtual_length");
  if (!vl) {
    const auto ev = children(seg, "End_vector");
    vl = new_object(seg, "Virtual_length", !ev.empty() ? ev.back() : !sv.empty() ? sv.back() : head);
  }
  set_measure(vl, c.length());
  // A drawing's Virtual_length was its formboard length: kept as the length to manufacture.
  if (const auto& nominal = h_.segments[k].nominal_length; nominal && !child(seg, "Physical_length"))
    set_measure(new_object(seg, "Physical_length", vl), *nominal);
}

void KblWriter::write_lengths(const HarnessTopology& topo) {
  for (std::size_t c = 0; c < h_.cables.size(); ++c) {
    const auto it = o_.wire_ids.find(h_.cables[c].id);
    if (it == o_.wire_ids.end()) continue;
    double length = 0.0;
    bool complete = true, moved = false;
    for (const SegmentUse& u : topo.cable_chain(static_cast<int>(c))) {
      const auto& b = h_.segments[static_cast<std::size_t>(u.segment)].bspline;
      moved = moved || changed_[static_cast<std::size_t>(u.segment)];
      if (!b) complete = false;
      else length += Centerline(b->degree, b->knots, b->control_points).length();
    }
    if (!complete || !moved) continue;  // the file's own length stands for an unchanged route
    for (const std::string& id : it->second) {
      pugi::xml_node occ = element(id);
      if (!occ) throw std::invalid_argument("harness_to_kbl: wire '" + id + "' is not in " + h_.source_file);
      pugi::xml_node dmu;
      for (auto li : children(occ, "Length_information")) {
        std::string type = text_of(child(li, "Length_type"));
        for (char& ch : type) ch = static_cast<char>(std::toupper(static_cast<unsigned char>(ch)));
        if (type == "DMU") dmu = li;
      }
      if (!dmu) {  // after the occurrence's other lengths, else after its Part
        pugi::xml_node after = child(occ, "Part");
        for (auto li : children(occ, "Length_information")) after = li;
        dmu = new_object(occ, "Length_information", after);
        set_text(dmu.append_child("Length_type"), "DMU");
      }
      pugi::xml_node lv = child(dmu, "Length_value");
      if (!lv) lv = new_object(dmu, "Length_value", child(dmu, "Length_type"));
      set_measure(lv, length);
    }
  }
}

void KblWriter::drop_unused_points(const std::set<std::string>& candidates) {
  // References to points: <Cartesian_point> inside other elements and <Control_points>.
  std::set<std::string> used;
  kbl_dom::for_each_node(root_, [&](const pugi::xml_node& n) {
    if (n.type() != pugi::node_element || n.parent() == root_ || n == root_) return;
    if (local_name(n) != "Cartesian_point" && local_name(n) != "Control_points") return;
    std::istringstream in(n.child_value());
    for (std::string t; in >> t;) used.insert(t);
  });
  for (const std::string& id : candidates)
    if (!used.count(id))
      if (const pugi::xml_node p = element(id); p && p.parent() == root_) root_.remove_child(p);
}

std::string KblWriter::write() {
  const auto res = doc_.load_buffer(o_.text->data(), o_.text->size(), kbl_dom::kKblParseFlags);
  if (!res) throw std::invalid_argument("harness_to_kbl: the KBL text kept from " + h_.source_file + " does not parse");
  root_ = doc_.document_element();
  kbl_dom::for_each_node(root_, [&](const pugi::xml_node& n) {
    if (n.type() == pugi::node_element)
      if (auto a = n.attribute("id")) by_id_.emplace(a.value(), n);
  });
  // The harness must still be the file's: the same segments between the same nodes.
  if (h_.segments.size() != o_.segment_ids.size())
    throw std::invalid_argument("harness_to_kbl: the harness has " + std::to_string(h_.segments.size()) +
                                " segments, " + h_.source_file + " " + std::to_string(o_.segment_ids.size()));
  for (std::size_t k = 0; k < h_.segments.size(); ++k) {
    const pugi::xml_node seg = element(o_.segment_ids[k]);
    const Segment& s = h_.segments[k];
    const auto a = o_.node_ids.find(s.from), b = o_.node_ids.find(s.to);
    if (!seg || a == o_.node_ids.end() || b == o_.node_ids.end() || text_of(child(seg, "Start_node")) != a->second ||
        text_of(child(seg, "End_node")) != b->second)
      throw std::invalid_argument("harness_to_kbl: segment " + s.from + " -> " + s.to + " is not Segment '" +
                                  o_.segment_ids[k] + "' of " + h_.source_file);
  }
  const HarnessTopology topo(h_);
  write_nodes();
  // Segments whose curve loom changed get new curves, tangents and length; the others keep
  // the file's own (read → write → read is then exact for them).
  changed_.assign(h_.segments.size(), false);
  for (std::size_t k = 0; k < h_.segments.size(); ++k) {
    const auto& b = h_.segments[k].bspline;
    const auto& read = k < o_.segment_curves.size() ? o_.segment_curves[k] : std::nullopt;
    changed_[k] = b && !(read && read->degree == b->degree && read->knots == b->knots &&
                         read->control_points == b->control_points);
    if (changed_[k]) write_segment(k, Centerline(b->degree, b->knots, b->control_points));
  }
  write_lengths(topo);
  drop_unused_points(dropped_points_);
  std::ostringstream os;
  doc_.save(os, "\t", pugi::format_default, pugi::encoding_utf8);
  return os.str();
}

}  // namespace

std::string harness_to_kbl(const Harness& h) {
  if (!h.kbl || !h.kbl->text) throw std::invalid_argument("harness_to_kbl: harness '" + h.name + "' was not read from KBL");
  return KblWriter(h, *h.kbl).write();
}

void write_harness_kbl(const Harness& h, const std::filesystem::path& path) { write_file_atomic(path, harness_to_kbl(h)); }

}  // namespace loom
