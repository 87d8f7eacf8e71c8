#include "index/alpha_sim.hpp"

#include "core/error.hpp"

#include <CGAL/AABB_face_graph_triangle_primitive.h>
#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Side_of_triangle_mesh.h>
#include <CGAL/Surface_mesh.h>

#include <BRepAlgoAPI_Common.hxx>
#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepBuilderAPI_MakePolygon.hxx>
#include <BRepMesh_IncrementalMesh.hxx>
#include <BRepPrimAPI_MakePrism.hxx>
#include <BRep_Builder.hxx>
#include <BRep_Tool.hxx>
#include <IFSelect_ReturnStatus.hxx>
#include <Poly_Triangulation.hxx>
#include <STEPControl_Writer.hxx>
#include <Standard_Failure.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Compound.hxx>
#include <TopoDS_Face.hxx>
#include <gp_Pln.hxx>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

namespace loom {

const char* projection_status_name(ProjectionStatus s) {
  switch (s) {
    case ProjectionStatus::Ok: return "ok";
    case ProjectionStatus::Repaired: return "repaired";
    case ProjectionStatus::Empty: return "empty";
    case ProjectionStatus::Torn: return "torn";
    case ProjectionStatus::Eroded: return "eroded";
  }
  return "?";
}

const char* alpha_sim_status_name(AlphaSimStatus s) {
  switch (s) {
    case AlphaSimStatus::Ok: return "ok";
    case AlphaSimStatus::HullFallback: return "hull_fallback";
    case AlphaSimStatus::Thin: return "thin";
    case AlphaSimStatus::Blocked: return "blocked";
    case AlphaSimStatus::Failed: return "failed";
    case AlphaSimStatus::EmptyInput: return "empty_input";
    case AlphaSimStatus::TooFine: return "too_fine";
  }
  return "?";
}

const char* alpha_sim_fallback_name(AlphaSimFallback f) {
  switch (f) {
    case AlphaSimFallback::None: return "none";
    case AlphaSimFallback::ConvexHull: return "convex_hull";
    case AlphaSimFallback::Original: return "original";
  }
  return "?";
}

// ---------------------------------------------------------------------------------------
// Implicit solid

AlphaSimSolid::AlphaSimSolid(std::vector<AlphaSimPrism> prisms) : prisms_(std::move(prisms)) {}

bool AlphaSimSolid::contains(const Vec3& p, double tol) const {
  if (prisms_.empty()) return false;
  for (const auto& pr : prisms_) {
    const double d = p.dot(pr.n);
    if (d < pr.depth_min - tol || d > pr.depth_max + tol) return false;
    if (!pr.shape->contains(pr.project(p), tol)) return false;
  }
  return true;
}

double AlphaSimSolid::distance_bound(const Vec3& p) const {
  double best = -std::numeric_limits<double>::infinity();
  for (const auto& pr : prisms_) {
    const double d = p.dot(pr.n);
    const double dz = std::max(pr.depth_min - d, d - pr.depth_max);  // > 0 outside the slab
    const double d2 = pr.shape->signed_distance(pr.project(p));
    double sd;
    if (d2 <= 0.0 && dz <= 0.0) sd = std::max(d2, dz);
    else sd = std::hypot(std::max(d2, 0.0), std::max(dz, 0.0));
    best = std::max(best, sd);
  }
  return prisms_.empty() ? std::numeric_limits<double>::infinity() : best;
}

// ---------------------------------------------------------------------------------------
// Sampling

std::vector<Vec3> dense_surface_samples(const Mesh& mesh, double spacing, double density,
                                        std::size_t max_samples, std::uint64_t seed) {
  std::vector<Vec3> out;
  const std::size_t nt = mesh.triangles.size();
  std::vector<char> used(mesh.vertices.size(), 0);
  for (const auto& f : mesh.triangles)
    for (auto i : f) used[i] = 1;
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i)
    if (used[i]) out.push_back(mesh.vertices[i]);
  // Random points: ≥ 2 per triangle, ≈ density per spacing² of area, capped.
  const double cell = spacing > 0.0 ? spacing * spacing : 1.0;
  std::vector<std::size_t> count(nt);
  std::size_t total = 0;
  for (std::size_t t = 0; t < nt; ++t) {
    const auto c = mesh.corners(t);
    const double area = 0.5 * (c[1] - c[0]).cross(c[2] - c[0]).norm();
    count[t] = 2 + static_cast<std::size_t>(std::min(1e6, density * area / cell));
    total += count[t];
  }
  const double scale = total > max_samples && total > 0 ? static_cast<double>(max_samples) / total : 1.0;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  for (std::size_t t = 0; t < nt; ++t) {
    const auto c = mesh.corners(t);
    out.push_back((c[0] + c[1]) / 2.0);
    out.push_back((c[1] + c[2]) / 2.0);
    out.push_back((c[2] + c[0]) / 2.0);
    out.push_back((c[0] + c[1] + c[2]) / 3.0);
    const std::size_t k = std::max<std::size_t>(1, static_cast<std::size_t>(count[t] * scale));
    for (std::size_t s = 0; s < k; ++s) {
      double a = uni(rng), b = uni(rng);
      if (a + b > 1.0) {
        a = 1.0 - a;
        b = 1.0 - b;
      }
      out.push_back(c[0] + a * (c[1] - c[0]) + b * (c[2] - c[0]));
    }
  }
  return out;
}

namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

/// The paper's point cloud: mesh vertices plus the points of a subdivision whose edges are
/// ≤ L_max (shared edges subdivided once), and check points (sub-triangle centroids and
/// sub-edge midpoints) that the 2D shapes must cover.
struct Cloud {
  std::vector<Vec3> points;
  std::vector<Vec3> checks;
};

Cloud sample_cloud(const Mesh& mesh, double l_max) {
  Cloud cl;
  std::vector<char> used(mesh.vertices.size(), 0);
  for (const auto& f : mesh.triangles)
    for (auto i : f) used[i] = 1;
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i)
    if (used[i]) cl.points.push_back(mesh.vertices[i]);
  // Unique edges, deterministic order.
  std::vector<std::pair<std::uint32_t, std::uint32_t>> edges;
  edges.reserve(mesh.triangles.size() * 3);
  for (const auto& f : mesh.triangles)
    for (int k = 0; k < 3; ++k) {
      auto a = f[k], b = f[(k + 1) % 3];
      if (a > b) std::swap(a, b);
      edges.emplace_back(a, b);
    }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  for (const auto& [a, b] : edges) {
    const Vec3 pa = mesh.vertices[a], pb = mesh.vertices[b];
    const int n = std::max(1, static_cast<int>(std::ceil((pb - pa).norm() / l_max)));
    for (int k = 1; k < n; ++k) cl.points.push_back(pa + (pb - pa) * (static_cast<double>(k) / n));
    for (int k = 0; k < n; ++k) cl.checks.push_back(pa + (pb - pa) * ((k + 0.5) / n));
  }
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto c = mesh.corners(t);
    const double longest = std::max({(c[1] - c[0]).norm(), (c[2] - c[1]).norm(), (c[0] - c[2]).norm()});
    const int n = std::max(1, static_cast<int>(std::ceil(longest / l_max)));
    const Vec3 e1 = (c[1] - c[0]) / n, e2 = (c[2] - c[0]) / n;
    for (int i = 1; i < n; ++i)
      for (int j = 1; i + j < n; ++j) cl.points.push_back(c[0] + i * e1 + j * e2);
    for (int i = 0; i < n; ++i)
      for (int j = 0; i + j < n; ++j) {
        cl.checks.push_back(c[0] + (i + 1.0 / 3.0) * e1 + (j + 1.0 / 3.0) * e2);
        if (i + j + 1 < n) cl.checks.push_back(c[0] + (i + 2.0 / 3.0) * e1 + (j + 2.0 / 3.0) * e2);
      }
  }
  return cl;
}

/// Orthonormal frame (u, v, n = u × v) for a plane normal.
AlphaSimPrism frame_for(const Vec3& normal) {
  AlphaSimPrism p;
  p.n = normal.normalized();
  Vec3 axis = Vec3::UnitX();
  if (std::abs(p.n.x()) > 0.9) axis = Vec3::UnitY();
  p.u = p.n.cross(axis).normalized();
  p.v = p.n.cross(p.u);
  // Ensure u × v = n.
  if (p.u.cross(p.v).dot(p.n) < 0.0) p.v = -p.v;
  return p;
}

struct PlaneSpec {
  std::string name;
  AlphaSimPrism frame;
};

