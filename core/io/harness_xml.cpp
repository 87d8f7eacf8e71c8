#include "core/io/harness_xml.hpp"

#include "core/error.hpp"
#include "core/harness_topology.hpp"
#include "core/io/atomic_file.hpp"
#include "core/io/input_file.hpp"
#include "core/io/line_map.hpp"

#include <pugixml.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <set>
#include <sstream>

namespace loom {

namespace {

/// Narrowest knot domain accepted for a <bspline>, relative to max(1, |knot|): the curve's
/// k-th derivative scales as 1/width^k and overflows long before 1e-100 (measured: a
/// domain of 1e-100 already broke the tube sweep, 1e-300 gave infinite positions).
constexpr double kMinKnotDomain = 1e-12;

/// Index of the first byte of `s` that does not belong to a valid UTF-8 sequence (overlong
/// forms, surrogates and code points beyond U+10FFFF included), or npos.
std::size_t first_invalid_utf8(const std::string& s) {
  std::size_t i = 0;
  while (i < s.size()) {
    const auto c = static_cast<unsigned char>(s[i]);
    std::size_t n = 0;
    unsigned long cp = 0;
    if (c < 0x80) { ++i; continue; }
    if (c >= 0xC2 && c <= 0xDF) { n = 1; cp = c & 0x1Fu; }
    else if (c >= 0xE0 && c <= 0xEF) { n = 2; cp = c & 0x0Fu; }
    else if (c >= 0xF0 && c <= 0xF4) { n = 3; cp = c & 0x07u; }
    else return i;
    for (std::size_t k = 1; k <= n; ++k) {
      if (i + k >= s.size()) return i;
      const auto d = static_cast<unsigned char>(s[i + k]);
      if ((d & 0xC0u) != 0x80u) return i;
      cp = (cp << 6) | (d & 0x3Fu);
    }
    if ((n == 2 && cp < 0x800) || (n == 3 && cp < 0x10000) || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF))
      return i;
    i += n + 1;
  }
  return std::string::npos;
}

/// Longest entity or character reference looked at ("&#x10FFFF;" and every predefined
/// entity fit); a longer one is not a reference pugixml or this reader knows.
constexpr std::size_t kMaxReferenceLength = 16;

/// What the harness reader accepts as references, for its messages.
constexpr const char* kKnownReferences =
    " (only &amp; &lt; &gt; &quot; &apos; and character references to XML characters; write a literal '&' as &amp;)";

/// True for a code point that XML 1.0 allows in a document (its production `Char`).
bool is_xml_char(unsigned long cp) {
  return cp == 0x9 || cp == 0xA || cp == 0xD || (cp >= 0x20 && cp <= 0xD7FF) || (cp >= 0xE000 && cp <= 0xFFFD) ||
         (cp >= 0x10000 && cp <= 0x10FFFF);
}

/// True for the body of a reference (between '&' and ';') that pugixml expands faithfully:
/// one of the five predefined entities, or a character reference to an XML character.
bool is_known_reference(const std::string& body) {
  for (const char* e : {"amp", "lt", "gt", "quot", "apos"})
    if (body == e) return true;
  if (body.size() < 2 || body[0] != '#') return false;
  const bool hex = body[1] == 'x';
  const std::size_t first = hex ? 2 : 1;
  if (first == body.size()) return false;
  unsigned long cp = 0;
  for (std::size_t i = first; i < body.size(); ++i) {
    const auto c = static_cast<unsigned char>(body[i]);
    if (hex ? !std::isxdigit(c) : !std::isdigit(c)) return false;
    cp = cp * (hex ? 16 : 10) + static_cast<unsigned long>(std::isdigit(c) ? c - '0' : std::tolower(c) - 'a' + 10);
    if (cp > 0x10FFFF) return false;
  }
  return is_xml_char(cp);
}

/// The first reference in `raw` (an attribute value or text as written, references not yet
/// expanded) that pugixml would not expand as XML does, or "": an entity other than the five
/// predefined ones stays as literal text, and `&#0;` cuts the value short.
std::string first_unknown_reference(const char* raw) {
  for (const char* amp = std::strchr(raw, '&'); amp; amp = std::strchr(amp + 1, '&')) {
    const char* semi = std::strchr(amp, ';');
    const std::size_t len = semi ? static_cast<std::size_t>(semi - amp) + 1 : std::strlen(amp);
    if (!semi || len > kMaxReferenceLength || !is_known_reference(std::string(amp + 1, semi)))
      return std::string(amp, std::min(len, kMaxReferenceLength));
  }
  return {};
}

/// Refuses markup that pugixml parses differently from XML, naming its line: a document type
/// declaration, which pugixml skips (its entities and attribute defaults would be lost; a
/// "billion laughs" file is harmless only because of that), and references it does not expand
/// as XML does (first_unknown_reference). `text` must be well-formed for pugixml; it is read a
/// second time with references left as written, so that any declared encoding is honoured.
void check_markup(const std::string& text, const std::string& file) {
  pugi::xml_document raw;
  const auto res =
      raw.load_buffer(text.data(), text.size(), (pugi::parse_default | pugi::parse_doctype) & ~pugi::parse_escapes);
  const LineMap lines(text);
  if (!res)  // only a document type declaration is parsed more strictly the second time
    throw InputError({file, lines.line(res.offset), ""}, std::string("malformed XML: ") + res.description());
  // Depth-first without recursion: the nesting is the file's to choose.
  for (pugi::xml_node n = raw.first_child(); n;) {
    const auto here = [&](const std::string& element, const std::string& reason) {
      throw InputError({file, lines.line(n.offset_debug()), element}, reason);
    };
    if (n.type() == pugi::node_doctype)
      here("", "a document type declaration (<!DOCTYPE ...>) is not supported: its entities and attribute "
               "defaults would be ignored");
    for (auto a : n.attributes())
      if (const std::string ref = first_unknown_reference(a.value()); !ref.empty())
        here("<" + std::string(n.name()) + ">",
             "attribute '" + std::string(a.name()) + "': unsupported reference '" + ref + "'" + kKnownReferences);
    if (n.type() == pugi::node_pcdata)
      if (const std::string ref = first_unknown_reference(n.value()); !ref.empty())
        here("", "unsupported reference '" + ref + "' in text" + kKnownReferences);
    if (n.first_child()) {
      n = n.first_child();
      continue;
    }
    while (n && !n.next_sibling()) n = n.parent();
    if (n) n = n.next_sibling();
  }
}

class Reader {
 public:
  Reader(const std::string& text, std::string file) : lines_(text), file_(std::move(file)) {}

