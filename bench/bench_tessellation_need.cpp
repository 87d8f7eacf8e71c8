// Tessellation by need on real STEP assemblies (stepcode's AS1 and S1 — eleven parts in nine
// files, curved body shells —, OpenCASCADE's link rods) and the wing section's 14 STEP parts:
// 2 mm cables (fine deflection r / 10 = 0.1 mm) drawn straight through the three largest
// parts' boxes along their longest axis, and one past the assembly. For each policy —
// uniform at the fine deflection (the reference), by need (coarse 20×, refined near the
// cables), uniform at the coarse deflection (not certified: what skipping the refinement
// would give) — the first load (an empty tessellation cache), triangles, parts refined,
// audit time and whether the findings are the reference's. Writes
// bench/results/tessellation_need.csv and tessellation_need.png.
//   bench_tessellation_need [ASSEMBLY...]   (as1, linkrods, s1, wing; default all)
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>
#include <string>
#include <vector>

#include "core/io/harness_xml.hpp"
#include "core/io/mesh_read.hpp"
#include "core/io/scene_load.hpp"
#include "core/stopwatch.hpp"
#include "routing/audit/audit.hpp"

using namespace loom;
namespace fs = std::filesystem;

namespace {

/// A STEP file read as one part per solid, or (no file) the wing section's scene.
struct Assembly {
  std::string name;
  fs::path file;
};

/// The wing section's scene file with its part paths absolute and the bench's harness.
std::string wing_parts_text() {
  const fs::path ex = fs::path(LOOM_SOURCE_DIR) / "examples" / "wing-section";
  std::ifstream in(ex / "scene.toml");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  text = text.substr(text.find("[[part]]"), text.find("[harness]") - text.find("[[part]]"));
  for (std::size_t at = text.find("file = \""); at != std::string::npos; at = text.find("file = \"", at + 1))
    text.insert(at + 8, (ex / "").string());
  return text;
}

/// Cable diameters, mm: fine deflections r / 10 = 0.1 and 0.02 mm.
constexpr double kDiameters[] = {2.0, 0.4};
constexpr double kClearance = 1.0;

/// The harness: a cable through each of the three largest leaves' boxes along their
/// longest axis, from outside the assembly to outside it, and one past the assembly.
Harness cables_through(const std::vector<AABB>& boxes, double diameter) {
  AABB all;
  for (const AABB& b : boxes) all.extend(b);
  std::vector<std::size_t> order(boxes.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(),
            [&](std::size_t a, std::size_t b) { return boxes[a].diagonal() > boxes[b].diagonal(); });
  Harness h;
  h.name = "through";
  auto add = [&](const std::string& id, const Vec3& a, const Vec3& b) {
    const Vec3 d = (b - a).normalized();
    h.ports.push_back({id + "a", a, d, 0});
    h.ports.push_back({id + "b", b, -d, 0});
    Segment s;
    s.from = id + "a", s.to = id + "b", s.interp = Interp::Polyline;
    h.segments.push_back(s);
    Cable c;
    c.id = id, c.ports[0] = id + "a", c.ports[1] = id + "b", c.physical.diameter = diameter;
    h.cables.push_back(c);
  };
  const double margin = 0.1 * all.diagonal();
  for (std::size_t k = 0; k < std::min<std::size_t>(3, order.size()); ++k) {
    const AABB b = boxes[order[k]];
    int axis = 0;
    b.size().maxCoeff(&axis);
    Vec3 a = b.center(), z = b.center();
    // Slightly off the centre line: through the part's material, not along a symmetry axis.
    a[(axis + 1) % 3] += 0.07 * b.size()[(axis + 1) % 3];
    z[(axis + 1) % 3] += 0.07 * b.size()[(axis + 1) % 3];
    a[axis] = all.min[axis] - margin;
    z[axis] = all.max[axis] + margin;
    add("T" + std::to_string(k), a, z);
  }
  add("P", all.min - Vec3::Constant(margin), Vec3(all.max.x() + margin, all.min.y() - margin, all.min.z() - margin));
  return h;
}

std::string scene_text(const Assembly& a, const std::string& policy, double diameter) {
  std::string t = "[scene]\nname = \"" + a.name + "\"\nunits = \"mm\"\n[harness]\nfile = \"harness.xml\"\n" +
                  "[routing]\nclearance = " + std::to_string(kClearance) + "\n[tessellation]\n";
  if (policy == "by-need") t += "by_need = true\n";
  // The coarse deflection by need uses: 20 fine deflections of r / 10.
  if (policy == "uniform-coarse") t += "linear_deflection = " + std::to_string(diameter) + "\n";
  if (a.file.empty()) return t + wing_parts_text();
  return t + "[[part]]\nname = \"" + a.name + "\"\nfile = \"" + a.file.string() + "\"\n";
}

/// The parts' boxes at a coarse deflection (where the cables go).
std::vector<AABB> part_boxes(const Assembly& a, const fs::path& dir) {
  std::vector<AABB> out;
  if (a.file.empty()) {
    std::ofstream(dir / "boxes.toml") << "[scene]\nname = \"boxes\"\nunits = \"mm\"\n[tessellation]\n"
                                         "linear_deflection = 2.0\n" +
                                             wing_parts_text();
    for (const Part& p : load_scene(dir / "boxes.toml").parts) out.push_back(p.mesh.bounds());
    return out;
  }
  TessellationParams coarse;
  coarse.linear_deflection = 2.0;
  for (const NamedMesh& m : read_cad_file(a.file, coarse, true)) out.push_back(m.mesh.bounds());
  return out;
}

std::set<std::string> finding_keys(const AuditReport& r) {
  std::set<std::string> out;
  for (const ClashEntry& e : r.result.clashes)
    out.insert(std::string(clash_kind_name(e.kind)) + " " + r.check_ids[static_cast<std::size_t>(e.cable)] + " " +
               (e.part >= 0 ? r.part_names[static_cast<std::size_t>(e.part)] : ""));
  for (const Violation& v : r.result.violations)
    out.insert(std::string(violation_kind_name(v.kind)) + " " + r.check_ids[static_cast<std::size_t>(v.cable)] + " " +
               (v.part >= 0 ? r.part_names[static_cast<std::size_t>(v.part)] : ""));
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  const fs::path data = LOOM_SHARED_DATA;
  std::vector<Assembly> all = {
      {"as1", data / "stepcode" / "as1-oc-214.stp"},
      {"linkrods", data / "occt" / "linkrods.step"},
      {"s1", data / "stepcode" / "s1-c5-214" / "s1-c5-214.stp"},
      {"wing", {}}};
  std::vector<Assembly> chosen;
  for (int i = 1; i < argc; ++i)
    for (const Assembly& a : all)
      if (a.name == argv[i]) chosen.push_back(a);
  if (chosen.empty()) chosen = all;
  const fs::path work = fs::temp_directory_path() / "loom-bench-tessellation-need";
  const fs::path results = fs::path(LOOM_SOURCE_DIR) / "bench" / "results";
  std::ofstream csv(results / "tessellation_need.csv");
  csv << "assembly,cable_mm,fine_deflection,policy,parts,refined,triangles,load_ms,load_cached_ms,audit_ms,clashes,"
         "violations,"
         "same_findings\n";
  for (const Assembly& a : chosen)
    for (const double diameter : kDiameters) {
      const fs::path dir = work / (a.name + "-" + std::to_string(diameter));
      fs::create_directories(dir);
      write_harness_xml(cables_through(part_boxes(a, dir), diameter), dir / "harness.xml");
      std::set<std::string> reference;
      for (const std::string policy : {"uniform-fine", "by-need", "uniform-coarse"}) {
        const fs::path scene = dir / (policy + ".toml");
        std::ofstream(scene) << scene_text(a, policy, diameter);
        // The first load: a tessellation cache of its own, empty.
        const fs::path cache = dir / ("cache-" + policy);
        fs::remove_all(cache);
        setenv("LOOM_CACHE_DIR", cache.c_str(), 1);
        const Stopwatch t0;
        const AuditReport rep = audit_scene_file(scene, AuditOptions{});
        const double total = t0.ms();
        // The next load: every tessellation from the cache.
        const double warm_ms = audit_scene_file(scene, AuditOptions{}).load_ms;
        const auto keys = finding_keys(rep);
        if (policy == "uniform-fine") reference = keys;
        const bool same = keys == reference;
        csv << a.name << "," << diameter << "," << diameter / 20.0 << "," << policy << "," << rep.part_names.size()
            << "," << rep.tessellation.refined.size() << "," << rep.triangles << "," << rep.load_ms << "," << warm_ms
            << "," << total - rep.load_ms << "," << rep.result.clashes.size() << "," << rep.result.violations.size()
            << "," << (same ? "yes" : "no") << "\n";
        std::printf(
            "%-9s d %.1f %-15s %3zu parts, %3zu refined, %9zu triangles, load %8.0f ms (cached %6.0f ms), audit %6.0f "
            "ms, %zu clashes, "
            "%zu violations, findings %s\n",
            a.name.c_str(), diameter, policy.c_str(), rep.part_names.size(), rep.tessellation.refined.size(),
            rep.triangles, rep.load_ms, warm_ms, total - rep.load_ms, rep.result.clashes.size(),
            rep.result.violations.size(), same ? "as the fine mesh" : "DIFFERENT");
      }
    }
  csv.close();
  const std::string gp = "set datafile separator ','\nset terminal pngcairo size 1200,560\nset output '" +
                         (results / "tessellation_need.png").string() +
                         "'\nset multiplot layout 1,2\nset style data histograms\nset style fill solid 0.8\n"
                         "set logscale y\nset xtics rotate by -50 font ',9'\nset bmargin 9\nset key top left\nset "
                         "title 'First load (empty cache), ms'\n"
                         "plot '" +
                         (results / "tessellation_need.csv").string() +
                         "' using 8:xtic(stringcolumn(1).' '.stringcolumn(2).' '.stringcolumn(4)) skip 1 notitle\n"
                         "set title 'Triangles'\nplot '' using 7:xtic(stringcolumn(1).' '.stringcolumn(2).' "
                         "'.stringcolumn(4)) skip 1 notitle\n"
                         "unset multiplot\n";
  if (FILE* p = popen("gnuplot", "w")) {
    std::fputs(gp.c_str(), p);
    pclose(p);
  }
  return 0;
}