std::vector<PlaneSpec> planes_for(const AlphaSimOptions& opt) {
  std::vector<PlaneSpec> out;
  if (opt.coordinate_planes) {
    AlphaSimPrism xy, xz, yz;
    xy.u = Vec3::UnitX(); xy.v = Vec3::UnitY(); xy.n = Vec3::UnitZ();
    xz.u = Vec3::UnitX(); xz.v = Vec3::UnitZ(); xz.n = -Vec3::UnitY();
    yz.u = Vec3::UnitY(); yz.v = Vec3::UnitZ(); yz.n = Vec3::UnitX();
    out.push_back({"XY", xy});
    out.push_back({"XZ", xz});
    out.push_back({"YZ", yz});
  }
  for (std::size_t i = 0; i < opt.extra_planes.size(); ++i) {
    const Vec3& n = opt.extra_planes[i];
    if (!n.allFinite() || n.norm() == 0.0)
      throw std::invalid_argument("alpha-sim: user plane normal " + std::to_string(i) + " is zero or not finite");
    out.push_back({"user" + std::to_string(i), frame_for(n)});
  }
  if (out.empty()) throw std::invalid_argument("alpha-sim: no projection plane");
  return out;
}

// --- CGAL mesh queries ----------------------------------------------------------------
using K3 = CGAL::Exact_predicates_inexact_constructions_kernel;
using SM = CGAL::Surface_mesh<K3::Point_3>;
using Prim = CGAL::AABB_face_graph_triangle_primitive<SM>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<K3, Prim>>;

/// A triangle mesh with an AABB tree for distance and inside queries (CGAL).
struct MeshQuery {
  SM sm;
  std::unique_ptr<Tree> tree;
  explicit MeshQuery(const Mesh& m) {
    // A triangle soup (own corners per face): prism intersections can touch along an
    // edge (non-manifold), which a half-edge structure rejects; the AABB tree and the
    // ray-parity inside test need only the triangles.
    for (const auto& f : m.triangles) {
      SM::Vertex_index c[3];
      for (int k = 0; k < 3; ++k) {
        const Vec3& v = m.vertices[f[k]];
        c[k] = sm.add_vertex(K3::Point_3(v.x(), v.y(), v.z()));
      }
      sm.add_face(c[0], c[1], c[2]);
    }
    tree = std::make_unique<Tree>(faces(sm).first, faces(sm).second, sm);
    tree->build();
    tree->accelerate_distance_queries();
  }
  double distance(const Vec3& p) const { return std::sqrt(tree->squared_distance(K3::Point_3(p.x(), p.y(), p.z()))); }
};

/// Fraction of `samples` inside or within tol of the closed mesh q (parallel).
std::size_t count_contained_mesh(const MeshQuery& q, const std::vector<Vec3>& samples, double tol) {
  return tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, samples.size(), 1024), std::size_t(0),
      [&](const tbb::blocked_range<std::size_t>& r, std::size_t acc) {
        CGAL::Side_of_triangle_mesh<SM, K3, CGAL::Default, Tree> side(*q.tree);
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
          const auto& p = samples[i];
          const K3::Point_3 cp(p.x(), p.y(), p.z());
          if (side(cp) != CGAL::ON_UNBOUNDED_SIDE || q.tree->squared_distance(cp) <= tol * tol) ++acc;
        }
        return acc;
      },
      std::plus<std::size_t>());
}

// --- OpenCASCADE prisms ∩ -----------------------------------------------------------------
gp_Pnt to_gp(const AlphaSimPrism& pr, const Vec2& q, double depth) {
  const Vec3 p = pr.u * q.x() + pr.v * q.y() + pr.n * depth;
  return gp_Pnt(p.x(), p.y(), p.z());
}

TopoDS_Wire ring_wire(const AlphaSimPrism& pr, const std::vector<Vec2>& ring, double depth) {
  BRepBuilderAPI_MakePolygon poly;
  for (const auto& q : ring) poly.Add(to_gp(pr, q, depth));
  poly.Close();
  if (!poly.IsDone()) throw std::runtime_error("polygon wire failed");
  return poly.Wire();
}

/// Extrudes the polygons of one plane over [depth_min - margin, depth_max + margin].
TopoDS_Shape prism_shape(const AlphaSimPrism& pr, const std::vector<PolygonWithHoles2>& polys, double margin) {
  BRep_Builder builder;
  TopoDS_Compound comp;
  builder.MakeCompound(comp);
  const double d0 = pr.depth_min - margin;
  const gp_Vec dir(pr.n.x() * (pr.depth_max - pr.depth_min + 2 * margin),
                   pr.n.y() * (pr.depth_max - pr.depth_min + 2 * margin),
                   pr.n.z() * (pr.depth_max - pr.depth_min + 2 * margin));
  const Vec3 o = pr.n * d0;
  const gp_Pln plane(gp_Pnt(o.x(), o.y(), o.z()), gp_Dir(pr.n.x(), pr.n.y(), pr.n.z()));
  int count = 0;
  for (const auto& poly : polys) {
    BRepBuilderAPI_MakeFace mf(plane, ring_wire(pr, poly.outer, d0), true);
    for (const auto& h : poly.holes) mf.Add(ring_wire(pr, h, d0));
    if (!mf.IsDone()) throw std::runtime_error("planar face failed");
    BRepPrimAPI_MakePrism prism(mf.Face(), dir);
    prism.Build();
    if (!prism.IsDone()) throw std::runtime_error("prism failed");
    builder.Add(comp, prism.Shape());
    ++count;
  }
  if (count == 0) throw std::runtime_error("no polygon");
  return comp;
}

