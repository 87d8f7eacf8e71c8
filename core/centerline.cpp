// Non-uniform B-spline centerlines: interpolation (seed: cable-bspline-interpolation-and-
// fairing §II), evaluation by basis-function derivatives (Piegl & Tiller A2.3), arc length
// by Gauss–Legendre quadrature per knot span, curvature and bend radius.
#include "core/centerline.hpp"
#include "core/gauss_legendre.hpp"

#include "core/error.hpp"

#include <Eigen/Sparse>
#include <Eigen/LU>
#include <Eigen/SparseLU>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace loom {

namespace {

/// Highest degree the fixed-size evaluation buffers support.
constexpr int kMaxDegree = 7;
/// Interpolation systems up to this many unknowns are solved densely (Eigen LU), larger
/// ones as sparse tridiagonal systems (Eigen SparseLU).
constexpr int kDenseSolveMax = 48;
/// Highest derivative order evaluate() returns.
constexpr int kMaxDerivative = 3;
/// Points closer than this fraction of the key-point bounding-box diagonal are the same
/// key point (merged before interpolation).
constexpr double kDuplicateRelTol = 1e-12;
/// Relative accuracy target of the arc-length quadrature.
constexpr double kArcLengthRelTol = 1e-13;
/// Deepest bisection of one knot span in the adaptive arc-length quadrature.
constexpr int kArcLengthMaxDepth = 14;
/// |C'| below this fraction of the curve's typical speed counts as a stationary point
/// (curvature reported as 0 there).
constexpr double kStationaryRelSpeed = 1e-12;
/// C'' within this sine of C' (rounding of a straight run) counts as straight: κ = 0.
constexpr double kStraightRelSine = 1e-12;
/// Samples per knot span in the dense search of the bend-radius minimum.
constexpr int kBendSamplesPerSpan = 64;
/// A tangent direction change across a knot larger than this (radians) is a kink.
constexpr double kKinkAngle = 1e-9;
/// Tangent turn between two dense bend-search samples that triggers a search for a fold.
constexpr double kFoldSampleAngle = 0.25 * M_PI;
/// A tangent turn that survives bisection down to the parameter resolution is a fold.
constexpr double kFoldAngle = 0.5 * M_PI;

/// Binomial coefficient C(n, k) for the small n of a curve's degree.
double binomial(int n, int k) {
  double c = 1.0;
  for (int i = 1; i <= k; ++i) c = c * (n - k + i) / i;
  return c;
}

constexpr const auto& kGLx = gauss_legendre8::kNodes;
constexpr const auto& kGLw = gauss_legendre8::kWeights;

/// ders[k][j] = k-th derivative of N_{span-p+j,p} at u, k = 0..nd (Piegl & Tiller A2.3).
void basis_derivatives(const double* U, int span, double u, int p, int nd,
                       double ders[kMaxDegree + 1][kMaxDegree + 1]) {
  double ndu[kMaxDegree + 1][kMaxDegree + 1];
  double left[kMaxDegree + 1], right[kMaxDegree + 1];
  ndu[0][0] = 1.0;
  for (int j = 1; j <= p; ++j) {
    left[j] = u - U[span + 1 - j];
    right[j] = U[span + j] - u;
    double saved = 0.0;
    for (int r = 0; r < j; ++r) {
      ndu[j][r] = right[r + 1] + left[j - r];
      const double temp = ndu[r][j - 1] / ndu[j][r];
      ndu[r][j] = saved + right[r + 1] * temp;
      saved = left[j - r] * temp;
    }
    ndu[j][j] = saved;
  }
  for (int j = 0; j <= p; ++j) ders[0][j] = ndu[j][p];
  double a[2][kMaxDegree + 1];
  for (int r = 0; r <= p; ++r) {
    int s1 = 0, s2 = 1;
    a[0][0] = 1.0;
    for (int k = 1; k <= nd; ++k) {
      double d = 0.0;
      const int rk = r - k, pk = p - k;
      if (r >= k) {
        a[s2][0] = a[s1][0] / ndu[pk + 1][rk];
        d = a[s2][0] * ndu[rk][pk];
      }
      const int j1 = rk >= -1 ? 1 : -rk;
      const int j2 = (r - 1 <= pk) ? k - 1 : p - r;
      for (int j = j1; j <= j2; ++j) {
        a[s2][j] = (a[s1][j] - a[s1][j - 1]) / ndu[pk + 1][rk + j];
        d += a[s2][j] * ndu[rk + j][pk];
      }
      if (r <= pk) {
        a[s2][k] = -a[s1][k - 1] / ndu[pk + 1][r];
        d += a[s2][k] * ndu[r][pk];
      }
      ders[k][r] = d;
      std::swap(s1, s2);
    }
  }
  double f = p;
  for (int k = 1; k <= nd; ++k) {
    for (int j = 0; j <= p; ++j) ders[k][j] *= f;
    f *= (p - k);
  }
}

}  // namespace