  int line(const pugi::xml_node& n) const { return lines_.line(n.offset_debug()); }

  [[noreturn]] void fail(const pugi::xml_node& n, const std::string& reason) const {
    throw InputError({file_, line(n), describe(n)}, reason);
  }

  static std::string describe(const pugi::xml_node& n) {
    std::string s = "<" + std::string(n.name());
    for (const char* key : {"id", "from", "to"}) {
      auto a = n.attribute(key);
      if (a) s += " " + std::string(key) + "=\"" + a.value() + "\"";
    }
    return s + ">";
  }

  std::string required(const pugi::xml_node& n, const char* attr) const {
    auto a = n.attribute(attr);
    if (!a) fail(n, std::string("missing attribute '") + attr + "'");
    std::string v = a.value();
    if (v.empty()) fail(n, std::string("attribute '") + attr + "' is empty");
    return v;
  }

  double number(const pugi::xml_node& n, const char* attr) const {
    const std::string v = required(n, attr);
    return parse_number(n, attr, v);
  }

  double parse_number(const pugi::xml_node& n, const std::string& attr, const std::string& v) const {
    // Blanks alone are no value: strtod converts nothing, and skipping the trailing blanks
    // before asking whether it did read " " as 0.
    if (std::all_of(v.begin(), v.end(), [](unsigned char c) { return std::isspace(c); }))
      fail(n, "attribute '" + attr + "' is empty");
    char* end = nullptr;
    const double d = std::strtod(v.c_str(), &end);
    if (end == v.c_str()) fail(n, "attribute '" + attr + "' is not a number: '" + v + "'");
    while (*end && std::isspace(static_cast<unsigned char>(*end))) ++end;
    if (*end != '\0') fail(n, "attribute '" + attr + "' is not a number: '" + v + "'");
    if (!std::isfinite(d)) fail(n, "attribute '" + attr + "' is not finite: '" + v + "'");
    if (std::abs(d) > kMaxInputMagnitude)
      fail(n, "attribute '" + attr + "' = " + v + " is beyond ±" + full_precision(kMaxInputMagnitude) +
                  " (scene units)");
    return d;
  }

