// α-SIM on adversarial input: hostile but valid parts (thin sheets, needles, cavities,
// through-holes oblique to the axes, tori, odd rotations, faces on the projection planes,
// open / non-manifold / duplicated / degenerate / misoriented input, huge offsets, several
// shells, blocked projections) checked by an oracle written here, independent of loom's
// indices: dense samples of every original triangle (its corners, points along its edges,
// a barycentric grid) must lie inside or within the containment tolerance of the output
// mesh (generalized winding number, brute force over the output's triangles, or the
// brute-force point–triangle distance) and of the implicit solid; the output mesh must be
// closed and consistently outward oriented, and the report finite and consistent with it.
#include "core/io/mesh_read.hpp"
#include "core/io/mesh_write.hpp"
#include "index/simplify/alpha_sim.hpp"
#include "index/simplify/alpha_sim_oracle.hpp"

#include <nlohmann/json.hpp>

#include <gtest/gtest.h>

#include <sys/wait.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <cmath>
#include <functional>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "common/run_loom.hpp"
#include "common/shared_data.hpp"

using namespace loom;
using namespace loom::alpha_sim_oracle;

namespace {

// ------------------------------------------------------------------ parts

using Quad = std::array<Vec3, 4>;

/// Appends the quad a b c d (counter-clockwise seen from outside) as two triangles.
void add_quad(Mesh& m, const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  const auto base = static_cast<std::uint32_t>(m.vertices.size());
  m.vertices.insert(m.vertices.end(), {a, b, c, d});
  m.triangles.push_back({base, base + 1, base + 2});
  m.triangles.push_back({base, base + 2, base + 3});
}

/// Closed outward box [lo, hi], vertices welded.
Mesh box(const Vec3& lo, const Vec3& hi) {
  Mesh m;
  const double x0 = lo.x(), y0 = lo.y(), z0 = lo.z(), x1 = hi.x(), y1 = hi.y(), z1 = hi.z();
  add_quad(m, {x0, y0, z1}, {x1, y0, z1}, {x1, y1, z1}, {x0, y1, z1});
  add_quad(m, {x0, y0, z0}, {x0, y1, z0}, {x1, y1, z0}, {x1, y0, z0});
  add_quad(m, {x0, y0, z0}, {x0, y0, z1}, {x0, y1, z1}, {x0, y1, z0});
  add_quad(m, {x1, y0, z0}, {x1, y1, z0}, {x1, y1, z1}, {x1, y0, z1});
  add_quad(m, {x0, y0, z0}, {x1, y0, z0}, {x1, y0, z1}, {x0, y0, z1});
  add_quad(m, {x0, y1, z0}, {x0, y1, z1}, {x1, y1, z1}, {x1, y1, z0});
  weld_identical_vertices(m);
  return m;
}

/// Closed mesh of an extruded occupancy grid (cells of size s, z ∈ [0, t]).
Mesh extruded_grid(int nx, int ny, double s, double t, const std::function<bool(int, int)>& filled) {
  Mesh m;
  auto in = [&](int i, int j) { return i >= 0 && j >= 0 && i < nx && j < ny && filled(i, j); };
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j) {
      if (!in(i, j)) continue;
      const double x0 = i * s, x1 = (i + 1) * s, y0 = j * s, y1 = (j + 1) * s;
      add_quad(m, {x0, y0, t}, {x1, y0, t}, {x1, y1, t}, {x0, y1, t});
      add_quad(m, {x0, y0, 0}, {x0, y1, 0}, {x1, y1, 0}, {x1, y0, 0});
      if (!in(i - 1, j)) add_quad(m, {x0, y0, 0}, {x0, y0, t}, {x0, y1, t}, {x0, y1, 0});
      if (!in(i + 1, j)) add_quad(m, {x1, y0, 0}, {x1, y1, 0}, {x1, y1, t}, {x1, y0, t});
      if (!in(i, j - 1)) add_quad(m, {x0, y0, 0}, {x1, y0, 0}, {x1, y0, t}, {x0, y0, t});
      if (!in(i, j + 1)) add_quad(m, {x0, y1, 0}, {x0, y1, t}, {x1, y1, t}, {x1, y1, 0});
    }
  weld_identical_vertices(m);
  return m;
}

/// Closed torus about z: major radius R, minor r, n × k facets.
Mesh torus(double R, double r, int n, int k) {
  Mesh m;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < k; ++j) {
      const double a = 2 * M_PI * i / n, b = 2 * M_PI * j / k;
      m.vertices.emplace_back((R + r * std::cos(b)) * std::cos(a), (R + r * std::cos(b)) * std::sin(a), r * std::sin(b));
    }
  auto id = [&](int i, int j) { return static_cast<std::uint32_t>(((i + n) % n) * k + (j + k) % k); };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < k; ++j) {
      m.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      m.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  return m;
}

