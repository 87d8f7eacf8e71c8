// α-SIM with and without splitting blocked parts, on scenes nobody here modelled for it:
// the wing section, the real-meshes example (an office, the CAx-IF AS1 assembly, a machined
// part, a motor), the AS1 assembly, the link-rod assembly and the CAx-IF S1 assembly (eleven
// parts in nine STEP files: hollow body shells with bulkheads) alone at dim_pre 2 mm, the
// motor housing and the Cesium milk truck (a concave body). For each: triangles kept, parts
// blocked (and those larger than 20·dim_pre), parts split and their pieces, least
// containment, time per input triangle, and the bytes of the Embree index over the exact
// and the simplified parts. Writes bench/results/alpha_sim_split.csv (+ .gp/.png).
//
//   bench_part_split [OUT_DIR]
#include "core/io/scene_load.hpp"
#include "core/stopwatch.hpp"
#include "index/embree_index.hpp"
#include "index/simplify/alpha_sim.hpp"

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using namespace loom;

namespace {

/// One input: a scene file, or one part file wrapped in a scene written here.
struct Case {
  std::string name;
  fs::path scene;     ///< a scene file, or empty
  fs::path part;      ///< else this file as the only part
  std::string units;  ///< of the wrapping scene
  double dim_pre = 0.0;     ///< > 0: overrides the scene's
  double deflection = 0.0;  ///< > 0: [tessellation] linear_deflection of the wrapping scene
};

/// What one run of simplify_parts gave.
struct Outcome {
  std::size_t before = 0, after = 0, blocked = 0, blocked_large = 0, split = 0, pieces = 0;
  double containment = 1.0, seconds = 0.0;
  std::size_t bytes = 0;
};

fs::path wrap(const Case& c, const fs::path& dir) {
  const fs::path toml = dir / (c.name + ".toml");
  std::ofstream f(toml);
  f << "[scene]\nname = \"" << c.name << "\"\nunits = \"" << c.units << "\"\n\n[[part]]\nname = \"" << c.name
    << "\"\nfile = \"" << c.part.string() << "\"\nrole = \"structure\"\n";
  if (c.deflection > 0.0) f << "\n[tessellation]\nlinear_deflection = " << c.deflection << "\n";
  return toml;
}

Outcome run(const std::vector<Part>& parts, const AlphaSimOptions& o) {
  Outcome out;
  std::vector<AlphaSimResult> results;
  const Stopwatch t;
  const std::vector<Part> simple = simplify_parts(parts, o, &results);
  out.seconds = t.seconds();
  for (const AlphaSimResult& r : results) {
    out.before += r.triangles_before;
    out.after += r.triangles_after;
    const bool blocked = r.status == AlphaSimStatus::Blocked;
    out.blocked += blocked;
    if (blocked) {
      std::printf("  blocked: %s: %s\n", r.name.c_str(), r.reason.c_str());
      double size = 0.0;
      for (const Part& p : parts)
        if (p.name == r.name) size = p.mesh.bounds().size().maxCoeff();
      out.blocked_large += size > 20.0 * o.dim_pre;
    }
    if (!r.pieces.empty() && r.fallback != AlphaSimFallback::Original) {
      ++out.split;
      for (const AlphaSimPiece& p : r.pieces) out.pieces += p.leaf;
    }
    out.containment = std::min(out.containment, r.containment);
  }
  out.bytes = EmbreeIndex(simple).memory_bytes();
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  const fs::path out_dir = argc > 1 ? fs::path(argv[1]) : fs::path(LOOM_SOURCE_DIR) / "bench" / "results";
  const fs::path data(LOOM_SHARED_DATA), src(LOOM_SOURCE_DIR);
  const fs::path tmp = fs::temp_directory_path() / "loom-bench-part-split";
  fs::create_directories(tmp);
  fs::create_directories(out_dir);
  const std::vector<Case> cases = {
      {"wing-section", src / "examples" / "wing-section" / "scene.toml", {}, "", 0.0, 0.0},
      {"wing-section-2mm", src / "examples" / "wing-section" / "scene.toml", {}, "", 2.0, 0.0},
      {"real-meshes", src / "examples" / "real-meshes" / "scene.toml", {}, "", 0.0, 0.0},
      {"as1-2mm", {}, data / "stepcode" / "as1-oc-214.stp", "mm", 2.0, 0.2},
      {"linkrods-2mm", {}, data / "occt" / "linkrods.step", "mm", 2.0, 0.2},
      {"s1-assembly-2mm", {}, data / "stepcode" / "s1-c5-214" / "s1-c5-214.stp", "mm", 2.0, 0.2},
      {"motor-2mm", {}, data / "occt" / "motor.stl", "mm", 2.0, 0.0},
      {"milk-truck-20mm", {}, data / "trimesh" / "CesiumMilkTruck.glb", "m", 0.02, 0.0},
  };
  const fs::path csv = out_dir / "alpha_sim_split.csv";
  std::ofstream f(csv);
  f << "case,parts,dim_pre,triangles_before,kept_unsplit,kept_split,ratio_unsplit,ratio_split,blocked_unsplit,"
       "blocked_split,blocked_large_split,parts_split,pieces,containment_split,seconds_unsplit,seconds_split,"
       "time_per_triangle_ratio,index_bytes_exact,index_bytes_unsplit,index_bytes_split\n";
  for (const Case& c : cases) {
    Scene scene;
    try {
      scene = load_scene(c.scene.empty() ? wrap(c, tmp) : c.scene);
    } catch (const std::exception& e) {
      std::printf("%-18s not loaded: %s\n", c.name.c_str(), e.what());
      continue;
    }
    AlphaSimOptions o;
    o.dim_pre = c.dim_pre > 0.0 ? c.dim_pre : scene.simplify.dim_pre.value;
    o.scene_size = scene.bounds().diagonal();
    o.hausdorff = false;  // not a figure here; containment and the lost-space probe stay
    AlphaSimOptions whole = o;
    whole.split_blocked = false;
    const Outcome a = run(scene.parts, whole), b = run(scene.parts, o);
    const std::size_t exact = EmbreeIndex(scene.parts).memory_bytes();
    const double per = (b.seconds / std::max<std::size_t>(b.before, 1)) / (a.seconds / std::max<std::size_t>(a.before, 1));
    f << c.name << ',' << scene.parts.size() << ',' << o.dim_pre << ',' << a.before << ',' << a.after << ','
      << b.after << ',' << double(a.after) / a.before << ',' << double(b.after) / b.before << ',' << a.blocked << ','
      << b.blocked << ',' << b.blocked_large << ',' << b.split << ',' << b.pieces << ',' << b.containment << ','
      << a.seconds << ',' << b.seconds << ',' << per << ',' << exact << ',' << a.bytes << ',' << b.bytes << '\n';
    std::printf("%-18s %3zu parts, dim_pre %g: %8zu tri -> %7zu (%5.1f%%) whole, %7zu (%5.1f%%) split; blocked %zu -> %zu "
                "(%zu > 20 dim_pre); %zu split into %zu pieces; containment %.6f; %.2f s vs %.2f s; index %.1f / %.1f / %.1f MB\n",
                c.name.c_str(), scene.parts.size(), o.dim_pre, a.before, a.after, 100.0 * a.after / a.before, b.after,
                100.0 * b.after / b.before, a.blocked, b.blocked, b.blocked_large, b.split, b.pieces, b.containment,
                a.seconds, b.seconds, exact / 1e6, a.bytes / 1e6, b.bytes / 1e6);
    std::fflush(stdout);
  }
  f.close();
  const fs::path gp = out_dir / "alpha_sim_split.gp";
  std::ofstream g(gp);
  g << "set terminal pngcairo size 900,500\nset output '" << (out_dir / "alpha_sim_split.png").string() << "'\n"
    << "set datafile separator ','\nset style data histograms\nset style fill solid 0.8\nset logscale y\n"
    << "set ylabel 'share of triangles kept (log)'\nset xtics rotate by -30\nset key top left\n"
    << "set title 'alpha-SIM: triangles kept, blocked parts whole vs split'\n"
    << "plot '" << csv.string() << "' using 7:xtic(1) title 'blocked kept whole', '' using 8 title 'blocked split'\n";
  g.close();
  if (std::system(("gnuplot '" + gp.string() + "'").c_str()) != 0) std::printf("gnuplot failed\n");
  std::printf("wrote %s\n", csv.string().c_str());
  return 0;
}