  std::optional<double> optional_number(const pugi::xml_node& n, const char* attr) const {
    if (!n.attribute(attr)) return std::nullopt;
    return number(n, attr);
  }

  Vec3 point(const pugi::xml_node& n) const { return {number(n, "x"), number(n, "y"), number(n, "z")}; }

  /// Every element the reader accepts passes here: it holds no text, its attributes must be
  /// known ones, and their values valid UTF-8 (ids, types and colours travel into report.json and view.html,
  /// which are UTF-8; pugixml has already converted a declared or BOM-marked encoding).
  void only_attributes(const pugi::xml_node& n, std::initializer_list<const char*> allowed) const {
    no_text(n);
    for (auto a : n.attributes()) {
      // pugixml keeps both of `id="C1" id="C2"` and lookups see only the first.
      for (auto b = n.first_attribute(); b != a; b = b.next_attribute())
        if (std::string(b.name()) == a.name()) fail(n, std::string("duplicate attribute '") + a.name() + "'");
      bool ok = false;
      for (const char* k : allowed) ok = ok || std::string(a.name()) == k;
      if (!ok) fail(n, std::string("unknown attribute '") + a.name() + "'");
      const std::string v = a.value();
      const std::size_t bad = first_invalid_utf8(v);
      if (bad != std::string::npos)
        fail(n, std::string("attribute '") + a.name() + "' is not valid UTF-8 (byte " + std::to_string(bad) +
                    " of its value; declare the file's encoding in <?xml ... encoding=\"...\"?>)");
      // XML allows no control characters but tab, newline and return; pugixml reads them, and
      // the writer would put them back as references that no XML reader (this one included) takes.
      for (std::size_t i = 0; i < v.size(); ++i) {
        const auto c = static_cast<unsigned char>(v[i]);
        if (c < 0x20 && !is_xml_char(c))
          fail(n, std::string("attribute '") + a.name() + "' holds control character " + std::to_string(c) +
                      " (byte " + std::to_string(i) + " of its value), which XML does not allow");
      }
    }
  }

  [[noreturn]] void unknown_child(const pugi::xml_node& parent, const pugi::xml_node& child) const {
    fail(child, std::string("unexpected element <") + child.name() + "> inside <" + parent.name() + ">");
  }

  /// Refuses text (other than blanks) directly inside `n`: no harness element holds text, and
  /// the element loops below look at child elements only, so it would be dropped unread.
  void no_text(const pugi::xml_node& n) const {
    for (auto c : n.children()) {
      if (c.type() != pugi::node_pcdata && c.type() != pugi::node_cdata) continue;
      std::string t = c.value();
      const auto blank = [](unsigned char ch) { return std::isspace(ch); };
      t.erase(t.begin(), std::find_if_not(t.begin(), t.end(), blank));
      if (t.empty()) continue;
      t.erase(std::find_if_not(t.rbegin(), t.rend(), blank).base(), t.end());
      constexpr std::size_t kShown = 40;
      throw InputError({file_, line(c), describe(n)},
                       "unexpected text '" + t.substr(0, kShown) + (t.size() > kShown ? "...'" : "'") + " inside <" +
                           n.name() + ">");
    }
  }

  /// Refuses any child element of an element that takes attributes only (<pt>, <cp>, <port>,
  /// <physical>): the reader would drop it unread.
  void leaf(const pugi::xml_node& n) const {
    for (auto c : n.children())
      if (c.type() == pugi::node_element) unknown_child(n, c);
  }