int bspline_basis(const std::vector<double>& knots, int degree, double u, int nder, double* ders) {
  if (degree < 1 || degree > kMaxDegree)
    throw std::invalid_argument("bspline_basis: degree " + std::to_string(degree) + " is outside 1..7");
  const int nb = static_cast<int>(knots.size()) - degree - 1;  // number of basis functions
  if (nb < degree + 1) throw std::invalid_argument("bspline_basis: too few knots for the degree");
  const double lo = knots[degree], hi = knots[nb];
  if (!(lo < hi)) throw std::invalid_argument("bspline_basis: empty knot domain");
  u = std::clamp(u, lo, hi);
  const auto first = knots.begin() + degree, last = knots.begin() + nb;
  int span = static_cast<int>(std::upper_bound(first, last, u) - knots.begin()) - 1;
  span = std::clamp(span, degree, nb - 1);
  while (span > degree && !(knots[span] < knots[span + 1])) --span;
  double d[kMaxDegree + 1][kMaxDegree + 1];
  const int nd = std::clamp(nder, 0, degree);
  basis_derivatives(knots.data(), span, u, degree, nd, d);
  for (int k = 0; k <= std::max(nder, 0); ++k)
    for (int j = 0; j <= degree; ++j) ders[k * (degree + 1) + j] = k <= nd ? d[k][j] : 0.0;
  return span - degree;
}

// ---------------------------------------------------------------------------------------
// Construction

Centerline::Centerline(int degree, std::vector<double> knots, std::vector<Vec3> control_points)
    : degree_(degree), knots_(std::move(knots)), cps_(std::move(control_points)) {
  if (degree_ < 1 || degree_ > kMaxDegree)
    throw std::invalid_argument("Centerline: degree " + std::to_string(degree_) + " is outside 1.." +
                                std::to_string(kMaxDegree));
  if (cps_.size() < static_cast<std::size_t>(degree_) + 1)
    throw std::invalid_argument("Centerline: " + std::to_string(cps_.size()) +
                                " control points are too few for degree " + std::to_string(degree_));
  if (knots_.size() != cps_.size() + degree_ + 1)
    throw std::invalid_argument("Centerline: " + std::to_string(knots_.size()) + " knots for " +
                                std::to_string(cps_.size()) + " control points of degree " +
                                std::to_string(degree_) + " (need control points + degree + 1)");
  for (std::size_t i = 0; i < knots_.size(); ++i) {
    if (!std::isfinite(knots_[i]))
      throw std::invalid_argument("Centerline: knot " + std::to_string(i) + " is not finite");
    if (i > 0 && knots_[i] < knots_[i - 1])
      throw std::invalid_argument("Centerline: knots decrease at index " + std::to_string(i));
  }
  for (std::size_t i = 0; i < cps_.size(); ++i)
    if (!is_finite(cps_[i]))
      throw std::invalid_argument("Centerline: control point " + std::to_string(i) + " is not finite " +
                                  full_precision(cps_[i]));
  if (!(u_min() < u_max())) throw std::invalid_argument("Centerline: the knot vector spans an empty domain");
  build_length_table();
}

namespace {

/// Key points with consecutive duplicates merged; `index_of[i]` maps input i to its merged point.
struct MergedPoints {
  std::vector<Vec3> pts;
  std::vector<int> index_of;
};

MergedPoints merge_points(const std::vector<Vec3>& points, const char* who) {
  if (points.empty()) throw std::invalid_argument(std::string(who) + ": no key points");
  AABB box;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!is_finite(points[i]))
      throw std::invalid_argument(std::string(who) + ": key point " + std::to_string(i) + " is not finite " +
                                  full_precision(points[i]));
    box.extend(points[i]);
  }
  const double tol = kDuplicateRelTol * box.diagonal();
  MergedPoints m;
  m.index_of.reserve(points.size());
  for (const Vec3& p : points) {
    if (m.pts.empty() || (p - m.pts.back()).norm() > tol) m.pts.push_back(p);
    m.index_of.push_back(static_cast<int>(m.pts.size()) - 1);
  }
  if (m.pts.size() < 2)
    throw std::invalid_argument(std::string(who) + ": need at least 2 distinct key points, got " +
                                std::to_string(m.pts.size()) + " (all " + std::to_string(points.size()) +
                                " points coincide)");
  return m;
}

/// Parameters of the merged key points in [0, total chord length].
std::vector<double> key_parameters_for(const std::vector<Vec3>& pts, KnotMethod method) {
  const std::size_t n = pts.size() - 1;
  std::vector<double> chord(n);
  double total = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    chord[i] = (pts[i + 1] - pts[i]).norm();
    total += chord[i];
  }
  std::vector<double> span(n);
  if (method == KnotMethod::ChordLength) {
    span = chord;
  } else {
    // Hartley–Judd (seed eq. 1): each span's length is proportional to the sum of the k = 3
    // polygon sides around it. The control polygon is not known before the solve, so the
    // data polygon stands in for it, with its end sides reflected (l_0 := l_1, l_{n+1} := l_n).
    for (std::size_t i = 0; i < n; ++i) {
      const double prev = i > 0 ? chord[i - 1] : chord[0];
      const double next = i + 1 < n ? chord[i + 1] : chord[n - 1];
      span[i] = prev + chord[i] + next;
    }
  }
  double span_total = 0.0;
  for (double s : span) span_total += s;
  std::vector<double> u(n + 1, 0.0);
  for (std::size_t i = 0; i < n; ++i) u[i + 1] = u[i] + span[i] * (total / span_total);
  u[n] = total;  // exact end, no rounding drift
  return u;
}

