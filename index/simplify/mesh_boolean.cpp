#include "index/simplify/mesh_boolean.hpp"

#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/corefinement.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>

#include <algorithm>
#include <array>
#include <memory>
#include <numeric>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>

namespace loom {
namespace {

using Kernel = CGAL::Exact_predicates_exact_constructions_kernel;
using SurfaceMesh = CGAL::Surface_mesh<Kernel::Point_3>;
using FaceIndex = SurfaceMesh::Face_index;
using LabelMap = SurfaceMesh::Property_map<FaceIndex, int>;
namespace PMP = CGAL::Polygon_mesh_processing;

/// Union-find root with path halving.
std::size_t root(std::vector<std::size_t>& parent, std::size_t i) {
  while (parent[i] != i) i = parent[i] = parent[parent[i]];
  return i;
}

/// True if the triangles `polygons` of `mesh` cross each other (PMP::does_self_intersect
/// on a Surface_mesh of the Epick kernel).
bool does_self_intersect_epick(const Mesh& mesh, const std::vector<std::array<std::size_t, 3>>& polygons) {
  using EpickPoint = CGAL::Exact_predicates_inexact_constructions_kernel::Point_3;
  std::vector<EpickPoint> points;
  points.reserve(mesh.vertices.size());
  for (const Vec3& p : mesh.vertices) points.emplace_back(p.x(), p.y(), p.z());
  CGAL::Surface_mesh<EpickPoint> sm;
  PMP::polygon_soup_to_polygon_mesh(points, polygons, sm);
  return PMP::does_self_intersect(sm);
}

SurfaceMesh to_surface_mesh(const FacedMesh& m, int label_offset, const char* which) {
  const std::string name = std::string("mesh intersection: ") + which;
  if (m.face.size() != m.mesh.triangles.size())
    throw std::runtime_error(name + " has " + std::to_string(m.face.size()) + " face labels for " +
                             std::to_string(m.mesh.triangles.size()) + " triangles");
  // Through a polygon soup, which CGAL orients and checks: where pieces of the solid touch
  // along an edge or at a vertex (rings that touch, two sliced pieces meeting) it would
  // duplicate the vertex there. CGAL 5.5's Boolean operations take no such input (it is
  // self-intersecting for them: they crashed on it), so it is refused and the caller uses
  // OpenCASCADE.
  std::vector<Kernel::Point_3> points;
  points.reserve(m.mesh.vertices.size());
  for (const Vec3& p : m.mesh.vertices) points.emplace_back(p.x(), p.y(), p.z());
  std::vector<std::array<std::size_t, 3>> polygons;
  polygons.reserve(m.mesh.triangles.size());
  for (const auto& t : m.mesh.triangles) polygons.push_back({t[0], t[1], t[2]});
  if (!PMP::orient_polygon_soup(points, polygons))
    throw std::runtime_error(name + " has pieces that touch along an edge or at a vertex (not a 2-manifold)");
  // No point was added, so the indices are the mesh's: the soup was oriented already
  // (outward), and no triangle may have been turned.
  for (std::size_t t = 0; t < polygons.size(); ++t) {
    const auto& tri = m.mesh.triangles[t];
    const auto& poly = polygons[t];
    bool same = false;
    for (std::size_t r = 0; r < 3; ++r)
      same = same || (poly[r] == tri[0] && poly[(r + 1) % 3] == tri[1] && poly[(r + 2) % 3] == tri[2]);
    if (!same) throw std::runtime_error(name + " is not consistently oriented (triangle " + std::to_string(t) + ")");
  }
  SurfaceMesh sm;
  PMP::polygon_soup_to_polygon_mesh(points, polygons, sm);
  if (sm.number_of_faces() != polygons.size())
    throw std::runtime_error(name + " could not be made a half-edge mesh");
  if (!CGAL::is_closed(sm)) throw std::runtime_error(name + " is not closed");
  // CGAL's precondition (crossing faces are undefined behaviour there, as the touching
  // pieces above were): checked, since the meshers' rounding is not proven never to fold.
  // On a copy with the inexact-constructions kernel: the test takes only predicates on the
  // input's doubles, exact there too, without the lazy exact kernel's overhead.
  if (does_self_intersect_epick(m.mesh, polygons)) throw std::runtime_error(name + " intersects itself");
  // Faces were added in polygon order to an empty mesh: face t is triangle t.
  LabelMap label = sm.add_property_map<FaceIndex, int>("f:label", -1).first;
  for (std::size_t t = 0; t < polygons.size(); ++t) label[FaceIndex(static_cast<SurfaceMesh::size_type>(t))] = m.face[t] + label_offset;
  return sm;
}

/// Carries each input triangle's label to its pieces and to their copies in the result.
/// CGAL copies the visitor: the state it shares lives in the meshes' property maps.
struct LabelVisitor : PMP::Corefinement::Default_visitor<SurfaceMesh> {
  std::shared_ptr<int> splitting = std::make_shared<int>(-1);  // label of the face being split

