#include "core/io/scene_load.hpp"
#include "core/stopwatch.hpp"

#include "core/error.hpp"
#include "core/harness_topology.hpp"
#include "core/io/harness_xml.hpp"
#include "core/io/input_file.hpp"
#include "core/io/kbl_read.hpp"
#include "core/io/kbl_vec.hpp"
#include "core/io/mesh_read.hpp"
#include "core/io/motion_toml.hpp"
#include "core/io/tessellation_cache.hpp"
#include "core/io/toml_checks.hpp"
#include "core/io/voxel_part.hpp"

#include <toml++/toml.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>

namespace loom {

namespace {

class TomlReader {
 public:
  explicit TomlReader(std::string file) : file_(std::move(file)) {}

  [[noreturn]] void fail(const toml::node* n, const std::string& key, const std::string& reason) const {
    const int line = n ? static_cast<int>(n->source().begin.line) : 0;
    throw InputError({file_, line, key}, reason);
  }

  void only_keys(const toml::table& t, const std::string& where, std::initializer_list<const char*> allowed) const {
    for (const auto& [k, v] : t) {
      bool ok = false;
      for (const char* a : allowed) ok = ok || k.str() == a;
      if (!ok) fail(&v, where + "." + std::string(k.str()), "unknown key (allowed: " + join(allowed) + ")");
    }
  }

  static std::string join(std::initializer_list<const char*> l) {
    std::string s;
    for (const char* a : l) s += (s.empty() ? "" : ", ") + std::string(a);
    return s;
  }

  std::optional<double> number(const toml::table& t, const std::string& where, const char* key) const {
    const toml::node* n = t.get(key);
    if (!n) return std::nullopt;
    double v;
    if (auto i = n->as_integer()) v = static_cast<double>(i->get());
    else if (auto f = n->as_floating_point()) v = f->get();
    else fail(n, where + "." + key, "expected a number");
    if (!std::isfinite(v)) fail(n, where + "." + key, "must be finite, got " + full_precision(v));
    if (std::abs(v) > kMaxInputMagnitude)
      fail(n, where + "." + key, "must be within ±" + full_precision(kMaxInputMagnitude) + ", got " + full_precision(v));
    return v;
  }

  std::optional<std::string> string(const toml::table& t, const std::string& where, const char* key) const {
    const toml::node* n = t.get(key);
    if (!n) return std::nullopt;
    auto s = n->as_string();
    if (!s) fail(n, where + "." + key, "expected a string");
    // TOML's "\u0000" is a valid escape, but a NUL ends every name handed to the OS and C
    // libraries: file = "a.obj\u0000.stl" passed the .stl check and then read a.obj.
    if (s->get().find('\0') != std::string::npos)
      fail(n, where + "." + key, "must not contain a NUL character (\\u0000)");
    return s->get();
  }

  Vec3 vec3(const toml::node* n, const std::string& key) const {
    auto a = n->as_array();
    if (!a || a->size() != 3) fail(n, key, "expected an array of 3 numbers");
    Vec3 v;
    for (int i = 0; i < 3; ++i) {
      const toml::node* e = a->get(static_cast<std::size_t>(i));
      if (auto x = e->as_integer()) v[i] = static_cast<double>(x->get());
      else if (auto f = e->as_floating_point()) v[i] = f->get();
      else fail(e, key, "expected numbers");
      if (!std::isfinite(v[i])) fail(e, key, "must be finite");
      if (std::abs(v[i]) > kMaxInputMagnitude)
        fail(e, key, "must be within ±" + full_precision(kMaxInputMagnitude) + ", got " + full_precision(v[i]));
    }
    return v;
  }

  /// The table `key` of the document, nullptr if absent; present as anything but a table
  /// (`harness = "h.xml"` for `[harness] file = "h.xml"`) it is an error, not ignored.
  const toml::table* section(const toml::table& doc, const char* key) const {
    const toml::node* n = doc.get(key);
    if (!n) return nullptr;
    const toml::table* t = n->as_table();
    if (!t) fail(n, key, std::string("expected a table [") + key + "]");
    return t;
  }

  const std::string& file() const { return file_; }

