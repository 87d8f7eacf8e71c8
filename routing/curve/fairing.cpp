// Fairing of interpolating cubic centerlines (seed: cable-bspline-interpolation-and-
// fairing §III). The seed's eq. 10 writes the strain term with ∫NᵢNⱼ; the strain energy
// of eq. 8 is ∫κ²ds, which for a parameter in chord-length units (|C'| ≈ 1) is ∫|C''|²du,
// so the matrix here is Gᵢⱼ = ∫Nᵢ''Nⱼ''du.
#include "routing/curve/fairing.hpp"
#include "core/gauss_legendre.hpp"

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace loom {

namespace {

constexpr int kDegree = 3;
constexpr int kOrder = kDegree + 1;
/// Gauss–Legendre (8 points) for ∫κ²ds per knot span; each span is split in this many parts.
constexpr int kEnergySubdivisions = 2;
/// Squared sine of the C'–C'' angle below which a point counts as straight (rounding).
constexpr double kStraightSine2 = 1e-24;
constexpr const auto& kGLx = gauss_legendre8::kNodes;
constexpr const auto& kGLw = gauss_legendre8::kWeights;
/// Doublings tried when the first α already meets ε (searching for the largest α that does).
constexpr int kMaxAlphaDoublings = 8;
/// A projected curvature smaller than this fraction of |C'||C''| has no sign (straight or
/// perpendicular to the projection plane).
constexpr double kSignRelTol = 1e-9;
/// Samples for the closest-point search of the selected-point re-fit, before Newton.
constexpr int kProjectionSamples = 32;
/// A revision that moves a point less than this fraction of ε makes no progress.
constexpr double kNoProgressRel = 1e-6;

/// Key-point data of a curve: unique parameters, the points there, and the map from each
/// input key point to its unique index.
struct KeyData {
  std::vector<double> u;
  std::vector<Vec3> p;
  std::vector<int> index_of;
};

KeyData key_data(const Centerline& c) {
  KeyData k;
  for (double u : c.key_parameters()) {
    if (k.u.empty() || u > k.u.back()) {
      k.u.push_back(u);
      k.p.push_back(c.position(u));
    }
    k.index_of.push_back(static_cast<int>(k.u.size()) - 1);
  }
  return k;
}

/// Symmetric band matrix with half-bandwidth kDegree (|i − j| ≤ 3), full storage of the band.
struct Band {
  int n = 0;
  std::vector<double> a;  // a[i*4 + (j-i)] for j ≥ i
  explicit Band(int size) : n(size), a(static_cast<std::size_t>(size) * kOrder, 0.0) {}
  void add(int i, int j, double v) {
    if (j < i) std::swap(i, j);
    a[static_cast<std::size_t>(i) * kOrder + (j - i)] += v;
  }
  double get(int i, int j) const {
    if (j < i) std::swap(i, j);
    return j - i < kOrder ? a[static_cast<std::size_t>(i) * kOrder + (j - i)] : 0.0;
  }
};

/// ∫ Nᵢ''Nⱼ'' du over the curve's domain (exact: 3-point Gauss per span, integrand quadratic).
Band strain_matrix(const Centerline& c) {
  const std::vector<double>& U = c.knots();
  const int ncp = static_cast<int>(c.control_points().size());
  Band G(ncp);
  const double x3[3] = {-std::sqrt(0.6), 0.0, std::sqrt(0.6)};
  const double w3[3] = {5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0};
  const std::vector<double>& bp = c.breakpoints();
  double ders[3 * kOrder];
  for (std::size_t k = 0; k + 1 < bp.size(); ++k) {
    const double a = bp[k], b = bp[k + 1], h = 0.5 * (b - a), m = 0.5 * (a + b);
    for (int q = 0; q < 3; ++q) {
      const int i0 = bspline_basis(U, kDegree, m + h * x3[q], 2, ders);
      const double* d2 = ders + 2 * kOrder;
      for (int i = 0; i < kOrder; ++i)
        for (int j = i; j < kOrder; ++j) G.add(i0 + i, i0 + j, w3[q] * h * d2[i] * d2[j]);
    }
  }
  return G;
}

}  // namespace

double bending_energy(const Centerline& c) {
  if (c.empty()) return 0.0;
  const std::vector<double>& bp = c.breakpoints();
  double e = 0.0;
  Vec3 d[3];
  // κ below 1e-12 / L (bend radius ≫ the curve) is rounding on a straight run: κ² ≤ that².
  const double L = std::max(c.length(), 1e-300);
  const double v2_min_scale = 1.0 / (L * L);
  for (std::size_t k = 0; k + 1 < bp.size(); ++k) {
    for (int part = 0; part < kEnergySubdivisions; ++part) {
      const double a = bp[k] + (bp[k + 1] - bp[k]) * part / kEnergySubdivisions;
      const double b = bp[k] + (bp[k + 1] - bp[k]) * (part + 1) / kEnergySubdivisions;
      const double h = 0.5 * (b - a), m = 0.5 * (a + b);
      for (int q = 0; q < 8; ++q) {
        c.evaluate_in_interval(k, m + h * kGLx[q], 2, d);  // inside interval k
        const double v = d[1].norm();
        if (!(v > 0.0)) continue;
        // κ²|C'| = |C'×C''|²/|C'|⁵ (same evaluation, no second lookup).
        const double cr = d[1].cross(d[2]).squaredNorm();
        if (cr <= kStraightSine2 * v * v * d[2].squaredNorm()) continue;  // C'' ∥ C': straight
        if (cr <= kStraightSine2 * v2_min_scale * v * v * v * v * v * v) continue;  // κ·L negligible
        const double v2 = v * v;
        e += kGLw[q] * h * cr / (v2 * v2 * v);
      }
    }
  }
  return e;
}

FairingResult fair_energy(const Centerline& interpolant, const FairingOptions& opt) {
  if (interpolant.empty() || interpolant.degree() != kDegree || interpolant.key_parameters().empty())
    throw std::invalid_argument("fair_energy: needs a cubic built by Centerline::interpolate (with key parameters)");
  if (!(opt.tolerance > 0.0) || !std::isfinite(opt.tolerance))
    throw std::invalid_argument("fair_energy: tolerance ε must be positive and finite");
  const KeyData kd = key_data(interpolant);
  const int nk = static_cast<int>(kd.u.size());
  if (!opt.weights.empty() && opt.weights.size() != interpolant.key_parameters().size())
    throw std::invalid_argument("fair_energy: " + std::to_string(opt.weights.size()) + " weights for " +
                                std::to_string(interpolant.key_parameters().size()) + " key points");
  std::vector<double> beta(nk, 0.0);
  for (std::size_t i = 0; i < interpolant.key_parameters().size(); ++i) {
    const double w = opt.weights.empty() ? 1.0 : opt.weights[i];
    if (!(w > 0.0) || !std::isfinite(w))
      throw std::invalid_argument("fair_energy: weight " + std::to_string(i) + " must be positive and finite");
    beta[kd.index_of[i]] += w;
  }

  const std::vector<double>& U = interpolant.knots();
  const int ncp = static_cast<int>(interpolant.control_points().size());
  const Band G = strain_matrix(interpolant);
  // M = Bᵀ diag(β) B and r = Bᵀ diag(β) P, with B the basis rows at the key parameters.
  Band M(ncp);
  Eigen::MatrixX3d r = Eigen::MatrixX3d::Zero(ncp, 3);
  std::vector<std::array<double, kOrder>> Brow(nk);
  std::vector<int> Bfirst(nk);
  for (int i = 0; i < nk; ++i) {
    double ders[kOrder];
    Bfirst[i] = bspline_basis(U, kDegree, kd.u[i], 0, ders);
    for (int a = 0; a < kOrder; ++a) {
      Brow[i][a] = ders[a];
      r.row(Bfirst[i] + a) += beta[i] * ders[a] * kd.p[i].transpose();
      for (int b = a; b < kOrder; ++b) M.add(Bfirst[i] + a, Bfirst[i] + b, beta[i] * ders[a] * ders[b]);
    }
  }

  // Fixed control points and the map of the free ones to unknowns.
  std::vector<int> unknown(ncp, -1);
  std::vector<bool> fixed(ncp, false);
  if (opt.ends != FairingEnds::Free) fixed[0] = fixed[ncp - 1] = true;
  if (opt.ends == FairingEnds::PositionAndTangent) fixed[1] = fixed[ncp - 2] = true;
  int nu = 0;
  for (int i = 0; i < ncp; ++i)
    if (!fixed[i]) unknown[i] = nu++;
  const std::vector<Vec3>& P0 = interpolant.control_points();

  FairingResult res;
  auto deviation_of = [&](const std::vector<Vec3>& D) {
    double dev = 0.0;
    for (int i = 0; i < nk; ++i) {
      Vec3 q = Vec3::Zero();
      for (int a = 0; a < kOrder; ++a) q += Brow[i][a] * D[Bfirst[i] + a];
      dev = std::max(dev, (q - kd.p[i]).norm());
    }
    return dev;
  };
  // The system (αG + M) restricted to the free control points has one sparsity pattern for
  // every α: assemble it and analyse it once; each α only refills the values and factorises.
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Lower, Eigen::NaturalOrdering<int>> ldlt;
  Eigen::SparseMatrix<double> A(nu, nu);
  std::vector<double> g_val, m_val;  // G and M at A's stored entries (A = αG + M)
  if (nu > 0) {
    std::vector<int> cp_of(nu);
    for (int i = 0; i < ncp; ++i)
      if (!fixed[i]) cp_of[unknown[i]] = i;
    std::vector<Eigen::Triplet<double>> trip;
    trip.reserve(static_cast<std::size_t>(nu) * kOrder);
    for (int i = 0; i < ncp; ++i) {
      if (fixed[i]) continue;
      for (int j = std::max(0, i - kDegree); j <= std::min(ncp - 1, i + kDegree); ++j)
        if (!fixed[j] && unknown[j] <= unknown[i]) trip.emplace_back(unknown[i], unknown[j], 1.0);
    }
    A.setFromTriplets(trip.begin(), trip.end());
    A.makeCompressed();
    g_val.resize(static_cast<std::size_t>(A.nonZeros()));
    m_val.resize(g_val.size());
    for (int col = 0; col < A.outerSize(); ++col)
      for (Eigen::SparseMatrix<double>::InnerIterator e(A, col); e; ++e) {
        const int i = cp_of[e.row()], j = cp_of[e.col()];
        const auto k = static_cast<std::size_t>(&e.value() - A.valuePtr());
        g_val[k] = G.get(i, j);
        m_val[k] = M.get(i, j);
      }
    ldlt.analyzePattern(A);
  }
  Eigen::MatrixX3d rhs(nu, 3);
  auto solve = [&](double alpha, std::vector<Vec3>& D) -> bool {
    if (nu == 0) {
      D = P0;
      return true;
    }
    for (int i = 0; i < ncp; ++i) {
      if (fixed[i]) continue;
      Eigen::RowVector3d row = r.row(i);
      for (int j = std::max(0, i - kDegree); j <= std::min(ncp - 1, i + kDegree); ++j)
        if (fixed[j]) row -= (alpha * G.get(i, j) + M.get(i, j)) * P0[j].transpose();
      rhs.row(unknown[i]) = row;
    }
    double* value = A.valuePtr();
    for (std::size_t k = 0; k < g_val.size(); ++k) value[k] = alpha * g_val[k] + m_val[k];
    ldlt.factorize(A);
    if (ldlt.info() != Eigen::Success) return false;
    const Eigen::MatrixX3d X = ldlt.solve(rhs);
    D = P0;
    for (int i = 0; i < ncp; ++i)
      if (!fixed[i]) D[i] = X.row(unknown[i]).transpose();
    for (const Vec3& v : D)
      if (!is_finite(v)) return false;
    return true;
  };

  // First α: the deviation of a smoothing spline at a key point is ≈ α·|[q''']|/β (the
  // jump of the third derivative there), so start at twice the α that would put the
  // largest interpolant jump at ε.
  double alpha = opt.alpha;
  if (!(alpha > 0.0)) {
    double jump = 0.0;
    for (int i = 1; i + 1 < nk; ++i) {
      Vec3 l[4], rr[4];
      interpolant.evaluate(kd.u[i], 3, l, true);
      interpolant.evaluate(kd.u[i], 3, rr, false);
      jump = std::max(jump, (rr[3] - l[3]).norm() / beta[i]);
    }
    if (jump > 0.0) {
      alpha = 2.0 * opt.tolerance / jump;
    } else {  // no jump (a single cubic piece): the length cubed (its table is built only here)
      const double L = interpolant.length();
      alpha = L * L * L;
    }
  }

  std::vector<Vec3> D, best;
  double best_alpha = 0.0, best_dev = 0.0;
  int it = 0;
  bool found = false;
  for (; it < opt.max_iterations; ++it) {
    if (!solve(alpha, D)) {
      alpha *= 0.5;
      continue;
    }
    const double dev = deviation_of(D);
    if (dev <= opt.tolerance) {
      found = true;
      best = D;
      best_alpha = alpha;
      best_dev = dev;
      break;
    }
    alpha *= 0.5;
  }
  if (found && it == 0 && !(opt.alpha > 0.0)) {
    // The derived start already meets ε: look upward for a smoother α that still does.
    for (int k = 0; k < kMaxAlphaDoublings; ++k) {
      const double a2 = best_alpha * 2.0;
      if (!solve(a2, D)) break;
      const double dev = deviation_of(D);
      ++it;
      if (dev > opt.tolerance) break;
      best = D;
      best_alpha = a2;
      best_dev = dev;
    }
  }
  res.iterations = it + 1;
  if (found) {
    res.curve = Centerline(kDegree, U, best);
    res.status = FairingStatus::Faired;
    res.alpha = best_alpha;
    res.max_deviation = best_dev;
  } else {
    res.curve = interpolant;
    res.status = FairingStatus::Interpolant;
    res.alpha = 0.0;
    res.max_deviation = 0.0;
  }
  res.curve.set_key_parameters(interpolant.key_parameters());
  res.points.reserve(interpolant.key_parameters().size());
  for (double u : interpolant.key_parameters()) res.points.push_back(res.curve.position(u));
  if (found) {
    double dev = 0.0;
    for (int i = 0; i < nk; ++i) dev = std::max(dev, (res.curve.position(kd.u[i]) - kd.p[i]).norm());
    res.max_deviation = dev;
  }
  return res;
}

// ---------------------------------------------------------------------------------------
// Selected-point method

namespace {

/// Signs (−1, 0, +1) of the relative curvature of the XY and ZX projections at u.
std::array<int, 2> projected_curvature_signs(const Centerline& c, double u) {
  Vec3 d[3];
  c.evaluate(u, 2, d);
  const double scale = kSignRelTol * d[1].norm() * d[2].norm();
  const double kxy = d[1].x() * d[2].y() - d[1].y() * d[2].x();
  const double kzx = d[1].z() * d[2].x() - d[1].x() * d[2].z();
  auto sgn = [scale](double v) { return v > scale ? 1 : (v < -scale ? -1 : 0); };
  return {sgn(kxy), sgn(kzx)};
}

/// Closest point of c to p with parameter in [a, b] (dense samples, then Newton).
Vec3 closest_point(const Centerline& c, const Vec3& p, double a, double b) {
  double best_u = a, best_d = std::numeric_limits<double>::infinity();
  for (int i = 0; i <= kProjectionSamples; ++i) {
    const double u = a + (b - a) * i / kProjectionSamples;
    const double dd = (c.position(u) - p).squaredNorm();
    if (dd < best_d) {
      best_d = dd;
      best_u = u;
    }
  }
  double u = best_u;
  for (int it = 0; it < 20; ++it) {
    Vec3 d[3];
    c.evaluate(u, 2, d);
    const Vec3 e = d[0] - p;
    const double f = e.dot(d[1]), fp = d[1].squaredNorm() + e.dot(d[2]);
    if (!(fp > 0.0)) break;
    const double un = std::clamp(u - f / fp, a, b);
    if (std::abs(un - u) <= 1e-15 * std::max(1.0, std::abs(u))) {
      u = un;
      break;
    }
    u = un;
  }
  const Vec3 q = c.position(u);
  return (q - p).squaredNorm() <= best_d ? q : c.position(best_u);
}

}  // namespace

FairingResult fair_selected_points(const std::vector<Vec3>& points, const InterpolationOptions& interp,
                                   const FairingOptions& opt) {
  if (!(opt.tolerance > 0.0) || !std::isfinite(opt.tolerance))
    throw std::invalid_argument("fair_selected_points: tolerance ε must be positive and finite");
  const double eps = opt.tolerance;
  const Centerline original = Centerline::interpolate(points, interp);
  const KeyData kd = key_data(original);
  const std::vector<Vec3>& orig = kd.p;
  std::vector<Vec3> cur = orig;
  std::vector<bool> stuck(cur.size(), false);
  const int n = static_cast<int>(cur.size());

  FairingResult res;
  Centerline c = original;
  int revisions = 0;
  bool bad_left = false;
  for (int it = 0; it < std::max(opt.max_iterations, 0) + 1; ++it) {
    // Bad points (eq. 4) in either projection, ranked by the third-derivative jump (eq. 5).
    std::vector<std::array<int, 2>> sg(n);
    const std::vector<double> u = key_data(c).u;
    for (int i = 0; i < n; ++i) sg[i] = projected_curvature_signs(c, u[i]);
    int worst = -1;
    double worst_n = -1.0;
    for (int i = 1; i + 1 < n; ++i) {
      if (stuck[i]) continue;
      bool bad = false;
      for (int pl = 0; pl < 2; ++pl)
        bad = bad || (sg[i - 1][pl] * sg[i][pl] < 0 && sg[i][pl] * sg[i + 1][pl] < 0);
      if (!bad) continue;
      Vec3 l[4], r[4];
      c.evaluate(u[i], 3, l, true);
      c.evaluate(u[i], 3, r, false);
      const double N = (r[3] - l[3]).norm();
      if (N > worst_n) {
        worst_n = N;
        worst = i;
      }
    }
    bad_left = worst >= 0;
    if (!bad_left || it == std::max(opt.max_iterations, 0)) break;
    // Re-fit without the worst point (eq. 6) and move it toward the re-fit (eq. 7), never
    // farther than ε from where it started.
    std::vector<Vec3> others;
    others.reserve(n - 1);
    for (int i = 0; i < n; ++i)
      if (i != worst) others.push_back(cur[i]);
    const Centerline refit = Centerline::interpolate(others, interp);
    const std::vector<double>& ru = refit.key_parameters();
    const Vec3 Y = closest_point(refit, cur[worst], ru[worst - 1], ru[worst]);
    const double Li = (Y - cur[worst]).norm();
    Vec3 target = Li <= eps ? Y : Vec3(cur[worst] + eps * (Y - cur[worst]) / Li);
    Vec3 move = target - orig[worst];
    if (move.norm() > eps) move *= eps / move.norm();
    const Vec3 next = orig[worst] + move;
    if ((next - cur[worst]).norm() <= kNoProgressRel * eps) {
      stuck[worst] = true;
      continue;
    }
    const Vec3 before = cur[worst];
    cur[worst] = next;
    Centerline cn = Centerline::interpolate(cur, interp);
    if (key_data(cn).u.size() != static_cast<std::size_t>(n)) {  // merged with a neighbour: undo
      cur[worst] = before;
      stuck[worst] = true;
      continue;
    }
    ++revisions;
    c = std::move(cn);
  }
  const bool any_stuck = std::find(stuck.begin(), stuck.end(), true) != stuck.end();
  res.curve = c;
  res.iterations = revisions;
  res.status = bad_left                             ? FairingStatus::IterationLimit
               : any_stuck                          ? FairingStatus::ToleranceLimit
               : revisions == 0                     ? FairingStatus::AlreadyFair
                                                    : FairingStatus::Faired;
  for (int i = 0; i < n; ++i) res.max_deviation = std::max(res.max_deviation, (cur[i] - orig[i]).norm());
  res.points.reserve(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) res.points.push_back(cur[kd.index_of[i]]);
  // Key parameters per input point (duplicates share theirs).
  std::vector<double> kp(points.size());
  const std::vector<double> cu = key_data(c).u;
  for (std::size_t i = 0; i < points.size(); ++i) kp[i] = cu[kd.index_of[i]];
  res.curve.set_key_parameters(kp);
  return res;
}

}  // namespace loom