  static LabelMap labels(const SurfaceMesh& tm) {
    return tm.property_map<FaceIndex, int>("f:label").first;
  }
  void before_subface_creations(FaceIndex f_old, SurfaceMesh& tm) { *splitting = labels(tm)[f_old]; }
  void after_subface_created(FaceIndex f_new, SurfaceMesh& tm) { labels(tm)[f_new] = *splitting; }
  void after_face_copy(FaceIndex f_old, const SurfaceMesh& src, FaceIndex f_new, SurfaceMesh& tgt) {
    labels(tgt)[f_new] = labels(src)[f_old];
  }
};

}  // namespace

std::vector<std::size_t> labelled_face_ids(const Mesh& m, const std::vector<int>& face) {
  // Each triangle is joined to the first triangle (lowest index) of each of its edges
  // when their labels agree: (edge, triangle) pairs sorted, a run per edge.
  std::vector<std::pair<std::uint64_t, std::size_t>> uses;
  uses.reserve(3 * m.triangles.size());
  for (std::size_t t = 0; t < m.triangles.size(); ++t)
    for (int e = 0; e < 3; ++e) {
      const std::uint32_t a = m.triangles[t][static_cast<std::size_t>(e)], b = m.triangles[t][static_cast<std::size_t>((e + 1) % 3)];
      uses.emplace_back(std::uint64_t(std::min(a, b)) << 32 | std::max(a, b), t);
    }
  std::sort(uses.begin(), uses.end());
  std::vector<std::size_t> parent(m.triangles.size());
  std::iota(parent.begin(), parent.end(), std::size_t(0));
  for (std::size_t i = 0, first = 0; i < uses.size(); ++i) {
    if (i == 0 || uses[i].first != uses[i - 1].first) {
      first = uses[i].second;
      continue;
    }
    const std::size_t t = uses[i].second;
    if (t == first || face[first] != face[t]) continue;  // (a triangle may repeat an edge)
    const std::size_t ra = root(parent, first), rb = root(parent, t);
    if (ra != rb) parent[ra] = rb;
  }
  // Name each face by its first triangle, whatever root the union ended with.
  std::vector<std::size_t> first(m.triangles.size(), m.triangles.size()), id(m.triangles.size());
  for (std::size_t t = 0; t < m.triangles.size(); ++t) {
    std::size_t& f = first[root(parent, t)];
    if (f == m.triangles.size()) f = t;
    id[t] = f;
  }
  return id;
}

int labelled_faces(const Mesh& m, const std::vector<int>& face) {
  const std::vector<std::size_t> id = labelled_face_ids(m, face);
  int n = 0;
  for (std::size_t t = 0; t < id.size(); ++t) n += id[t] == t ? 1 : 0;
  return n;
}

FacedMesh mesh_intersection(const FacedMesh& a, const FacedMesh& b) {
  const int shift = a.face.empty() ? 0 : *std::max_element(a.face.begin(), a.face.end()) + 1;
  SurfaceMesh sa = to_surface_mesh(a, 0, "the first mesh"), sb = to_surface_mesh(b, shift, "the second mesh"), out;
  out.add_property_map<FaceIndex, int>("f:label", -1);
  LabelVisitor visitor;
  if (!PMP::corefine_and_compute_intersection(sa, sb, out, CGAL::parameters::visitor(visitor)))
    throw std::runtime_error("mesh intersection: CGAL could not build the intersection as a manifold mesh");
  if (out.number_of_faces() == 0) throw std::runtime_error("mesh intersection: the intersection is empty");
  if (!CGAL::is_triangle_mesh(out)) throw std::runtime_error("mesh intersection: the result is not a triangle mesh");

  // The same solid comes out in an order that varies from run to run: CGAL's box
  // intersection breaks ties between equal box bounds by the boxes' addresses, so the
  // intersection points are numbered in heap order. Vertices are sorted by their
  // coordinates and triangles by their vertices, so equal inputs give equal outputs.
  // (out was built fresh, so its indices are dense: no removed elements.)
  std::vector<Vec3> points;
  points.reserve(out.number_of_vertices());
  for (const auto v : out.vertices()) {
    const auto& p = out.point(v);
    points.emplace_back(CGAL::to_double(p.x()), CGAL::to_double(p.y()), CGAL::to_double(p.z()));
  }
  std::vector<std::uint32_t> order(points.size());
  std::iota(order.begin(), order.end(), 0u);
  const auto less = [&](std::uint32_t i, std::uint32_t j) {
    const Vec3 &pi = points[i], &pj = points[j];
    return std::tie(pi.x(), pi.y(), pi.z()) < std::tie(pj.x(), pj.y(), pj.z());
  };
  std::stable_sort(order.begin(), order.end(), less);
  std::vector<std::uint32_t> rank(points.size());
  FacedMesh r;
  r.mesh.vertices.reserve(points.size());
  for (std::uint32_t i = 0; i < order.size(); ++i) {
    rank[order[i]] = i;
    r.mesh.vertices.push_back(points[order[i]]);
  }
  const LabelMap label = LabelVisitor::labels(out);
  std::vector<std::pair<std::array<std::uint32_t, 3>, int>> tris;
  tris.reserve(out.number_of_faces());
  for (const auto f : out.faces()) {
    std::array<std::uint32_t, 3> t{};
    std::size_t k = 0;
    for (const auto v : CGAL::vertices_around_face(out.halfedge(f), out)) t[k++] = rank[static_cast<std::size_t>(v)];
    // Rotated to start at the smallest index (orientation kept).
    std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
    if (label[f] < 0) throw std::runtime_error("mesh intersection: a result triangle lost its face label");
    tris.emplace_back(t, label[f]);
  }
  std::sort(tris.begin(), tris.end());
  r.mesh.triangles.reserve(tris.size());
  r.face.reserve(tris.size());
  for (const auto& [t, l] : tris) {
    r.mesh.triangles.push_back(t);
    r.face.push_back(l);
  }
  r.faces = labelled_faces(r.mesh, r.face);
  return r;
}

}  // namespace loom