Vec3 unit_tangent(const Vec3& t, const char* which) {
  if (!is_finite(t)) throw std::invalid_argument(std::string("Centerline::interpolate: ") + which +
                                                 " tangent is not finite " + full_precision(t));
  const double n = t.norm();
  if (!(n > 0.0))
    throw std::invalid_argument(std::string("Centerline::interpolate: ") + which + " tangent is zero");
  return t / n;
}

}  // namespace

Centerline Centerline::interpolate(const std::vector<Vec3>& points, const InterpolationOptions& opt) {
  return interpolate(points, std::vector<double>{}, opt);
}

Centerline Centerline::interpolate(const std::vector<Vec3>& points, const std::vector<double>& parameters,
                                   const InterpolationOptions& opt) {
  const MergedPoints m = merge_points(points, "Centerline::interpolate");
  std::optional<Vec3> t0, t1;
  if (opt.start_tangent) t0 = unit_tangent(*opt.start_tangent, "start");
  if (opt.end_tangent) t1 = unit_tangent(*opt.end_tangent, "end");

  const std::vector<Vec3>& P = m.pts;
  const int n = static_cast<int>(P.size()) - 1;  // last key-point index
  std::vector<double> ub;
  if (parameters.empty()) {
    ub = key_parameters_for(P, opt.knots);
  } else {
    if (parameters.size() != points.size())
      throw std::invalid_argument("Centerline::interpolate: " + std::to_string(parameters.size()) +
                                  " parameters for " + std::to_string(points.size()) + " key points");
    ub.assign(P.size(), 0.0);
    for (std::size_t i = points.size(); i-- > 0;) ub[m.index_of[i]] = parameters[i];  // first of each group
    for (std::size_t i = 0; i < ub.size(); ++i) {
      if (!std::isfinite(ub[i]))
        throw std::invalid_argument("Centerline::interpolate: parameter " + std::to_string(i) + " is not finite");
      if (i > 0 && !(ub[i] > ub[i - 1]))
        throw std::invalid_argument("Centerline::interpolate: parameters do not increase at key point " +
                                    std::to_string(i));
    }
  }
  const int p = 3;
  const int ncp = n + 3;  // control points d_0 .. d_{n+2}

  // Clamped knots: 4× ū_0, interior ū_1..ū_{n-1}, 4× ū_n.
  std::vector<double> U;
  U.reserve(ncp + p + 1);
  for (int i = 0; i < 4; ++i) U.push_back(ub[0]);
  for (int i = 1; i < n; ++i) U.push_back(ub[i]);
  for (int i = 0; i < 4; ++i) U.push_back(ub[n]);

  // Tangent magnitude: the chord-derived speed |C'| of a chord-length parameterisation
  // (total chord / parameter range); with parameters in chord units it is 1.
  double chord = 0.0;
  for (int i = 0; i < n; ++i) chord += (P[i + 1] - P[i]).norm();
  const double speed = chord / (ub[n] - ub[0]);

  // Unknowns d_1..d_{n+1} (n+1 of them); d_0 = P_0 and d_{n+2} = P_n are fixed.
  const int nu = n + 1;
  Eigen::SparseMatrix<double> A(nu, nu);
  std::vector<Eigen::Triplet<double>> trip;
  trip.reserve(3 * nu);
  Eigen::MatrixX3d rhs = Eigen::MatrixX3d::Zero(nu, 3);
  double ders[kMaxDegree + 1][kMaxDegree + 1];

  auto add_row = [&](int row, int span, int order, const Vec3& value) {
    // Row: Σ_j N^{(order)}_{span-3+j}(u) d_{span-3+j} = value; known d_0 / d_{n+2} go right.
    Vec3 r = value;
    for (int j = 0; j <= p; ++j) {
      const int cp = span - p + j;
      const double c = ders[order][j];
      if (c == 0.0) continue;
      if (cp == 0)
        r -= c * P[0];
      else if (cp == ncp - 1)
        r -= c * P[n];
      else
        trip.emplace_back(row, cp - 1, c);
    }
    rhs.row(row) = r.transpose();
  };

  // Start condition: C'(ū_0) = speed·t0, or natural C''(ū_0) = 0.
  {
    const int span = p;
    basis_derivatives(U.data(), span, ub[0], p, 2, ders);
    if (t0)
      add_row(0, span, 1, speed * *t0);
    else
      add_row(0, span, 2, Vec3::Zero());
  }
  // Interior interpolation conditions C(ū_k) = P_k.
  for (int k = 1; k < n; ++k) {
    const int span = p + k;  // U[span] = ū_k
    basis_derivatives(U.data(), span, ub[k], p, 0, ders);
    add_row(k, span, 0, P[k]);
  }
  // End condition.
  {
    const int span = ncp - 1;
    basis_derivatives(U.data(), span, ub[n], p, 2, ders);
    if (t1)
      add_row(n, span, 1, speed * *t1);
    else
      add_row(n, span, 2, Vec3::Zero());
  }
  Eigen::MatrixX3d D;
  if (nu <= kDenseSolveMax) {
    // Small systems: a dense LU with partial pivoting is faster than the sparse machinery.
    Eigen::MatrixXd Ad = Eigen::MatrixXd::Zero(nu, nu);
    for (const auto& t : trip) Ad(t.row(), t.col()) += t.value();
    const Eigen::PartialPivLU<Eigen::MatrixXd> lu(Ad);
    if (!(std::abs(lu.determinant()) > 0.0))
      throw std::invalid_argument("Centerline::interpolate: the interpolation system is singular");
    D = lu.solve(rhs);
  } else {
    A.setFromTriplets(trip.begin(), trip.end());
    A.makeCompressed();
    Eigen::SparseLU<Eigen::SparseMatrix<double>, Eigen::NaturalOrdering<int>> lu;
    lu.compute(A);
    if (lu.info() != Eigen::Success)
      throw std::invalid_argument("Centerline::interpolate: the interpolation system is singular (" +
                                  lu.lastErrorMessage() + ")");
    D = lu.solve(rhs);
  }

  std::vector<Vec3> cps(ncp);
  cps[0] = P[0];
  cps[ncp - 1] = P[n];
  for (int i = 0; i < nu; ++i) cps[i + 1] = D.row(i).transpose();
  for (std::size_t i = 0; i < cps.size(); ++i)
    if (!is_finite(cps[i]))
      throw std::invalid_argument("Centerline::interpolate: the solve produced a non-finite control point "
                                  "(key points too close relative to their spread)");

  Centerline c(p, std::move(U), std::move(cps));
  c.key_params_.resize(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) c.key_params_[i] = ub[m.index_of[i]];
  return c;
}