TopoDS_Shape common(const TopoDS_Shape& a, const TopoDS_Shape& b, double fuzzy) {
  BRepAlgoAPI_Common op(a, b);
  // Constructor builds; set fuzzy and rebuild only if it failed.
  if (!op.IsDone() || op.HasErrors()) {
    TopTools_ListOfShape args, tools;
    args.Append(a);
    tools.Append(b);
    BRepAlgoAPI_Common op2;
    op2.SetArguments(args);
    op2.SetTools(tools);
    op2.SetFuzzyValue(fuzzy);
    op2.Build();
    if (!op2.IsDone() || op2.HasErrors()) throw std::runtime_error("Boolean common failed");
    return op2.Shape();
  }
  return op.Shape();
}

Mesh mesh_shape(const TopoDS_Shape& shape, double deflection, int* face_count) {
  BRepMesh_IncrementalMesh mesher(shape, deflection, false, 0.5, false);
  Mesh m;
  int faces_n = 0;
  for (TopExp_Explorer ex(shape, TopAbs_FACE); ex.More(); ex.Next()) {
    const TopoDS_Face& face = TopoDS::Face(ex.Current());
    ++faces_n;
    TopLoc_Location loc;
    const Handle(Poly_Triangulation) tri = BRep_Tool::Triangulation(face, loc);
    if (tri.IsNull()) throw std::runtime_error("face without triangulation");
    const gp_Trsf trsf = loc.Transformation();
    const auto base = static_cast<std::uint32_t>(m.vertices.size());
    for (int i = 1; i <= tri->NbNodes(); ++i) {
      const gp_Pnt p = tri->Node(i).Transformed(trsf);
      m.vertices.emplace_back(p.X(), p.Y(), p.Z());
    }
    const bool reversed = face.Orientation() == TopAbs_REVERSED;
    for (int i = 1; i <= tri->NbTriangles(); ++i) {
      int a, b, c;
      tri->Triangle(i).Get(a, b, c);
      if (reversed) std::swap(b, c);
      m.triangles.push_back({base + static_cast<std::uint32_t>(a - 1), base + static_cast<std::uint32_t>(b - 1),
                             base + static_cast<std::uint32_t>(c - 1)});
    }
  }
  if (face_count) *face_count = faces_n;
  return m;
}

void write_step_atomic(const TopoDS_Shape& shape, const std::filesystem::path& path) {
  std::filesystem::create_directories(path.parent_path().empty() ? "." : path.parent_path());
  const std::filesystem::path tmp = path.string() + ".tmp";
  STEPControl_Writer writer;
  if (writer.Transfer(shape, STEPControl_AsIs) != IFSelect_RetDone ||
      writer.Write(tmp.string().c_str()) != IFSelect_RetDone) {
    std::filesystem::remove(tmp);
    throw std::runtime_error("cannot write STEP file " + path.string());
  }
  std::filesystem::rename(tmp, path);
}

std::string safe_file_name(const std::string& name) {
  std::string s = name.empty() ? "part" : name;
  for (auto& ch : s)
    if (!(std::isalnum(static_cast<unsigned char>(ch)) || ch == '-' || ch == '_' || ch == '.')) ch = '_';
  return s;
}

void keep_original(AlphaSimPart& out, const Part& part, AlphaSimStatus status, const std::string& reason) {
  out.mesh = part.mesh;
  out.solid.reset();
  auto& r = out.result;
  r.status = status;
  r.fallback = AlphaSimFallback::Original;
  r.reason = reason;
  r.triangles_after = r.triangles_before;
  r.faces_after = r.faces_before;
  r.closed_after = r.closed_before;
  r.volume_after = r.volume_before;
  r.containment = r.containment_implicit = 1.0;  // the same surface
  r.hausdorff = 0.0;
}

}  // namespace

// ---------------------------------------------------------------------------------------

