// VEC files: the topology read through the KBL reader, the missing geometry said (kbl_vec.hpp).
#include "core/io/kbl_vec.hpp"

#include "core/error.hpp"
#include "core/io/input_file.hpp"
#include "core/io/kbl_dom.hpp"
#include "core/io/kbl_read.hpp"
#include "core/io/line_map.hpp"

#include <pugixml.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <map>
#include <memory>
#include <set>
#include <sstream>
#include <string>
#include <unordered_map>
#include <vector>

namespace loom {

namespace {

using kbl_dom::child;
using kbl_dom::children;
using kbl_dom::describe;
using kbl_dom::words;
using kbl_dom::local_name;

std::string text_of(const pugi::xml_node& n) { return kbl_dom::words_text(n); }

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

/// Per line of `kbl` where an element starts: the id of that element, or of the nearest
/// one around it with an id (where the KBL reader found a fault, or read a node or segment).
std::map<int, std::string> kbl_ids_by_line(const std::string& kbl) {
  std::map<int, std::string> out;
  pugi::xml_document doc;
  if (!doc.load_buffer(kbl.data(), kbl.size())) return out;
  const LineMap lines(kbl);
  kbl_dom::for_each_node(doc.document_element(), [&](const pugi::xml_node& n) {
    if (n.type() != pugi::node_element) return;
    pugi::xml_node with_id = n;
    for (; with_id && !with_id.attribute("id"); with_id = with_id.parent()) {}
    if (with_id) out.emplace(lines.line(n.offset_debug()), with_id.attribute("id").value());
  });
  return out;
}

/// A VEC topology (TopologyNode, TopologySegment, placements, contact points, wires,
/// routings) written as the KBL 2.4 document that says the same, so that the KBL reader
/// reads it (ports, cables, routing checks, topology-only nodes) exactly as a KBL drawing.
/// Ids are the VEC's (a node's is its Identification where unique): a fault the KBL reader
/// finds is reported at the VEC element of that id.
class VecReader {
 public:
  VecReader(const std::string& text, std::string file) : lines_(text), file_(std::move(file)) {}

  Harness read(const pugi::xml_document& doc);

 private:
  int vec_line(const std::map<int, std::string>& ids, int kbl_line) const;
  void to_vec_lines(const std::string& kbl, Harness& h, KblOrigin& origin) const;
  int line(const pugi::xml_node& n) const { return lines_.line(n.offset_debug()); }
  [[noreturn]] void fail(const pugi::xml_node& n, const std::string& reason) const {
    throw InputError({file_, line(n), describe(n)}, reason);
  }
  pugi::xml_node lookup(const pugi::xml_node& from, const std::string& id) const {
    const auto it = by_id_.find(id);
    if (it == by_id_.end()) fail(from, "<" + std::string(local_name(from)) + "> refers to '" + id + "', which no element of the file has as its id");
    return it->second;
  }
  /// The nearest enclosing element with this local name (empty if none).
  static pugi::xml_node ancestor(pugi::xml_node n, std::string_view name) {
    for (n = n.parent(); n && local_name(n) != name; n = n.parent()) {}
    return n;
  }
  double number(const pugi::xml_node& n) const {
    const std::string v = text_of(n);
    char* end = nullptr;
    const double d = std::strtod(v.c_str(), &end);
    if (v.empty() || end == v.c_str() || *end != '\0' || !std::isfinite(d) || std::abs(d) > kMaxInputMagnitude)
      fail(n, "not a finite number within ±" + full_precision(kMaxInputMagnitude) + ": '" + v + "'");
    return d;
  }
  double length_mm(const pugi::xml_node& value) const;
  std::vector<pugi::xml_node> all(std::string_view name) const {
    const auto it = by_name_.find(std::string(name));
    return it == by_name_.end() ? std::vector<pugi::xml_node>() : it->second;
  }
  std::string kbl_text(const pugi::xml_node& root);
  std::map<std::string, std::vector<std::string>> placements() const;
  std::map<std::string, std::vector<pugi::xml_node>> write_contacts(pugi::xml_node harness);
  void write_wires(pugi::xml_node kbl_root, pugi::xml_node harness);
  void add_wire_part(pugi::xml_node kbl_root, const pugi::xml_node& wer, const pugi::xml_node& spec);
  std::map<std::string, std::string> write_nodes(pugi::xml_node kbl_root,
                                                 const std::map<std::string, std::vector<pugi::xml_node>>& contacts);
  void write_routings(pugi::xml_node kbl_root);
  void write_segments(pugi::xml_node kbl_root, const std::map<std::string, std::string>& node_id);