/// Closed UV sphere of radius r about c.
Mesh sphere(const Vec3& c, double r, int n, int k) {
  Mesh m;
  m.vertices.push_back(c + Vec3(0, 0, r));
  for (int i = 1; i < k; ++i)
    for (int j = 0; j < n; ++j) {
      const double t = M_PI * i / k, p = 2 * M_PI * j / n;
      m.vertices.push_back(c + r * Vec3(std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t)));
    }
  m.vertices.push_back(c - Vec3(0, 0, r));
  auto id = [&](int i, int j) { return static_cast<std::uint32_t>(1 + (i - 1) * n + (j + n) % n); };
  const auto south = static_cast<std::uint32_t>(m.vertices.size() - 1);
  for (int j = 0; j < n; ++j) m.triangles.push_back({0, id(1, j), id(1, j + 1)});
  for (int i = 1; i + 1 < k; ++i)
    for (int j = 0; j < n; ++j) {
      m.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      m.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  for (int j = 0; j < n; ++j) m.triangles.push_back({south, id(k - 1, j + 1), id(k - 1, j)});
  return m;
}

/// The mesh with every triangle reversed (an inner shell).
Mesh reversed(Mesh m) {
  for (auto& f : m.triangles) std::swap(f[1], f[2]);
  return m;
}

/// The mesh turned by deg_x about X, then deg_y about Y, then deg_z about Z, then moved by t.
Mesh turned(Mesh m, double deg_x, double deg_y, double deg_z = 0.0, const Vec3& t = Vec3::Zero()) {
  const double k = M_PI / 180.0;
  Eigen::Affine3d a = Eigen::Translation3d(t) * Eigen::AngleAxisd(deg_z * k, Vec3::UnitZ()) *
                      Eigen::AngleAxisd(deg_y * k, Vec3::UnitY()) * Eigen::AngleAxisd(deg_x * k, Vec3::UnitX());
  m.transform(a);
  return m;
}

Mesh moved(Mesh m, const Vec3& t) {
  for (auto& v : m.vertices) v += t;
  return m;
}

/// Square frame (a ring of width w around a square hole of side h), thickness t, centred at
/// the origin in x, y: a through-hole along z.
Mesh frame(double h, double w, double t) {
  const int n = 3;
  const double s = 1.0;
  Mesh m = extruded_grid(n, n, s, 1.0, [](int i, int j) { return !(i == 1 && j == 1); });
  // Cell sizes: w, h, w across; thickness t.
  auto map1 = [&](double x) { return x <= 1.0 ? x * w : (x <= 2.0 ? w + (x - 1.0) * h : w + h + (x - 2.0) * w); };
  const double half = w + h / 2.0;
  for (auto& v : m.vertices) v = Vec3(map1(v.x()) - half, map1(v.y()) - half, v.z() * t - t / 2.0);
  return m;
}

Part make_part(const std::string& name, Mesh m) {
  Part p;
  p.name = name;
  p.mesh = std::move(m);
  Mesh w = p.mesh;
  weld_identical_vertices(w);
  p.closed = analyse_topology(w).closed;
  return p;
}

// ------------------------------------------------------------------ oracle

struct OracleReport {
  std::size_t samples = 0, outside_mesh = 0, outside_solid = 0;
  double worst_mesh = 0.0;  ///< largest distance of a sample outside the mesh
  Vec3 first_outside = Vec3::Zero();
};

/// Checks every oracle sample of `original` against the output mesh (distance ≤ tol or
/// winding number > 1/2) and, when there is one, the implicit solid.
OracleReport oracle(const Mesh& original, const AlphaSimPart& sp, double tol, int grid) {
  OracleReport r;
  const auto samples = oracle_samples(original, grid);
  r.samples = samples.size();
  for (const auto& p : samples) {
    const double d = distance_to_mesh(p, sp.mesh);
    if (!(d <= tol) && !(winding_number(p, sp.mesh) > 0.5)) {
      if (r.outside_mesh++ == 0) r.first_outside = p;
      r.worst_mesh = std::max(r.worst_mesh, d);
    }
    if (sp.solid && !sp.solid->contains(p, tol)) ++r.outside_solid;
  }
  return r;
}

bool finite_report(const AlphaSimResult& r) {
  for (double v : {r.volume_before, r.volume_after, r.containment, r.containment_implicit, r.hausdorff,
                   r.lost_space_radius, r.time_ms, r.tolerance, r.alpha, r.l_max})
    if (!std::isfinite(v)) return false;
  for (const auto& p : r.projections)
    if (!std::isfinite(p.area) || !std::isfinite(p.hull_area) || !std::isfinite(p.alpha_area)) return false;
  return true;
}