Centerline Centerline::polyline(const std::vector<Vec3>& points) {
  const MergedPoints m = merge_points(points, "Centerline::polyline");
  const std::vector<double> ub = key_parameters_for(m.pts, KnotMethod::ChordLength);
  std::vector<double> U;
  U.reserve(ub.size() + 2);
  U.push_back(ub.front());
  for (double u : ub) U.push_back(u);
  U.push_back(ub.back());
  Centerline c(1, std::move(U), m.pts);
  c.key_params_.resize(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) c.key_params_[i] = ub[m.index_of[i]];
  return c;
}

void Centerline::set_key_parameters(std::vector<double> u) {
  for (std::size_t i = 0; i < u.size(); ++i) {
    if (!(u[i] >= u_min() && u[i] <= u_max()))
      throw std::invalid_argument("Centerline::set_key_parameters: parameter " + std::to_string(i) +
                                  " is outside the curve's domain");
    if (i > 0 && u[i] < u[i - 1])
      throw std::invalid_argument("Centerline::set_key_parameters: parameters decrease at " + std::to_string(i));
  }
  key_params_ = std::move(u);
}

// ---------------------------------------------------------------------------------------
// Evaluation

int Centerline::find_span(double u) const {
  const int n = static_cast<int>(cps_.size()) - 1;
  const auto first = knots_.begin() + degree_;
  const auto last = knots_.begin() + n + 1;
  int span = static_cast<int>(std::upper_bound(first, last, u) - knots_.begin()) - 1;
  return std::clamp(span, degree_, n);
}


std::size_t Centerline::piece_of(double u, bool left_limit) const {
  const std::size_t K = span_index_.size();
  const auto it = left_limit ? std::lower_bound(span_u_.begin() + 1, span_u_.end() - 1, u)
                             : std::upper_bound(span_u_.begin() + 1, span_u_.end() - 1, u);
  return std::min<std::size_t>(static_cast<std::size_t>(it - span_u_.begin()) - 1, K - 1);
}

void Centerline::evaluate(double u, int nder, Vec3* out, bool left_limit) const {
  if (cps_.empty()) throw std::logic_error("Centerline: evaluating an empty curve");
  nder = std::clamp(nder, 0, kMaxDerivative);
  u = std::clamp(u, u_min(), u_max());
  evaluate_on_span(static_cast<int>(piece_of(u, left_limit)), u, nder, out);
}

void Centerline::evaluate_on_span(int piece, double u, int nder, Vec3* out) const {
  // Horner on the piece's Taylor coefficients c_j = C⁽ʲ⁾(a)/j! about its start a.
  const int p = degree_;
  const Vec3* c = &poly_[static_cast<std::size_t>(piece) * (p + 1)];
  const double t = u - span_u_[piece];
  if (p == 3) {
    // The cubic case unrolled: the same operations in the same order as the general loop
    // below (so the same results), without its loop and factorial bookkeeping.
    out[0] = ((c[3] * t + c[2]) * t + c[1]) * t + c[0];
    if (nder >= 1) out[1] = ((3.0 * c[3]) * t + 2.0 * c[2]) * t + c[1];
    if (nder >= 2) out[2] = (6.0 * c[3]) * t + 2.0 * c[2];
    if (nder >= 3) out[3] = 6.0 * c[3];
    return;
  }
  for (int k = 0; k <= nder; ++k) {
    if (k > p) {
      out[k] = Vec3::Zero();
      continue;
    }
    // d^k/dt^k Σ c_j t^j = Σ_{j≥k} j!/(j−k)! c_j t^{j−k}
    Vec3 v = Vec3::Zero();
    for (int j = p; j >= k; --j) {
      double f = 1.0;
      for (int q = 0; q < k; ++q) f *= (j - q);
      v = v * t + f * c[j];
    }
    out[k] = v;
  }
}