AlphaSimPart simplify_part(const Part& part, const AlphaSimOptions& opt) {
  const auto t0 = Clock::now();
  if (!(std::isfinite(opt.dim_pre) && opt.dim_pre > 0.0))
    throw std::invalid_argument("alpha-sim: dim_pre must be finite and > 0, got " + full_precision(opt.dim_pre));
  if (!(opt.sampling_factor > 0.0 && opt.alpha_factor > 0.0))
    throw std::invalid_argument("alpha-sim: sampling_factor and alpha_factor must be > 0");
  const auto specs = planes_for(opt);

  AlphaSimPart out;
  AlphaSimResult& r = out.result;
  r.name = part.name;
  r.dim_pre = opt.dim_pre;
  r.alpha = opt.alpha_factor * opt.dim_pre;
  r.l_max = opt.sampling_factor * opt.dim_pre;
  r.triangles_before = part.mesh.triangle_count();
  r.faces_before = part.source_faces;
  const MeshTopology topo = analyse_topology(part.mesh);
  r.closed_before = topo.closed;
  r.volume_before = topo.closed ? std::abs(part.mesh.signed_volume()) : 0.0;
  const AABB box = part.mesh.bounds();
  const double size = opt.scene_size > 0.0 ? opt.scene_size : box.diagonal();
  r.tolerance = opt.containment_tolerance_factor * (size > 0.0 ? size : 1.0);
  const double tol = r.tolerance;
  auto finish = [&]() {
    r.time_ms = ms_since(t0);
    return std::move(out);
  };

  if (part.mesh.empty()) {
    keep_original(out, part, AlphaSimStatus::EmptyInput, "the part has no triangles");
    return finish();
  }
  if (first_non_finite_vertex(part.mesh) >= 0)
    throw std::invalid_argument("alpha-sim: part '" + part.name + "' has a non-finite vertex");

  // Too thin along a projection normal: the part is a sheet, extrusions would be flat.
  for (const auto& s : specs) {
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (const auto& f : part.mesh.triangles)
      for (auto i : f) {
        const double d = part.mesh.vertices[i].dot(s.frame.n);
        lo = std::min(lo, d);
        hi = std::max(hi, d);
      }
    if (hi - lo < opt.thin_factor * opt.dim_pre) {
      keep_original(out, part, AlphaSimStatus::Thin,
                    "extent along the " + s.name + " normal is " + full_precision(hi - lo) +
                        " < " + full_precision(opt.thin_factor * opt.dim_pre) + " (a sheet): original kept");
      return finish();
    }
  }

  // The cloud size is known before sampling: refuse what would not fit in memory.
  {
    double estimate = 0.0;
    for (std::size_t t = 0; t < part.mesh.triangles.size(); ++t) {
      const auto c = part.mesh.corners(t);
      const double longest = std::max({(c[1] - c[0]).norm(), (c[2] - c[1]).norm(), (c[0] - c[2]).norm()});
      const double n = std::ceil(longest / r.l_max);
      estimate += 0.5 * n * n + 1.5 * n;
    }
    if (estimate > static_cast<double>(opt.max_cloud_points)) {
      keep_original(out, part, AlphaSimStatus::TooFine,
                    "sampling at L_max = " + full_precision(r.l_max) + " needs about " +
                        std::to_string(static_cast<long long>(estimate)) + " points > " +
                        std::to_string(opt.max_cloud_points) + ": original kept (raise dim_pre)");
      return finish();
    }
  }

  // 1. Sample (L_max), 2–3. project and build α-shapes per plane (in parallel).
  const Cloud cloud = sample_cloud(part.mesh, r.l_max);
  r.sample_points = cloud.points.size();
  std::vector<AlphaSimPrism> prisms(specs.size());
  std::vector<std::shared_ptr<AlphaShape2D>> shapes(specs.size());
  r.projections.resize(specs.size());
  std::atomic<bool> degenerate{false};
  tbb::parallel_for(std::size_t(0), specs.size(), [&](std::size_t k) {
    AlphaSimPrism pr = specs[k].frame;
    ProjectionReport& rep = r.projections[k];
    rep.plane = specs[k].name;
    rep.normal = pr.n;
    std::vector<Vec2> pts;
    pts.reserve(cloud.points.size());
    pr.depth_min = std::numeric_limits<double>::infinity();
    pr.depth_max = -pr.depth_min;
    // Snap projections to a grid of snap ≤ tol/4 and drop duplicates: points that are
    // equal up to rounding (the same 3D edge subdivided from either end, front and back
    // faces) would otherwise give sliver triangles and spurious boundary loops.
    // A power of two, so that coordinates on a binary grid (integers, halves) stay exact.
    const double snap = std::exp2(std::floor(std::log2(tol / 4.0)));
    for (const auto& p : cloud.points) {
      const Vec2 q = pr.project(p);
      pts.emplace_back(std::round(q.x() / snap) * snap, std::round(q.y() / snap) * snap);
      const double d = p.dot(pr.n);
      pr.depth_min = std::min(pr.depth_min, d);
      pr.depth_max = std::max(pr.depth_max, d);
    }
    std::sort(pts.begin(), pts.end(),
              [](const Vec2& a, const Vec2& b) { return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y()); });
    pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
    rep.points = pts.size();
    auto shape = std::make_shared<AlphaShape2D>(pts, r.alpha, std::min(opt.short_edge_factor * r.l_max, r.alpha));
    rep.delaunay_triangles = shape->delaunay_triangle_count();
    rep.alpha_area = shape->area();
    rep.hull_area = shape->hull_area();
    if (shape->degenerate()) degenerate = true;
    if (shape->kept_triangle_count() == 0) {
      rep.status = ProjectionStatus::Empty;
      shape->keep_all();
    } else {
      std::vector<Vec2> checks;
      checks.reserve(cloud.checks.size());
      for (const auto& p : cloud.checks) checks.push_back(pr.project(p));
      const double added = shape->cover(checks, tol);
      if (added > opt.torn_fraction * shape->area()) {
        rep.status = ProjectionStatus::Torn;
        shape->keep_all();
      } else if (added > 0.0) {
        rep.status = ProjectionStatus::Repaired;
      }
    }
    pr.shape = shape;
    prisms[k] = pr;
    shapes[k] = shape;
  });
  if (degenerate) {
    keep_original(out, part, AlphaSimStatus::Thin, "a projection is degenerate (collinear points): original kept");
    return finish();
  }

  // Verify containment of dense samples on the implicit solid; a plane that misses
  // samples is replaced by its convex hull (which contains every projected point).
  const std::vector<Vec3> samples =
      dense_surface_samples(part.mesh, r.l_max, opt.containment_density, opt.containment_max_samples, opt.seed);
  r.containment_samples = samples.size();
  auto plane_misses = [&]() {
    std::vector<std::size_t> miss(specs.size(), 0);
    std::vector<std::atomic<std::size_t>> counter(specs.size());
    for (auto& c : counter) c = 0;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, samples.size(), 4096), [&](const auto& rg) {
      std::vector<std::size_t> local(specs.size(), 0);
      for (std::size_t i = rg.begin(); i != rg.end(); ++i)
        for (std::size_t k = 0; k < prisms.size(); ++k)
          if (!prisms[k].shape->contains(prisms[k].project(samples[i]), tol)) ++local[k];
      for (std::size_t k = 0; k < specs.size(); ++k) counter[k] += local[k];
    });
    for (std::size_t k = 0; k < specs.size(); ++k) miss[k] = counter[k];
    return miss;
  };
  for (int round = 0; round < 2; ++round) {
    const auto miss = plane_misses();
    bool any = false;
    for (std::size_t k = 0; k < specs.size(); ++k)
      if (miss[k] > 0) {
        any = true;
        if (round == 0) {
          r.projections[k].status = ProjectionStatus::Eroded;
          shapes[k]->keep_all();
        }
      }
    if (!any) break;
    if (round == 1) {
      keep_original(out, part, AlphaSimStatus::Failed,
                    "convex hull of a projection misses surface samples: original kept");
      return finish();
    }
  }
  bool hull = false;
  for (std::size_t k = 0; k < specs.size(); ++k) {
    auto& rep = r.projections[k];
    rep.kept_triangles = shapes[k]->kept_triangle_count();
    rep.area = shapes[k]->area();
    if (rep.status == ProjectionStatus::Empty || rep.status == ProjectionStatus::Torn ||
        rep.status == ProjectionStatus::Eroded)
      hull = true;
  }
  auto solid = std::make_shared<AlphaSimSolid>(prisms);
  {
    const std::size_t in = tbb::parallel_reduce(
        tbb::blocked_range<std::size_t>(0, samples.size(), 4096), std::size_t(0),
        [&](const auto& rg, std::size_t acc) {
          for (std::size_t i = rg.begin(); i != rg.end(); ++i) acc += solid->contains(samples[i], tol) ? 1 : 0;
          return acc;
        },
        std::plus<std::size_t>());
    r.containment_implicit = samples.empty() ? 1.0 : static_cast<double>(in) / samples.size();
  }
  out.solid = solid;
  if (hull) {
    r.status = AlphaSimStatus::HullFallback;
    r.fallback = AlphaSimFallback::ConvexHull;
    std::string planes;
    for (const auto& rep : r.projections)
      if (rep.status == ProjectionStatus::Empty || rep.status == ProjectionStatus::Torn ||
          rep.status == ProjectionStatus::Eroded)
        planes += (planes.empty() ? "" : ", ") + rep.plane + " (" + projection_status_name(rep.status) + ")";
    r.reason = "convex hull used for " + planes;
  }

  // 4. boundary polygons, merged collinear points (paper: included angle < 1e-6 deg).
  // Vertices within merge_tol (tol/4) of the chord replacing them are merged too: the
  // snapped projections of a straight edge are collinear only up to the snap grid. The
  // region may shrink by merge_tol, which the containment tolerance covers (verified below).
  constexpr double kCollinearAngle = 1e-6 * M_PI / 180.0;
  const double merge_tol = tol / 4.0;
  std::vector<std::vector<PolygonWithHoles2>> polys(specs.size());
  for (std::size_t k = 0; k < specs.size(); ++k) {
    polys[k] = shapes[k]->polygons();
    auto& rep = r.projections[k];
    std::vector<PolygonWithHoles2> kept;
    for (auto& p : polys[k]) {
      merge_collinear(p.outer, kCollinearAngle, merge_tol);
      if (p.outer.size() < 3) continue;
      std::vector<std::vector<Vec2>> holes;
      for (auto& h : p.holes) {
        merge_collinear(h, kCollinearAngle, merge_tol);
        if (h.size() >= 3) holes.push_back(std::move(h));
      }
      p.holes = std::move(holes);
      rep.polygon_vertices += p.outer.size();
      for (const auto& h : p.holes) rep.polygon_vertices += h.size();
      rep.holes += p.holes.size();
      kept.push_back(std::move(p));
    }
    rep.polygons = kept.size();
    polys[k] = std::move(kept);
  }

  r.shapes_ms = ms_since(t0);
  if (!opt.build_mesh) return finish();
  const auto t_mesh = Clock::now();

  // 5–6. extrude and intersect (OpenCASCADE), mesh the result.
  TopoDS_Shape result;
  try {
    const double margin = std::max(10.0 * tol, 1e-3 * opt.dim_pre);
    std::vector<TopoDS_Shape> shapes3(specs.size());
    for (std::size_t k = 0; k < specs.size(); ++k) shapes3[k] = prism_shape(prisms[k], polys[k], margin);
    result = shapes3[0];
    for (std::size_t k = 1; k < specs.size(); ++k) result = common(result, shapes3[k], tol);
    out.mesh = mesh_shape(result, opt.dim_pre, &r.faces_after);
  } catch (const Standard_Failure& e) {
    keep_original(out, part, AlphaSimStatus::Failed,
                  std::string("OpenCASCADE failed: ") + (e.GetMessageString() ? e.GetMessageString() : "?") +
                      ": original kept");
    return finish();
  } catch (const std::exception& e) {
    keep_original(out, part, AlphaSimStatus::Failed, std::string("OpenCASCADE failed: ") + e.what() + ": original kept");
    return finish();
  }
  r.mesh_ms = ms_since(t_mesh);
  weld_identical_vertices(out.mesh);
  const MeshTopology otopo = analyse_topology(out.mesh);
  // Watertight: no boundary and no misoriented edge. Edges shared by four triangles are
  // allowed: two pieces of the intersection may touch along an edge.
  const bool watertight = otopo.boundary_edges == 0 && otopo.misoriented_edges == 0;
  if (watertight && out.mesh.signed_volume() < 0.0)
    for (auto& f : out.mesh.triangles) std::swap(f[1], f[2]);
  r.closed_after = watertight;
  r.triangles_after = out.mesh.triangle_count();
  r.volume_after = watertight ? std::abs(out.mesh.signed_volume()) : 0.0;
  if (!watertight || out.mesh.empty()) {
    keep_original(out, part, AlphaSimStatus::Failed,
                  "the OpenCASCADE result mesh is not closed (" + std::to_string(otopo.boundary_edges) +
                      " boundary, " + std::to_string(otopo.nonmanifold_edges) + " non-manifold, " +
                      std::to_string(otopo.misoriented_edges) + " misoriented edges): original kept");
    return finish();
  }

  const auto t_measure = Clock::now();
  if (opt.measure) {
    // Containment of the original surface in the output mesh (what indices will use).
    MeshQuery simplified(out.mesh);
    const std::size_t in = count_contained_mesh(simplified, samples, tol);
    r.containment = samples.empty() ? 1.0 : static_cast<double>(in) / samples.size();
    if (in != samples.size()) {
      const double c = r.containment;
      keep_original(out, part, AlphaSimStatus::Failed,
                    "output mesh contains only " + full_precision(c) + " of the surface samples: original kept");
      r.containment = c;  // report what was measured before falling back
      return finish();
    }
    // One-sided Hausdorff distance: output surface → original surface.
    MeshQuery original(part.mesh);
    const auto surf = dense_surface_samples(out.mesh, r.l_max, 1.0, 200000, opt.seed + 1);
    r.hausdorff = tbb::parallel_reduce(
        tbb::blocked_range<std::size_t>(0, surf.size(), 1024), 0.0,
        [&](const auto& rg, double acc) {
          for (std::size_t i = rg.begin(); i != rg.end(); ++i) acc = std::max(acc, original.distance(surf[i]));
          return acc;
        },
        [](double a, double b) { return std::max(a, b); });

    // Lost space (blocked projections): largest ball inside the simplified solid and
    // outside the original, probed on a grid.
    if (opt.detect_lost_space && r.closed_before) {
      const double r_lost = opt.lost_space_factor * opt.dim_pre;
      const Vec3 ext = box.size();
      const double vol = std::max(ext.x(), 1e-12) * std::max(ext.y(), 1e-12) * std::max(ext.z(), 1e-12);
      double h = std::max(r_lost / 2.0, std::cbrt(vol / static_cast<double>(opt.lost_space_max_samples)));
      r.lost_space_resolution = h;
      const int nx = std::max(1, static_cast<int>(std::floor(ext.x() / h))),
                ny = std::max(1, static_cast<int>(std::floor(ext.y() / h))),
                nz = std::max(1, static_cast<int>(std::floor(ext.z() / h)));
      const std::size_t total = static_cast<std::size_t>(nx) * ny * nz;
      r.lost_space_radius = tbb::parallel_reduce(
          tbb::blocked_range<std::size_t>(0, total, 256), 0.0,
          [&](const auto& rg, double acc) {
            CGAL::Side_of_triangle_mesh<SM, K3, CGAL::Default, Tree> side(*original.tree);
            for (std::size_t i = rg.begin(); i != rg.end(); ++i) {
              const std::size_t ix = i % nx, iy = (i / nx) % ny, iz = i / (static_cast<std::size_t>(nx) * ny);
              const Vec3 p = box.min + Vec3((ix + 0.5) * ext.x() / nx, (iy + 0.5) * ext.y() / ny,
                                            (iz + 0.5) * ext.z() / nz);
              const double depth = -solid->distance_bound(p);  // exact inside the intersection
              if (depth <= acc) continue;
              const double d = original.distance(p);
              const double ball = std::min(depth, d);
              if (ball <= acc) continue;
              if (side(K3::Point_3(p.x(), p.y(), p.z())) == CGAL::ON_UNBOUNDED_SIDE) acc = ball;
            }
            return acc;
          },
          [](double a, double b) { return std::max(a, b); });
      if (r.lost_space_radius >= r_lost) {
        const double lost = r.lost_space_radius;
        keep_original(out, part, AlphaSimStatus::Blocked,
                      "a ball of radius " + full_precision(lost) + " ≥ " + full_precision(r_lost) +
                          " outside the original fits inside the simplified part: a feature is hidden in every "
                          "projection (split the part); original kept");
        r.lost_space_radius = lost;
        return finish();
      }
    }
  }

  r.measure_ms = ms_since(t_measure);
  if (!opt.step_dir.empty()) write_step_atomic(result, opt.step_dir / (safe_file_name(part.name) + ".step"));
  return finish();
}

std::vector<Part> simplify_parts(const std::vector<Part>& parts, const AlphaSimOptions& opt,
                                 std::vector<AlphaSimResult>* results) {
  AlphaSimOptions o = opt;
  if (!(o.scene_size > 0.0)) {
    AABB all;
    for (const auto& p : parts) all.extend(p.mesh.bounds());
    o.scene_size = all.diagonal() > 0.0 ? all.diagonal() : 1.0;
  }
  std::vector<Part> out(parts.size());
  std::vector<AlphaSimResult> res(parts.size());
  tbb::parallel_for(std::size_t(0), parts.size(), [&](std::size_t i) {
    AlphaSimPart sp = simplify_part(parts[i], o);
    Part p = parts[i];
    p.mesh = std::move(sp.mesh);
    p.closed = sp.result.closed_after;
    if (sp.result.fallback != AlphaSimFallback::Original) p.source_faces = sp.result.faces_after;
    out[i] = std::move(p);
    res[i] = std::move(sp.result);
  });
  if (results) *results = std::move(res);
  return out;
}

}  // namespace loom