/// Runs simplify_part on `m` and applies every check; returns the result for more.
AlphaSimPart check_part(const std::string& name, const Mesh& m, AlphaSimOptions o, int grid = 4) {
  SCOPED_TRACE(name);
  const Part part = make_part(name, m);
  const auto t0 = std::chrono::steady_clock::now();
  AlphaSimPart sp = simplify_part(part, o);
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const AlphaSimResult& r = sp.result;
  const std::string info = std::string(alpha_sim_status_name(r.status)) + " / " + alpha_sim_fallback_name(r.fallback) +
                           ": " + r.reason;
  // No timing assert (flaky on a loaded machine): a hang is caught by CTest's timeout and the
  // sample guard (too_fine) by the tests below; the seconds are printed.
  std::printf("  %-28s %-14s %6zu -> %6zu  containment %.6f / %.6f  hausdorff %.4g  lost %.4g  %.3f s %s\n",
              name.c_str(), alpha_sim_status_name(r.status), r.triangles_before, r.triangles_after, r.containment,
              r.containment_implicit, r.hausdorff, r.lost_space_radius, secs, (r.reason + " [" + r.booleans_by + ": " + r.booleans_note + "]").c_str());
  EXPECT_TRUE(finite_report(r)) << info;
  EXPECT_EQ(r.triangles_before, m.triangle_count());
  EXPECT_EQ(r.triangles_after, sp.mesh.triangle_count()) << info;
  const double tol = r.tolerance;
  EXPECT_GT(tol, 0.0);
  if (r.fallback == AlphaSimFallback::Original) {
    // The original itself: nothing to contain, but it must be the original.
    EXPECT_EQ(sp.mesh.triangle_count(), m.triangle_count()) << info;
    EXPECT_FALSE(sp.solid) << info;
    EXPECT_FALSE(r.reason.empty()) << info;
    return sp;
  }
  std::string why;
  EXPECT_TRUE(closed_consistent(sp.mesh, &why)) << info << ": " << why;
  EXPECT_TRUE(r.closed_after);
  const double vol = sp.mesh.signed_volume();
  EXPECT_GT(vol, 0.0) << "output not outward oriented; " << info;
  EXPECT_NEAR(r.volume_after, vol, 1e-9 * std::max(1.0, std::abs(vol))) << info;
  if (r.closed_before) {
    const double vb = std::abs(m.signed_volume());
    EXPECT_NEAR(r.volume_before, vb, 1e-9 * std::max(1.0, vb)) << info;
  } else {
    EXPECT_EQ(r.volume_before, 0.0) << info;
  }
  EXPECT_TRUE(sp.solid) << info;
  const OracleReport o_r = oracle(m, sp, tol, grid);
  EXPECT_EQ(o_r.outside_mesh, 0u) << o_r.outside_mesh << " of " << o_r.samples
                                   << " samples outside the output mesh, worst by " << o_r.worst_mesh
                                   << " (tol " << tol << "), first at " << o_r.first_outside.transpose()
                                   << "; reported containment " << r.containment << "; " << info;
  EXPECT_EQ(o_r.outside_solid, 0u) << o_r.outside_solid << " of " << o_r.samples
                                    << " samples outside the implicit solid; reported "
                                    << r.containment_implicit << "; " << info;
  if (o_r.outside_mesh > 0) {
    EXPECT_LT(r.containment, 1.0) << "a false containment 1.0";
  }
  // One-sided Hausdorff (output → original): at least the distance of each output vertex.
  double vmax = 0.0;
  for (const auto& v : sp.mesh.vertices) vmax = std::max(vmax, distance_to_mesh(v, m));
  EXPECT_GE(r.hausdorff, vmax - tol) << info;
  return sp;
}

AlphaSimOptions opts(double dim_pre) {
  AlphaSimOptions o;
  o.dim_pre = dim_pre;
  return o;
}

}  // namespace

// ------------------------------------------------------------------ thin, small, large

TEST(AlphaSimAdversarial, SheetThinnerThanDimPre) {
  check_part("sheet-0.1", box({0, 0, 0}, {10, 10, 0.1}), opts(1.0));
  check_part("sheet-1e-3", box({0, 0, 0}, {10, 10, 1e-3}), opts(1.0));
  const auto sp = check_part("sheet-1e-6", box({0, 0, 0}, {10, 10, 1e-6}), opts(1.0));
  EXPECT_EQ(sp.result.status, AlphaSimStatus::Thin) << sp.result.reason;
  check_part("sheet-turned", turned(box({0, 0, 0}, {10, 10, 0.05}), 17, 45), opts(1.0));
}