Vec3 Centerline::position(double u) const {
  Vec3 out[1];
  evaluate(u, 0, out);
  return out[0];
}

Vec3 Centerline::derivative(double u, int k) const {
  if (k < 0 || k > kMaxDerivative)
    throw std::invalid_argument("Centerline::derivative: order " + std::to_string(k) + " is outside 0..3");
  Vec3 out[kMaxDerivative + 1];
  evaluate(u, k, out);
  return out[k];
}

double Centerline::curvature_from(const Vec3& d1, const Vec3& d2) const {
  const double speed = d1.norm();
  if (!(speed > kStationaryRelSpeed * typical_speed_)) return 0.0;
  const double cross = d1.cross(d2).norm();
  if (cross <= kStraightRelSine * speed * d2.norm()) return 0.0;  // C'' ∥ C' up to rounding
  const double kappa = cross / (speed * speed * speed);
  return kappa * scale_length_ <= kStraightRelSine ? 0.0 : kappa;  // bend radius ≫ the curve
}

double Centerline::curvature(double u) const {
  Vec3 d[3];
  evaluate(u, 2, d);
  return curvature_from(d[1], d[2]);
}

std::vector<Vec3> Centerline::hull_points(double a, double b) const {
  std::vector<Vec3> out;
  if (cps_.empty()) return out;
  a = std::clamp(a, u_min(), u_max());
  b = std::clamp(b, u_min(), u_max());
  if (a > b) std::swap(a, b);
  // Breakpoint intervals holding a and b (b at an interval's left end belongs to the one
  // before: the piece ends there).
  const std::size_t last = span_index_.size() - 1;
  std::size_t ka = std::upper_bound(span_u_.begin(), span_u_.end(), a) - span_u_.begin();
  std::size_t kb = std::lower_bound(span_u_.begin(), span_u_.end(), b) - span_u_.begin();
  ka = std::min(ka == 0 ? 0 : ka - 1, last);
  kb = std::max(std::min(kb == 0 ? 0 : kb - 1, last), ka);
  const int p = degree_;
  out.reserve((kb - ka + 1) * static_cast<std::size_t>(p + 1));
  for (std::size_t k = ka; k <= kb; ++k) {
    if (p > kMaxDerivative) {  // no derivatives that high: the span's control points
      for (int q = span_index_[k] - p; q <= span_index_[k]; ++q) out.push_back(cps_[static_cast<std::size_t>(q)]);
      continue;
    }
    // Bézier points of the piece [s, t] of interval k, from the derivatives at s:
    // B_j = Σ_{i ≤ j} C(j,i)/C(p,i) · hⁱ/i! · C⁽ⁱ⁾(s). Unlike the B-spline's control
    // points, which reach about an interval beyond, they end exactly at C(s) and C(t).
    const double s0 = k == ka ? a : span_u_[k], t0 = k == kb ? b : span_u_[k + 1];
    Vec3 d[kMaxDerivative + 1];
    evaluate_on_span(static_cast<int>(k), s0, p, d);
    const double h = t0 - s0;
    for (int j = 0; j <= p; ++j) {
      Vec3 bj = Vec3::Zero();
      double term = 1.0;  // hⁱ / i!
      for (int i = 0; i <= j; ++i) {
        if (i > 0) term *= h / i;
        bj += binomial(j, i) / binomial(p, i) * term * d[i];
      }
      out.push_back(bj);
    }
  }
  return out;
}

Centerline::HullBounds Centerline::hull_bounds(double a, double b) const {
  HullBounds out;
  if (cps_.empty()) return out;
  const Vec3 pa = position(std::min(a, b)), pb = position(std::max(a, b));
  const std::vector<Vec3> h = hull_points(a, b);
  double worst2 = 0.0;
  for (const Vec3& q : h) worst2 = std::max(worst2, point_segment_dist2(q, pa, pb));
  out.deviation = std::sqrt(worst2);
  const Vec3 chord = pb - pa;
  const double len = chord.norm();
  if (!(len > 0.0)) return out;  // turn_sine stays 1: no direction to compare with
  const Vec3 dir = chord / len;
  const std::size_t stride = static_cast<std::size_t>(degree_ + 1);
  double worst = 0.0;
  for (std::size_t q = 0; q + 1 < h.size(); ++q) {
    if ((q + 1) % stride == 0) continue;  // the next span's points start here
    // On each span C' is a Bézier curve whose control points are positive multiples of
    // these differences; a zero difference adds nothing to their hull.
    const Vec3 d = h[q + 1] - h[q];
    const double n = d.norm();
    if (!(n > 0.0)) continue;
    if (!(d.dot(dir) > 0.0)) return out;  // C' may turn against the chord: turn_sine 1
    worst = std::max(worst, d.cross(dir).norm() / n);
  }
  out.turn_sine = worst;
  return out;
}