  Harness read(const pugi::xml_document& doc) {
    Harness h;
    h.source_file = file_;
    pugi::xml_node root = doc.document_element();
    if (!root) throw InputError({file_, 1, ""}, "no root element");
    // pugixml reads a document with more elements after the root; a harness file holds one
    // root, and a second would be ignored.
    for (auto n = root.next_sibling(); n; n = n.next_sibling())
      if (n.type() == pugi::node_element) fail(n, "a second root element: a harness file holds one <harness> root");
    h.name = root.attribute("name") ? root.attribute("name").value() : root.name();
    // A name taken from the element travels into report.json and routed.xml like an
    // attribute value, so it must be UTF-8 as they are (pugixml reads any bytes in names).
    if (const std::size_t bad = first_invalid_utf8(h.name); bad != std::string::npos)
      fail(root, "the root element's name, the harness name without a 'name' attribute, is not valid UTF-8 (byte " +
                     std::to_string(bad) + ")");
    if (auto u = root.attribute("units")) {
      auto unit = parse_unit(u.value());
      if (!unit) fail(root, std::string("unknown units '") + u.value() + "' (use mm, cm, m or in)");
      h.units = *unit;
    }
    only_attributes(root, {"name", "units"});
    bool seen_attr = false, seen_struct = false;
    for (auto child : root.children()) {
      if (child.type() != pugi::node_element) continue;
      const std::string name = child.name();
      if (name == "attributes") {
        if (seen_attr) fail(child, "duplicate <attributes>");
        seen_attr = true;
        read_attributes(child, h);
      } else if (name == "structure") {
        if (seen_struct) fail(child, "duplicate <structure>");
        seen_struct = true;
        read_structure(child, h);
      } else {
        unknown_child(root, child);
      }
    }
    if (!seen_struct && !h.cables.empty()) fail(root, "missing <structure> (ports and segments)");
    // Canonical segment order (the order the writer uses): segments nested under branch
    // points, branch by branch, then top-level ones; so read → write → read is the identity.
    std::stable_partition(h.segments.begin(), h.segments.end(),
                          [](const Segment& s) { return !s.parent_branch.empty(); });
    resolve_clamp_segments(h);
    return h;
  }

 private:
  void read_attributes(const pugi::xml_node& node, Harness& h) {
    no_text(node);
    for (auto c : node.children()) {
      if (c.type() != pugi::node_element) continue;
      if (std::string(c.name()) != "cable") unknown_child(node, c);
      only_attributes(c, {"id"});
      Cable cab;
      cab.id = required(c, "id");
      cab.line = line(c);
      bool have_el = false, have_phys = false;
      for (auto sub : c.children()) {
        if (sub.type() != pugi::node_element) continue;
        const std::string sn = sub.name();
        if (sn == "electrical") {
          if (have_el) fail(sub, "duplicate <electrical>");
          have_el = true;
          only_attributes(sub, {});
          int n = 0;
          for (auto p : sub.children()) {
            if (p.type() != pugi::node_element) continue;
            if (std::string(p.name()) != "port") unknown_child(sub, p);
            only_attributes(p, {"id"});
            leaf(p);
            if (n >= 2) fail(p, "a cable connects exactly two ports; this is a third");
            cab.ports[n++] = required(p, "id");
          }
          if (n != 2) fail(sub, "a cable connects exactly two ports, found " + std::to_string(n));
        } else if (sn == "physical") {
          if (have_phys) fail(sub, "duplicate <physical>");
          have_phys = true;
          only_attributes(sub, {"type", "color", "colour", "diameter", "min_bend_radius", "class"});
          leaf(sub);
          cab.physical.type = sub.attribute("type").value();
          if (auto k = sub.attribute("class")) {
            cab.physical.cable_class = k.value();
            if (cab.physical.cable_class.empty()) fail(sub, "attribute 'class' is empty");
          }
          if (sub.attribute("color") && sub.attribute("colour"))
            fail(sub, "both 'color' and 'colour' given: one would be ignored");
          cab.physical.color = sub.attribute("color") ? sub.attribute("color").value() : sub.attribute("colour").value();
          cab.physical.diameter = number(sub, "diameter");
          if (!(cab.physical.diameter > 0.0))
            fail(sub, "diameter must be positive, got " + full_precision(cab.physical.diameter));
          cab.physical.min_bend_radius = optional_number(sub, "min_bend_radius").value_or(0.0);
          if (cab.physical.min_bend_radius < 0.0)
            fail(sub, "min_bend_radius must not be negative, got " + full_precision(cab.physical.min_bend_radius));
        } else {
          unknown_child(c, sub);
        }
      }
      if (!have_el) fail(c, "missing <electrical> (the two port ids)");
      if (!have_phys) fail(c, "missing <physical> (diameter, min_bend_radius)");
      h.cables.push_back(std::move(cab));
    }
  }

