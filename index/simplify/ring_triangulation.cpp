#include "index/simplify/ring_triangulation.hpp"

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Constrained_triangulation_face_base_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_face_base_with_info_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>

#include <stdexcept>

namespace loom {
namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Vb = CGAL::Triangulation_vertex_base_with_info_2<int, K>;
using Fbb = CGAL::Triangulation_face_base_with_info_2<int, K>;
using Fb = CGAL::Constrained_triangulation_face_base_2<K, Fbb>;
using Tds = CGAL::Triangulation_data_structure_2<Vb, Fb>;
// Crossing constraints throw instead of inserting constructed points: the triangles must
// use the rings' own vertices, which the neighbouring faces share.
using Cdt = CGAL::Constrained_Delaunay_triangulation_2<K, Tds, CGAL::No_constraint_intersection_requiring_constructions_tag>;

/// Face info = nesting level: 0 outside every ring, +1 across each constraint.
void mark_nesting(Cdt& cdt) {
  for (auto f = cdt.all_faces_begin(); f != cdt.all_faces_end(); ++f) f->info() = -1;
  std::vector<Cdt::Face_handle> frontier{cdt.infinite_face()}, next;
  cdt.infinite_face()->info() = 0;
  for (int level = 0; !frontier.empty(); ++level) {
    // Flood the current level; faces across a constraint start the next one.
    while (!frontier.empty()) {
      const Cdt::Face_handle f = frontier.back();
      frontier.pop_back();
      for (int i = 0; i < 3; ++i) {
        const Cdt::Face_handle g = f->neighbor(i);
        if (g->info() != -1) continue;
        if (cdt.is_constrained(Cdt::Edge(f, i))) {
          next.push_back(g);
        } else {
          g->info() = level;
          frontier.push_back(g);
        }
      }
    }
    for (const auto& g : next)
      if (g->info() == -1) {
        g->info() = level + 1;
        frontier.push_back(g);
      }
    next.clear();
  }
}

}  // namespace

std::vector<std::array<int, 3>> triangulate_rings(const std::vector<Vec2>& points,
                                                  const std::vector<std::vector<int>>& rings) {
  Cdt cdt;
  std::vector<Cdt::Vertex_handle> handle(points.size());
  auto vertex = [&](int i) {
    auto& h = handle[static_cast<std::size_t>(i)];
    if (h == Cdt::Vertex_handle()) {
      const Vec2& q = points[static_cast<std::size_t>(i)];
      h = cdt.insert(K::Point_2(q.x(), q.y()));
      h->info() = i;
    }
    return h;
  };
  try {
    for (const auto& ring : rings)
      for (std::size_t k = 0; k < ring.size(); ++k) {
        const int a = ring[k], b = ring[(k + 1) % ring.size()];
        if (a != b) cdt.insert_constraint(vertex(a), vertex(b));
      }
  } catch (const Cdt::Intersection_of_constraints_exception&) {
    throw std::runtime_error("ring triangulation: two rings cross");
  }
  mark_nesting(cdt);
  std::vector<std::array<int, 3>> tris;
  for (auto f = cdt.finite_faces_begin(); f != cdt.finite_faces_end(); ++f)
    if (f->info() % 2 == 1) tris.push_back({f->vertex(0)->info(), f->vertex(1)->info(), f->vertex(2)->info()});
  return tris;
}

}  // namespace loom
