#include "core/io/kbl_curve.hpp"

#include "core/bspline_ops.hpp"

#include <Eigen/Dense>

#include <array>
#include <mutex>
#include <stdexcept>
#include <string>

namespace loom {

namespace {

constexpr int kMaxKblDegree = 7;

/// Knots of the KBL convention: −p, −p + 1, …, n (n + p + 1 of them).
std::vector<double> uniform_knots(int p, std::size_t n) {
  std::vector<double> k(n + static_cast<std::size_t>(p) + 1);
  for (std::size_t i = 0; i < k.size(); ++i) k[i] = static_cast<double>(i) - p;
  return k;
}

/// For degree p: the matrix taking a uniform single-span curve's control points to the Bézier
/// points of that span, inverted (Bézier points → uniform control points). Its columns are
/// found by clamping the span of each basis function, so the same kernel as bezier_pieces.
const Eigen::MatrixXd& bezier_to_uniform(int p) {
  static std::array<Eigen::MatrixXd, kMaxKblDegree + 1> inverse;
  static std::array<std::once_flag, kMaxKblDegree + 1> once;
  std::call_once(once[static_cast<std::size_t>(p)], [p] {
    const int n = p + 1;
    Eigen::MatrixXd m(n, n);
    for (int j = 0; j < n; ++j) {
      std::vector<Vec3> e(static_cast<std::size_t>(n), Vec3::Zero());
      e[static_cast<std::size_t>(j)] = Vec3::UnitX();
      const auto pieces = bezier_pieces(Centerline(p, uniform_knots(p, e.size()), e));
      for (int i = 0; i < n; ++i) m(i, j) = pieces.front()[static_cast<std::size_t>(i)].x();
    }
    inverse[static_cast<std::size_t>(p)] = m.inverse();
  });
  return inverse[static_cast<std::size_t>(p)];
}

}  // namespace

Centerline kbl_uniform_curve(int degree, std::vector<Vec3> control_points) {
  if (degree < 1 || degree > kMaxKblDegree)
    throw std::invalid_argument("degree " + std::to_string(degree) + " is outside 1.." + std::to_string(kMaxKblDegree));
  if (control_points.size() < static_cast<std::size_t>(degree) + 1)
    throw std::invalid_argument("a degree-" + std::to_string(degree) + " curve needs at least " +
                                std::to_string(degree + 1) + " control points, found " +
                                std::to_string(control_points.size()));
  std::vector<double> knots = uniform_knots(degree, control_points.size());
  return Centerline(degree, std::move(knots), std::move(control_points));
}

std::vector<std::vector<Vec3>> kbl_uniform_spans(const Centerline& c) {
  const int p = c.degree();
  if (p < 1 || p > kMaxKblDegree) throw std::invalid_argument("kbl_uniform_spans: degree " + std::to_string(p));
  const Eigen::MatrixXd& inv = bezier_to_uniform(p);
  std::vector<std::vector<Vec3>> out;
  for (const auto& b : bezier_pieces(c)) {
    std::vector<Vec3> q(b.size(), Vec3::Zero());
    for (std::size_t i = 0; i < q.size(); ++i)
      for (std::size_t j = 0; j < b.size(); ++j)
        q[i] += inv(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) * b[j];
    out.push_back(std::move(q));
  }
  return out;
}

}  // namespace loom
