// α-SIM regressions on hostile input (see tests/index/simplify/test_alpha_sim_adversarial.cpp):
// one test per bug, inputs written out at full precision. The oracle (alpha_sim_oracle.hpp)
// is independent of loom's indices.
#include "core/io/mesh_read.hpp"
#include "core/io/mesh_write.hpp"
#include "index/simplify/alpha_sim.hpp"

#include "index/simplify/alpha_sim_oracle.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

using namespace loom;
using namespace loom::alpha_sim_oracle;

namespace {

/// A tetrahedron 1e5 from the origin (float-exact corners, as a binary STL holds them).
Mesh far_tetrahedron() {
  Mesh m;
  m.vertices = {{100000.0, -100000.0, 50000.0},
                {100007.0, -99999.0, 50002.0},
                {100002.0, -99994.0, 50001.0},
                {100001.0, -99998.0, 50008.0}};
  m.triangles = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}};
  return m;
}

Part part_of(const std::string& name, const Mesh& m) {
  Part p;
  p.name = name;
  p.mesh = m;
  p.closed = true;
  return p;
}

/// The mesh as `loom simplify` writes it (binary STL) and reads it back.
Mesh through_stl(const Mesh& m, const std::string& stem) {
  const auto path = std::filesystem::temp_directory_path() / ("loom_alpha_regression_" + stem + ".stl");
  write_mesh(path, m);
  Mesh back = read_mesh_file(path);
  std::filesystem::remove(path);
  return back;
}

}  // namespace

// A part 1e5 from the origin came out "ok", containment 1.0,
// but the binary STL that `loom simplify` writes rounds the computed vertices of the
// simplified mesh to float32 (by up to 2e-3 here, tolerance 1e-5): 10% of the original's
// samples lay outside the file, triangles collapsed (triangles_after and volume_after no
// longer described the file). The mesh is rounded to float32 before it is checked and
// measured (AlphaSimOptions::float32_vertices): here the rounding breaks containment, the
// measure finds it and the original is kept, with the reason.
TEST(AlphaSimRegression, FarPartStlContainsTheOriginal) {
  const Mesh m = far_tetrahedron();
  AlphaSimOptions o;
  o.dim_pre = 1.0;
  const AlphaSimPart sp = simplify_part(part_of("far", m), o);
  const Mesh file = through_stl(sp.mesh, "far");
  EXPECT_EQ(file.triangle_count(), sp.result.triangles_after) << sp.result.reason;
  EXPECT_EQ(samples_outside(m, file, sp.result.tolerance, 6), 0u)
      << alpha_sim_status_name(sp.result.status) << ": " << sp.result.reason;
}

// A translated copy of a part near the origin, placed 1e5
// away, got the first part's simplified mesh moved (copy_of) — vertices that are not
// float32, which the binary STL rounds by up to ~4e-3 (tolerance 1e-5): four of the copy's
// 22 triangles collapsed in the file (18 read back, 22 reported), and nothing bounded its
// containment. A copy's moved mesh is rounded too and must stay within the share of
// the tolerance kept for rounding (else the copy is simplified on its own: here the
// original is kept).
TEST(AlphaSimRegression, FarCopyStlContainsTheCopy) {
  Mesh near = far_tetrahedron();
  for (auto& v : near.vertices) v -= Vec3(100000.0, -100000.0, 50000.0);
  const std::vector<Part> parts{part_of("near", near), part_of("far", far_tetrahedron())};
  AlphaSimOptions o;
  o.dim_pre = 1.0;
  std::vector<AlphaSimResult> results;
  const std::vector<Part> out = simplify_parts(parts, o, &results);
  ASSERT_EQ(out.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    SCOPED_TRACE(parts[i].name);
    const Mesh file = through_stl(out[i].mesh, parts[i].name);
    EXPECT_EQ(file.triangle_count(), results[i].triangles_after);
    EXPECT_EQ(samples_outside(parts[i].mesh, file, results[i].tolerance, 6), 0u)
        << alpha_sim_status_name(results[i].status) << " (copy of '" << results[i].copy_of << "'): " << results[i].reason;
  }
}

// `loom simplify --dim-pre 1e-300` (a valid finite > 0
// value) on a part with a face seen edge-on in a projection: L_max² underflowed to 0, the
// sample estimate of that plane was 0/0 = NaN, `NaN > max_cloud_points` is false, and the
// part went on to be sampled at L_max = 5e-301 (lattice indices converted from ~1e301 to
// long: undefined behaviour; here it came out "hull_fallback" with three empty planes
// instead of "too_fine"). The other parts' estimates were +inf, printed through a cast to
// long long as "needs about -9223372036854775808 points".
TEST(AlphaSimRegression, DimPreWhoseSquareUnderflowsIsTooFine) {
  // An open box (its top missing): the walls are seen edge-on from above.
  Mesh open;
  open.vertices = {{0, 0, 0}, {5, 0, 0}, {5, 5, 0}, {0, 5, 0}, {0, 0, 5}, {5, 0, 5}, {5, 5, 5}, {0, 5, 5}};
  open.triangles = {{0, 3, 2}, {0, 2, 1}, {0, 1, 5}, {0, 5, 4}, {1, 2, 6}, {1, 6, 5},
                    {2, 3, 7}, {2, 7, 6}, {3, 0, 4}, {3, 4, 7}};
  Part p = part_of("open", open);
  p.closed = false;
  for (double dim_pre : {1e-300, 1e-200, 1e-160}) {
    AlphaSimOptions o;
    o.dim_pre = dim_pre;
    o.scene_size = 10.0;
    const AlphaSimPart sp = simplify_part(p, o);
    EXPECT_EQ(sp.result.status, AlphaSimStatus::TooFine) << dim_pre << ": " << sp.result.reason;
    EXPECT_EQ(sp.result.reason.find("-9223372036854775808"), std::string::npos) << sp.result.reason;
    // The closed box: an estimate of +inf, reported as such.
    Part closed = part_of("closed", open);
    closed.mesh.triangles.push_back({4, 5, 6});
    closed.mesh.triangles.push_back({4, 6, 7});
    const AlphaSimPart sc = simplify_part(closed, o);
    EXPECT_EQ(sc.result.status, AlphaSimStatus::TooFine) << dim_pre << ": " << sc.result.reason;
    EXPECT_EQ(sc.result.reason.find("-9223372036854775808"), std::string::npos) << sc.result.reason;
  }
}