// ---------------------------------------------------------------------------------------
// Arc length

namespace {

template <class Speed>
double gauss8(const Speed& speed, double a, double b) {
  const double h = 0.5 * (b - a), c = 0.5 * (a + b);
  double s = 0.0;
  for (int i = 0; i < 8; ++i) s += kGLw[i] * speed(c + h * kGLx[i]);
  return s * h;
}

template <class Speed>
double adaptive_length(const Speed& speed, double a, double b, double whole, double abs_tol, int depth) {
  const double m = 0.5 * (a + b);
  const double l = gauss8(speed, a, m), r = gauss8(speed, m, b);
  if (depth >= kArcLengthMaxDepth || std::abs(l + r - whole) <= abs_tol) return l + r;
  return adaptive_length(speed, a, m, l, 0.5 * abs_tol, depth + 1) +
         adaptive_length(speed, m, b, r, 0.5 * abs_tol, depth + 1);
}

}  // namespace

double Centerline::span_length(int piece, double a, double b) const {
  if (!(b > a)) return 0.0;
  auto speed = [&](double u) {
    Vec3 d[2];
    evaluate_on_span(piece, u, 1, d);
    return d[1].norm();
  };
  const double whole = gauss8(speed, a, b);
  // Tolerance relative to the larger of this piece's scale and the whole curve's (never
  // zero). Why the curve's: a piece a micrometre long on a metre-long cable (key points
  // from a dense export) need not be resolved to 1e-13 of itself; near a cusp of a wiggly
  // piece that took the bisection to its deepest level at every call (seconds per cable).
  const double chord = (position(b) - position(a)).norm();
  const double tol = kArcLengthRelTol * std::max({whole, chord, scale_length_, 1e-300});
  return adaptive_length(speed, a, b, whole, tol, 0);
}

void Centerline::build_length_table() {
  span_u_.clear();
  span_len_.reset();
  span_index_.clear();
  const int n = static_cast<int>(cps_.size()) - 1;
  // Typical speed: control-polygon length over the parameter range.
  double poly = 0.0;
  for (std::size_t i = 1; i < cps_.size(); ++i) poly += (cps_[i] - cps_[i - 1]).norm();
  typical_speed_ = poly / (u_max() - u_min());
  scale_length_ = poly;
  if (!(typical_speed_ > 0.0)) typical_speed_ = 1.0;
  span_u_.push_back(u_min());
  poly_.clear();
  for (int i = degree_; i <= n; ++i) {
    if (!(knots_[i] < knots_[i + 1])) continue;
    span_index_.push_back(i);
    span_u_.push_back(knots_[i + 1]);
  }
  // Taylor coefficients of each polynomial piece about its start.
  const int p = degree_;
  poly_.assign(span_index_.size() * (p + 1), Vec3::Zero());
  double ders[kMaxDegree + 1][kMaxDegree + 1];
  for (std::size_t k = 0; k < span_index_.size(); ++k) {
    const int i = span_index_[k];
    basis_derivatives(knots_.data(), i, span_u_[k], p, p, ders);
    double fact = 1.0;
    for (int j = 0; j <= p; ++j) {
      if (j > 1) fact *= j;
      Vec3 v = Vec3::Zero();
      for (int r = 0; r <= p; ++r) v += ders[j][r] * cps_[i - p + r];
      poly_[k * (p + 1) + j] = v / fact;
    }
  }
}

std::vector<double> Centerline::build_lengths() const {
  std::vector<double> len;
  len.reserve(span_index_.size() + 1);
  len.push_back(0.0);
  for (std::size_t k = 0; k < span_index_.size(); ++k)
    len.push_back(len.back() + span_length(static_cast<int>(k), span_u_[k], span_u_[k + 1]));
  return len;
}

const std::vector<double>& Centerline::lengths() const {
  return span_len_.get([this] { return build_lengths(); });
}

double Centerline::length() const { return cps_.empty() ? 0.0 : lengths().back(); }

double Centerline::arc_length_at(double u) const {
  if (cps_.empty()) return 0.0;
  if (u <= u_min()) return 0.0;
  if (u >= u_max()) return length();
  const std::size_t k = std::upper_bound(span_u_.begin(), span_u_.end(), u) - span_u_.begin() - 1;
  return lengths()[k] + span_length(static_cast<int>(k), span_u_[k], u);
}