 private:
  std::string file_;
};

/// Transform of DESIGN §3: scale, then rotate about X, Y, Z (fixed axes), then translate.
Eigen::Affine3d part_transform(const TomlReader& r, const toml::table* t, const std::string& where) {
  Eigen::Affine3d m = Eigen::Affine3d::Identity();
  if (!t) return m;
  r.only_keys(*t, where, {"translate", "rotate_deg", "scale"});
  Vec3 tr = Vec3::Zero(), rot = Vec3::Zero();
  double scale = 1.0;
  if (auto n = t->get("translate")) tr = r.vec3(n, where + ".translate");
  if (auto n = t->get("rotate_deg")) rot = r.vec3(n, where + ".rotate_deg");
  if (auto s = r.number(*t, where, "scale")) {
    scale = *s;
    if (!(scale > 0.0)) r.fail(t->get("scale"), where + ".scale", "must be positive");
  }
  const double d2r = M_PI / 180.0;
  // Fixed-axis X then Y then Z: R = Rz · Ry · Rx.
  const Eigen::Matrix3d R = (Eigen::AngleAxisd(rot.z() * d2r, Vec3::UnitZ()) *
                             Eigen::AngleAxisd(rot.y() * d2r, Vec3::UnitY()) *
                             Eigen::AngleAxisd(rot.x() * d2r, Vec3::UnitX()))
                                .toRotationMatrix();
  m.linear() = R * scale;
  m.translation() = tr;
  return m;
}

/// Scanned-part settings of a [[part]] (resolution, origin, unknown), or none for a mesh or
/// CAD part. A .bt, .ot, .pcd or .xyz file is scanned, and so is a .ply given a resolution.
std::optional<VoxelPartOptions> scan_options(const TomlReader& r, const toml::table& t, const std::filesystem::path& f,
                                             const std::string& where) {
  const auto res = r.number(t, where, "resolution");
  std::string ext = f.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  const bool tree = is_octree_file(f);
  if (!tree && !is_point_cloud_only_file(f) && !(res && ext == ".ply")) {
    for (const char* k : {"resolution", "origin", "unknown"})
      if (t.get(k))
        r.fail(t.get(k), where + "." + k, "applies to scanned parts only (.bt .ot .pcd .xyz, or .ply with a resolution)");
    return std::nullopt;
  }
  VoxelPartOptions o;
  if (tree && res) r.fail(t.get("resolution"), where + ".resolution", "an OctoMap tree has its own resolution");
  if (tree && t.get("origin")) r.fail(t.get("origin"), where + ".origin", "applies to point clouds only");
  if (!tree && !res) r.fail(&t, where, "a point cloud part needs a 'resolution' (voxel edge, file units)");
  if (res && !(*res > 0.0)) r.fail(t.get("resolution"), where + ".resolution", "must be positive, got " + full_precision(*res));
  o.resolution = res.value_or(0.0);
  if (const toml::node* n = t.get("origin")) o.origin = r.vec3(n, where + ".origin");
  if (auto u = r.string(t, where, "unknown")) {
    if (*u == "occupied") o.unknown_occupied = true;
    else if (*u != "free") r.fail(t.get("unknown"), where + ".unknown", "must be 'free' or 'occupied', got '" + *u + "'");
  }
  return o;
}

std::filesystem::path resolve(const std::filesystem::path& base, const std::string& rel) {
  std::filesystem::path p(rel);
  return p.is_absolute() ? p : base / p;
}

/// The harness file by its extension: KBL (.kbl), VEC (.vec), else loom's harness XML.
Harness read_harness_file(const std::filesystem::path& p) {
  std::string ext = p.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (ext == ".kbl") return read_harness_kbl(p);
  if (ext == ".vec") return read_harness_vec(p);
  return read_harness_xml(p);
}

/// The loom port id a [harness.place] key names: the port's own id, or the id of its node
/// in the file (a KBL Node id); empty if neither.
std::string placed_port_id(const Harness& h, const std::string& key) {
  if (h.find_port(key) >= 0) return key;
  if (h.kbl)
    for (const auto& [loom_id, file_id] : h.kbl->node_ids)
      if (file_id == key && h.find_port(loom_id) >= 0) return loom_id;
  return {};
}

/// [harness.place]: per port, `ID = { at = [x, y, z], dir = [dx, dy, dz] }` in scene units.
/// A port of a topology-only harness gets its position here; a 3D one is moved (said in the
/// notes) and its segments' curves, which no longer reach it, are dropped for the router.
void place_ports(const TomlReader& r, const toml::node& pn, Harness& h, std::vector<std::string>& notes) {
  const toml::table* place = pn.as_table();
  if (!place) r.fail(&pn, "harness.place", "expected a table [harness.place] of ID = { at = [x, y, z], dir = [dx, dy, dz] }");
  for (const auto& [k, v] : *place) {
    const std::string key(k.str()), where = "harness.place." + key;
    const toml::table* t = v.as_table();
    if (!t) r.fail(&v, where, "expected an inline table { at = [x, y, z], dir = [dx, dy, dz] }");
    r.only_keys(*t, where, {"at", "dir"});
    if (!t->get("at") || !t->get("dir")) r.fail(&v, where, "needs both 'at' (position) and 'dir' (exit direction)");
    const std::string id = placed_port_id(h, key);
    if (id.empty()) {
      const bool branch = h.find_branch(key) >= 0 || (h.kbl && std::any_of(h.kbl->node_ids.begin(), h.kbl->node_ids.end(),
                                                                               [&](const auto& e) { return e.second == key; }));
      r.fail(&v, where, "'" + key + "' is " + (branch ? "a branch point" : "no port") + " of harness file " + h.source_file +
                            (branch ? ": the router places branch points; [harness.place] places ports"
                                    : " (a key is a port id or its node's id in the file)"));
    }
    const Vec3 at = r.vec3(t->get("at"), where + ".at"), dir = r.vec3(t->get("dir"), where + ".dir");
    if (!(dir.norm() > 0.0)) r.fail(t->get("dir"), where + ".dir", "the exit direction must not be zero");
    Port& p = h.ports[static_cast<std::size_t>(h.find_port(id))];
    if (p.placed) {
      notes.push_back("port '" + id + "': the scene's [harness.place] moves it from " + full_precision(p.position) +
                      " to " + full_precision(at) + " (the file's position is replaced)");
      for (auto& s : h.segments)
        if ((s.from == id || s.to == id) && (s.bspline || !s.path.empty())) {
          s.bspline.reset();
          s.path.clear();
          notes.push_back("segment " + s.from + " -> " + s.to + ": its curve no longer reaches the moved port '" + id +
                          "': the router plans it");
        }
    }
    p.position = at;
    p.direction = stable_unit_direction(dir);
    p.placed = true;
  }
}

/// Refuses a harness with ports still unplaced, naming them all, the harness file and the
/// scene table that places them.
void require_placed_ports(const Harness& h, const std::string& scene_file) {
  std::string missing;
  int first_line = 0, count = 0;
  for (const auto& p : h.ports)
    if (!p.placed) {
      missing += (missing.empty() ? "" : ", ") + p.id + (p.line ? " (line " + std::to_string(p.line) + ")" : "");
      if (!count++) first_line = p.line;
    }
  if (!count) return;
  const std::string first = h.ports[static_cast<std::size_t>(
      std::find_if(h.ports.begin(), h.ports.end(), [](const Port& p) { return !p.placed; }) - h.ports.begin())].id;
  throw InputError({h.source_file, first_line, ""},
                   "no 3D geometry: " + std::to_string(count) + " port" + (count == 1 ? " has" : "s have") +
                       " no position: " + missing + "; give each in the [harness.place] table of " + scene_file +
                       ", e.g. " + first + " = { at = [x, y, z], dir = [dx, dy, dz] } (scene units)");
}

/// The scene's part of a harness without 3D geometry: what it must place said in the notes,
/// [harness.place] applied, and every port required placed.
void place_harness(const TomlReader& r, const toml::table& ht, Harness& h, SceneLoadReport* report) {
  const auto unplaced = std::count_if(h.ports.begin(), h.ports.end(), [](const Port& p) { return !p.placed; });
  const auto open = std::count_if(h.branches.begin(), h.branches.end(), [](const BranchPoint& b) { return !b.position; });
  std::vector<std::string> notes;
  if (unplaced)
    notes.push_back("harness file " + h.source_file + " has no 3D geometry: topology only, " + std::to_string(unplaced) +
                    " nodes to be placed by the scene, " + std::to_string(open) + " by the router");
  if (const toml::node* pn = ht.get("place")) place_ports(r, *pn, h, notes);
  require_placed_ports(h, r.file());
  if (report) report->notes.insert(report->notes.end(), notes.begin(), notes.end());
}

/// [routing] clamp_spacing and clamp_reach (positive, finite, scene units) and the
/// [routing.separation] table of class pairs (`power.signal = 50.0`, symmetric).
void read_supports(const TomlReader& r, const toml::table& rt, RoutingSettings& out) {
  for (const char* key : {"clamp_spacing", "clamp_reach"}) {
    const auto v = r.number(rt, "routing", key);
    if (!v) continue;
    if (!(*v > 0.0)) r.fail(rt.get(key), std::string("routing.") + key, "must be positive, got " + full_precision(*v));
    (std::string(key) == "clamp_spacing" ? out.clamp_spacing : out.clamp_reach) = {*v, "scene file"};
  }
  if (const auto v = r.number(rt, "routing", "support_weight")) {
    if (!(*v >= 0.0)) r.fail(rt.get("support_weight"), "routing.support_weight", "must not be negative, got " + full_precision(*v));
    out.support_weight = {*v, "scene file"};
  }
  out.supports = rt.get("clamp_spacing") != nullptr;
  const toml::node* sn = rt.get("separation");
  if (!sn) return;
  const toml::table* sep = sn->as_table();
  if (!sep) r.fail(sn, "routing.separation", "expected a table [routing.separation] (power.signal = 50.0)");
  for (const auto& [a, an] : *sep) {
    const std::string where = "routing.separation." + std::string(a.str());
    const toml::table* inner = an.as_table();
    if (!inner) r.fail(&an, where, "expected CLASS.CLASS = distance, e.g. power.signal = 50.0");
    for (const auto& [b, bn] : *inner) {
      const std::string key = where + "." + std::string(b.str());
      const auto d = r.number(*inner, where, std::string(b.str()).c_str());
      if (!(*d > 0.0)) r.fail(&bn, key, "must be positive, got " + full_precision(*d));
      const std::string ca(a.str()), cb(b.str());
      const auto pair = ca < cb ? std::make_pair(ca, cb) : std::make_pair(cb, ca);
      const auto [it, fresh] = out.separation.emplace(pair, *d);
      if (!fresh && it->second != *d)
        r.fail(&bn, key, "contradicts " + pair.first + "." + pair.second + " = " + full_precision(it->second) +
                             " given for the same pair (the separation is symmetric)");
    }
  }
}

}  // namespace

void apply_routes(Scene& scene, const std::filesystem::path& routes) {
  Harness routed = read_harness_xml(routes);
  if (routed.units != scene.units)
    throw InputError({routes.string(), 0, "harness"}, std::string("unit mismatch: the routes are in ") +
                                                         unit_name(routed.units) + " but the scene is in " +
                                                         unit_name(scene.units));
  scene.harness = std::move(routed);
  scene.has_harness = true;
}

Scene load_scene(const std::filesystem::path& toml_path, const SceneLoadOptions& opt, SceneLoadReport* report) {
  const Stopwatch t0;
  const std::string file = toml_path.string();
  require_input_file(toml_path, "scene file");
  std::string text;
  {
    std::ifstream in(toml_path, std::ios::binary);
    std::ostringstream ss;
    ss << in.rdbuf();
    text = ss.str();
  }
  check_toml_nesting(text, file);  // before toml++ recurses through it
  toml::table doc;
  try {
    doc = toml::parse(text, file);
  } catch (const toml::parse_error& e) {
    throw InputError({file, static_cast<int>(e.source().begin.line), ""},
                     std::string("malformed TOML: ") + std::string(e.description()));
  }
  TomlReader r(file);
  r.only_keys(doc, "", {"scene", "part", "motion", "harness", "routing", "simplify", "tessellation"});
  const std::filesystem::path base = toml_path.parent_path();
  Scene scene;
  scene.source_file = file;

  const toml::table* sc = r.section(doc, "scene");
  if (!sc) r.fail(nullptr, "[scene]", "missing [scene] table (name, units)");
  r.only_keys(*sc, "scene", {"name", "units"});
  scene.name = r.string(*sc, "scene", "name").value_or(toml_path.stem().string());
  const std::string units = r.string(*sc, "scene", "units").value_or("mm");
  auto unit = parse_unit(units);
  if (!unit) r.fail(sc->get("units"), "scene.units", "unknown unit '" + units + "' (use mm, cm, m or in)");
  scene.units = *unit;

  // Harness first: cable sizes drive the derived tessellation deflection.
  if (const toml::table* ht = r.section(doc, "harness")) {
    r.only_keys(*ht, "harness", {"file", "place"});
    auto hf = r.string(*ht, "harness", "file");
    if (!hf) r.fail(ht, "harness.file", "missing harness file name");
    if (hf->empty()) r.fail(ht->get("file"), "harness.file", "empty file name");
    try {
      scene.harness = read_harness_file(resolve(base, *hf));
    } catch (const InputError& e) {
      if (e.where().file.empty() || e.where().line == 0) {
        // Point at the scene entry as well so the user sees where the path came from.
        throw InputError(e.where(), e.reason() + " (referenced by " + file + ":" +
                                        std::to_string(ht->get("file")->source().begin.line) + " harness.file)");
      }
      throw;
    }
    if (scene.harness.units != scene.units)
      r.fail(ht->get("file"), "harness.file",
             std::string("unit mismatch: the harness is in ") + unit_name(scene.harness.units) +
                 " but the scene is in " + unit_name(scene.units) + " (all lengths must share the scene unit)");
    place_harness(r, *ht, scene.harness, report);
    scene.has_harness = true;
  }
  const double dmin = scene.harness.smallest_diameter();
  const double mm = 1.0 / unit_in_mm(scene.units);  // one millimetre in scene units

  // [routing]
  scene.routing.clearance = {dmin > 0 ? dmin : 1.0 * mm,
                             dmin > 0 ? "default: smallest cable diameter" : "default: 1 mm (no cables)"};
  scene.routing.time_limit = {1.0, "default: 1 s per cable or bundle"};
  scene.routing.iterations = {0.0, "default: none (stop on time and convergence)"};
  scene.routing.clamp_spacing = {450.0 * mm, "default: 450 mm"};
  scene.routing.clamp_reach = {25.0 * mm, "default: 25 mm"};
  scene.routing.support_weight = {0.0, "default: 0 (off; the route is pulled to structure after planning)"};
  if (const toml::table* rt = r.section(doc, "routing")) {
    r.only_keys(*rt, "routing",
                {"clearance", "planner", "time_limit", "seed", "iterations", "clamp_spacing", "clamp_reach",
                 "support_weight", "separation"});
    read_supports(r, *rt, scene.routing);
    if (auto v = r.number(*rt, "routing", "clearance")) {
      if (*v < 0) r.fail(rt->get("clearance"), "routing.clearance", "must not be negative");
      scene.routing.clearance = {*v, "scene file"};
    }
    if (auto v = r.number(*rt, "routing", "time_limit")) {
      if (*v < 0) r.fail(rt->get("time_limit"), "routing.time_limit", "must not be negative");
      scene.routing.time_limit = {*v, "scene file"};
    }
    if (auto v = r.string(*rt, "routing", "planner")) {
      const std::vector<std::string>& known = routing_planner_names();
      if (std::find(known.begin(), known.end(), *v) == known.end()) {
        std::string valid;
        for (const auto& k : known) valid += (valid.empty() ? "" : ", ") + k;
        r.fail(rt->get("planner"), "routing.planner", "unknown planner '" + *v + "'; valid planners: " + valid);
      }
      scene.routing.planner = *v;
    }
    if (auto v = r.number(*rt, "routing", "seed")) {
      // The seed is an unsigned 32-bit value: a larger one would be cut, silently another seed.
      if (*v < 0 || *v != std::floor(*v) || *v > static_cast<double>(std::numeric_limits<std::uint32_t>::max()))
        r.fail(rt->get("seed"), "routing.seed",
               "must be an integer in 0.." + std::to_string(std::numeric_limits<std::uint32_t>::max()) + ", got " +
                   full_precision(*v));
      scene.routing.seed = static_cast<unsigned>(*v);
    }
    if (auto v = r.number(*rt, "routing", "iterations")) {
      // A whole number of planner iterations; 0 would read as "none", which leaving the key
      // out already says.
      if (*v < 1 || *v != std::floor(*v) || *v > static_cast<double>(kMaxPlanIterations))
        r.fail(rt->get("iterations"), "routing.iterations",
               "must be an integer in 1.." + std::to_string(kMaxPlanIterations) + ", got " + full_precision(*v));
      scene.routing.iterations = {*v, "scene file"};
    }
  }
  // [simplify]
  scene.simplify.dim_pre = {dmin > 0 ? dmin : 1.0 * mm,
                            dmin > 0 ? "default: smallest cable diameter" : "default: 1 mm (no cables)"};
  if (const toml::table* st = r.section(doc, "simplify")) {
    r.only_keys(*st, "simplify", {"dim_pre", "planes", "split"});
    if (auto v = r.number(*st, "simplify", "dim_pre")) {
      if (!(*v > 0)) r.fail(st->get("dim_pre"), "simplify.dim_pre", "must be positive");
      scene.simplify.dim_pre = {*v, "scene file"};
    }
    if (const toml::node* n = st->get("planes")) {
      const toml::array* a = n->as_array();
      if (!a) r.fail(n, "simplify.planes", "expected an array of normals, e.g. [[1, 1, 0]]");
      if (a->size() > kMaxSimplifyPlanes)
        r.fail(n, "simplify.planes", "at most " + std::to_string(kMaxSimplifyPlanes) + " planes, got " + std::to_string(a->size()));
      for (std::size_t i = 0; i < a->size(); ++i) {
        const std::string key = "simplify.planes[" + std::to_string(i) + "]";
        const Vec3 normal = r.vec3(a->get(i), key);
        // A normal whose length underflows gives no direction.
        if (!(normal.norm() > 0.0))
          r.fail(a->get(i), key, "must be a non-zero normal");
        scene.simplify.planes.push_back(normal);
      }
    }
    if (const toml::node* n = st->get("split")) {
      const auto b = n->as_boolean();
      if (!b) r.fail(n, "simplify.split", "expected true or false");
      scene.simplify.split = b->get();
    }
  }
  // [tessellation]
  scene.tessellation.linear_deflection = {dmin > 0 ? dmin / 20.0 : 0.1 * mm,
                                          dmin > 0 ? "default: smallest cable radius / 10" : "default: 0.1 mm (no cables)"};
  scene.tessellation.angular_deflection_deg = {20.0, "default: 20 degrees"};
  const toml::table* tt = r.section(doc, "tessellation");
  if (tt) {
    r.only_keys(*tt, "tessellation", {"linear_deflection", "angular_deflection_deg", "by_need", "coarse_deflection"});
    if (const toml::node* n = tt->get("by_need")) {
      const auto b = n->as_boolean();
      if (!b) r.fail(n, "tessellation.by_need", "expected true or false");
      scene.tessellation.by_need = b->get();
    }
    if (auto v = r.number(*tt, "tessellation", "linear_deflection")) {
      if (!(*v > 0)) r.fail(tt->get("linear_deflection"), "tessellation.linear_deflection", "must be positive");
      scene.tessellation.linear_deflection = {*v, "scene file"};
    }
    if (auto v = r.number(*tt, "tessellation", "angular_deflection_deg")) {
      if (!(*v > 0 && *v < 180))
        r.fail(tt->get("angular_deflection_deg"), "tessellation.angular_deflection_deg", "must be in (0, 180)");
      scene.tessellation.angular_deflection_deg = {*v, "scene file"};
    }
  }
  scene.tessellation.coarse_deflection = {kCoarseDeflectionFactor * scene.tessellation.linear_deflection.value,
                                          "default: 20 x linear_deflection"};
  // Its default and its bound follow the fine deflection, read above.
  if (tt)
    if (auto v = r.number(*tt, "tessellation", "coarse_deflection")) {
      if (!(*v >= scene.tessellation.linear_deflection.value))
        r.fail(tt->get("coarse_deflection"), "tessellation.coarse_deflection",
               "must be at least linear_deflection (" + full_precision(scene.tessellation.linear_deflection.value) + ")");
      scene.tessellation.coarse_deflection = {*v, "scene file"};
    }
  const bool coarse_first = opt.tessellate_by_need && scene.tessellation.by_need;
  if (scene.tessellation.by_need && !opt.tessellate_by_need && opt.load_parts && report)
    report->notes.push_back("tessellation.by_need applies to `loom audit`: CAD parts meshed at the fine deflection");

  // [[part]]
  const std::map<std::string, Motion> motions = read_named_motions(doc, file);
  std::set<std::string> names;
  if (const toml::node* pn = doc.get("part")) {
    const toml::array* parts = pn->as_array();
    if (!parts) r.fail(pn, "part", "expected [[part]] tables");
    ProgressCounter loaded(opt.load_parts ? opt.progress : ProgressFn(), "load", parts->size(), "files");
    int idx = 0;
    for (const toml::node& node : *parts) {
      ++idx;
      const toml::table* pt = node.as_table();
      const std::string where = "part[" + std::to_string(idx) + "]";
      if (!pt) r.fail(&node, where, "expected a table");
      r.only_keys(*pt, where, {"name", "file", "transform", "role", "clearance", "compound", "resolution",
                                  "origin", "unknown", "motion"});
      auto file_rel = r.string(*pt, where, "file");
      if (!file_rel) r.fail(&node, where, "missing 'file'");
      const std::optional<std::string> given_name = r.string(*pt, where, "name");
      // A part's name identifies it in every report (and names its simplify output).
      if (given_name && given_name->empty()) r.fail(pt->get("name"), where + ".name", "must not be empty");
      const std::string pname = given_name.value_or(std::filesystem::path(*file_rel).stem().string());
      const std::string pwhere = "part '" + pname + "'";
      PartRole role = PartRole::Structure;
      if (auto ro = r.string(*pt, where, "role")) {
        if (*ro == "structure") role = PartRole::Structure;
        else if (*ro == "keep_out") role = PartRole::KeepOut;
        else r.fail(pt->get("role"), pwhere + ".role", "role must be 'structure' or 'keep_out', got '" + *ro + "'");
      }
      const double extra = r.number(*pt, where, "clearance").value_or(0.0);
      if (extra < 0) r.fail(pt->get("clearance"), pwhere + ".clearance", "must not be negative");
      bool compound = false;
      if (const toml::node* cn = pt->get("compound")) {
        auto b = cn->as_boolean();
        if (!b) r.fail(cn, pwhere + ".compound", "expected true or false");
        compound = b->get();
      }
      std::optional<Motion> motion;
      if (const toml::node* mn = pt->get("motion")) motion = read_part_motion(*mn, motions, file, pwhere);
      const Eigen::Affine3d xf = part_transform(r, pt->get("transform") ? pt->get("transform")->as_table() : nullptr,
                                                pwhere + ".transform");
      if (pt->get("transform") && !pt->get("transform")->as_table())
        r.fail(pt->get("transform"), pwhere + ".transform", "expected an inline table { translate, rotate_deg, scale }");
      const std::filesystem::path fpath = resolve(base, *file_rel);
      const std::optional<VoxelPartOptions> scan = scan_options(r, *pt, fpath, pwhere);
      if (!scan && !is_cad_file(fpath) && !is_mesh_file(fpath))
        r.fail(pt->get("file"), pwhere + ".file",
               "unknown file extension '" + fpath.extension().string() +
                   "' (meshes: .stl .obj .ply .off .gltf .glb .dae; CAD: .step .stp .iges .igs; scans: .bt .ot .pcd "
                   ".xyz, .ply with a resolution)");
      if (!opt.entries.empty() && !(static_cast<std::size_t>(idx - 1) < opt.entries.size() && opt.entries[idx - 1]))
        continue;  // another shard's part
      if (!opt.load_parts) {
        std::error_code ec;
        if (!std::filesystem::exists(fpath, ec))
          r.fail(pt->get("file"), pwhere + ".file", "file not found: " + fpath.string());
        Part p;
        p.name = pname;
        p.role = role;
        p.clearance = extra;
        p.source_file = fpath.string();
        p.motion = motion;
        if (!names.insert(p.name).second) r.fail(&node, pwhere, "duplicate part name");
        scene.parts.push_back(std::move(p));
        if (report) report->part_entries.push_back(idx - 1);
        continue;
      }
      std::vector<NamedMesh> pieces;
      double voxel_edge = 0.0;  // scanned parts, scene units
      double deflection = 0.0;  // CAD parts, scene units
      try {
        if (is_cad_file(fpath)) {
          TessellationParams tp;
          deflection = coarse_first ? scene.tessellation.coarse_deflection.value : scene.tessellation.linear_deflection.value;
          tp.linear_deflection = deflection;
          tp.angular_deflection_deg = scene.tessellation.angular_deflection_deg.value;
          tp.unit_in_mm = unit_in_mm(scene.units);
          // Transferred files are kept only for a coarse pass: the refinement meshes from them.
          CadShapeStore* keep = coarse_first ? opt.cad_shapes : nullptr;
          pieces = opt.use_cache ? read_cad_file_cached(fpath, tp, !compound, nullptr, nullptr, keep)
                                 : read_cad_file(fpath, tp, !compound, nullptr, keep);
        } else if (scan) {
          VoxelPart vp = read_voxel_part(fpath, *scan);
          voxel_edge = vp.resolution * xf.linear().col(0).norm();
          if (report)
            report->notes.push_back("part '" + pname + "' is scanned: " + std::to_string(vp.occupied_voxels) +
                                    " occupied voxels of " + full_precision(voxel_edge) + " (" +
                                    std::to_string(vp.unknown_filled) + " of them unknown), accuracy " +
                                    full_precision(0.5 * std::sqrt(3.0) * voxel_edge));
          pieces.push_back({pname, std::move(vp.mesh), 0});
        } else {
          pieces.push_back({pname, read_mesh_file(fpath), 0});
        }
      } catch (const InputError& e) {
        throw InputError(e.where(), e.reason() + " (" + file + ":" + std::to_string(pt->get("file")->source().begin.line) +
                                        " " + pwhere + ")");
      }
      for (auto& piece : pieces) {
        Part p;
        p.name = pieces.size() == 1 ? pname : pname + "/" + piece.name;
        p.mesh = std::move(piece.mesh);
        p.mesh.transform(xf);
        // The mesh file's own coordinates, or a transform's scale and translation, can put the
        // part where single-precision queries lose it (or overflow).
        for (const Vec3& v : p.mesh.vertices)
          if (!(v.cwiseAbs().maxCoeff() <= kMaxInputMagnitude))
            r.fail(pt->get("file"), pwhere,
                   "a vertex lands at " + full_precision(v) + ", beyond ±" + full_precision(kMaxInputMagnitude) +
                       " scene units (check the file's units and the part's transform)");
        p.role = role;
        p.clearance = extra;
        p.source_file = fpath.string();
        p.source_name = piece.name;
        p.source_faces = piece.brep_faces;
        p.deflection = deflection;
        p.source_leaf = compound ? -1 : piece.leaf;
        p.source_transform = xf;
        p.voxel_edge = voxel_edge;
        p.unknown_occupied = scan && scan->unknown_occupied;
        p.motion = motion;
        const MeshTopology topo = analyse_topology(p.mesh);
        p.closed = topo.closed;
        orient_outward(p.mesh, topo);
        if (p.mesh.empty()) r.fail(pt->get("file"), pwhere + ".file", "empty mesh");
        if (!p.closed && report)
          report->notes.push_back("part '" + p.name + "' is open (" + std::to_string(topo.boundary_edges) +
                                  " boundary edges): it has no inside, surface checks only");
        if (!names.insert(p.name).second) r.fail(&node, pwhere, "duplicate part name '" + p.name + "'");
        scene.parts.push_back(std::move(p));
        if (report) report->part_entries.push_back(idx - 1);
      }
      loaded.add();
    }
    loaded.finish();
  }
  // Ports and branch points must be finite (checked by the XML reader) and, if the scene has
  // parts, inside the OctoMap-addressable range; that check belongs to the voxel map.
  if (report) {
    report->load_ms = t0.ms();
  }
  return scene;
}

void retessellate_parts(Scene& scene, const std::vector<int>& parts, double deflection, CadShapeStore* cad_shapes) {
  TessellationParams tp;
  tp.linear_deflection = deflection;
  tp.angular_deflection_deg = scene.tessellation.angular_deflection_deg.value;
  tp.unit_in_mm = unit_in_mm(scene.units);
  // One reading per file and reading mode: the leaves asked for from a split file, the
  // whole compound otherwise.
  std::map<std::pair<std::string, bool>, std::vector<int>> by_file;
  for (const int k : parts) {
    const Part& p = scene.parts.at(static_cast<std::size_t>(k));
    if (!is_cad_file(p.source_file))
      throw std::invalid_argument("retessellate_parts: part '" + p.name + "' is not a CAD part");
    by_file[{p.source_file, p.source_leaf < 0}].push_back(k);
  }
  for (const auto& [key, ks] : by_file) {
    const std::string& file = key.first;
    const bool compound = key.second;  // a plain variable: lambdas may not capture structured bindings (C++17)
    std::vector<int> leaves;
    for (const int k : ks) leaves.push_back(scene.parts[static_cast<std::size_t>(k)].source_leaf);
    std::sort(leaves.begin(), leaves.end());
    leaves.erase(std::unique(leaves.begin(), leaves.end()), leaves.end());
    std::vector<NamedMesh> pieces = compound ? read_cad_file_cached(file, tp, false, nullptr, nullptr, cad_shapes)
                                             : read_cad_file_cached(file, tp, true, nullptr, &leaves, cad_shapes);
    for (const int k : ks) {
      Part& p = scene.parts[static_cast<std::size_t>(k)];
      const auto it = std::find_if(pieces.begin(), pieces.end(),
                                   [&](const NamedMesh& nm) { return compound || nm.leaf == p.source_leaf; });
      if (it == pieces.end())
        throw InputError({file, 0, "part '" + p.name + "'"},
                         "its leaf " + std::to_string(p.source_leaf) + " gave no triangles at deflection " +
                             full_precision(deflection));
      Mesh m = it->mesh;
      m.transform(p.source_transform);
      const MeshTopology topo = analyse_topology(m);
      orient_outward(m, topo);
      p.mesh = std::move(m);
      p.closed = topo.closed;
      p.source_faces = it->brep_faces;
      p.deflection = deflection;
    }
  }
}

}  // namespace loom