  void read_segment(const pugi::xml_node& s, Harness& h, const std::string& parent) {
    Segment seg;
    seg.line = line(s);
    seg.parent_branch = parent;
    if (parent.empty()) {
      only_attributes(s, {"from", "to", "diameter"});
      seg.from = required(s, "from");
    } else {
      only_attributes(s, {"to", "diameter"});
      seg.from = parent;
    }
    seg.to = required(s, "to");
    seg.diameter = optional_number(s, "diameter");
    if (seg.diameter && !(*seg.diameter > 0.0))
      fail(s, "diameter must be positive, got " + full_precision(*seg.diameter));
    bool have_path = false;
    for (auto c : s.children()) {
      if (c.type() != pugi::node_element) continue;
      const std::string n = c.name();
      if (n == "path") {
        if (have_path) fail(c, "duplicate <path>");
        have_path = true;
        only_attributes(c, {"interp"});
        if (auto a = c.attribute("interp")) {
          const std::string v = a.value();
          if (v == "bspline") seg.interp = Interp::BSpline;
          else if (v == "polyline") seg.interp = Interp::Polyline;
          else fail(c, "interp must be 'bspline' or 'polyline', got '" + v + "'");
        }
        for (auto p : c.children()) {
          if (p.type() != pugi::node_element) continue;
          if (std::string(p.name()) != "pt") unknown_child(c, p);
          only_attributes(p, {"x", "y", "z"});
          leaf(p);
          seg.path.push_back(point(p));
        }
      } else if (n == "bspline") {
        if (seg.bspline) fail(c, "duplicate <bspline>");
        only_attributes(c, {"degree", "knots"});
        BSplineData b;
        const double deg = number(c, "degree");
        if (deg < 1 || deg > 7 || deg != std::floor(deg)) fail(c, "degree must be an integer in 1..7");
        b.degree = static_cast<int>(deg);
        std::istringstream ks(required(c, "knots"));
        std::string tok;
        while (ks >> tok) b.knots.push_back(parse_number(c, "knots", tok));
        for (std::size_t i = 1; i < b.knots.size(); ++i)
          if (b.knots[i] < b.knots[i - 1]) fail(c, "knots must not decrease (knot " + std::to_string(i) + ")");
        for (auto p : c.children()) {
          if (p.type() != pugi::node_element) continue;
          if (std::string(p.name()) != "cp") unknown_child(c, p);
          only_attributes(p, {"x", "y", "z"});
          leaf(p);
          b.control_points.push_back(point(p));
        }
        if (b.control_points.size() < static_cast<std::size_t>(b.degree) + 1)
          fail(c, "a degree-" + std::to_string(b.degree) + " spline needs at least " +
                      std::to_string(b.degree + 1) + " control points, found " +
                      std::to_string(b.control_points.size()));
        if (b.knots.size() != b.control_points.size() + b.degree + 1)
          fail(c, "expected " + std::to_string(b.control_points.size() + b.degree + 1) +
                      " knots (control points + degree + 1), found " + std::to_string(b.knots.size()));
        {
          // The curve lives on [knots[degree], knots[count - 1 - degree]]; its derivatives scale
          // as 1/width^k, so a domain narrower than kMinKnotDomain (relative) overflows them.
          const double lo = b.knots[static_cast<std::size_t>(b.degree)];
          const double hi = b.knots[b.knots.size() - 1 - static_cast<std::size_t>(b.degree)];
          const double scale = std::max({1.0, std::abs(lo), std::abs(hi)});
          if (!(hi - lo >= kMinKnotDomain * scale)) {
            std::ostringstream limit;  // shortest form ("1e-12"), as written above
            limit << kMinKnotDomain;
            fail(c, "the knots span the domain [" + full_precision(lo) + ", " + full_precision(hi) +
                        "], narrower than " + limit.str() + " x max(1, |knot|): not a curve");
          }
        }
        seg.bspline = std::move(b);
      } else {
        unknown_child(s, c);
      }
    }
    h.segments.push_back(std::move(seg));
  }