double Centerline::solve_length_in_span(std::size_t k, double u0, double s0, double target) const {
  // Find u in [span_u_[k], span_u_[k+1]] with s(u) = target, starting from the known
  // (u0, s0) in that span: safeguarded Newton on s(u) − target with bisection bracketing.
  const int span = static_cast<int>(k);
  double lo = span_u_[k], hi = span_u_[k + 1];
  const std::vector<double>& span_len = lengths();
  double s_lo = span_len[k], s_hi = span_len[k + 1];
  if (target <= s_lo) return lo;
  if (target >= s_hi) return hi;
  // Start from linear interpolation if the anchor is not informative.
  double u = u0, s = s0;
  if (!(u0 >= lo && u0 <= hi)) {
    u = lo;
    s = s_lo;
  }
  const double tol = kArcLengthRelTol * std::max(length(), 1e-300) * 10.0;
  for (int it = 0; it < 60; ++it) {
    if (s < target) {
      lo = std::max(lo, u);
      s_lo = s;
    } else {
      hi = std::min(hi, u);
      s_hi = s;
    }
    if (std::abs(s - target) <= tol) return u;
    Vec3 d[2];
    evaluate_on_span(span, u, 1, d);
    const double v = d[1].norm();
    double un = v > 0.0 ? u + (target - s) / v : 0.5 * (lo + hi);
    if (!(un > lo && un < hi)) un = lo + (hi - lo) * std::clamp((target - s_lo) / (s_hi - s_lo), 0.05, 0.95);
    s = un >= u ? s + span_length(span, u, un) : s - span_length(span, un, u);
    u = un;
    if (hi - lo <= 1e-15 * std::max(std::abs(hi), 1.0)) return u;
  }
  return u;
}

double Centerline::parameter_at_length(double s) const {
  if (cps_.empty()) return 0.0;
  if (!(s > 0.0)) return u_min();  // also maps NaN to the start
  if (s >= length()) return u_max();
  const std::vector<double>& span_len = lengths();
  const std::size_t k = std::upper_bound(span_len.begin(), span_len.end(), s) - span_len.begin() - 1;
  const std::size_t kk = std::min(k, span_index_.size() - 1);
  return solve_length_in_span(kk, span_u_[kk], span_len[kk], s);
}

std::vector<std::pair<double, Vec3>> Centerline::sample_by_arc_length(double spacing) const {
  std::vector<std::pair<double, Vec3>> out;
  if (cps_.empty()) return out;
  if (!(spacing > 0.0) || !std::isfinite(spacing))
    throw std::invalid_argument("Centerline::sample_by_arc_length: spacing must be positive and finite");
  const double L = length();
  const double count = std::ceil(L / spacing);
  if (count > kMaxArcSamples)
    throw std::invalid_argument("Centerline::sample_by_arc_length: spacing " + full_precision(spacing) +
                                " gives more than " + full_precision(kMaxArcSamples) +
                                " samples on a curve of length " + full_precision(L));
  const std::size_t n = std::max<std::size_t>(1, static_cast<std::size_t>(count));
  const double step = L / static_cast<double>(n);
  out.reserve(n + 1);
  out.emplace_back(0.0, position(u_min()));
  const std::vector<double>& span_len = lengths();
  std::size_t k = 0;
  double u = u_min(), s_at_u = 0.0;
  for (std::size_t i = 1; i < n; ++i) {
    const double target = step * static_cast<double>(i);
    while (k + 1 < span_index_.size() && target >= span_len[k + 1]) {
      ++k;
      u = span_u_[k];
      s_at_u = span_len[k];
    }
    u = solve_length_in_span(k, u, s_at_u, target);
    s_at_u = target;
    out.emplace_back(target, position(u));
  }
  out.emplace_back(L, position(u_max()));
  return out;
}


// ---------------------------------------------------------------------------------------
// Bend radius

namespace {
/// Turning angle between two vectors in [0, π] (0 if either is zero), robust near 0 and π.
double angle_between(const Vec3& a, const Vec3& b) { return std::atan2(a.cross(b).norm(), a.dot(b)); }
}  // namespace

double Centerline::locate_fold(double a, double b) const {
  // Keep the half over which the tangent turns more; a fold keeps a turn > kFoldAngle
  // over an interval that shrinks to the parameter resolution.
  auto tangent = [&](double u) {
    Vec3 d[2];
    evaluate(u, 1, d);
    return d[1];
  };
  Vec3 ta = tangent(a), tb = tangent(b);
  for (int it = 0; it < 200 && b - a > 4.0 * std::numeric_limits<double>::epsilon() * std::max(1.0, std::abs(b));
       ++it) {
    const double m = 0.5 * (a + b);
    const Vec3 tm = tangent(m);
    if (!(tm.norm() > kStationaryRelSpeed * typical_speed_)) return m;  // C' = 0 between opposed tangents
    if (angle_between(ta, tm) >= angle_between(tm, tb)) {
      b = m;
      tb = tm;
    } else {
      a = m;
      ta = tm;
    }
    if (angle_between(ta, tb) < kFoldAngle) return std::numeric_limits<double>::quiet_NaN();
  }
  return 0.5 * (a + b);
}