TEST(AlphaSimAdversarial, Needle) {
  check_part("needle-z", box({0, 0, 0}, {0.05, 0.05, 20}), opts(1.0));
  check_part("needle-turned", turned(box({0, 0, 0}, {0.05, 0.05, 20}), 17, 45), opts(1.0));
  check_part("needle-1e-5", box({0, 0, 0}, {1e-3, 1e-3, 20}), opts(1.0));
}

TEST(AlphaSimAdversarial, PartMuchSmallerThanDimPre) {
  check_part("tiny-box", box({0, 0, 0}, {0.1, 0.1, 0.1}), opts(10.0));
  check_part("tiny-sphere", sphere({1, 2, 3}, 0.05, 16, 8), opts(10.0));
  const auto huge = check_part("dim-pre-1e6", turned(box({0, 0, 0}, {1, 2, 3}), 17, 45), opts(1e6));
  // Thin along every normal is not "a sheet": the reason says what it is.
  EXPECT_NE(huge.result.reason.find("smaller than the cable scale"), std::string::npos) << huge.result.reason;
  check_part("tiny-torus", torus(1, 0.3, 24, 12), opts(1e3));
}

TEST(AlphaSimAdversarial, DimPreFarBelowThePartIsBounded) {
  const auto sp = check_part("fine-box", box({0, 0, 0}, {100, 100, 100}), opts(1e-4));
  EXPECT_EQ(sp.result.status, AlphaSimStatus::TooFine) << sp.result.reason;
  const auto sp2 = check_part("fine-sphere", sphere({0, 0, 0}, 50, 64, 32), opts(1e-3));
  EXPECT_EQ(sp2.result.status, AlphaSimStatus::TooFine) << sp2.result.reason;
}

TEST(AlphaSimAdversarial, DimPreJustAboveTheSampleLimitIsBounded) {
  // A sphere of radius 50 at dim_pre 0.2: ~6e5 samples, below max_cloud_points (0.13
  // would be above it: too_fine). It ends in bounded time (2–4 s, ~350 MB on a
  // 2-core machine) — here kept as the original ("blocked": the three cylinders' corners leave
  // balls of radius 4.7 outside the sphere). Bounded time is CTest's timeout's to judge.
  check_part("sphere-fine", turned(sphere({0, 0, 0}, 50, 96, 48), 17, 45), opts(0.2), 2);
}

// ------------------------------------------------------------------ topology of the shape

TEST(AlphaSimAdversarial, InnerCavity) {
  Mesh m = box({0, 0, 0}, {10, 10, 10});
  m.append(reversed(box({3, 3, 3}, {7, 7, 7})));
  check_part("cavity", m, opts(1.0));
  check_part("cavity-turned", turned(m, 17, 45), opts(1.0));
}

TEST(AlphaSimAdversarial, ThroughHoles) {
  check_part("frame-z", frame(4, 2, 3), opts(1.0));
  check_part("frame-oblique", turned(frame(4, 2, 3), 17, 45, 31), opts(1.0));
  check_part("frame-oblique-small-hole", turned(frame(0.5, 2, 3), 17, 45, 31), opts(1.0));
  check_part("torus", torus(5, 1.5, 48, 16), opts(1.0));
  check_part("torus-turned", turned(torus(5, 1.5, 48, 16), 17, 45), opts(1.0));
  check_part("torus-coarse", turned(torus(5, 0.4, 12, 5), 30, 60), opts(0.3));
}

TEST(AlphaSimAdversarial, FacesOnAndParallelToTheProjectionPlanes) {
  check_part("on-planes", box({0, 0, 0}, {3, 4, 5}), opts(1.0));
  check_part("negative-on-planes", box({-3, -4, -5}, {0, 0, 0}), opts(1.0));
  // Two boxes overlapping, sharing coplanar overlapping faces (a self-intersecting union).
  Mesh m = box({0, 0, 0}, {4, 4, 2});
  m.append(box({2, 2, 0}, {6, 6, 2}));
  check_part("coplanar-overlap", m, opts(1.0));
  // Stairs whose treads are exactly dim_pre and L_max wide.
  Mesh s = box({0, 0, 0}, {1, 5, 1});
  s.append(box({1, 0, 0}, {1.5, 5, 2}));
  s.append(box({1.5, 0, 0}, {2.25, 5, 3}));
  check_part("stairs", s, opts(1.0));
}