  void read_structure(const pugi::xml_node& node, Harness& h) {
    no_text(node);
    for (auto c : node.children()) {
      if (c.type() != pugi::node_element) continue;
      const std::string n = c.name();
      if (n == "port") {
        only_attributes(c, {"id", "x", "y", "z", "dx", "dy", "dz"});
        leaf(c);
        Port p;
        p.id = required(c, "id");
        p.line = line(c);
        p.position = point(c);
        Vec3 d{number(c, "dx"), number(c, "dy"), number(c, "dz")};
        if (!(d.cwiseAbs().maxCoeff() > 0.0)) fail(c, "exit direction (dx, dy, dz) has zero length");
        p.direction = stable_unit_direction(d);
        h.ports.push_back(std::move(p));
      } else if (n == "branch") {
        only_attributes(c, {"id", "x", "y", "z"});
        BranchPoint b;
        b.id = required(c, "id");
        b.line = line(c);
        const bool any = c.attribute("x") || c.attribute("y") || c.attribute("z");
        if (any) b.position = point(c);
        h.branches.push_back(b);
        for (auto s : c.children()) {
          if (s.type() != pugi::node_element) continue;
          if (std::string(s.name()) != "segment") unknown_child(c, s);
          read_segment(s, h, b.id);
        }
      } else if (n == "segment") {
        read_segment(c, h, "");
      } else if (n == "clamp") {
        read_clamp(c, h);
      } else {
        unknown_child(node, c);
      }
    }
  }

  /// <clamp id x y z [segment="FROM/TO"] [part] [placed]/>: a support holding the bundle
  /// at (x, y, z); its segment is resolved once every segment is read (resolve_clamp_segments).
  void read_clamp(const pugi::xml_node& c, Harness& h) {
    only_attributes(c, {"id", "x", "y", "z", "segment", "part", "placed"});
    leaf(c);
    Clamp k;
    k.id = required(c, "id");
    k.line = line(c);
    k.position = point(c);
    for (const Clamp& other : h.clamps)
      if (other.id == k.id) fail(c, "duplicate clamp id (first on line " + std::to_string(other.line) + ")");
    k.part = c.attribute("part").value();
    if (auto a = c.attribute("placed")) {
      const std::string v = a.value();
      if (v != "true" && v != "false") fail(c, "placed must be 'true' or 'false', got '" + v + "'");
      k.placed = v == "true";
    }
    clamp_nodes_.push_back(c);
    h.clamps.push_back(std::move(k));
  }

  /// Sets each clamp's segment index from its `segment="FROM/TO"` attribute (either end
  /// first): the attribute is compared whole with every segment's two spellings, so node
  /// ids holding '/' still resolve unless two segments spell the same.
  void resolve_clamp_segments(Harness& h) const {
    for (std::size_t k = 0; k < h.clamps.size(); ++k) {
      const pugi::xml_node c = clamp_nodes_[k];
      const auto a = c.attribute("segment");
      if (!a) continue;
      const std::string want = a.value();
      if (want.empty()) fail(c, "attribute 'segment' is empty");
      int found = -1;
      for (std::size_t s = 0; s < h.segments.size(); ++s) {
        const Segment& seg = h.segments[s];
        if (want != seg.from + "/" + seg.to && want != seg.to + "/" + seg.from) continue;
        if (found >= 0) fail(c, "segment '" + want + "' names more than one segment");
        found = static_cast<int>(s);
      }
      if (found < 0) fail(c, "unknown segment '" + want + "' (write it as FROM/TO, the ids of its two nodes)");
      h.clamps[k].segment = found;
    }
  }

  LineMap lines_;
  std::string file_;
  std::vector<pugi::xml_node> clamp_nodes_;  ///< the <clamp> element of each Harness::clamps entry
};

std::string fmt(double v) { return full_precision(v); }

void put_point(pugi::xml_node n, const Vec3& p) {
  n.append_attribute("x") = fmt(p.x()).c_str();
  n.append_attribute("y") = fmt(p.y()).c_str();
  n.append_attribute("z") = fmt(p.z()).c_str();
}

/// A segment is written inside its branch element only if it starts there (the nested
/// form has no `from` attribute).
bool nested_under(const Segment& s, const std::string& branch) {
  return s.parent_branch == branch && s.from == branch;
}

void put_segment(pugi::xml_node parent, const Segment& s, bool nested) {
  auto e = parent.append_child("segment");
  if (!nested) e.append_attribute("from") = s.from.c_str();
  e.append_attribute("to") = s.to.c_str();
  if (s.diameter) e.append_attribute("diameter") = fmt(*s.diameter).c_str();
  if (!s.path.empty() || s.interp == Interp::Polyline) {
    auto p = e.append_child("path");
    p.append_attribute("interp") = s.interp == Interp::Polyline ? "polyline" : "bspline";
    for (const auto& q : s.path) put_point(p.append_child("pt"), q);
  }
  if (s.bspline) {
    auto b = e.append_child("bspline");
    b.append_attribute("degree") = s.bspline->degree;
    std::string knots;
    for (std::size_t i = 0; i < s.bspline->knots.size(); ++i) knots += (i ? " " : "") + fmt(s.bspline->knots[i]);
    b.append_attribute("knots") = knots.c_str();
    for (const auto& q : s.bspline->control_points) put_point(b.append_child("cp"), q);
  }
}

}  // namespace