  LineMap lines_;
  std::string file_;
  std::unordered_map<std::string, pugi::xml_node> by_id_;
  std::map<std::string, std::vector<pugi::xml_node>> by_name_;  ///< elements by local name, in order
  std::map<std::string, pugi::xml_node> kbl_source_;  ///< KBL id → the VEC element it stands for
  std::map<std::string, std::string> contact_of_end_;  ///< WireEnd id → ContactPoint id
  std::set<std::string> parts_written_;
  std::vector<std::string> notes_;  ///< what the translation left out, for KblOrigin::notes
};

double VecReader::length_mm(const pugi::xml_node& value) const {
  const pugi::xml_node v = child(value, "ValueComponent");
  if (!v) fail(value, "has no <ValueComponent>");
  const pugi::xml_node uc = child(value, "UnitComponent");
  if (!uc) return number(v);  // no unit: millimetres, as KBL
  const pugi::xml_node unit = lookup(uc, text_of(uc));
  static const std::map<std::string, double> prefixes{{"", 1000.0}, {"milli", 1.0}, {"centi", 10.0},
                                                      {"deci", 100.0}, {"micro", 1e-3}, {"kilo", 1e6}};
  const auto p = prefixes.find(lower(text_of(child(unit, "SiPrefix"))));
  const std::string exponent = text_of(child(unit, "Exponent"));
  if (lower(text_of(child(unit, "SiUnitName"))) != "metre" || p == prefixes.end() || !(exponent.empty() || exponent == "1"))
    fail(value, "its unit " + describe(unit) + " is not a length loom knows (a metre with an SI prefix)");
  return number(v) * p->second;
}

/// A General_wire for the wire element's specification (once per specification): its
/// outside diameter and static bend radius. A wire without a diameter is refused here, named
/// as the VEC names it.
void VecReader::add_wire_part(pugi::xml_node kbl_root, const pugi::xml_node& wer, const pugi::xml_node& spec) {
  const std::string sid = spec.attribute("id").value();
  if (!parts_written_.insert(sid).second) return;
  const pugi::xml_node od = child(spec, "OutsideDiameter");
  if (!od)
    fail(wer, "wire '" + text_of(child(wer, "Identification")) + "': its " + describe(spec) + " (line " +
                  std::to_string(line(spec)) + ") has no <OutsideDiameter>: loom needs the outer diameter of the "
                  "wire to route and audit it");
  pugi::xml_node gw = kbl_root.append_child("General_wire");
  gw.append_attribute("id") = sid.c_str();
  gw.append_child("Part_number").text().set(text_of(child(spec, "Identification")).c_str());
  auto measure = [&](const char* name, double mm) {
    pugi::xml_node m = gw.append_child(name);
    m.append_attribute("id") = (sid + "." + name).c_str();
    m.append_child("Value_component").text().set(full_precision(mm).c_str());
  };
  if (const pugi::xml_node br = child(spec, "MinBendRadiusStatic")) measure("Bend_radius", length_mm(br));
  measure("Outside_diameter", length_mm(od));
  kbl_source_[sid] = spec;
}

/// Components placed at nodes (OnPointPlacement → NodeLocation): VEC node id → component ids.
std::map<std::string, std::vector<std::string>> VecReader::placements() const {
  std::map<std::string, std::vector<std::string>> at_node;
  for (const auto& pl : all("Placement")) {
    const pugi::xml_node placed = child(pl, "PlacedElement");
    if (!placed) continue;
    const pugi::xml_node role = lookup(placed, text_of(placed));
    const pugi::xml_node comp = local_name(role) == "Component" ? role : ancestor(role, "Component");
    for (auto loc : children(pl, "Location"))
      for (auto rn : children(loc, "ReferencedNode"))
        if (const pugi::xml_node node = lookup(rn, text_of(rn)); comp && local_name(node) == "TopologyNode")
          at_node[node.attribute("id").value()].push_back(comp.attribute("id").value());
  }
  return at_node;
}

/// Contact points as the Contact_points of the connector occurrence whose cavity they equip;
/// returns component id → its contact points (and notes which contact mounts each wire end).
std::map<std::string, std::vector<pugi::xml_node>> VecReader::write_contacts(pugi::xml_node harness) {
  std::map<std::string, std::vector<pugi::xml_node>> contacts;
  for (const auto& cp : all("ContactPoint")) {
    pugi::xml_node comp;
    for (auto cm : children(cp, "CavityMounting"))
      for (auto ref : children(cm, "EquippedCavityRef"))
        for (const auto& t : words(ref))
          if (!comp) comp = ancestor(lookup(ref, t), "Component");
    if (comp) contacts[comp.attribute("id").value()].push_back(cp);
    for (auto wm : children(cp, "WireMounting"))
      for (auto ref : children(wm, "ReferencedWireEnd"))
        for (const auto& t : words(ref)) contact_of_end_.emplace(lookup(ref, t).attribute("id").value(), cp.attribute("id").value());
  }
  for (const auto& [comp_id, cps] : contacts) {
    const pugi::xml_node comp = by_id_.at(comp_id);
    pugi::xml_node co = harness.append_child("Connector_occurrence");
    co.append_attribute("id") = comp_id.c_str();
    kbl_source_[comp_id] = comp;
    co.append_child("Id").text().set(text_of(child(comp, "Identification")).c_str());
    for (const auto& cp : cps) {
      pugi::xml_node c = co.append_child("Contact_points");
      c.append_attribute("id") = cp.attribute("id").value();
      kbl_source_[cp.attribute("id").value()] = cp;
      c.append_child("Id").text().set(text_of(child(cp, "Identification")).c_str());
    }
  }
  return contacts;
}

/// Each WireElementReference with its ends: a wire occurrence of its specification's
/// General_wire and the Connection between the contact points that mount its ends.
void VecReader::write_wires(pugi::xml_node kbl_root, pugi::xml_node harness) {
  for (const auto& wer : all("WireElementReference")) {
    const std::string wid = wer.attribute("id").value();
    const pugi::xml_node rwe = child(wer, "ReferencedWireElement");
    if (!rwe) fail(wer, "has no <ReferencedWireElement>");
    const pugi::xml_node we = lookup(rwe, text_of(rwe));
    const pugi::xml_node wes = child(we, "WireElementSpecification");
    if (!wes) fail(we, "has no <WireElementSpecification>");
    add_wire_part(kbl_root, wer, lookup(wes, text_of(wes)));
    pugi::xml_node conn = harness.append_child("Connection");
    conn.append_attribute("id") = ("loom.conn." + wid).c_str();
    kbl_source_["loom.conn." + wid] = wer;
    conn.append_child("Id").text().set(text_of(child(wer, "Identification")).c_str());
    conn.append_child("Wire").text().set(wid.c_str());
    for (auto end : children(wer, "WireEnd")) {
      pugi::xml_node ex = conn.append_child("Extremities");
      ex.append_attribute("id") = end.attribute("id").value();
      kbl_source_[end.attribute("id").value()] = end;
      if (const pugi::xml_node pos = child(end, "PositionOnWire"))
        ex.append_child("Position_on_wire").text().set(full_precision(number(pos)).c_str());
      const auto cp = contact_of_end_.find(end.attribute("id").value());
      if (cp == contact_of_end_.end()) fail(end, "no <ContactPoint> mounts this wire end: loom cannot tell where the wire ends");
      ex.append_child("Contact_point").text().set(cp->second.c_str());
    }
    pugi::xml_node occ = harness.append_child("General_wire_occurrence");
    occ.append_attribute("xsi:type") = "kbl:Wire_occurrence";
    occ.append_attribute("id") = wid.c_str();
    kbl_source_[wid] = wer;
    occ.append_child("Part").text().set(text_of(wes).c_str());
    occ.append_child("Wire_number").text().set(text_of(child(wer, "Identification")).c_str());
  }
}

/// Nodes, named by their Identification where it is unique (the name the drawing shows),
/// referencing the connectors placed on them; returns VEC node id → KBL node id.
std::map<std::string, std::string> VecReader::write_nodes(pugi::xml_node kbl_root,
                                                          const std::map<std::string, std::vector<pugi::xml_node>>& contacts) {
  const auto at_node = placements();
  std::map<std::string, int> names;
  for (const auto& n : all("TopologyNode")) ++names[text_of(child(n, "Identification"))];
  std::map<std::string, std::string> node_id;
  for (const auto& n : all("TopologyNode")) {
    const std::string name = text_of(child(n, "Identification")), vid = n.attribute("id").value();
    const std::string kid = !name.empty() && names[name] == 1 && !by_id_.count(name) ? name : vid;
    node_id[vid] = kid;
    kbl_source_[kid] = n;
    pugi::xml_node kn = kbl_root.append_child("Node");
    kn.append_attribute("id") = kid.c_str();
    kn.append_child("Id").text().set(name.c_str());
    std::string refs;
    if (const auto it = at_node.find(vid); it != at_node.end())
      for (const auto& c : it->second)
        if (contacts.count(c)) refs += (refs.empty() ? "" : " ") + c;
    if (!refs.empty()) kn.append_child("Referenced_components").text().set(refs.c_str());
  }
  return node_id;
}

/// Routings of single wires, their segments once each; a path that passes a segment twice
/// (out along a branch and back) is noted and left out: a tree route cannot hold the loop.
void VecReader::write_routings(pugi::xml_node kbl_root) {
  for (const auto& r : all("Routing")) {
    const pugi::xml_node re = child(r, "RoutedElement");
    if (!re) fail(r, "has no <RoutedElement>");
    const pugi::xml_node wer = lookup(re, text_of(re));
    if (local_name(wer) != "WireElementReference") continue;  // a routed group: its wires carry their own
    std::set<std::string> seen;
    std::string segs, twice;
    for (auto path : children(r, "Path"))
      for (auto s : children(path, "Segment"))
        for (const auto& t : words(s)) {
          lookup(s, t);
          if (seen.insert(t).second) segs += (segs.empty() ? "" : " ") + t;
          else twice += (twice.empty() ? "" : " ") + text_of(child(by_id_.at(t), "Identification"));
        }
    if (!twice.empty()) {
      notes_.push_back("routing '" + text_of(child(r, "Identification")) + "' (line " + std::to_string(line(r)) +
                       ") passes " + twice + " twice, out and back: loom routes its wire along the tree path "
                       "between its ends (the loop is not modelled)");
      continue;
    }
    pugi::xml_node kr = kbl_root.append_child("Routing");
    kr.append_attribute("id") = r.attribute("id").value();
    kbl_source_[r.attribute("id").value()] = r;
    kr.append_child("Routed_wire").text().set(("loom.conn." + std::string(wer.attribute("id").value())).c_str());
    kr.append_child("Segments").text().set(segs.c_str());
  }
}

/// Segments between their nodes, with the adapted length (rounded for manufacture), else
/// the designed one, as their Physical_length.
void VecReader::write_segments(pugi::xml_node kbl_root, const std::map<std::string, std::string>& node_id) {
  for (const auto& s : all("TopologySegment")) {
    pugi::xml_node ks = kbl_root.append_child("Segment");
    ks.append_attribute("id") = s.attribute("id").value();
    kbl_source_[s.attribute("id").value()] = s;
    ks.append_child("Id").text().set(text_of(child(s, "Identification")).c_str());
    pugi::xml_node length;
    for (auto li : children(s, "LengthInformation"))
      if (const pugi::xml_node l = child(li, "Length"); l && (!length || lower(text_of(child(li, "Classification"))) == "adapted"))
        length = l;
    if (length) {
      pugi::xml_node pl = ks.append_child("Physical_length");
      pl.append_attribute("id") = (std::string(s.attribute("id").value()) + ".length").c_str();
      pl.append_child("Value_component").text().set(full_precision(length_mm(length)).c_str());
    }
    for (const char* end : {"StartNode", "EndNode"}) {
      const pugi::xml_node e = child(s, end);
      if (!e) fail(s, std::string("has no <") + end + ">");
      const pugi::xml_node n = lookup(e, text_of(e));
      if (local_name(n) != "TopologyNode") fail(e, "refers to a <" + std::string(n.name()) + ">, not a <TopologyNode>");
      ks.append_child(std::string(end) == "StartNode" ? "Start_node" : "End_node")
          .text()
          .set(node_id.at(n.attribute("id").value()).c_str());
    }
  }
}

std::string VecReader::kbl_text(const pugi::xml_node& root) {
  pugi::xml_document kdoc;
  pugi::xml_node k = kdoc.append_child("kbl:KBL_container");
  k.append_attribute("xmlns:kbl") = "http://www.prostep.org/Car_electric_container/KBL2.3/KBLSchema";
  k.append_attribute("xmlns:xsi") = "http://www.w3.org/2001/XMLSchema-instance";
  k.append_attribute("id") = root.attribute("id").value();
  k.append_attribute("version_id") = "2.4";
  pugi::xml_node harness = k.append_child("Harness");
  harness.append_attribute("id") = "loom.harness";
  const auto contacts = write_contacts(harness);
  write_wires(k, harness);
  const auto node_id = write_nodes(k, contacts);
  write_routings(k);
  write_segments(k, node_id);
  std::ostringstream os;
  kdoc.save(os, "  ");
  return os.str();
}

/// The VEC line of the element a line of the KBL text stands for (0 if none).
int VecReader::vec_line(const std::map<int, std::string>& ids, int kbl_line) const {
  const auto id = ids.find(kbl_line);
  const auto src = id == ids.end() ? kbl_source_.end() : kbl_source_.find(id->second);
  return src == kbl_source_.end() ? 0 : line(src->second);
}

/// The lines the KBL reader recorded (of the KBL text) made the VEC file's: those of ports,
/// branch points, segments, cables, clamps, and the "(line N)" of its notes.
void VecReader::to_vec_lines(const std::string& kbl, Harness& h, KblOrigin& origin) const {
  const auto ids = kbl_ids_by_line(kbl);
  for (auto& p : h.ports) p.line = vec_line(ids, p.line);
  for (auto& b : h.branches) b.line = vec_line(ids, b.line);
  for (auto& s : h.segments) s.line = vec_line(ids, s.line);
  for (auto& c : h.cables) c.line = vec_line(ids, c.line);
  for (auto& c : h.clamps) c.line = vec_line(ids, c.line);
  const std::string tag = "(line ";
  for (auto& note : origin.notes)
    for (auto at = note.find(tag); at != std::string::npos; at = note.find(tag, at + 1)) {
      const auto digits = note.find_first_not_of("0123456789", at + tag.size());
      if (digits == at + tag.size()) continue;
      const int l = std::atoi(note.c_str() + at + tag.size());
      note.replace(at + tag.size(), digits - at - tag.size(), std::to_string(vec_line(ids, l)));
    }
}

Harness VecReader::read(const pugi::xml_document& doc) {
  const pugi::xml_node root = doc.document_element();
  const SourceLocation where{file_, line(root), "<" + std::string(root.name()) + ">"};
  if (local_name(root) != "VecContent")
    throw InputError(where, "not a VEC file: the root element is <" + std::string(root.name()) +
                                ">, a VEC file's is <vec:VecContent>");
  int geometry_3d = 0;
  kbl_dom::for_each_node(root, [&](const pugi::xml_node& n) {
    if (n.type() != pugi::node_element) return;
    const std::string name(local_name(n));
    by_name_[name].push_back(n);
    // VEC keeps 3D geometry in GeometryNode3D, GeometrySegment3D, CartesianPoint3D, ...
    if (name.find("3D") != std::string::npos) ++geometry_3d;
    if (auto a = n.attribute("id")) {
      const auto [it, fresh] = by_id_.emplace(a.value(), n);
      if (!fresh) fail(n, "duplicate id '" + std::string(a.value()) + "' (also line " + std::to_string(line(it->second)) + ")");
    }
  });
  const std::string version = child(root, "VecVersion").child_value();
  auto n = [&](const char* what) { return std::to_string(all(what).size()) + " " + what; };
  const std::string holds = "VEC " + (version.empty() ? std::string("(no VecVersion)") : version) + " with " +
                            n("TopologyNode") + ", " + n("TopologySegment") + ", " + n("Routing") + ", " +
                            n("WireElement") + ", " + n("ContactPoint");
  if (geometry_3d > 0)
    throw InputError(where, holds + ", and " + std::to_string(geometry_3d) +
                                " elements of 3D geometry, which loom does not read from VEC: give the harness as "
                                "KBL 2.3/2.4 (.kbl), or the VEC without its 3D geometry (topology only, placed by "
                                "the scene)");
  if (all("TopologyNode").empty())
    throw InputError(where, holds + ": no <TopologyNode>, no harness topology to route");
  const std::string kbl = kbl_text(root);
  Harness h;
  try {
    h = parse_harness_kbl(kbl, file_);
  } catch (const InputError& e) {
    std::string reason = e.reason();
    if (reason.find("cycle") != std::string::npos && !all("VariantConfiguration").empty())
      reason += " (the file holds " + std::to_string(all("VariantConfiguration").size()) +
                " variant configurations; loom routes one harness tree: give one variant's topology)";
    const auto ids = kbl_ids_by_line(kbl);
    const auto id = ids.find(e.where().line);
    const auto src = id == ids.end() ? kbl_source_.end() : kbl_source_.find(id->second);
    if (src == kbl_source_.end()) throw InputError(where, reason + " (in the file's topology read as KBL)");
    throw InputError({file_, line(src->second), describe(src->second)}, reason);
  }
  auto origin = std::make_shared<KblOrigin>(*h.kbl);
  to_vec_lines(kbl, h, *origin);
  origin->version = "2.4 (read from VEC " + version + ")";
  origin->notes.insert(origin->notes.begin(), holds + " and no 3D geometry, read as its KBL 2.4 equivalent; routed "
                                                     "output in KBL (routed.kbl) is that KBL with the routed geometry");
  origin->notes.insert(origin->notes.begin() + 1, notes_.begin(), notes_.end());
  h.kbl = std::move(origin);
  return h;
}

}  // namespace

Harness parse_harness_vec(const std::string& text, const std::string& name_for_errors) {
  const LineMap lines(text);
  pugi::xml_document doc;
  const auto res = doc.load_buffer(text.data(), text.size());
  if (!res) throw InputError({name_for_errors, lines.line(res.offset), ""}, std::string("malformed XML: ") + res.description());
  return VecReader(text, name_for_errors).read(doc);
}

Harness read_harness_vec(const std::filesystem::path& path) {
  require_input_file(path, "harness file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError({path.string(), 0, ""}, "cannot read harness file");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return parse_harness_vec(text, path.string());
}

}  // namespace loom
