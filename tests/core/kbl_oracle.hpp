#pragma once
// An independent reading of KBL for the tests: the raw nodes, segments and centre curves
// of a file (pugixml, no loom code), and the uniform B-spline of the KBL convention evaluated
// by the Cox–de Boor recursion straight from its definition (knots −p, −p + 1, …, n).

#include "core/geometry.hpp"

#include <pugixml.hpp>

#include <cmath>
#include <cstdlib>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace loom::kbl_oracle {

/// N_{i,p}(u) over the uniform knots t_j = j − p (Cox–de Boor, recursive).
inline double basis(int i, int p, double u, int degree) {
  const double ti = i - degree, tip1 = i + 1 - degree;
  if (p == 0) return (u >= ti && u < tip1) ? 1.0 : 0.0;
  const double a = (u - ti) / p;                 // knots are 1 apart: t_{i+p} − t_i = p
  const double b = (i + p + 1 - degree - u) / p;  // (t_{i+p+1} − u) / (t_{i+p+1} − t_{i+1})
  return a * basis(i, p - 1, u, degree) + b * basis(i + 1, p - 1, u, degree);
}

/// One centre curve: degree and control points; lives on [0, n − p].
struct Curve {
  int degree = 0;
  std::vector<Vec3> cps;
  double u_max() const { return static_cast<double>(cps.size()) - degree; }
  Vec3 at(double u) const { return derivative(u, 0); }
  /// k-th derivative (k ≤ 2): for knots 1 apart N′_{i,p} = N_{i,p−1} − N_{i+1,p−1}, so
  /// N⁽ᵏ⁾_{i,p} = Σ_j (−1)^j C(k, j) N_{i+j,p−k}.
  Vec3 derivative(double u, int k) const {
    // At the right end the half-open basis is 0: evaluate a hair inside.
    if (u >= u_max()) u = u_max() * (1 - 1e-15);
    const double binom[3][3] = {{1, 0, 0}, {1, 1, 0}, {1, 2, 1}};
    Vec3 p = Vec3::Zero();
    if (k > degree) return p;
    for (int i = 0; i < static_cast<int>(cps.size()); ++i) {
      double w = 0;
      for (int j = 0; j <= k; ++j) w += (j % 2 ? -1 : 1) * binom[k][j] * basis(i + j, degree - k, u, degree);
      p += w * cps[static_cast<std::size_t>(i)];
    }
    return p;
  }
  /// Curvature |C′ × C″| / |C′|³.
  double curvature(double u) const {
    const Vec3 d1 = derivative(u, 1), d2 = derivative(u, 2);
    return d1.cross(d2).norm() / std::pow(d1.norm(), 3);
  }
};

struct Segment {
  std::string id, start, end;
  std::vector<Curve> curves;
  double virtual_length = -1;
  Vec3 start_vector = Vec3::Zero(), end_vector = Vec3::Zero();
};

struct File {
  std::map<std::string, Vec3> node;  ///< Node id → position
  std::vector<Segment> segments;
  int connections = 0;
};

inline std::vector<std::string> words(const char* s) {
  std::istringstream in(s);
  std::vector<std::string> out;
  for (std::string w; in >> w;) out.push_back(w);
  return out;
}

inline File read(const std::string& path) {
  pugi::xml_document doc;
  doc.load_file(path.c_str());
  const pugi::xml_node root = doc.document_element();
  std::map<std::string, Vec3> points;
  for (auto cp : root.children("Cartesian_point")) {
    std::vector<double> c;
    for (auto x : cp.children("Coordinates")) c.push_back(std::strtod(x.child_value(), nullptr));
    if (c.size() == 3) points[cp.attribute("id").value()] = Vec3(c[0], c[1], c[2]);
  }
  File f;
  for (auto n : root.children("Node")) f.node[n.attribute("id").value()] = points.at(words(n.child("Cartesian_point").child_value())[0]);
  for (auto s : root.children("Segment")) {
    Segment g;
    g.id = s.attribute("id").value();
    g.start = words(s.child("Start_node").child_value())[0];
    g.end = words(s.child("End_node").child_value())[0];
    int k = 0;
    for (auto v : s.children("Start_vector")) g.start_vector[k++] = std::strtod(v.child_value(), nullptr);
    k = 0;
    for (auto v : s.children("End_vector")) g.end_vector[k++] = std::strtod(v.child_value(), nullptr);
    if (auto vl = s.child("Virtual_length")) g.virtual_length = std::strtod(vl.child("Value_component").child_value(), nullptr);
    for (auto c : s.children("Center_curve")) {
      Curve cu;
      cu.degree = std::atoi(c.child("Degree").child_value());
      for (const auto& id : words(c.child("Control_points").child_value())) cu.cps.push_back(points.at(id));
      g.curves.push_back(cu);
    }
    f.segments.push_back(g);
  }
  if (auto h = root.child("Harness")) for (auto c : h.children("Connection")) { (void)c; ++f.connections; }
  return f;
}

/// Dense samples of a segment's curves, in order: (position, arc length from the start).
inline std::vector<std::pair<Vec3, double>> samples(const Segment& s, int per_curve) {
  std::vector<std::pair<Vec3, double>> out;
  double len = 0;
  for (const Curve& c : s.curves)
    for (int i = 0; i <= per_curve; ++i) {
      const Vec3 p = c.at(c.u_max() * i / per_curve);
      if (!out.empty()) len += (p - out.back().first).norm();
      out.emplace_back(p, len);
    }
  return out;
}

/// Distance from q to a polyline of samples, and the arc length there.
inline std::pair<double, double> closest(const std::vector<std::pair<Vec3, double>>& poly, const Vec3& q) {
  double best = 1e300, at = 0;
  for (std::size_t i = 0; i + 1 < poly.size(); ++i) {
    const Vec3 a = poly[i].first, b = poly[i + 1].first;
    const double l2 = (b - a).squaredNorm();
    const double t = l2 > 0 ? std::clamp((q - a).dot(b - a) / l2, 0.0, 1.0) : 0.0;
    const double d = (a + t * (b - a) - q).norm();
    if (d < best) best = d, at = poly[i].second + t * (poly[i + 1].second - poly[i].second);
  }
  return {best, at};
}

}  // namespace loom::kbl_oracle