std::vector<Centerline::BendPoint> Centerline::bend_profile() const {
  std::vector<BendPoint> out;
  if (cps_.empty()) return out;
  const double inf = std::numeric_limits<double>::infinity();
  // Kinks: tangent direction jumps across interior knots (possible for degree 1 or with
  // multiple knots) have zero bend radius.
  for (std::size_t k = 1; k + 1 < span_u_.size(); ++k) {
    const double u = span_u_[k];
    Vec3 l[2], r[2];
    evaluate(u, 1, l, true);
    evaluate(u, 1, r, false);
    if (l[1].norm() > 0.0 && r[1].norm() > 0.0 && angle_between(l[1], r[1]) > kKinkAngle)
      out.push_back({u, inf, BendPoint::Kink});
  }
  const std::size_t kinks = out.size();  // out[0, kinks): the kinks, in u order
  Vec3 t_prev = Vec3::Zero();  // last non-zero tangent of the dense search, and its u
  double u_prev = u_min();
  for (std::size_t k = 0; k < span_index_.size(); ++k) {
    const int span = static_cast<int>(k);
    const double a = span_u_[k], b = span_u_[k + 1];
    auto kappa = [&](double u) {
      Vec3 d[3];
      evaluate_on_span(span, u, 2, d);
      return curvature_from(d[1], d[2]);
    };
    const int N = degree_ == 1 ? 1 : kBendSamplesPerSpan;
    double samples[kBendSamplesPerSpan + 1];
    for (int i = 0; i <= N; ++i) {
      const double ui = a + (b - a) * i / N;
      Vec3 d[3];
      evaluate_on_span(span, ui, 2, d);
      samples[i] = curvature_from(d[1], d[2]);
      out.push_back({ui, samples[i], BendPoint::Sample});
      // A fold (cusp, C' = 0 with the tangent reversing) has zero bend radius but no finite
      // curvature sample shows it: look for a large tangent turn between samples and
      // bisect it down to a point.
      if (!(d[1].norm() > kStationaryRelSpeed * typical_speed_)) continue;  // no direction here
      // A kink between the two samples turns the tangent too: it is that kink, not a fold.
      if (t_prev.norm() > 0.0 && angle_between(t_prev, d[1]) > kFoldSampleAngle &&
          std::none_of(out.begin(), out.begin() + static_cast<std::ptrdiff_t>(kinks), [&](const BendPoint& q) {
            return q.u >= u_prev && q.u <= ui;
          })) {
        const double uc = locate_fold(u_prev, ui);
        if (!std::isnan(uc)) out.push_back({uc, inf, BendPoint::Fold});
      }
      t_prev = d[1];
      u_prev = ui;
    }
    // Golden-section refinement of every sampled local maximum on its neighbouring interval.
    const double g = 0.5 * (std::sqrt(5.0) - 1.0);
    for (int i = 0; i <= N; ++i) {
      const double ki = samples[i];
      if ((i > 0 && samples[i - 1] > ki) || (i < N && samples[i + 1] > ki) || ki <= 0.0) continue;
      double lo = a + (b - a) * std::max(i - 1, 0) / N, hi = a + (b - a) * std::min(i + 1, N) / N;
      double x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo);
      double f1 = kappa(x1), f2 = kappa(x2);
      for (int it = 0; it < 60 && hi - lo > 1e-14 * std::max(1.0, std::abs(hi)); ++it) {
        if (f1 > f2) {
          hi = x2;
          x2 = x1;
          f2 = f1;
          x1 = hi - g * (hi - lo);
          f1 = kappa(x1);
        } else {
          lo = x1;
          x1 = x2;
          f1 = f2;
          x2 = lo + g * (hi - lo);
          f2 = kappa(x2);
        }
      }
      out.push_back({x1, f1, BendPoint::Peak});
      out.push_back({x2, f2, BendPoint::Peak});
    }
  }
  // In u order; at equal u the scan's order (kinks, samples, folds and peaks as found).
  std::stable_sort(out.begin(), out.end(), [](const BendPoint& x, const BendPoint& y) { return x.u < y.u; });
  return out;
}

BendExtremum Centerline::min_bend_radius() const {
  BendExtremum best;
  best.radius = std::numeric_limits<double>::infinity();
  const std::vector<BendPoint> profile = bend_profile();
  // A kink is the minimum wherever it lies (the first one), then the first fold, then the
  // sharpest smooth point (the first of equals).
  const BendPoint* at = nullptr;
  for (auto kind : {BendPoint::Kink, BendPoint::Fold})
    for (const BendPoint& b : profile)
      if (!at && b.kind == kind) at = &b;
  if (at) {
    best.radius = 0.0;
  } else {
    for (const BendPoint& b : profile)
      if (b.kappa > 0.0 && (!at || b.kappa > at->kappa)) at = &b;
    if (!at) return best;
    best.radius = 1.0 / at->kappa;
  }
  best.u = at->u;
  best.s = arc_length_at(at->u);
  return best;
}

std::vector<BendExtremum> Centerline::bend_stretches_below(double limit) const {
  std::vector<BendExtremum> out;
  if (!(limit > 0.0)) return out;
  const double k_limit = 1.0 / limit;
  const BendPoint* tightest = nullptr;  // of the stretch being walked, if any
  auto close = [&]() {
    if (!tightest) return;
    BendExtremum e;
    e.radius = std::isinf(tightest->kappa) ? 0.0 : 1.0 / tightest->kappa;
    e.u = tightest->u;
    e.s = arc_length_at(tightest->u);
    out.push_back(e);
    tightest = nullptr;
  };
  const std::vector<BendPoint> profile = bend_profile();
  for (const BendPoint& b : profile) {
    if (!(b.kappa > k_limit)) {
      // A sample at or below the limit ends the stretch; refined peaks and kinks lie on it.
      if (b.kind == BendPoint::Sample) close();
      continue;
    }
    if (!tightest || b.kappa > tightest->kappa) tightest = &b;
  }
  close();
  return out;
}

}  // namespace loom
