// Writes the audit bench's scene (bench/audit_scenes.hpp: the seed paper's complex scene,
// or a multiple of it) as files — binary STL parts, a routed harness XML, scene.toml — so
// that `loom audit` and `mpirun -np K loom audit` can read it (bench/bench_mpi_audit.sh).
//   bench_write_audit_scene DIR [MULT]   (MULT = 1: 200 parts, 100 cables, ~1 M triangles)
#include "audit_scenes.hpp"

#include "core/io/harness_xml.hpp"
#include "core/io/mesh_write.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

using namespace loom;

namespace {

/// The bench cable as a harness: its own two ports (exits along the curve's end tangents)
/// and one segment carrying its exact B-spline.
void add_cable(Harness& h, const CableInput& in) {
  const Centerline& c = in.curve;
  Vec3 d0[2], d1[2];
  c.evaluate(c.u_min(), 1, d0);
  c.evaluate(c.u_max(), 1, d1, true);
  const std::string a = in.id + "-a", b = in.id + "-b";
  h.ports.push_back({a, d0[0], d0[1].normalized(), 0});
  h.ports.push_back({b, d1[0], (-d1[1]).normalized(), 0});
  Segment s;
  s.from = a;
  s.to = b;
  s.bspline = BSplineData{c.degree(), c.knots(), c.control_points()};
  h.segments.push_back(s);
  Cable cable;
  cable.id = in.id;
  cable.ports[0] = a;
  cable.ports[1] = b;
  cable.physical.diameter = 2.0 * in.radius;
  cable.physical.min_bend_radius = in.min_bend_radius;
  h.cables.push_back(cable);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: bench_write_audit_scene DIR [MULT]\n");
    return 2;
  }
  const std::filesystem::path dir = argv[1];
  const int mult = argc > 2 ? std::atoi(argv[2]) : 1;
  if (mult < 1) return 2;
  // The same scene as bench_audit's "x1" / "x10" rows.
  const bench::BenchScene sc = bench::make_scene(200 * mult, 7500, 100 * mult, std::cbrt(mult), 42);
  std::filesystem::create_directories(dir / "parts");
  std::ofstream toml(dir / "scene.toml");
  toml << "# The audit bench's scene x" << mult << ": " << sc.parts.size() << " closed parts, " << sc.triangles
       << " triangles, " << sc.cables.size() << " cables (bench/audit_scenes.hpp, seed 42).\n"
       << "[scene]\nname = \"audit-bench-x" << mult << "\"\nunits = \"mm\"\n\n[routing]\nclearance = 3.0\n\n"
       << "[harness]\nfile = \"harness.xml\"\n";
  for (const Part& p : sc.parts) {
    const std::string file = "parts/" + p.name + ".stl";
    write_mesh(dir / file, p.mesh);
    toml << "\n[[part]]\nname = \"" << p.name << "\"\nfile = \"" << file << "\"\n";
    if (p.clearance > 0.0) toml << "clearance = " << p.clearance << "\n";
  }
  Harness h;
  h.name = "audit-bench-x" + std::to_string(mult);
  for (const CableInput& c : sc.cables) add_cable(h, c);
  write_harness_xml(h, dir / "harness.xml");
  std::printf("%s: %zu parts, %zu triangles, %zu cables\n", dir.string().c_str(), sc.parts.size(), sc.triangles,
              sc.cables.size());
  return 0;
}
