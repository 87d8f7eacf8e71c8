#include "core/io/motion_toml.hpp"

#include "core/error.hpp"

#include <cmath>
#include <limits>

namespace loom {

namespace {

int line_of(const toml::node* n) { return n ? static_cast<int>(n->source().begin.line) : 0; }

[[noreturn]] void fail(const std::string& file, const toml::node* n, const std::string& where, const std::string& why) {
  throw InputError({file, line_of(n), where}, why);
}

/// A required number; NaN and infinities are refused here, with the key named (TOML has
/// `nan` and `inf` literals).
double number(const toml::table& t, const char* key, const std::string& file, const std::string& where) {
  const toml::node* n = t.get(key);
  if (!n) fail(file, &t, where, std::string("missing '") + key + "'");
  double v = std::numeric_limits<double>::quiet_NaN();
  if (auto i = n->as_integer()) v = static_cast<double>(i->get());
  else if (auto f = n->as_floating_point()) v = f->get();
  else fail(file, n, where + "." + key, "expected a number");
  if (!std::isfinite(v)) fail(file, n, where + "." + key, "must be finite, got " + full_precision(v));
  if (std::abs(v) > kMaxInputMagnitude)
    fail(file, n, where + "." + key, "must be within ±" + full_precision(kMaxInputMagnitude));
  return v;
}

Vec3 vec3(const toml::table& t, const char* key, const std::string& file, const std::string& where) {
  const toml::node* n = t.get(key);
  if (!n) fail(file, &t, where, std::string("missing '") + key + "'");
  const toml::array* a = n->as_array();
  if (!a || a->size() != 3) fail(file, n, where + "." + key, "expected an array of 3 numbers");
  Vec3 v;
  for (std::size_t i = 0; i < 3; ++i) {
    const toml::node* e = a->get(i);
    if (auto x = e->as_integer()) v[static_cast<int>(i)] = static_cast<double>(x->get());
    else if (auto f = e->as_floating_point()) v[static_cast<int>(i)] = f->get();
    else fail(file, e, where + "." + key, "expected numbers");
    if (!std::isfinite(v[static_cast<int>(i)])) fail(file, e, where + "." + key, "must be finite");
    if (std::abs(v[static_cast<int>(i)]) > kMaxInputMagnitude)
      fail(file, e, where + "." + key, "must be within ±" + full_precision(kMaxInputMagnitude));
  }
  return v;
}

void only_keys(const toml::table& t, std::initializer_list<const char*> allowed, const std::string& file,
               const std::string& where) {
  for (const auto& [k, v] : t) {
    bool ok = false;
    std::string list;
    for (const char* a : allowed) {
      ok = ok || k.str() == a;
      list += (list.empty() ? "" : ", ") + std::string(a);
    }
    if (!ok) fail(file, &v, where + "." + std::string(k.str()), "unknown key (allowed: " + list + ")");
  }
}

/// The body of a motion: a table holding exactly one of `rotate` / `translate` (and, for a
/// [[motion]] entry, `name`).
Motion read_body(const toml::table& t, bool named, const std::string& file, const std::string& where) {
  if (named) only_keys(t, {"name", "rotate", "translate"}, file, where);
  else only_keys(t, {"rotate", "translate"}, file, where);
  const toml::node* rn = t.get("rotate");
  const toml::node* tn = t.get("translate");
  if ((rn != nullptr) == (tn != nullptr))
    fail(file, &t, where, "give exactly one of rotate = { axis_point, axis, from_deg, to_deg } or "
                          "translate = { direction, from, to }");
  Motion m;
  const toml::node* body = rn ? rn : tn;
  const toml::table* b = body->as_table();
  const std::string bw = where + (rn ? ".rotate" : ".translate");
  if (!b) fail(file, body, bw, "expected an inline table");
  if (rn) {
    only_keys(*b, {"axis_point", "axis", "from_deg", "to_deg"}, file, bw);
    m.kind = MotionKind::Rotate;
    m.axis_point = vec3(*b, "axis_point", file, bw);
    m.axis = vec3(*b, "axis", file, bw);
    m.from = number(*b, "from_deg", file, bw);
    m.to = number(*b, "to_deg", file, bw);
  } else {
    only_keys(*b, {"direction", "from", "to"}, file, bw);
    m.kind = MotionKind::Translate;
    m.axis = vec3(*b, "direction", file, bw);
    m.from = number(*b, "from", file, bw);
    m.to = number(*b, "to", file, bw);
  }
  validate_motion(m, file, line_of(body), where);
  return m;
}

}  // namespace

std::map<std::string, Motion> read_named_motions(const toml::table& doc, const std::string& file) {
  std::map<std::string, Motion> out;
  const toml::node* n = doc.get("motion");
  if (!n) return out;
  const toml::array* arr = n->as_array();
  if (!arr) fail(file, n, "motion", "expected [[motion]] tables (name, and rotate or translate)");
  int idx = 0;
  for (const toml::node& e : *arr) {
    const std::string where = "motion[" + std::to_string(++idx) + "]";
    const toml::table* t = e.as_table();
    if (!t) fail(file, &e, where, "expected a table");
    const toml::node* nn = t->get("name");
    const auto name = nn ? nn->value<std::string>() : std::nullopt;
    if (!name || name->empty()) fail(file, nn ? nn : &e, where + ".name", "a [[motion]] needs a non-empty name");
    Motion m = read_body(*t, true, file, "motion '" + *name + "'");
    m.name = *name;
    if (!out.emplace(*name, m).second) fail(file, nn, "motion '" + *name + "'", "duplicate motion name");
  }
  return out;
}

Motion read_part_motion(const toml::node& n, const std::map<std::string, Motion>& named, const std::string& file,
                        const std::string& part) {
  if (auto s = n.as_string()) {
    const auto it = named.find(s->get());
    if (it == named.end()) fail(file, &n, part + ".motion", "no [[motion]] named '" + s->get() + "'");
    return it->second;
  }
  const toml::table* t = n.as_table();
  if (!t) fail(file, &n, part + ".motion", "expected { rotate = {...} }, { translate = {...} } or a [[motion]] name");
  return read_body(*t, false, file, part + ".motion");
}

}  // namespace loom