TEST(AlphaSimAdversarial, OddRotations) {
  Mesh l = box({0, 0, 0}, {10, 2, 2});
  l.append(box({0, 0, 2}, {2, 2, 10}));
  for (auto [ax, ay, az] : {std::tuple{17.0, 45.0, 0.0}, std::tuple{45.0, 45.0, 0.0}, std::tuple{1e-7, 0.0, 0.0},
                            std::tuple{0.0, 89.9999, 0.0}, std::tuple{33.0, 71.0, 12.0}})
    check_part("L-" + std::to_string(ax) + "-" + std::to_string(ay) + "-" + std::to_string(az), turned(l, ax, ay, az),
               opts(1.0));
}

// ------------------------------------------------------------------ bad input

TEST(AlphaSimAdversarial, OpenMeshes) {
  Mesh open = box({0, 0, 0}, {5, 5, 5});
  open.triangles.resize(10);  // one face missing
  check_part("open-box", open, opts(1.0));
  Mesh tri;
  tri.vertices = {{0, 0, 0}, {5, 0, 0}, {0, 5, 3}};
  tri.triangles = {{0, 1, 2}};
  check_part("one-triangle", tri, opts(1.0));
  check_part("one-triangle-turned", turned(tri, 17, 45), opts(1.0));
}

TEST(AlphaSimAdversarial, NonManifoldDuplicateDegenerateMisoriented) {
  // Three fins sharing one edge.
  Mesh fins;
  fins.vertices = {{0, 0, 0}, {0, 0, 5}, {3, 0, 2}, {0, 3, 2}, {-2, -2, 2}};
  fins.triangles = {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}};
  check_part("fins", fins, opts(1.0));
  // Two boxes sharing an edge (non-manifold, four triangles at it).
  Mesh edge = box({0, 0, 0}, {2, 2, 2});
  edge.append(box({2, 2, 0}, {4, 4, 2}));
  weld_identical_vertices(edge);
  check_part("edge-touch", edge, opts(1.0));
  // Duplicated triangles.
  Mesh dup = box({0, 0, 0}, {3, 3, 3});
  const auto tris = dup.triangles;
  dup.triangles.insert(dup.triangles.end(), tris.begin(), tris.end());
  check_part("duplicates", dup, opts(1.0));
  // Zero-area triangles: repeated index, collinear corners far outside the rest.
  Mesh deg = box({0, 0, 0}, {3, 3, 3});
  const auto n = static_cast<std::uint32_t>(deg.vertices.size());
  deg.vertices.push_back({3, 3, 3});
  deg.vertices.push_back({6, 6, 6});
  deg.vertices.push_back({9, 9, 9});
  deg.triangles.push_back({n, n + 1, n + 2});
  deg.triangles.push_back({0, 0, 1});
  check_part("degenerate", deg, opts(1.0));
  // Half the triangles reversed (closed but inconsistently oriented).
  Mesh mis = box({0, 0, 0}, {3, 4, 5});
  for (std::size_t t = 0; t < mis.triangles.size(); t += 2) std::swap(mis.triangles[t][1], mis.triangles[t][2]);
  check_part("misoriented", mis, opts(1.0));
  check_part("inside-out", reversed(box({0, 0, 0}, {3, 4, 5})), opts(1.0));
}

TEST(AlphaSimAdversarial, HugeCoordinateOffsets) {
  for (double off : {1e5, 1e6}) {
    const Vec3 t(off, -off, 0.5 * off);
    check_part("box-" + std::to_string(off), moved(box({0, 0, 0}, {3, 4, 5}), t), opts(1.0));
    check_part("torus-" + std::to_string(off), moved(turned(torus(5, 1.5, 32, 12), 17, 45), t), opts(1.0));
    check_part("frame-" + std::to_string(off), moved(turned(frame(4, 2, 3), 17, 45, 31), t), opts(1.0));
  }
}

TEST(AlphaSimAdversarial, SeveralShellsAndCompounds) {
  Mesh two = box({0, 0, 0}, {2, 2, 2});
  two.append(box({10, 10, 10}, {12, 12, 12}));
  check_part("two-shells", two, opts(1.0));
  Mesh near = box({0, 0, 0}, {2, 2, 2});
  near.append(box({2.3, 0, 0}, {4, 2, 2}));  // a gap below dim_pre
  check_part("two-shells-close", near, opts(1.0));
  Mesh comp = box({0, 0, 0}, {6, 1, 1});
  comp.append(box({0, 0, 0}, {1, 6, 1}));
  comp.append(box({0, 0, 0}, {1, 1, 6}));
  comp.append(turned(box({2, 2, 2}, {4, 4, 4}), 17, 45));
  comp.append(sphere({5, 5, 5}, 1.0, 16, 8));
  check_part("compound", comp, opts(1.0));
}

