/// loom_example_gen OUTDIR [--stats DEFLECTION]: writes the bundled wing-section example
/// (STEP parts, harness.xml, scene.toml) into OUTDIR. With --stats, also tessellates each
/// STEP solid at the given linear deflection (mm, angular 20°) and prints faces/triangles.

#include "examples/generator/wing_parts.hpp"
#include "examples/generator/wing_section.hpp"

#include <BRepMesh_IncrementalMesh.hxx>
#include <BRep_Tool.hxx>
#include <Poly_Triangulation.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

namespace {

constexpr double kStatsAngularDeg = 20.0;  // matches TessellationParams' default

void print_stats(double deflection) {
  std::printf("%-24s %8s %10s   (deflection %g mm, angular %g deg)\n", "file", "faces", "triangles", deflection,
              kStatsAngularDeg);
  for (auto& p : loom::examples::make_wing_parts()) {
    BRepMesh_IncrementalMesh mesh(p.shape, deflection, false, kStatsAngularDeg * M_PI / 180.0, false);
    long faces = 0, tris = 0;
    for (TopExp_Explorer e(p.shape, TopAbs_FACE); e.More(); e.Next(), ++faces) {
      TopLoc_Location loc;
      const Handle(Poly_Triangulation) t = BRep_Tool::Triangulation(TopoDS::Face(e.Current()), loc);
      if (!t.IsNull()) tris += t->NbTriangles();
    }
    std::printf("%-24s %8ld %10ld\n", p.file.c_str(), faces, tris);
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2 && !(argc == 4 && std::string(argv[2]) == "--stats")) {
    std::fprintf(stderr, "usage: %s OUTDIR [--stats DEFLECTION_MM]\n", argv[0]);
    return 2;
  }
  try {
    for (const auto& f : loom::examples::generate_wing_section(argv[1])) std::printf("wrote %s/%s\n", argv[1], f.c_str());
    if (argc == 4) {
      char* end = nullptr;
      const double d = std::strtod(argv[3], &end);
      if (end == argv[3] || *end != '\0' || !(d > 0.0) || !std::isfinite(d)) {
        std::fprintf(stderr, "error: --stats needs a positive deflection in mm, got '%s'\n", argv[3]);
        return 2;
      }
      print_stats(d);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
  return 0;
}
