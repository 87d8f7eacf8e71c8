// KBL 2.3 / 2.4 into loom's harness model (kbl_read.hpp).
#include "core/io/kbl_read.hpp"

#include "core/bspline_ops.hpp"
#include "core/error.hpp"
#include "core/harness_topology.hpp"
#include "core/io/input_file.hpp"
#include "core/io/kbl_curve.hpp"
#include "core/io/kbl_dom.hpp"
#include "core/io/line_map.hpp"

#include <pugixml.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <optional>
#include <set>
#include <sstream>
#include <string_view>
#include <stdexcept>
#include <tuple>
#include <unordered_map>

namespace loom {

namespace {

using kbl_dom::child;
using kbl_dom::describe;
using kbl_dom::children;
using kbl_dom::local_name;

/// Largest angle, degrees, between a Start_vector or End_vector and the curve's own tangent
/// there before the reader says so (the VW samples agree to 1e-5 degrees).
constexpr double kTangentNoteDeg = 1.0;
/// Relative and absolute difference between a segment's Virtual_length and the length of
/// its curve before the reader says so (the samples agree to 2e-6 relative).
constexpr double kLengthNoteRel = 1e-3;
constexpr double kLengthNoteAbs = 0.01;
/// Samples per knot span in the search for the point of a curve closest to a node it
/// overruns; the best is refined by golden section within its neighbours.
constexpr int kClosestSamplesPerSpan = 64;

std::string trimmed(const std::string& s) {
  const auto a = s.find_first_not_of(" \t\r\n");
  if (a == std::string::npos) return {};
  return s.substr(a, s.find_last_not_of(" \t\r\n") - a + 1);
}

/// Whitespace-separated tokens of a text (IDREFS).
std::vector<std::string> tokens(const std::string& s) {
  std::istringstream in(s);
  std::vector<std::string> out;
  for (std::string t; in >> t;) out.push_back(t);
  return out;
}

/// A figure for a note: 6 significant digits ("9.8", "219.801").
std::string figure(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

double angle_deg(const Vec3& a, const Vec3& b) { return std::atan2(a.cross(b).norm(), a.dot(b)) * 180.0 / M_PI; }

/// A KBL Node as the reader sees it.
struct NodeRec {
  pugi::xml_node el;
  std::optional<Vec3> position;
  pugi::xml_node flat_point;  ///< its Cartesian_point when that has 2 coordinates (formboard)
  std::vector<std::string> components;  ///< Referenced_components
  std::string loom_id;
  bool port = false;
  std::string port_name;  ///< the Id of the connector, terminal or box there, if any
};

/// A KBL Segment as the reader sees it.
struct SegmentRec {
  pugi::xml_node el;
  int from = -1, to = -1;  ///< node indices
  std::optional<Vec3> start_vector, end_vector;
};

/// One end of a wire or core: the node its contact point sits at.
struct WireEnds {
  pugi::xml_node connection;
  int node[2] = {-1, -1};
};

class KblReader {
 public:
  KblReader(const std::string& text, std::string file) : lines_(text), file_(std::move(file)) {}

  Harness read(const pugi::xml_document& doc, std::shared_ptr<const std::string> text);

 private:
  int line(const pugi::xml_node& n) const { return lines_.line(n.offset_debug()); }

  [[noreturn]] void fail(const pugi::xml_node& n, const std::string& reason) const {
    throw InputError({file_, line(n), describe(n)}, reason);
  }

  static std::string text_of(const pugi::xml_node& n) { return trimmed(n.child_value()); }

  /// The element an id refers to; a missing one is a fault of `from`.
  pugi::xml_node lookup(const pugi::xml_node& from, const std::string& id, const std::string& role) const {
    const auto it = by_id_.find(id);
    if (it == by_id_.end()) fail(from, role + " refers to '" + id + "', which no element of the file has as its id");
    return it->second;
  }
  /// The element named by the text of child `name` of `n` (empty if the child is absent).
  pugi::xml_node ref(const pugi::xml_node& n, const char* name) const {
    const pugi::xml_node c = child(n, name);
    if (!c) return {};
    const std::string id = text_of(c);
    if (id.empty()) fail(c, std::string("<") + name + "> is empty");
    return lookup(c, id, std::string("<") + name + ">");
  }

  double number(const pugi::xml_node& n) const {
    const std::string v = text_of(n);
    char* end = nullptr;
    const double d = std::strtod(v.c_str(), &end);
    if (v.empty() || end == v.c_str() || *end != '\0') fail(n, "not a number: '" + v + "'");
    if (!std::isfinite(d)) fail(n, "not finite: '" + v + "'");
    if (std::abs(d) > kMaxInputMagnitude)
      fail(n, v + " is beyond ±" + full_precision(kMaxInputMagnitude) + " (millimetres)");
    return d;
  }

  /// A 3D vector given as three repeated elements (Start_vector, End_vector, U, V);
  /// nullopt when absent or of zero length.
  std::optional<Vec3> vector3(const pugi::xml_node& n, const char* name) const {
    const auto parts = children(n, name);
    if (parts.empty()) return std::nullopt;
    if (parts.size() != 3) fail(parts.front(), std::string("<") + name + "> needs 3 values, found " + std::to_string(parts.size()));
    const Vec3 v(number(parts[0]), number(parts[1]), number(parts[2]));
    if (!(v.cwiseAbs().maxCoeff() > 0.0)) return std::nullopt;
    return stable_unit_direction(v);
  }

  /// A Cartesian_point as a 3D position; 2D points (a formboard drawing) are refused.
  Vec3 point(const pugi::xml_node& cp) const {
    if (local_name(cp) != "Cartesian_point") fail(cp, "is not a <Cartesian_point>");
    const auto c = children(cp, "Coordinates");
    if (c.size() == 2)
      fail(cp, "has 2 coordinates: this KBL holds 2D (formboard) geometry only; loom needs the 3D (DMU) positions of "
               "the nodes and centre curves");
    if (c.size() != 3) fail(cp, "needs 3 coordinates, found " + std::to_string(c.size()));
    return {number(c[0]), number(c[1]), number(c[2])};
  }

  /// Millimetres (or square millimetres for `power` 2) per unit of a value's Unit_component.
  double unit_factor(const pugi::xml_node& value, int power) const;
  /// A Numerical_value (Value_component with its Unit_component) in mm (power 1) or mm²
  /// (power 2).
  double measure(const pugi::xml_node& value, int power) const {
    const pugi::xml_node v = child(value, "Value_component");
    if (!v) fail(value, "has no <Value_component>");
    return number(v) * unit_factor(value, power);
  }

  void index_ids(const pugi::xml_node& root);
  void read_nodes(const pugi::xml_node& root);
  void find_ports(const pugi::xml_node& harness);
  void read_segments(const pugi::xml_node& root, Harness& h);
  std::optional<BSplineData> segment_curve(const SegmentRec& s);
  Centerline trim_to_nodes(const SegmentRec& s, Centerline c, const pugi::xml_node& curve_el);
  void port_directions(Harness& h);
  void read_cables(const pugi::xml_node& harness, Harness& h);
  CablePhysical wire_physical(const pugi::xml_node& part, const pugi::xml_node& occurrence, bool need_diameter);
  std::optional<WireEnds> wire_ends(const pugi::xml_node& connection);
  void segment_diameters(const HarnessTopology& topo, Harness& h);
  void check_routings(const pugi::xml_node& root, const HarnessTopology& topo, const Harness& h);
  void read_fixings(Harness& h);
  std::optional<double> nominal_length(const pugi::xml_node& segment) const;
  void count_ignored(const pugi::xml_node& root, const pugi::xml_node& harness);

  LineMap lines_;
  std::string file_;
  std::unordered_map<std::string, pugi::xml_node> by_id_;
  std::vector<NodeRec> nodes_;
  std::unordered_map<std::string, int> node_index_;  ///< KBL Node id → index
  std::unordered_map<std::string, int> occurrence_node_;  ///< component occurrence id → node index
  std::unordered_map<std::string, int> contact_node_;     ///< contact point id → node index (−1: none)
  std::vector<SegmentRec> segments_;
  std::map<std::string, std::vector<pugi::xml_node>> cable_connections_;  ///< loom cable id → its connections
  std::vector<std::optional<double>> file_diameter_;  ///< per segment, from its cross-section
  KblOrigin origin_;
  /// No node has a 3D position (a formboard drawing or bare topology): ports wait for the
  /// scene's placement, branch points for the router, and 2D centre curves are not read.
  bool topology_only_ = false;
  int wires_ = 0, cores_ = 0, multicores_ = 0;
};

double KblReader::unit_factor(const pugi::xml_node& value, int power) const {
  const pugi::xml_node unit = ref(value, "Unit_component");
  if (!unit) return 1.0;  // no unit given: millimetres, as the coordinates
  const std::string si = text_of(child(unit, "Si_unit_name"));
  const std::string prefix = text_of(child(unit, "Si_prefix"));
  const std::string dim = text_of(child(unit, "Si_dimension"));
  const std::string name = text_of(child(unit, "Unit_name"));
  double metre_in_mm = 0.0;
  if (si == "metre") {
    static const std::map<std::string, double> prefixes{{"", 1000.0}, {"milli", 1.0}, {"centi", 10.0},
                                                        {"deci", 100.0}, {"micro", 1e-3}, {"kilo", 1e6}};
    const auto it = prefixes.find(prefix);
    if (it != prefixes.end()) metre_in_mm = it->second;
  } else if (si.empty() && (name == "mm" || name == "mm2" || name == "mm^2" || name == "mm²")) {
    metre_in_mm = 1.0;
  }
  const int unit_power = dim == "square" ? 2 : dim == "cubic" ? 3 : (name == "mm2" || name == "mm^2" || name == "mm²") ? 2 : 1;
  if (!(metre_in_mm > 0.0) || unit_power != power)
    fail(value, std::string("its unit <") + unit.name() + " id=\"" + unit.attribute("id").value() + "\"> is not " +
                    (power == 1 ? "a length" : "an area") + " loom knows (" +
                    (si.empty() ? "'" + name + "'" : prefix + si + (dim.empty() ? "" : " " + dim)) + ")");
  return std::pow(metre_in_mm, power);
}

void KblReader::index_ids(const pugi::xml_node& root) {
  by_id_.reserve(lines_.count() / 2);  // about one id per two lines in KBL
  kbl_dom::for_each_node(root, [&](const pugi::xml_node& n) {
    if (n.type() != pugi::node_element) return;
    if (auto a = n.attribute("id")) {
      const auto [it, fresh] = by_id_.emplace(a.value(), n);
      if (!fresh) fail(n, "duplicate id '" + std::string(a.value()) + "' (also line " + std::to_string(line(it->second)) + ")");
    }
  });
}

void KblReader::read_nodes(const pugi::xml_node& root) {
  for (auto el : children(root, "Node")) {
    NodeRec r;
    r.el = el;
    const std::string id = el.attribute("id").value();
    if (id.empty()) fail(el, "a <Node> needs an id");
    if (const pugi::xml_node cp = ref(el, "Cartesian_point")) {
      if (children(cp, "Coordinates").size() == 2) r.flat_point = cp;
      else r.position = point(cp);
    }
    for (auto c : children(el, "Referenced_components"))
      for (const auto& t : tokens(c.child_value())) {
        lookup(c, t, "<Referenced_components>");
        r.components.push_back(t);
      }
    node_index_[id] = static_cast<int>(nodes_.size());
    nodes_.push_back(std::move(r));
  }
  for (std::size_t i = 0; i < nodes_.size(); ++i)
    for (const auto& c : nodes_[i].components) occurrence_node_.emplace(c, static_cast<int>(i));
  // A file is either 3D (DMU) or a drawing: a 2D point among 3D ones has no 3D position to
  // take, and guessing one would route the harness somewhere the file does not say.
  const auto in_3d = std::count_if(nodes_.begin(), nodes_.end(), [](const NodeRec& n) { return n.position.has_value(); });
  topology_only_ = in_3d == 0;
  if (!topology_only_)
    for (const auto& n : nodes_)
      if (n.flat_point)
        fail(n.flat_point, "has 2 coordinates: a 2D (formboard) point of node '" + std::string(n.el.attribute("id").value()) +
                               "' while " + std::to_string(in_3d) + " other nodes have 3D (DMU) positions; loom needs "
                               "the 3D positions of all nodes, or of none (topology only, placed by the scene)");
}

void KblReader::find_ports(const pugi::xml_node& harness) {
  // A contact point sits where its connector (or component box) is, or where one of its
  // associated parts (a ring terminal placed on its own) is.
  for (auto occ : harness.children()) {
    if (occ.type() != pugi::node_element) continue;
    for (auto cp : children(occ, "Contact_points")) {
      int node = -1;
      if (auto it = occurrence_node_.find(occ.attribute("id").value()); it != occurrence_node_.end()) node = it->second;
      for (auto a : children(cp, "Associated_parts"))
        for (const auto& t : tokens(a.child_value())) {
          lookup(a, t, "<Associated_parts>");
          if (auto it = occurrence_node_.find(t); node < 0 && it != occurrence_node_.end()) node = it->second;
        }
      contact_node_[cp.attribute("id").value()] = node;
    }
  }
  // A node is a port where a connector, terminal or component box sits; its name is that
  // component's Id (a connector's before a terminal's).
  for (auto& n : nodes_)
    for (int pass = 0; pass < 2 && n.port_name.empty(); ++pass)
      for (const auto& c : n.components) {
        const pugi::xml_node el = by_id_.at(c);
        const std::string_view kind = local_name(el);
        const bool wanted = pass == 0 ? (kind == "Connector_occurrence" || kind == "Component_box_occurrence")
                                      : kind == "Special_terminal_occurrence";
        if (!wanted) continue;
        n.port = true;
        n.port_name = text_of(child(el, "Id"));
        if (!n.port_name.empty()) break;
      }
}


/// Largest angle, radians, between the tangents of two centre curves where they meet that
/// is taken for a smooth joint: CAD systems join curves tangent to ~1e-6 rad (the VW
/// samples: 3e-7), and the audit would see any jump as a kink of zero bend radius.
constexpr double kKblSmoothJoint = 1e-4;

/// Makes the joint of two clamped curves exactly tangent when it nearly is: the legs next to
/// the joint (prev's last, next's first) are turned onto their mean direction, keeping their
/// lengths (the curves move by at most angle × leg).
void smooth_joint(std::vector<Vec3>& prev, std::vector<Vec3>& next) {
  const std::size_t n = prev.size() - 1;
  const Vec3 a = prev[n] - prev[n - 1], b = next[1] - next[0];
  if (!(a.norm() > 0.0 && b.norm() > 0.0)) return;
  const Vec3 ta = a.normalized(), tb = b.normalized();
  if (std::atan2(ta.cross(tb).norm(), ta.dot(tb)) > kKblSmoothJoint) return;  // a real kink: kept
  const Vec3 t = (ta + tb).normalized();
  prev[n - 1] = prev[n] - a.norm() * t;
  next[1] = next[0] + b.norm() * t;
}

/// The point of `c` closest to `q`: dense samples per knot span, the best refined by golden
/// section between its neighbours. Returns (parameter, distance).
std::pair<double, double> closest_on(const Centerline& c, const Vec3& q) {
  const auto& br = c.breakpoints();
  std::vector<double> us;
  for (std::size_t k = 0; k + 1 < br.size(); ++k)
    for (int i = 0; i < kClosestSamplesPerSpan; ++i)
      us.push_back(br[k] + (br[k + 1] - br[k]) * i / kClosestSamplesPerSpan);
  us.push_back(c.u_max());
  std::size_t best = 0;
  double best_d = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < us.size(); ++i) {
    const double d = (c.position(us[i]) - q).norm();
    if (d < best_d) best_d = d, best = i;
  }
  double a = us[best > 0 ? best - 1 : 0], b = us[std::min(best + 1, us.size() - 1)];
  const double g = 0.5 * (std::sqrt(5.0) - 1.0);
  for (int it = 0; it < 100 && b - a > 1e-15 * std::max(1.0, std::abs(b)); ++it) {
    const double x1 = b - g * (b - a), x2 = a + g * (b - a);
    if ((c.position(x1) - q).norm() < (c.position(x2) - q).norm()) b = x2;
    else a = x1;
  }
  const double u = 0.5 * (a + b);
  const double d = (c.position(u) - q).norm();
  return d < best_d ? std::make_pair(u, d) : std::make_pair(us[best], best_d);
}

Centerline KblReader::trim_to_nodes(const SegmentRec& s, Centerline c, const pugi::xml_node& curve_el) {
  double ua = c.u_min(), ub = c.u_max();
  for (int end = 0; end < 2; ++end) {
    const NodeRec& n = nodes_[static_cast<std::size_t>(end == 0 ? s.from : s.to)];
    if (!n.position) continue;  // an unplaced node takes the curve's end
    const double u_end = end == 0 ? c.u_min() : c.u_max();
    if ((c.position(u_end) - *n.position).norm() <= kKblNodeGap) continue;
    // The curve overruns its node (or stops short of it): it is trimmed where it passes it.
    const auto [u, d] = closest_on(c, *n.position);
    if (d > kKblNodeGap)
      fail(curve_el, std::string("the centre curve of segment '") + s.el.attribute("id").value() + "' " +
                         (end == 0 ? "starts " : "ends ") + full_precision((c.position(u_end) - *n.position).norm()) +
                         " mm from its " + (end == 0 ? "start" : "end") + " node '" + n.el.attribute("id").value() +
                         "' and passes it " + full_precision(d) + " mm away at the closest (at most " +
                         full_precision(kKblNodeGap) + " mm)");
    (end == 0 ? ua : ub) = u;
  }
  if (!(ua < ub))
    fail(curve_el, std::string("the centre curve of segment '") + s.el.attribute("id").value() +
                       "' passes its end node before its start node");
  if (ua > c.u_min() || ub < c.u_max()) {
    origin_.notes.push_back(std::string("segment '") + s.el.attribute("id").value() + "': its centre curve overruns " +
                            (ua > c.u_min() && ub < c.u_max() ? "both nodes" : ua > c.u_min() ? "its start node" : "its end node") +
                            " and is trimmed there (" + figure(c.length()) + " mm of curve, " +
                            figure(sub_curve(c, ua, ub).length()) + " mm between the nodes)");
    c = sub_curve(c, ua, ub);
  } else {
    c = clamped(c);
  }
  // Within the gap: the ends are put on the nodes (the curve moves by at most kKblNodeGap).
  std::vector<Vec3> cps = c.control_points();
  if (nodes_[static_cast<std::size_t>(s.from)].position) cps.front() = *nodes_[static_cast<std::size_t>(s.from)].position;
  if (nodes_[static_cast<std::size_t>(s.to)].position) cps.back() = *nodes_[static_cast<std::size_t>(s.to)].position;
  return Centerline(c.degree(), c.knots(), std::move(cps));
}

std::optional<BSplineData> KblReader::segment_curve(const SegmentRec& s) {
  const auto curves = children(s.el, "Center_curve");
  if (curves.empty()) return std::nullopt;  // not routed yet: the router plans it
  if (topology_only_) {
    ++origin_.ignored["Center_curve (2D, of a topology-only file)"];
    return std::nullopt;  // a formboard curve: the router plans the 3D one
  }
  std::optional<Centerline> joined;
  const NodeRec& a = nodes_[static_cast<std::size_t>(s.from)];
  for (const auto& cel : curves) {
    const pugi::xml_node deg = child(cel, "Degree");
    if (!deg) fail(cel, "has no <Degree>");
    const double dv = number(deg);
    if (dv != std::floor(dv) || dv < 1 || dv > 7) fail(deg, "degree must be an integer in 1..7, got " + text_of(deg));
    std::vector<Vec3> cps;
    for (auto cp : children(cel, "Control_points"))
      for (const auto& t : tokens(cp.child_value())) cps.push_back(point(lookup(cp, t, "<Control_points>")));
    Centerline c;
    try {
      c = clamped(kbl_uniform_curve(static_cast<int>(dv), std::move(cps)));
    } catch (const std::invalid_argument& e) {
      fail(cel, e.what());
    }
    // Curves follow each other end to start; one given the other way round is turned.
    const Vec3 from = joined ? joined->position(joined->u_max()) : a.position.value_or(c.position(c.u_min()));
    if ((c.position(c.u_max()) - from).norm() < (c.position(c.u_min()) - from).norm()) c = reversed(c);
    if (joined) {
      const double gap = (c.position(c.u_min()) - from).norm();
      if (gap > kKblNodeGap)
        fail(cel, "does not start where the segment's previous centre curve ends (gap " + full_precision(gap) +
                      " mm, at most " + full_precision(kKblNodeGap) + ")");
      std::vector<Vec3> cp = c.control_points();
      cp.front() = from;
      std::vector<Vec3> prev = joined->control_points();
      smooth_joint(prev, cp);
      joined = join(Centerline(joined->degree(), joined->knots(), std::move(prev)),
                    Centerline(c.degree(), c.knots(), std::move(cp)));
    } else {
      joined = std::move(c);
    }
  }
  Centerline c = trim_to_nodes(s, std::move(*joined), curves.front());
  if (!(c.length() > 0.0)) fail(curves.front(), "the centre curve has zero length");
  // What the file says about its own curve, checked (a disagreement is said, not refused).
  const std::string sid = s.el.attribute("id").value();
  if (const pugi::xml_node vl = child(s.el, "Virtual_length")) {
    const double want = measure(vl, 1);
    if (std::abs(want - c.length()) > std::max(kLengthNoteAbs, kLengthNoteRel * want))
      origin_.notes.push_back("segment '" + sid + "': Virtual_length " + figure(want) +
                              " mm, its centre curve is " + figure(c.length()) + " mm long");
  }
  Vec3 d0[2], d1[2];
  c.evaluate(c.u_min(), 1, d0);
  c.evaluate(c.u_max(), 1, d1, true);
  for (const auto& [given, tangent, name] :
       {std::tuple(s.start_vector, d0[1], "Start_vector"), std::tuple(s.end_vector, d1[1], "End_vector")})
    if (given && tangent.norm() > 0.0 && angle_deg(*given, tangent) > kTangentNoteDeg)
      origin_.notes.push_back("segment '" + sid + "': its " + name + " is " + figure(angle_deg(*given, tangent)) +
                              " degrees from the tangent of its centre curve");
  return BSplineData{c.degree(), c.knots(), c.control_points()};
}

void KblReader::read_segments(const pugi::xml_node& root, Harness& h) {
  for (auto el : children(root, "Segment")) {
    SegmentRec r;
    r.el = el;
    for (const auto& [name, end] : {std::pair("Start_node", &r.from), std::pair("End_node", &r.to)}) {
      const pugi::xml_node n = ref(el, name);
      if (!n) fail(el, std::string("has no <") + name + ">");
      if (local_name(n) != "Node") fail(child(el, name), std::string("<") + name + "> refers to a <" + n.name() + ">, not a <Node>");
      *end = node_index_.at(n.attribute("id").value());
    }
    if (!topology_only_) {  // a drawing's tangents are 2D
      r.start_vector = vector3(el, "Start_vector");
      r.end_vector = vector3(el, "End_vector");
    }
    Segment seg;
    seg.from = nodes_[static_cast<std::size_t>(r.from)].loom_id;
    seg.to = nodes_[static_cast<std::size_t>(r.to)].loom_id;
    seg.line = line(el);
    seg.bspline = segment_curve(r);
    seg.nominal_length = nominal_length(el);
    origin_.segment_curves.push_back(seg.bspline);
    // The bundle's nominal diameter from its cross-section (the largest one given).
    std::optional<double> area;
    for (auto csa : children(el, "Cross_section_area_information"))
      if (const pugi::xml_node a = child(csa, "Area")) {
        const double v = measure(a, 2);
        if (!(v > 0.0)) fail(a, "a cross-section area must be positive, got " + full_precision(v));
        area = std::max(area.value_or(0.0), v);
      }
    file_diameter_.push_back(area ? std::optional<double>(2.0 * std::sqrt(*area / M_PI)) : std::nullopt);
    origin_.segment_ids.push_back(el.attribute("id").value());
    segments_.push_back(r);
    h.segments.push_back(std::move(seg));
  }
}

void KblReader::port_directions(Harness& h) {
  // A port's exit direction is the tangent of its first segment leaving it: the segment's
  // Start_vector (or End_vector reversed), else its curve's tangent, else towards its other
  // node.
  std::vector<bool> done(nodes_.size(), false);
  for (std::size_t k = 0; k < segments_.size(); ++k) {
    const SegmentRec& s = segments_[k];
    for (int end = 0; end < 2; ++end) {
      const int n = end == 0 ? s.from : s.to;
      if (done[static_cast<std::size_t>(n)] || !nodes_[static_cast<std::size_t>(n)].port) continue;
      std::optional<Vec3> d = end == 0 ? s.start_vector : s.end_vector;
      if (d && end == 1) d = -*d;
      if (!d && h.segments[k].bspline) {
        const auto& b = *h.segments[k].bspline;
        const Centerline c(b.degree, b.knots, b.control_points);
        Vec3 der[2];
        c.evaluate(end == 0 ? c.u_min() : c.u_max(), 1, der, end == 1);
        if (der[1].norm() > 0.0) d = (end == 0 ? 1.0 : -1.0) * der[1].normalized();
      }
      const auto& other = nodes_[static_cast<std::size_t>(end == 0 ? s.to : s.from)].position;
      const auto& here = nodes_[static_cast<std::size_t>(n)].position;
      if (!d && other && here && (*other - *here).norm() > 0.0) d = (*other - *here).normalized();
      if (!d) continue;
      h.ports[static_cast<std::size_t>(h.find_port(nodes_[static_cast<std::size_t>(n)].loom_id))].direction = *d;
      done[static_cast<std::size_t>(n)] = true;
    }
  }
}


CablePhysical KblReader::wire_physical(const pugi::xml_node& part, const pugi::xml_node& occurrence, bool need_diameter) {
  CablePhysical ph;
  ph.type = text_of(child(part, "Part_number"));
  if (ph.type.empty()) ph.type = text_of(child(part, "Id"));
  for (const char* colour : {"Cover_colour", "Core_colour"})
    for (auto c : children(part, colour)) {
      const std::string v = text_of(child(c, "Colour_value"));
      if (!v.empty()) ph.color += (ph.color.empty() ? "" : "/") + v;
    }
  if (const pugi::xml_node d = child(part, "Outside_diameter")) ph.diameter = measure(d, 1);
  else if (need_diameter)
    fail(part, std::string("has no <Outside_diameter>: loom needs the outer diameter of ") +
                   describe(occurrence) + " (line " + std::to_string(line(occurrence)) + ") to route and audit it");
  if (need_diameter && !(ph.diameter > 0.0))
    fail(child(part, "Outside_diameter"), "the outside diameter must be positive, got " + full_precision(ph.diameter));
  if (const pugi::xml_node b = child(part, "Bend_radius")) {
    ph.min_bend_radius = measure(b, 1);
    if (ph.min_bend_radius < 0.0) fail(b, "a bend radius must not be negative, got " + full_precision(ph.min_bend_radius));
  }
  if (const pugi::xml_node a = child(part, "Cross_section_area")) ph.cross_section = measure(a, 2);
  return ph;
}

std::optional<WireEnds> KblReader::wire_ends(const pugi::xml_node& connection) {
  // The wire runs from its first extremity to its last (by Position_on_wire, else in order).
  std::vector<std::pair<double, pugi::xml_node>> ex;
  for (auto e : children(connection, "Extremities")) {
    const pugi::xml_node pos = child(e, "Position_on_wire");
    ex.emplace_back(pos ? number(pos) : static_cast<double>(ex.size()), e);
  }
  const std::string cid = text_of(child(connection, "Id")).empty() ? connection.attribute("id").value()
                                                                    : text_of(child(connection, "Id"));
  if (ex.size() < 2) {
    origin_.notes.push_back("connection '" + cid + "' (line " + std::to_string(line(connection)) + ") has " +
                            std::to_string(ex.size()) + " extremit" + (ex.size() == 1 ? "y" : "ies") +
                            ": no wire to route");
    return std::nullopt;
  }
  std::stable_sort(ex.begin(), ex.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
  if (ex.size() > 2)
    origin_.notes.push_back("connection '" + cid + "' has " + std::to_string(ex.size()) +
                            " extremities: routed from its first to its last");
  WireEnds w;
  w.connection = connection;
  for (int k = 0; k < 2; ++k) {
    const pugi::xml_node e = k == 0 ? ex.front().second : ex.back().second;
    const pugi::xml_node cp = ref(e, "Contact_point");
    if (!cp) fail(e, "has no <Contact_point>");
    const auto it = contact_node_.find(cp.attribute("id").value());
    if (it == contact_node_.end()) fail(child(e, "Contact_point"), "refers to a <" + std::string(cp.name()) + ">, not a contact point");
    if (it->second < 0) {
      origin_.notes.push_back("connection '" + cid + "': its contact point '" + cp.attribute("id").value() + "' of " +
                              describe(cp.parent()) + " sits at no node (no Node references its connector or "
                              "terminal): the wire is not routed");
      return std::nullopt;
    }
    w.node[k] = it->second;
  }
  return w;
}

void KblReader::read_cables(const pugi::xml_node& harness, Harness& h) {
  std::set<std::string> ids;
  auto unique_id = [&](std::string id, const pugi::xml_node& el) {
    if (id.empty() || ids.count(id)) id = el.attribute("id").value();
    ids.insert(id);
    return id;
  };
  auto add_port = [&](int n) {
    NodeRec& r = nodes_[static_cast<std::size_t>(n)];
    r.port = true;
    return r.loom_id;
  };
  // Cores of one multicore, collected first: the multicore is routed as its jacket when all
  // of its cores run between the same two nodes.
  std::map<std::string, std::vector<std::pair<WireEnds, pugi::xml_node>>> cores_of;
  std::vector<std::string> multicore_order;
  int within_one = 0;
  for (auto conn : children(harness, "Connection")) {
    const pugi::xml_node wire = ref(conn, "Wire");
    if (!wire) fail(conn, "has no <Wire>");
    const auto ends = wire_ends(conn);
    if (!ends) continue;
    if (ends->node[0] == ends->node[1]) {
      ++within_one;
      origin_.notes.push_back("connection '" + text_of(child(conn, "Id")) + "' joins two contacts at node '" +
                              nodes_[static_cast<std::size_t>(ends->node[0])].el.attribute("id").value() +
                              "': it does not leave the connector, nothing to route");
      continue;
    }
    if (local_name(wire) == "Core_occurrence") {
      const std::string jacket = wire.parent().attribute("id").value();
      if (!cores_of.count(jacket)) multicore_order.push_back(jacket);
      cores_of[jacket].emplace_back(*ends, wire);
      continue;
    }
    const pugi::xml_node part = ref(wire, "Part");
    if (!part) fail(wire, "has no <Part> (its General_wire)");
    Cable c;
    c.id = unique_id(text_of(child(conn, "Id")), conn);
    c.ports[0] = add_port(ends->node[0]);
    c.ports[1] = add_port(ends->node[1]);
    c.physical = wire_physical(part, wire, true);
    c.line = line(conn);
    origin_.wire_ids[c.id] = {wire.attribute("id").value()};
    cable_connections_[c.id] = {conn};
    ++wires_;
    h.cables.push_back(std::move(c));
  }
  for (const std::string& jid : multicore_order) {
    const auto& cores = cores_of[jid];
    const pugi::xml_node jacket = by_id_.at(jid);
    ++multicores_;
    cores_ += static_cast<int>(cores.size());
    const std::set<int> first{cores.front().first.node[0], cores.front().first.node[1]};
    bool together = true;
    for (const auto& [e, w] : cores) together = together && std::set<int>{e.node[0], e.node[1]} == first;
    const pugi::xml_node jpart = ref(jacket, "Part");
    if (!jpart) fail(jacket, "has no <Part> (its General_wire)");
    if (together) {
      Cable c;
      std::string name = text_of(child(jacket, "Special_wire_id"));
      if (name.empty()) name = text_of(child(jacket, "Wire_number"));
      c.id = unique_id(name, jacket);
      c.ports[0] = add_port(cores.front().first.node[0]);
      c.ports[1] = add_port(cores.front().first.node[1]);
      c.physical = wire_physical(jpart, jacket, true);
      c.line = line(jacket);
      origin_.wire_ids[c.id] = {jid};
      for (const auto& [e, w] : cores) {
        const pugi::xml_node cpart = ref(w, "Part");
        if (!cpart) fail(w, "has no <Part> (its Core)");
        std::string cid = text_of(child(w, "Wire_number"));
        c.cores.push_back({cid.empty() ? w.attribute("id").value() : cid, wire_physical(cpart, w, false)});
        origin_.wire_ids[c.id].push_back(w.attribute("id").value());
        cable_connections_[c.id].push_back(e.connection);
      }
      h.cables.push_back(std::move(c));
      continue;
    }
    origin_.notes.push_back("multicore " + describe(jacket) + " (line " + std::to_string(line(jacket)) +
                            "): its cores end at different nodes, so they are routed as single wires (the "
                            "jacket's diameter is not applied)");
    for (const auto& [e, w] : cores) {
      const pugi::xml_node cpart = ref(w, "Part");
      if (!cpart) fail(w, "has no <Part> (its Core)");
      Cable c;
      c.id = unique_id(text_of(child(e.connection, "Id")), e.connection);
      c.ports[0] = add_port(e.node[0]);
      c.ports[1] = add_port(e.node[1]);
      c.physical = wire_physical(cpart, w, true);
      c.line = line(e.connection);
      origin_.wire_ids[c.id] = {w.attribute("id").value()};
      cable_connections_[c.id] = {e.connection};
      h.cables.push_back(std::move(c));
    }
  }
  if (within_one) origin_.counts.emplace_back("connections within one connector (not routed)", within_one);
}

void KblReader::segment_diameters(const HarnessTopology& topo, Harness& h) {
  // The file's cross-section is the bundle's nominal diameter, never a reason to refuse it:
  // one smaller than a wire it carries cannot hold it and gives way to the bundle rule.
  for (std::size_t s = 0; s < h.segments.size(); ++s) {
    if (!file_diameter_[s]) continue;
    const double d = *file_diameter_[s];
    std::vector<double> ds;
    double largest = 0.0;
    std::string thickest;
    for (int c : topo.segment_cables(static_cast<int>(s))) {
      ds.push_back(h.cables[static_cast<std::size_t>(c)].physical.diameter);
      if (ds.back() > largest) largest = ds.back(), thickest = h.cables[static_cast<std::size_t>(c)].id;
    }
    const double rule = ds.size() > 1 ? bundle_diameter(ds) : largest;
    const std::string sid = "segment '" + origin_.segment_ids[s] + "'";
    if (d < largest) {
      origin_.notes.push_back(sid + ": its cross-section gives a diameter of " + figure(d) +
                              " mm, less than the " + figure(largest) + " mm of wire '" + thickest +
                              "' it carries: loom uses " + figure(rule) + " mm (" +
                              (ds.size() > 1 ? "1.2·√(Σd²) of its " + std::to_string(ds.size()) + " wires" : "the wire") + ")");
      continue;
    }
    if (d < rule)
      origin_.notes.push_back(sid + ": its cross-section gives a diameter of " + figure(d) + " mm, less than the " +
                              figure(rule) + " mm that 1.2·√(Σd²) of its " + std::to_string(ds.size()) +
                              " wires needs (kept: the file's nominal diameter)");
    h.segments[s].diameter = d;
  }
}

void KblReader::check_routings(const pugi::xml_node& root, const HarnessTopology& topo, const Harness& h) {
  std::unordered_map<std::string, int> cable_of_connection;
  for (std::size_t c = 0; c < h.cables.size(); ++c)
    for (const auto& conn : cable_connections_[h.cables[c].id])
      cable_of_connection[conn.attribute("id").value()] = static_cast<int>(c);
  std::unordered_map<std::string, int> segment_of;
  for (std::size_t s = 0; s < origin_.segment_ids.size(); ++s) segment_of[origin_.segment_ids[s]] = static_cast<int>(s);
  int checked = 0;
  std::set<int> with_routing;
  for (auto r : children(root, "Routing")) {
    const pugi::xml_node conn = ref(r, "Routed_wire");
    if (!conn) fail(r, "has no <Routed_wire>");
    std::set<int> given;
    for (auto sl : children(r, "Segments"))
      for (const auto& t : tokens(sl.child_value())) {
        const pugi::xml_node seg = lookup(sl, t, "<Segments>");
        if (local_name(seg) != "Segment") fail(sl, "'" + t + "' is a <" + seg.name() + ">, not a <Segment>");
        given.insert(segment_of.at(t));
      }
    const auto it = cable_of_connection.find(conn.attribute("id").value());
    if (it == cable_of_connection.end()) continue;  // a wire loom does not route (said in the notes)
    std::set<int> path;
    for (const SegmentUse& u : topo.cable_chain(it->second)) path.insert(u.segment);
    ++checked;
    with_routing.insert(it->second);
    if (given == path) continue;
    auto names = [&](const std::set<int>& ss) {
      std::string out;
      for (int s : ss) out += (out.empty() ? "" : " ") + origin_.segment_ids[static_cast<std::size_t>(s)];
      return out.empty() ? std::string("none") : out;
    };
    std::set<int> extra, missing;
    std::set_difference(given.begin(), given.end(), path.begin(), path.end(), std::inserter(extra, extra.end()));
    std::set_difference(path.begin(), path.end(), given.begin(), given.end(), std::inserter(missing, missing.end()));
    fail(r, "the routing of connection '" + text_of(child(conn, "Id")) + "' (wire of cable '" +
                h.cables[static_cast<std::size_t>(it->second)].id + "') differs from the path through the harness "
                "tree between its ends: it lists " + names(extra) + " off that path and misses " + names(missing) +
                " (the tree path is " + names(path) + ")");
  }
  origin_.counts.emplace_back("routings checked against the tree", checked);
  if (with_routing.size() < h.cables.size())
    origin_.notes.push_back(std::to_string(h.cables.size() - with_routing.size()) +
                            " cables have no <Routing>: they run along the tree path between their ends");
}


void KblReader::read_fixings(Harness& h) {
  // Fixings hold the bundle where the file places them (their Placement), else at their
  // Location (share of the segment's length from its start node) on the centre curve.
  int fixings = 0, protections = 0;
  std::set<std::string> protected_segments;
  for (std::size_t s = 0; s < segments_.size(); ++s) {
    const pugi::xml_node seg = segments_[s].el;
    for (auto fa : children(seg, "Fixing_assignment")) {
      const pugi::xml_node fix = ref(fa, "Fixing");
      if (!fix) fail(fa, "has no <Fixing>");
      Clamp c;
      c.id = text_of(child(fix, "Id"));
      if (c.id.empty()) c.id = fix.attribute("id").value();
      c.segment = static_cast<int>(s);
      c.line = line(fa);
      std::optional<Vec3> at;
      // A topology-only file places fixings on its drawing (2D), not in the vehicle.
      if (const pugi::xml_node pl = topology_only_ ? pugi::xml_node() : child(fix, "Placement"))
        if (const pugi::xml_node cp = ref(pl, "Cartesian_point")) {
          // A drawing's placement (2D) kept in a file that loom gave 3D geometry: the fixing
          // sits at its location on the segment instead.
          if (children(cp, "Coordinates").size() == 2)
            origin_.notes.push_back("fixing '" + c.id + "' (line " + std::to_string(c.line) +
                                    "): its placement is a 2D (formboard) point; placed by its location on the segment");
          else
            at = point(cp);
        }
      if (!at && h.segments[s].bspline) {
        const pugi::xml_node loc = child(fa, "Location");
        const double share = loc ? number(loc) : 0.5;
        if (share < 0.0 || share > 1.0) fail(loc, "a location along the segment must lie in 0..1, got " + text_of(loc));
        const auto& b = *h.segments[s].bspline;
        const Centerline curve(b.degree, b.knots, b.control_points);
        at = curve.position(curve.parameter_at_length(share * curve.length()));
      }
      if (!at) {
        origin_.notes.push_back("fixing '" + c.id + "' (line " + std::to_string(c.line) +
                                ") has no placement and its segment no centre curve: not placed");
        continue;
      }
      c.position = *at;
      h.clamps.push_back(std::move(c));
      ++fixings;
    }
    for (auto pa : children(seg, "Protection_area")) {
      if (const pugi::xml_node p = child(pa, "Associated_protection")) lookup(p, text_of(p), "<Associated_protection>");
      ++protections;
      protected_segments.insert(origin_.segment_ids[s]);
    }
  }
  origin_.counts.emplace_back("fixings (clamps)", fixings);
  if (protections)
    origin_.notes.push_back(std::to_string(protections) + " protection areas (tape, tube) on " +
                            std::to_string(protected_segments.size()) +
                            " segments: not modelled as material; each segment's cross-section (else the bundle "
                            "rule) gives its diameter");
}

std::optional<double> KblReader::nominal_length(const pugi::xml_node& segment) const {
  // Physical_length is the length to manufacture; a drawing's Virtual_length is the length
  // on the formboard (in a 3D file it is the centre curve's, checked in segment_curve).
  pugi::xml_node len = child(segment, "Physical_length");
  if (!len && topology_only_) len = child(segment, "Virtual_length");
  if (!len) return std::nullopt;
  const double mm = measure(len, 1);
  if (!(mm > 0.0)) fail(len, "a segment length must be positive, got " + full_precision(mm));
  return mm;
}

void KblReader::count_ignored(const pugi::xml_node& root, const pugi::xml_node& harness) {
  // Objects (elements with an id) under the container and the harness that loom has no use
  // for, by element name; plain values (Part_number, Description, ...) are not counted.
  static const std::set<std::string> used_root{"Cartesian_point", "Node", "Segment", "Routing", "Unit", "General_wire",
                                               "Fixing", "Wire_protection", "Harness"};
  static const std::set<std::string> used_harness{
      "Connection",          "Connector_occurrence",       "Special_terminal_occurrence", "Component_box_occurrence",
      "General_wire_occurrence", "Wire_occurrence",        "Special_wire_occurrence",     "Fixing_occurrence",
      "Wire_protection_occurrence"};
  for (auto n : root.children())
    if (n.type() == pugi::node_element && n.attribute("id") && !used_root.count(std::string(local_name(n))))
      ++origin_.ignored[std::string(local_name(n))];
  if (harness)
    for (auto n : harness.children())
      if (n.type() == pugi::node_element && n.attribute("id") && !used_harness.count(std::string(local_name(n))))
        ++origin_.ignored[std::string(local_name(n))];
}

Harness KblReader::read(const pugi::xml_document& doc, std::shared_ptr<const std::string> text) {
  const pugi::xml_node root = doc.document_element();
  if (!root) throw InputError({file_, 1, ""}, "no root element");
  if (local_name(root) != "KBL_container")
    fail(root, "not a KBL file: the root element is <" + std::string(root.name()) + ">, a KBL file's is <kbl:KBL_container>");
  index_ids(root);
  origin_.version = root.attribute("version_id").value();
  origin_.text = std::move(text);
  const pugi::xml_node harness = child(root, "Harness");
  Harness h;
  h.source_file = file_;
  h.units = Unit::Millimetre;
  h.name = harness ? text_of(child(harness, "Part_number")) : std::string();
  if (h.name.empty()) h.name = root.attribute("id").value();
  read_nodes(root);
  if (nodes_.empty() && children(root, "Segment").empty())
    fail(root, "holds no <Node> and no <Segment>: no harness topology and no 3D geometry, nothing for loom to route "
               "or audit (a parts list or a 2D drawing only)");
  if (harness) find_ports(harness);
  // Loom ids: a port is named by the connector, terminal or box it holds, a branch point by
  // its KBL id; every id is unique among both.
  std::set<std::string> taken;
  for (auto& n : nodes_) taken.insert(n.el.attribute("id").value());
  for (auto& n : nodes_) {
    const std::string own = n.el.attribute("id").value();
    n.loom_id = own;
    if (n.port && !n.port_name.empty() && !taken.count(n.port_name)) {
      n.loom_id = n.port_name;
      taken.insert(n.port_name);
    }
  }
  if (harness) read_cables(harness, h);
  for (auto& n : nodes_) {
    origin_.node_ids[n.loom_id] = n.el.attribute("id").value();
    if (n.port) {
      if (!n.position && !topology_only_)
        fail(n.el, "holds connector '" + n.loom_id + "' but has no <Cartesian_point>: a port needs its position");
      h.ports.push_back({n.loom_id, n.position.value_or(Vec3::Zero()), Vec3::UnitX(), line(n.el), n.position.has_value()});
    } else {
      h.branches.push_back({n.loom_id, n.position, line(n.el)});
    }
  }
  read_segments(root, h);
  port_directions(h);
  const HarnessTopology topo(h);  // ids, cycles, connectivity
  segment_diameters(topo, h);
  check_routings(root, topo, h);
  read_fixings(h);
  count_ignored(root, harness);
  int connectors = 0, ring = 0, boxes = 0, splices = 0;
  if (harness)
    for (auto n : harness.children()) {
      const std::string_view k = n.type() == pugi::node_element ? local_name(n) : std::string_view();
      if (k == "Component_box_occurrence") ++boxes;
      if (k != "Connector_occurrence") continue;
      const std::string usage = text_of(child(n, "Usage"));
      ++(usage == "ring terminal" ? ring : usage == "splice" ? splices : connectors);
    }
  origin_.counts.insert(origin_.counts.begin(),
                        {{"wires", wires_}, {"multicores", multicores_}, {"cores", cores_}, {"connectors", connectors},
                         {"ring terminals", ring}, {"splices", splices}, {"component boxes", boxes}});
  h.kbl = std::make_shared<const KblOrigin>(std::move(origin_));
  return h;
}

}  // namespace

Harness parse_harness_kbl(std::string text, const std::string& name_for_errors) {
  auto owned = std::make_shared<const std::string>(std::move(text));
  pugi::xml_document doc;
  const auto res = doc.load_buffer(owned->data(), owned->size(), kbl_dom::kKblParseFlags);
  const LineMap lines(*owned);
  if (!res) throw InputError({name_for_errors, lines.line(res.offset), ""}, std::string("malformed XML: ") + res.description());
  for (auto n : doc.children())
    if (n.type() == pugi::node_doctype)
      throw InputError({name_for_errors, lines.line(n.offset_debug()), ""},
                       "a document type declaration (<!DOCTYPE ...>) is not supported: its entities and attribute "
                       "defaults would be ignored");
  return KblReader(*owned, name_for_errors).read(doc, owned);
}

Harness read_harness_kbl(const std::filesystem::path& path) {
  require_input_file(path, "harness file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError({path.string(), 0, ""}, "cannot read harness file");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return parse_harness_kbl(std::move(text), path.string());
}

}  // namespace loom