TEST(AlphaSimAdversarial, BlockedProjection) {
  // A worm-gear-like part: a shaft with a helical flight whose gaps hide in all three axis
  // projections.
  Mesh worm = box({-1, -1, 0}, {1, 1, 20});
  for (int i = 0; i < 40; ++i) {
    const double a = 2 * M_PI * i / 10.0;
    Mesh tooth = box({1, -0.4, 0}, {4, 0.4, 0.6});
    tooth = turned(tooth, 0, 0, a * 180 / M_PI, Vec3(0, 0, 0.5 * i));
    worm.append(tooth);
  }
  const auto sp = check_part("worm", worm, opts(1.0), 2);
  // Either simplified (contained, checked above) or kept with a reason.
  if (sp.result.fallback == AlphaSimFallback::None) {
    EXPECT_LT(sp.result.lost_space_radius, 2.0) << sp.result.reason;
  }
}

TEST(AlphaSimAdversarial, HelicalFlightWormGear) {
  // A shaft with a helical flight (pitch 6, flight 0.8 thick, radius 1 → 4): every side
  // view shows the flight's gaps only partly, the top view is a full disc.
  Mesh worm = box({-1, -1, 0}, {1, 1, 18});
  const int steps = 36 * 3;
  for (int i = 0; i < steps; ++i) {
    const double deg = 10.0 * i, z = 6.0 * i / 36.0;
    worm.append(turned(box({0.9, -0.4, 0}, {4, 0.4, 0.8}), 0, 0, deg, Vec3(0, 0, z)));
  }
  check_part("helical-flight", worm, opts(0.5), 2);
}

TEST(AlphaSimAdversarial, ToleranceCoarserThanTheFeatures) {
  // The scene is much larger than the part: the containment tolerance (1e-6 of the scene)
  // is larger than the part's thickness, or than dim_pre itself.
  auto o = opts(1.0);
  o.scene_size = 1e4;  // tol 0.01
  check_part("sheet-under-tol", box({0, 0, 0}, {10, 10, 0.004}), o);
  check_part("sheet-under-tol-turned", turned(box({0, 0, 0}, {10, 10, 0.004}), 17, 45), o);
  check_part("needle-under-tol-turned", turned(box({0, 0, 0}, {0.003, 0.003, 10}), 17, 45), o);
  auto o2 = opts(0.1);
  o2.scene_size = 1e6;  // tol 1 > dim_pre
  check_part("dim-pre-under-tol", turned(torus(5, 1.5, 32, 12), 17, 45), o2);
  check_part("dim-pre-under-tol-frame", turned(frame(4, 2, 3), 17, 45, 31), o2);
}

TEST(AlphaSimAdversarial, JustAboveTheThinLimit) {
  for (double t : {1.01e-4, 2e-4, 1e-3})
    for (auto [ax, ay] : {std::pair{0.0, 0.0}, std::pair{17.0, 45.0}, std::pair{0.0, 1e-3}})
      check_part("plate-" + std::to_string(t) + "-" + std::to_string(ax) + "-" + std::to_string(ay),
                 turned(box({0, 0, 0}, {10, 7, t}), ax, ay), opts(1.0));
}

TEST(AlphaSimAdversarial, UserPlanes) {
  auto o = opts(1.0);
  o.extra_planes = {Vec3(1, 1, 1), Vec3(0, 0, 1), Vec3(1e-9, 0, 1), Vec3(1, -1, 0), Vec3(-1, 0, 0)};
  check_part("planes-torus", turned(torus(5, 1.5, 32, 12), 17, 45), o);
  check_part("planes-frame", turned(frame(4, 2, 3), 17, 45, 31), o);
  check_part("planes-sheet", turned(box({0, 0, 0}, {10, 10, 0.01}), 17, 45), o);
  auto o2 = opts(1.0);
  o2.coordinate_planes = false;
  o2.extra_planes = {Vec3(1, 1, 1)};
  check_part("one-oblique-plane", turned(frame(4, 2, 3), 17, 45, 31), o2);
  o2.extra_planes = {Vec3(1, 1, 0), Vec3(1, -1, 0)};
  check_part("two-planes-unbounded-axis", turned(frame(4, 2, 3), 17, 45, 31), o2);
}