Harness parse_harness_xml(const std::string& text, const std::string& name_for_errors) {
  pugi::xml_document doc;
  auto res = doc.load_buffer(text.data(), text.size(), pugi::parse_default | pugi::parse_ws_pcdata_single);
  if (!res) {
    LineMap lm(text);
    throw InputError({name_for_errors, lm.line(res.offset), ""}, std::string("malformed XML: ") + res.description());
  }
  check_markup(text, name_for_errors);
  Reader r(text, name_for_errors);
  Harness h = r.read(doc);
  HarnessTopology topo(h);  // validates ids, cycles, connectivity (nodes of any degree)
  (void)topo;
  return h;
}

Harness read_harness_xml(const std::filesystem::path& path) {
  require_input_file(path, "harness file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError({path.string(), 0, ""}, "cannot read harness file");
  std::stringstream ss;
  ss << in.rdbuf();
  return parse_harness_xml(ss.str(), path.string());
}

std::string harness_to_xml(const Harness& h) {
  pugi::xml_document doc;
  auto root = doc.append_child("harness");
  root.append_attribute("name") = h.name.c_str();
  root.append_attribute("units") = unit_name(h.units);
  auto attrs = root.append_child("attributes");
  for (const auto& c : h.cables) {
    auto e = attrs.append_child("cable");
    e.append_attribute("id") = c.id.c_str();
    auto el = e.append_child("electrical");
    el.append_child("port").append_attribute("id") = c.ports[0].c_str();
    el.append_child("port").append_attribute("id") = c.ports[1].c_str();
    auto ph = e.append_child("physical");
    ph.append_attribute("type") = c.physical.type.c_str();
    ph.append_attribute("color") = c.physical.color.c_str();
    ph.append_attribute("diameter") = fmt(c.physical.diameter).c_str();
    ph.append_attribute("min_bend_radius") = fmt(c.physical.min_bend_radius).c_str();
    if (!c.physical.cable_class.empty()) ph.append_attribute("class") = c.physical.cable_class.c_str();
  }
  auto st = root.append_child("structure");
  for (const auto& p : h.ports) {
    auto e = st.append_child("port");
    e.append_attribute("id") = p.id.c_str();
    put_point(e, p.position);
    e.append_attribute("dx") = fmt(p.direction.x()).c_str();
    e.append_attribute("dy") = fmt(p.direction.y()).c_str();
    e.append_attribute("dz") = fmt(p.direction.z()).c_str();
  }
  for (const auto& b : h.branches) {
    auto e = st.append_child("branch");
    e.append_attribute("id") = b.id.c_str();
    if (b.position) put_point(e, *b.position);
    for (const auto& s : h.segments)
      if (nested_under(s, b.id)) put_segment(e, s, true);
  }
  for (const auto& s : h.segments)
    if (s.parent_branch.empty() || h.find_branch(s.parent_branch) < 0 || !nested_under(s, s.parent_branch))
      put_segment(st, s, false);
  for (const Clamp& k : h.clamps) {
    auto e = st.append_child("clamp");
    e.append_attribute("id") = k.id.c_str();
    put_point(e, k.position);
    if (k.segment >= 0 && static_cast<std::size_t>(k.segment) < h.segments.size()) {
      const Segment& seg = h.segments[static_cast<std::size_t>(k.segment)];
      e.append_attribute("segment") = (seg.from + "/" + seg.to).c_str();
    }
    if (!k.part.empty()) e.append_attribute("part") = k.part.c_str();
    if (k.placed) e.append_attribute("placed") = "true";
  }
  std::ostringstream os;
  doc.save(os, "  ", pugi::format_default, pugi::encoding_utf8);
  return os.str();
}

void write_harness_xml(const Harness& h, const std::filesystem::path& path) {
  write_file_atomic(path, harness_to_xml(h));
}

}  // namespace loom
