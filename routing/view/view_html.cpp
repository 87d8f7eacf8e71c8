#include "routing/view/view_html.hpp"
#include "routing/view/motion_view.hpp"

#include "core/error.hpp"
#include "core/harness_topology.hpp"
#include "core/io/atomic_file.hpp"
#include "core/units.hpp"
#include "routing/curve/cable_geometry.hpp"
#include "routing/view/render.hpp"
#include "core/io/json_text.hpp"
#include "routing/audit/report_json.hpp"
#include "routing/view/view_assets.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <set>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <vector>

namespace loom {

namespace {

/// Coordinate rounding when none is given: 0.01 scene unit, finer for scenes under 1000 units.
constexpr double kDefaultQuantumUnits = 0.01;
constexpr double kQuantumPerDiagonal = 1e-5;
/// Growth of the clustering cell when a pass leaves too many triangles.
constexpr double kCellGrowth = 1.25;
constexpr int kMaxClusterPasses = 200;

struct CellKey {
  std::int64_t x, y, z;
  bool operator==(const CellKey& o) const { return x == o.x && y == o.y && z == o.z; }
};
struct CellHash {
  std::size_t operator()(const CellKey& k) const {
    std::uint64_t h = 1469598103934665603ull;
    for (std::int64_t v : {k.x, k.y, k.z}) h = (h ^ static_cast<std::uint64_t>(v)) * 1099511628211ull;
    return static_cast<std::size_t>(h);
  }
};
struct TriKey {
  std::array<std::uint32_t, 3> v;
  bool operator==(const TriKey& o) const { return v == o.v; }
};
struct TriHash {
  std::size_t operator()(const TriKey& k) const {
    std::uint64_t h = 1469598103934665603ull;
    for (std::uint32_t v : k.v) h = (h ^ v) * 1099511628211ull;
    return static_cast<std::size_t>(h);
  }
};

Mesh cluster(const Mesh& m, const Vec3& origin, double cell) {
  std::unordered_map<CellKey, std::uint32_t, CellHash> cells;
  std::vector<Vec3> sum;
  std::vector<double> count;
  std::vector<std::uint32_t> rep(m.vertices.size());
  for (std::size_t i = 0; i < m.vertices.size(); ++i) {
    const Vec3 c = ((m.vertices[i] - origin) / cell).array().floor();
    const CellKey key{static_cast<std::int64_t>(c.x()), static_cast<std::int64_t>(c.y()),
                      static_cast<std::int64_t>(c.z())};
    auto [it, fresh] = cells.emplace(key, static_cast<std::uint32_t>(sum.size()));
    if (fresh) {
      sum.push_back(Vec3::Zero());
      count.push_back(0.0);
    }
    rep[i] = it->second;
    sum[it->second] += m.vertices[i];
    count[it->second] += 1.0;
  }
  Mesh out;
  std::unordered_set<TriKey, TriHash> seen;
  std::vector<std::uint32_t> used(sum.size(), UINT32_MAX);
  for (const auto& t : m.triangles) {
    const std::array<std::uint32_t, 3> r{rep[t[0]], rep[t[1]], rep[t[2]]};
    if (r[0] == r[1] || r[1] == r[2] || r[0] == r[2]) continue;
    TriKey k{r};
    std::sort(k.v.begin(), k.v.end());
    if (!seen.insert(k).second) continue;
    std::array<std::uint32_t, 3> nt{};
    for (int j = 0; j < 3; ++j) {
      if (used[r[j]] == UINT32_MAX) {
        used[r[j]] = static_cast<std::uint32_t>(out.vertices.size());
        out.vertices.push_back(sum[r[j]] / count[r[j]]);
      }
      nt[j] = used[r[j]];
    }
    out.triangles.push_back(nt);
  }
  return out;
}

double derived_quantum(const Scene& scene) {
  const AABB b = scene.bounds();
  const double diag = b.empty() ? 0.0 : b.size().norm();
  const double q = std::min(kDefaultQuantumUnits, kQuantumPerDiagonal * diag);
  return q > 0.0 ? q : kDefaultQuantumUnits;
}

void append_int(std::string& s, long long v) { s += std::to_string(v); }

long long quantize(double x, double q) {
  const double r = std::round(x / q);
  return std::isfinite(r) ? static_cast<long long>(r) : 0;
}

void append_points(std::string& s, const std::vector<Vec3>& pts, double q) {
  s += '[';
  bool first = true;
  for (const Vec3& p : pts)
    for (int k = 0; k < 3; ++k) {
      if (!first) s += ',';
      first = false;
      append_int(s, quantize(p[k], q));
    }
  s += ']';
}

std::string js(const std::string& text) { return json_text(nlohmann::json(text)); }

/// A report value as a finite number for the page (the reports never hold NaN; be safe).
double finite_or(const nlohmann::json& j, const char* key, double fallback) {
  if (!j.contains(key) || !j[key].is_number()) return fallback;
  const double v = j[key].get<double>();
  return std::isfinite(v) ? v : fallback;
}

/// One clash or violation of the report as the page's JSON, or false if it has no point.
bool marker_json(const nlohmann::json& e, double q, std::string& s) {
  if (!e.contains("point") || !e["point"].is_array() || e["point"].size() != 3) return false;
  nlohmann::json o;
  for (const char* k : {"kind", "cable", "part", "other"})
    if (e.contains(k) && e[k].is_string()) o[k] = e[k];
  for (const char* k : {"clearance", "s", "value", "limit"})
    if (e.contains(k) && e[k].is_number()) o[k] = std::round(finite_or(e, k, 0.0) / q) * q;
  // DESIGN §4 violations: bend-radius carries radius/min, clearance carries clearance/required.
  for (const auto& [from, to] : {std::pair<const char*, const char*>{"radius", "value"}, {"min", "limit"},
                                 {"required", "limit"}})
    if (e.contains(from) && e[from].is_number()) o[to] = std::round(finite_or(e, from, 0.0) / q) * q;
  if (e.contains("required") && o.contains("clearance")) o["value"] = o["clearance"];
  nlohmann::json p = nlohmann::json::array();
  for (const auto& c : e["point"]) p.push_back(c.is_number() ? quantize(c.get<double>(), q) : 0);
  o["p"] = p;
  s += json_text(o);
  return true;
}

/// Keeps "</" out of the inlined JSON so that it cannot close its <script> element.
std::string script_safe(std::string s) {
  std::string out;
  out.reserve(s.size());
  for (std::size_t i = 0; i < s.size(); ++i) {
    out += s[i];
    if (s[i] == '<' && i + 1 < s.size() && s[i + 1] == '/') out += '\\';
  }
  return out;
}

extern const char* const kPageHead;
extern const char* const kPageApp;

}  // namespace

Mesh decimate_vertex_clustering(const Mesh& mesh, std::size_t max_triangles) {
  if (mesh.triangles.size() <= max_triangles) return mesh;
  if (max_triangles == 0) return Mesh{};
  const AABB b = mesh.bounds();
  const double diag = b.size().norm();
  // A surface of area A clustered on cells of edge c keeps about 2A/c² triangles.
  double cell = std::sqrt(2.0 * mesh.area() / static_cast<double>(max_triangles));
  if (!(cell > 0.0) || !std::isfinite(cell)) cell = diag / std::cbrt(static_cast<double>(max_triangles));
  if (!(cell > 0.0)) return Mesh{};  // every vertex in one place: nothing to draw
  for (int pass = 0; pass < kMaxClusterPasses; ++pass, cell *= kCellGrowth) {
    Mesh out = cluster(mesh, b.min, cell);
    if (out.triangles.size() <= max_triangles) return out;
  }
  return Mesh{};  // unreachable: a cell larger than the box leaves no triangle
}

std::string view_data_json(const Scene& scene, const Harness& harness, const nlohmann::json& report,
                           const ViewOptions& opt, ViewStats* stats_out) {
  ViewStats st;
  const double q = opt.quantum > 0.0 ? opt.quantum : derived_quantum(scene);
  st.quantum = q;
  std::string s = "{\"name\":" + js(scene.name) + ",\"units\":" + js(unit_name(scene.units)) + ",\"quantum\":";
  s += nlohmann::json(q).dump();
  AABB box = scene.bounds();

  // Parts, decimated to the budget in proportion to their size.
  st.part_triangles = scene.triangle_count();
  s += ",\"budget\":" + std::to_string(opt.triangle_budget) + ",\"parts\":[";
  // Moving parts are drawn at rest (as parts), then at their extreme and clash poses.
  std::vector<PosedPartView> views;
  for (const Part& p : scene.parts) views.push_back({p.name, role_name(p.role), Mesh{}});
  std::vector<PosedPartView> posed = motion_view_meshes(scene, report);
  std::size_t total = st.part_triangles;  // the budget is shared out over the posed copies too
  for (auto& v : posed) total += v.mesh.triangles.size();
  for (std::size_t i = 0; i < views.size() + posed.size(); ++i) {
    const bool rest = i < views.size();
    const PosedPartView& pv = rest ? views[i] : posed[i - views.size()];
    const Mesh& pm = rest ? scene.parts[i].mesh : pv.mesh;
    std::size_t share = pm.triangles.size();
    if (total > opt.triangle_budget)
      share = static_cast<std::size_t>(static_cast<double>(opt.triangle_budget) *
                                       static_cast<double>(pm.triangles.size()) / static_cast<double>(total));
    const Mesh m = decimate_vertex_clustering(pm, share);
    st.shown_triangles += m.triangles.size();
    if (!rest)
      for (const Vec3& v : pm.vertices) box.extend(v);
    if (i) s += ',';
    s += "{\"name\":" + js(pv.name) + ",\"role\":" + js(pv.role) +
         ",\"triangles\":" + std::to_string(pm.triangles.size()) + ",\"v\":";
    append_points(s, m.vertices, q);
    s += ",\"t\":[";
    for (std::size_t t = 0; t < m.triangles.size(); ++t)
      for (int k = 0; k < 3; ++k) {
        if (t || k) s += ',';
        append_int(s, m.triangles[t][static_cast<std::size_t>(k)]);
      }
    s += "]}";
  }

  // Cables: sampled centerlines.
  s += "],\"cables\":[";
  const HarnessTopology topo(harness);
  SegmentCurves curves(topo);
  const std::set<std::string> unrouted = unrouted_cable_ids(report);  // listed, never drawn
  for (std::size_t c = 0; c < harness.cables.size(); ++c) {
    const Cable& cab = harness.cables[c];
    std::vector<Vec3> pts;
    if (auto cl = unrouted.count(cab.id) ? std::nullopt : curves.cable(static_cast<int>(c))) {
      const double len = cl->length();
      const double spacing = len / static_cast<double>(std::max<std::size_t>(2, opt.max_cable_samples));
      if (spacing > 0.0)
        for (const auto& us : cl->sample_by_arc_length(spacing)) pts.push_back(us.second);
    }
    for (const Vec3& p : pts) box.extend(p);
    if (pts.size() >= 2) ++st.cables_drawn;
    if (c) s += ',';
    s += "{\"id\":" + js(cab.id) + ",\"color\":" + js(cab.physical.color) + ",\"radius\":" +
         nlohmann::json(std::max(q, std::round(cab.radius() / q) * q)).dump() + ",\"p\":";
    append_points(s, pts, q);
    s += '}';
  }

  // Clashes and violations exactly as the report lists them (their index is the report's).
  s += "],\"clashes\":[";
  bool first = true;
  if (report.contains("clashes") && report["clashes"].is_array())
    for (const auto& e : report["clashes"]) {
      if (!first) s += ',';
      first = false;
      if (marker_json(e, q, s)) ++st.clashes;
      else s += "null";
    }
  s += "],\"violations\":[";
  first = true;
  if (report.contains("violations") && report["violations"].is_array())
    for (const auto& e : report["violations"]) {
      if (!first) s += ',';
      first = false;
      if (marker_json(e, q, s)) ++st.violations;
      else s += "null";
    }
  // Clamps (route-placed and the harness's own), with the bundle they hold.
  s += "],\"clamps\":[";
  first = true;
  if (report.contains("clamps") && report["clamps"].is_array())
    for (const auto& c : report["clamps"]) {
      if (!c.contains("point") || !c["point"].is_array() || c["point"].size() != 3) continue;
      nlohmann::json o;
      o["id"] = c.contains("id") && c["id"].is_string() ? c["id"] : nlohmann::json("?");
      if (c.contains("part") && c["part"].is_string()) o["part"] = c["part"];
      o["d"] = std::round(finite_or(c, "bundle_diameter", 0.0) / q) * q;
      o["placed"] = c.contains("placed") && c["placed"].is_boolean() && c["placed"].get<bool>();
      nlohmann::json pt = nlohmann::json::array();
      for (const auto& v : c["point"]) pt.push_back(v.is_number() ? quantize(v.get<double>(), q) : 0);
      o["p"] = pt;
      if (!first) s += ',';
      first = false;
      s += json_text(o);
      ++st.clamps;
    }
  s += "],\"bounds\":";
  std::vector<Vec3> corners;
  if (!box.empty()) corners = {box.min, box.max};
  else corners = {Vec3::Zero(), Vec3::Ones()};
  append_points(s, corners, q);
  s += '}';
  if (stats_out) *stats_out = st;
  return s;
}

ViewStats write_view_html(const std::filesystem::path& file, const Scene& scene, const Harness& harness,
                          const nlohmann::json& report, const ViewOptions& opt) {
  ViewStats st;
  const std::string data = view_data_json(scene, harness, report, opt, &st);
  const std::string title = opt.title.empty() ? "loom — " + scene.name : opt.title;
  std::string html;
  html.reserve(view_assets::three_js().size() + view_assets::orbit_controls_js().size() + data.size() + 20000);
  html += "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>";
  for (char ch : title) {
    if (ch == '<') html += "&lt;";
    else if (ch == '&') html += "&amp;";
    else html += ch;
  }
  html += "</title>\n";
  html += kPageHead;
  html += "<script>\n";
  html += view_assets::three_js();
  html += "\n</script>\n<script>\n";
  html += view_assets::orbit_controls_js();
  html += "\n</script>\n<script type=\"application/json\" id=\"loom-data\">";
  html += script_safe(data);
  html += "</script>\n<script>\n";
  html += kPageApp;
  html += "</script>\n</body></html>\n";
  write_file_atomic(file, html);
  st.bytes = html.size();
  return st;
}

std::vector<std::filesystem::path> view_output_files(const std::filesystem::path& dir) {
  return {dir / "view.html", dir / "render.png"};
}

ViewStats write_view_outputs(const std::filesystem::path& dir, const Scene& scene, const Harness& harness,
                             const nlohmann::json& report, const RenderOptions& render) {
  // Render first: if the picture is refused (its tube budget), neither file is written.
  const Image img = render_scene(scene, harness, report, render);
  const ViewStats st = write_view_html(dir / "view.html", scene, harness, report);
  write_png(dir / "render.png", img);
  return st;
}

namespace {

const char* const kPageHead = R"HTML(<style>
html,body{margin:0;height:100%;font:13px/1.35 system-ui,sans-serif;color:#1d232b;overflow:hidden}
#side{position:absolute;left:0;top:0;bottom:0;width:300px;overflow:auto;background:#fff;border-right:1px solid #ccd;padding:8px;box-sizing:border-box}
#view{position:absolute;left:300px;right:0;top:0;bottom:0;background:#f4f5f7}
h1{font-size:15px;margin:0 0 4px} h2{font-size:13px;margin:10px 0 3px;color:#445}
ol,ul{margin:0;padding-left:22px} li{cursor:pointer;padding:1px 2px;border-radius:3px}
li:hover{background:#eef} li.selected{background:#ffe27a}
.sw{display:inline-block;width:10px;height:10px;border-radius:2px;margin-right:4px;vertical-align:middle}
#parts li{cursor:default} #msg{color:#a00} .muted{color:#778}
</style></head>
<body data-ready="0">
<div id="side"><h1 id="title"></h1><div id="summary" class="muted"></div><div id="msg"></div>
<h2>Clashes (<span id="clash-count">0</span>)</h2><ol id="clash-list" start="0"></ol>
<h2>Violations (<span id="violation-count">0</span>)</h2><ol id="violation-list" start="0"></ol>
<h2>Clamps (<span id="clamp-count">0</span>)</h2><ol id="clamp-list" start="0"></ol>
<h2>Cables (<span id="cable-count">0</span>)</h2><ol id="cable-list" start="0"></ol>
<h2>Parts</h2><ul id="parts"></ul>
<p class="muted">Drag: orbit · right-drag: pan · wheel: zoom. Click an item to fly to it.</p></div>
<div id="view"></div>
)HTML";

const char* const kPageApp = R"JS(
(function () {
'use strict';
var D = JSON.parse(document.getElementById('loom-data').textContent);
var q = D.quantum, body = document.body;
function st(k, v) { body.setAttribute('data-' + k, String(v)); }
function el(id) { return document.getElementById(id); }
function P(a, i) { return [a[3 * i] * q, a[3 * i + 1] * q, a[3 * i + 2] * q]; }
function fmt(x) { return x === undefined ? '?' : String(Math.round(x * 1000) / 1000); }
var MARK = { clash: 0xe02020, 'bend-radius': 0xff8c00, clearance: 0xe0c000, clamp: 0x0090a8 };
var SELECTED = 0xd000ff;
var palette = [];
D.cables.forEach(function (c, i) { palette.push('hsl(' + ((i * 137.508) % 360).toFixed(1) + ',70%,45%)'); });

var bmin = P(D.bounds, 0), bmax = P(D.bounds, 1);
var diag = Math.max(1e-9, Math.hypot(bmax[0] - bmin[0], bmax[1] - bmin[1], bmax[2] - bmin[2]));
var markerR = diag * 0.006;
el('title').textContent = D.name || 'scene';
var shown = 0, total = 0;
D.parts.forEach(function (p) { shown += p.t.length / 3; total += p.triangles; });
el('summary').textContent = D.parts.length + ' parts, ' + shown + ' of ' + total + ' triangles drawn (budget ' +
  D.budget + '), units ' + D.units;

// --- the lists: items carry what the camera needs to fly to them -------------------------
var items = { clash: [], violation: [], clamp: [], cable: [] };
var view = null;
function addItem(kind, i, text, center, radius, swatch) {
  var li = document.createElement('li');
  if (swatch) { var s = document.createElement('span'); s.className = 'sw'; s.style.background = swatch; li.appendChild(s); }
  li.appendChild(document.createTextNode(text));
  li.setAttribute('data-index', i);
  li.addEventListener('click', function () { select(kind, i); });
  el(kind + '-list').appendChild(li);
  items[kind][i] = { li: li, center: center, radius: radius, text: text };
}
D.clashes.forEach(function (c, i) {
  if (!c) return;
  addItem('clash', i, c.cable + ' × ' + (c.part || c.other || (c.kind === 'self' ? 'itself' : '?')) + ' (' + c.kind + '), clearance ' + fmt(c.clearance),
          P(c.p, 0), 0);
});
D.violations.forEach(function (v, i) {
  if (!v) return;
  addItem('violation', i, v.kind + ' ' + v.cable + ': ' + fmt(v.value) + ' (limit ' + fmt(v.limit) + ')', P(v.p, 0), 0);
});
D.clamps.forEach(function (c, i) {
  addItem('clamp', i, c.id + (c.part ? ' on ' + c.part : ' (no structure within reach)') + ', bundle \u00d8 ' + fmt(c.d) +
          (c.placed ? ' (placed)' : ''), P(c.p, 0), 0);
});
D.cables.forEach(function (c, i) {
  var n = c.p.length / 3, lo = [1e300, 1e300, 1e300], hi = [-1e300, -1e300, -1e300];
  for (var k = 0; k < n; ++k) { var p = P(c.p, k); for (var a = 0; a < 3; ++a) { lo[a] = Math.min(lo[a], p[a]); hi[a] = Math.max(hi[a], p[a]); } }
  var center = n ? [(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, (lo[2] + hi[2]) / 2] : null;
  var r = n ? Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]) / 2 : 0;
  addItem('cable', i, c.id + (n ? '' : ' (not routed)') + (c.color ? ' (' + c.color + ' insulation)' : ''), center, r, palette[i]);
});
el('clash-count').textContent = items.clash.filter(Boolean).length;
el('violation-count').textContent = items.violation.filter(Boolean).length;
el('clamp-count').textContent = D.clamps.length;
st('clamp-count', D.clamps.length);
el('cable-count').textContent = D.cables.length;
st('clash-count', items.clash.filter(Boolean).length);
st('violation-count', items.violation.filter(Boolean).length);
st('cable-count', D.cables.length);

var selected = null;
function select(kind, i) {
  var it = items[kind][i];
  if (!it) return;
  if (selected) { selected.it.li.classList.remove('selected'); if (view) view.highlight(selected.kind, selected.i, false); }
  selected = { kind: kind, i: i, it: it };
  it.li.classList.add('selected');
  st('selected', kind + ':' + i);
  st('selected-label', it.text);
  if (view) { view.highlight(kind, i, true); if (it.center) view.flyTo(it.center, it.radius); }
}

// --- three.js ------------------------------------------------------------------------------
function initThree() {
  var host = el('view');
  var w = host.clientWidth || 800, h = host.clientHeight || 600;
  var renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
  renderer.setPixelRatio(1);
  renderer.setSize(w, h);
  host.appendChild(renderer.domElement);
  var scene = new THREE.Scene();
  scene.background = new THREE.Color(0xf4f5f7);
  var V = function (p) { return new THREE.Vector3(p[0], p[1], p[2]); };
  var center = V([(bmin[0] + bmax[0]) / 2, (bmin[1] + bmax[1]) / 2, (bmin[2] + bmax[2]) / 2]);
  var camera = new THREE.PerspectiveCamera(40, w / h, diag * 1e-4, diag * 50);
  camera.up.set(0, 0, 1);
  camera.position.copy(center).add(new THREE.Vector3(1.0, -1.4, 0.9).normalize().multiplyScalar(diag * 1.15));
  scene.add(camera);
  scene.add(new THREE.AmbientLight(0xffffff, 0.45));
  var sun = new THREE.DirectionalLight(0xffffff, 0.75);
  sun.position.set(0.3, 0.5, 1);
  camera.add(sun);

  var partMeshes = [];
  D.parts.forEach(function (p, i) {
    var g = new THREE.BufferGeometry();
    var pos = new Float32Array(p.v.length);
    for (var k = 0; k < p.v.length; ++k) pos[k] = p.v[k] * q;
    g.setAttribute('position', new THREE.BufferAttribute(pos, 3));
    g.setIndex(p.t);
    g.computeVertexNormals();
    var keep = p.role === 'keep_out', swept = p.role === 'swept', hit = p.role === 'clash-pose';
    var see = keep || swept || hit;
    var m = new THREE.MeshPhongMaterial({ color: hit ? 0xe02020 : swept ? 0x6090e0 : keep ? 0xd07070 : 0xa3adb8,
      flatShading: true, side: THREE.DoubleSide, transparent: see, opacity: swept ? 0.25 : see ? 0.35 : 1.0,
      shininess: 10, depthWrite: !see });
    var mesh = new THREE.Mesh(g, m);
    scene.add(mesh);
    partMeshes.push(mesh);
    var li = document.createElement('li');
    var cb = document.createElement('input');
    cb.type = 'checkbox'; cb.checked = true;
    cb.addEventListener('change', function () { mesh.visible = cb.checked; });
    li.appendChild(cb);
    li.appendChild(document.createTextNode(p.name + (keep ? ' (keep-out)' : '') + ' — ' + p.t.length / 3 + '/' + p.triangles + ' tri'));
    el('parts').appendChild(li);
  });

  var cableMats = [];
  D.cables.forEach(function (c, i) {
    var n = c.p.length / 3, pts = [];
    for (var k = 0; k < n; ++k) pts.push(V(P(c.p, k)));
    var col = new THREE.Color(palette[i]);
    var mat = new THREE.MeshPhongMaterial({ color: col, shininess: 40 });
    cableMats[i] = mat;
    if (n < 2) return;
    var curve = new THREE.CatmullRomCurve3(pts);
    scene.add(new THREE.Mesh(new THREE.TubeBufferGeometry(curve, Math.min(4 * n, 2000), c.radius, 8, false), mat));
    scene.add(new THREE.Line(new THREE.BufferGeometry().setFromPoints(pts), new THREE.LineBasicMaterial({ color: col })));
  });

  // Markers are drawn over everything: a clash point lies where a cable meets a part.
  var markers = { clash: [], violation: [], clamp: [] };
  var sphere = new THREE.SphereBufferGeometry(markerR, 16, 12);
  var cube = new THREE.BoxBufferGeometry(1.2 * markerR, 1.2 * markerR, 1.2 * markerR);
  function marker(kind, i, e, color) {
    var m = new THREE.Mesh(kind === 'clamp' ? cube : sphere, new THREE.MeshBasicMaterial({ color: color, depthTest: false }));
    m.position.copy(V(P(e.p, 0)));
    m.renderOrder = 10;
    m.userData.color = color;
    scene.add(m);
    markers[kind][i] = m;
  }
  D.clashes.forEach(function (c, i) { if (c) marker('clash', i, c, MARK.clash); });
  D.violations.forEach(function (v, i) { if (v) marker('violation', i, v, MARK[v.kind] || MARK.clearance); });
  D.clamps.forEach(function (c, i) { marker('clamp', i, c, MARK.clamp); });

  var controls = new THREE.OrbitControls(camera, renderer.domElement);
  controls.target.copy(center);
  controls.screenSpacePanning = true;
  controls.update();

  var fly = null;
  function frame() {
    if (fly) {
      fly.t = Math.min(1, fly.t + 1 / 30);
      var a = fly.t * fly.t * (3 - 2 * fly.t);
      controls.target.lerpVectors(fly.t0, fly.t1, a);
      camera.position.lerpVectors(fly.c0, fly.c1, a);
      if (fly.t >= 1) fly = null;
    }
    controls.update();
    renderer.render(scene, camera);
  }
  function loop() { frame(); requestAnimationFrame(loop); }

  window.addEventListener('resize', function () {
    var w2 = host.clientWidth || 800, h2 = host.clientHeight || 600;
    camera.aspect = w2 / h2; camera.updateProjectionMatrix(); renderer.setSize(w2, h2);
  });

  frame();
  // What the test reads: how much of the first frame is not background, and how much is marker red.
  var gl = renderer.getContext();
  var size = renderer.getDrawingBufferSize(new THREE.Vector2());
  var px = new Uint8Array(size.x * size.y * 4);
  gl.readPixels(0, 0, size.x, size.y, gl.RGBA, gl.UNSIGNED_BYTE, px);
  var nonbg = 0, red = 0, hash = 2166136261;
  for (var k = 0; k < px.length; k += 4) {
    var r = px[k], g = px[k + 1], b = px[k + 2];
    if (Math.abs(r - 0xf4) + Math.abs(g - 0xf5) + Math.abs(b - 0xf7) > 12) ++nonbg;
    if (r > 180 && g < 80 && b < 80) ++red;
    hash = Math.imul(hash ^ (r | (g << 8) | (b << 16)), 16777619) >>> 0;
  }
  st('pixels', size.x * size.y);
  st('nonbg-pixels', nonbg);
  st('red-pixels', red);
  st('pixel-hash', hash.toString(16));
  requestAnimationFrame(loop);

  return {
    flyTo: function (p, r) {
      var t1 = V(p), dir = camera.position.clone().sub(controls.target).normalize();
      var dist = Math.max(r * 2.5, markerR * 25);
      fly = { t: 0, t0: controls.target.clone(), t1: t1, c0: camera.position.clone(), c1: t1.clone().add(dir.multiplyScalar(dist)) };
      st('camera-target', [p[0].toFixed(2), p[1].toFixed(2), p[2].toFixed(2)].join(','));
    },
    highlight: function (kind, i, on) {
      if (kind === 'cable') {
        var m = cableMats[i];
        if (m) m.emissive.setHex(on ? 0x555555 : 0x000000);
        return;
      }
      var mk = markers[kind][i];
      if (!mk) return;
      mk.material.color.setHex(on ? SELECTED : mk.userData.color);
      mk.scale.setScalar(on ? 2 : 1);
    }
  };
}

try {
  view = initThree();
  st('webgl', 'ok');
} catch (e) {
  el('msg').textContent = '3D view unavailable: ' + e.message;
  st('webgl', 'unavailable: ' + e.message);
}

// Test hook: #select=clash:2 (or #select=2 for a clash; also violation:, clamp:, cable:) clicks that list item.
function applyHash() {
  var m = /select=(?:(clash|violation|clamp|cable):)?(\d+)/.exec(location.hash);
  if (!m) return;
  var it = items[m[1] || 'clash'][+m[2]];
  if (it) it.li.click();
  else st('selected', 'none');
}
window.addEventListener('hashchange', applyHash);
applyHash();
st('ready', 1);
})();
)JS";

}  // namespace

}  // namespace loom