TEST(AlphaSimAdversarial, CopiesInAScene) {
  // A chiral part and its copies: translated, turned about the axes, mirrored (not a copy),
  // far away; every result is checked against its own original.
  Mesh l = box({0, 0, 0}, {10, 2, 2});
  l.append(box({0, 0, 2}, {2, 2, 10}));
  l.append(box({0, 0, 8}, {2, 6, 10}));
  weld_identical_vertices(l);
  std::vector<Part> parts{make_part("a", l), make_part("moved", moved(l, Vec3(100, 0, 0))),
                          make_part("turned", turned(l, 90, 0, 0, Vec3(0, 100, 0))),
                          make_part("turned2", turned(l, 0, 180, 90, Vec3(0, 0, 100)))};
  Mesh mirror = l;
  for (auto& v : mirror.vertices) v.x() = -v.x();
  mirror = reversed(mirror);
  parts.push_back(make_part("mirrored", moved(mirror, Vec3(-50, 0, 0))));
  parts.push_back(make_part("far", moved(l, Vec3(1e5, 1e5, 0))));
  auto o = opts(1.0);
  std::vector<AlphaSimResult> results;
  const auto out = simplify_parts(parts, o, &results);
  ASSERT_EQ(out.size(), parts.size());
  for (std::size_t i = 0; i < parts.size(); ++i) {
    SCOPED_TRACE(parts[i].name + " (copy of '" + results[i].copy_of + "')");
    AlphaSimPart sp;
    sp.mesh = out[i].mesh;
    sp.result = results[i];
    const OracleReport r = oracle(parts[i].mesh, sp, results[i].tolerance, 4);
    EXPECT_EQ(r.outside_mesh, 0u) << "first at " << r.first_outside.transpose();
    std::string why;
    EXPECT_TRUE(closed_consistent(out[i].mesh, &why)) << why;
    EXPECT_GT(out[i].mesh.signed_volume(), 0.0);
    EXPECT_EQ(results[i].triangles_after, out[i].mesh.triangle_count());
    EXPECT_NEAR(results[i].volume_after, out[i].mesh.signed_volume(), 1e-9 * results[i].volume_after);
  }
}

TEST(AlphaSimAdversarial, ManyShellsAndRandomTurns) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> ang(0.0, 360.0), pos(-20.0, 20.0), sz(0.05, 6.0);
  for (int trial = 0; trial < 12; ++trial) {
    Mesh m;
    const int n = 1 + trial % 4;
    for (int k = 0; k < n; ++k) {
      const int kind = (trial + k) % 4;
      Mesh s = kind == 0   ? box({0, 0, 0}, {sz(rng), sz(rng), sz(rng)})
               : kind == 1 ? torus(sz(rng) + 1.0, 0.5, 24, 8)
               : kind == 2 ? frame(sz(rng), sz(rng), sz(rng))
                           : sphere({0, 0, 0}, sz(rng), 12, 6);
      m.append(turned(s, ang(rng), ang(rng), ang(rng), Vec3(pos(rng), pos(rng), pos(rng)) * (trial % 3) / 4.0));
    }
    const double dim = std::vector<double>{0.3, 1.0, 2.5}[trial % 3];
    check_part("random-" + std::to_string(trial), m, opts(dim), 3);
  }
}

// ------------------------------------------------------------------ the command line

namespace {

using loom::testing::run_loom;

std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// Writes each mesh as <dir>/<name>.stl and a scene naming them; returns the scene path.
std::filesystem::path write_scene(const std::filesystem::path& dir, const std::vector<std::pair<std::string, Mesh>>& parts,
                                  double dim_pre) {
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  std::ostringstream toml;
  toml << "[scene]\nname = \"adversarial\"\nunits = \"mm\"\n\n";
  for (const auto& [name, m] : parts) {
    write_mesh(dir / (name + ".stl"), m);
    toml << "[[part]]\nname = \"" << name << "\"\nfile = \"" << name << ".stl\"\n\n";
  }
  toml << "[simplify]\ndim_pre = " << dim_pre << "\n";
  std::ofstream(dir / "scene.toml") << toml.str();
  return dir / "scene.toml";
}

/// Runs `loom simplify` on the parts and checks simplify.json and every STL written against
/// the parts as loom read them (the STL input, float vertices).
void check_cli(const std::string& test, const std::vector<std::pair<std::string, Mesh>>& parts, double dim_pre) {
  const auto dir = std::filesystem::temp_directory_path() / ("loom_alpha_adv_" + test);
  const auto scene = write_scene(dir, parts, dim_pre);
  const auto out = dir / "out";
  const loom::testing::LoomRun r = run_loom("simplify " + scene.string() + " --quiet --out " + out.string());
  ASSERT_EQ(r.status, 0) << r.out;
  const std::string text = slurp(out / "simplify.json");
  EXPECT_EQ(text.find("null"), std::string::npos) << text;
  EXPECT_EQ(text.find("nan"), std::string::npos) << text;
  const auto j = nlohmann::json::parse(text);
  const double tol = j.at("tolerance").get<double>();
  std::size_t before = 0, after = 0;
  for (const auto& pj : j.at("parts")) {
    const std::string name = pj.at("name");
    SCOPED_TRACE(test + "/" + name);
    const Mesh original = read_mesh_file(dir / (name + ".stl"));
    const Mesh simple = read_mesh_file(out / pj.at("file").get<std::string>());
    before += pj.at("triangles_before").get<std::size_t>();
    after += pj.at("triangles_after").get<std::size_t>();
    EXPECT_EQ(pj.at("triangles_before").get<std::size_t>(), original.triangle_count());
    EXPECT_EQ(pj.at("triangles_after").get<std::size_t>(), simple.triangle_count()) << pj.dump();
    if (pj.at("fallback") == "original") continue;
    std::string why;
    EXPECT_TRUE(closed_consistent(simple, &why)) << why;
    const double vol = simple.signed_volume();
    EXPECT_GT(vol, 0.0);
    EXPECT_NEAR(pj.at("volume_after").get<double>(), vol, 1e-6 * vol);
    AlphaSimPart sp;
    sp.mesh = simple;
    const OracleReport o = oracle(original, sp, tol, 3);
    EXPECT_EQ(o.outside_mesh, 0u) << o.outside_mesh << " of " << o.samples << " samples outside the written STL, worst by "
                                  << o.worst_mesh << " (tol " << tol << "); simplify.json says containment "
                                  << pj.at("containment");
  }
  EXPECT_EQ(j.at("triangles_before").get<std::size_t>(), before);
  EXPECT_EQ(j.at("triangles_after").get<std::size_t>(), after);
}

}  // namespace

TEST(AlphaSimAdversarialCli, HostilePartsNearTheOrigin) {
  Mesh open = box({0, 0, 0}, {5, 5, 5});
  open.triangles.resize(10);
  check_cli("near", {{"torus", turned(torus(5, 1.5, 32, 12), 17, 45)},
                     {"frame", moved(turned(frame(4, 2, 3), 17, 45, 31), Vec3(20, 0, 0))},
                     {"open", moved(open, Vec3(0, 20, 0))},
                     {"sheet", moved(turned(box({0, 0, 0}, {10, 10, 0.05}), 17, 45), Vec3(0, 0, 20))}},
            1.0);
}

TEST(AlphaSimAdversarialCli, PartFarFromTheOrigin) {
  check_cli("far", {{"torus", moved(turned(torus(5, 1.5, 32, 12), 17, 45), Vec3(1e5, -1e5, 5e4))}}, 1.0);
}

TEST(AlphaSimAdversarial, RealMeshesTurnedByOddAngles) {
  LOOM_SHARED_DATA_OR_SKIP(loom::testing::shared_data(""));
  for (const char* rel : {"fcl/rob.obj", "trimesh/tube.obj", "occt/shape.stl", "trimesh/featuretype.STL"}) {
    const auto path = std::filesystem::path(LOOM_SHARED_DATA) / rel;
    if (!std::filesystem::exists(path)) continue;
    const Mesh m = read_mesh_file(path);
    const double diag = m.bounds().diagonal();
    for (auto [ax, ay, az] : {std::tuple{17.0, 45.0, 0.0}, std::tuple{33.0, 71.0, 12.0}}) {
      const Mesh t = turned(m, ax, ay, az, Vec3(0.37, -0.21, 0.11) * diag);
      check_part(std::string(rel) + "-" + std::to_string(int(ax)), t, opts(0.04 * diag), 2);
    }
  }
}

TEST(AlphaSimAdversarial, ThinPlatesTurnedAtRandom) {
  // Plates 0.001–0.3 thick at random angles, on the axis planes and with two user planes
  // (where about a quarter of them can come out of OpenCASCADE's
  // Booleans wrong — "mesh intersection: the first mesh intersects itself" sent them there —
  // and the measure kept the original: a reported fallback, which check_part accepts).
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> ang(0.0, 90.0), lt(-3.0, -0.5), len(2.0, 12.0);
  for (int trial = 0; trial < 30; ++trial) {
    const double t = std::pow(10.0, lt(rng));
    const Mesh m = turned(box({0, 0, 0}, {len(rng), len(rng), t}), ang(rng), ang(rng), ang(rng));
    check_part("thin-" + std::to_string(trial), m, opts(1.0), 3);
    AlphaSimOptions o = opts(1.0);
    o.extra_planes = {Vec3(1, 1, 1), Vec3(1, -1, 0)};
    check_part("thin-planes-" + std::to_string(trial), m, o, 3);
  }
}
