#include "core/bspline_ops.hpp"

#include "core/error.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace loom {

void insert_knot(int p, std::size_t k, double u, std::vector<double>& U, std::vector<Vec3>& P) {
  const std::size_t q = static_cast<std::size_t>(p);
  std::vector<Vec3> Q(P.size() + 1);
  for (std::size_t i = 0; i + q <= k; ++i) Q[i] = P[i];
  for (std::size_t i = k - q + 1; i <= k; ++i) {
    const double a = (u - U[i]) / (U[i + q] - U[i]);
    Q[i] = a * P[i] + (1.0 - a) * P[i - 1];
  }
  for (std::size_t i = k + 1; i < Q.size(); ++i) Q[i] = P[i - 1];
  U.insert(U.begin() + static_cast<std::ptrdiff_t>(k) + 1, u);
  P = std::move(Q);
}

namespace {

/// Raises the multiplicity of u (inside the domain of the degree-p curve U, P) to at least p.
void raise_to_degree(int p, double u, std::vector<double>& U, std::vector<Vec3>& P) {
  for (auto r = std::equal_range(U.begin(), U.end(), u); r.second - r.first < p;
       r = std::equal_range(U.begin(), U.end(), u)) {
    // The interval [U[k], U[k + 1]) that u lies in: k is the last knot at or before u.
    insert_knot(p, static_cast<std::size_t>(r.second - U.begin()) - 1, u, U, P);
  }
}

}  // namespace

Centerline clamped(const Centerline& c) {
  const int p = c.degree();
  const std::size_t q = static_cast<std::size_t>(p);
  std::vector<double> U = c.knots();
  std::vector<Vec3> P = c.control_points();
  auto run = [&U](double u) { return std::equal_range(U.begin(), U.end(), u); };
  // Start: after insertion u_min fills U[j, j + m) with m ≥ p, and the curve starts at
  // control point j + m − p − 1.
  const double a = U[q];
  for (auto r = run(a); r.second - r.first < p; r = run(a))
    insert_knot(p, static_cast<std::size_t>(r.second - U.begin()) - 1, a, U, P);
  {
    const auto r = run(a);
    const std::size_t j = static_cast<std::size_t>(r.first - U.begin()), m = static_cast<std::size_t>(r.second - r.first);
    std::vector<double> V(q + 1, a);
    V.insert(V.end(), U.begin() + static_cast<std::ptrdiff_t>(j + m), U.end());
    P.erase(P.begin(), P.begin() + static_cast<std::ptrdiff_t>(j + m - q - 1));
    U = std::move(V);
  }
  // End: u_max fills U[f, f + m) with m ≥ p, and the curve ends at control point f − 1.
  const double b = U[P.size()];
  for (auto r = run(b); r.second - r.first < p; r = run(b))
    insert_knot(p, static_cast<std::size_t>(r.first - U.begin()) - 1, b, U, P);
  const std::size_t f = static_cast<std::size_t>(run(b).first - U.begin());
  U.resize(f);
  U.insert(U.end(), q + 1, b);
  P.resize(f);
  return Centerline(p, std::move(U), std::move(P));
}

Centerline sub_curve(const Centerline& c, double a, double b) {
  a = std::clamp(a, c.u_min(), c.u_max());
  b = std::clamp(b, c.u_min(), c.u_max());
  if (!(a < b)) throw std::invalid_argument("sub_curve: empty parameter range");
  const Centerline cl = clamped(c);
  const int p = cl.degree();
  std::vector<double> U = cl.knots();
  std::vector<Vec3> P = cl.control_points();
  if (a > cl.u_min()) raise_to_degree(p, a, U, P);
  if (b < cl.u_max()) raise_to_degree(p, b, U, P);
  // Cut between the runs: the knots from a's run to b's run, each end repeated p + 1 times.
  // A knot of multiplicity ≥ p at u whose run ends before index e puts the curve at u on
  // control point e − p − 1 (and one whose run starts at index j on control point j − 1): the
  // part over [a, b] runs from the end of a's run to the start of b's.
  const std::size_t q = static_cast<std::size_t>(p);
  const std::size_t ea = static_cast<std::size_t>(std::upper_bound(U.begin(), U.end(), a) - U.begin());
  const std::size_t sb = static_cast<std::size_t>(std::lower_bound(U.begin(), U.end(), b) - U.begin());
  std::vector<double> V(q + 1, a);
  V.insert(V.end(), U.begin() + static_cast<std::ptrdiff_t>(ea), U.begin() + static_cast<std::ptrdiff_t>(sb));
  V.insert(V.end(), q + 1, b);
  std::vector<Vec3> Q(P.begin() + static_cast<std::ptrdiff_t>(ea - q - 1), P.begin() + static_cast<std::ptrdiff_t>(sb));
  return Centerline(p, std::move(V), std::move(Q));
}

Centerline reversed(const Centerline& c) {
  const auto& k = c.knots();
  const double a = k.front(), b = k.back();
  std::vector<double> knots(k.size());
  for (std::size_t i = 0; i < k.size(); ++i) knots[i] = a + b - k[k.size() - 1 - i];
  std::vector<Vec3> cps(c.control_points().rbegin(), c.control_points().rend());
  return Centerline(c.degree(), std::move(knots), std::move(cps));
}

std::vector<std::vector<Vec3>> bezier_pieces(const Centerline& c) {
  const Centerline cl = clamped(c);
  const int p = cl.degree();
  std::vector<double> U = cl.knots();
  std::vector<Vec3> P = cl.control_points();
  const std::vector<double>& breaks = cl.breakpoints();
  for (std::size_t k = 1; k + 1 < breaks.size(); ++k) raise_to_degree(p, breaks[k], U, P);
  std::vector<std::vector<Vec3>> out;
  const std::size_t q = static_cast<std::size_t>(p);
  for (std::size_t i = 0; i + q < P.size(); i += q) out.emplace_back(P.begin() + static_cast<std::ptrdiff_t>(i),
                                                                     P.begin() + static_cast<std::ptrdiff_t>(i + q + 1));
  return out;
}

Centerline from_bezier_pieces(int degree, const std::vector<std::vector<Vec3>>& pieces,
                              const std::vector<double>& breaks) {
  const std::size_t q = static_cast<std::size_t>(degree);
  if (pieces.empty() || breaks.size() != pieces.size() + 1)
    throw std::invalid_argument("from_bezier_pieces: need one more break than pieces");
  std::vector<double> U(q + 1, breaks.front());
  std::vector<Vec3> P{pieces.front().front()};
  for (std::size_t k = 0; k < pieces.size(); ++k) {
    if (pieces[k].size() != q + 1) throw std::invalid_argument("from_bezier_pieces: a piece of the wrong degree");
    P.insert(P.end(), pieces[k].begin() + 1, pieces[k].end());
    U.insert(U.end(), k + 1 < pieces.size() ? q : q + 1, breaks[k + 1]);
  }
  return Centerline(degree, std::move(U), std::move(P));
}

Centerline elevated(const Centerline& c, int degree) {
  const int p = c.degree();
  if (degree == p) return c;
  if (degree < p || degree > 7)
    throw std::invalid_argument("elevated: cannot raise degree " + std::to_string(p) + " to " + std::to_string(degree));
  std::vector<std::vector<Vec3>> pieces = bezier_pieces(c);
  for (auto& b : pieces)
    for (int d = static_cast<int>(b.size()) - 1; d < degree; ++d) {
      // One degree up: Q_i = i/(d+1) P_{i−1} + (1 − i/(d+1)) P_i.
      std::vector<Vec3> e(b.size() + 1);
      e.front() = b.front();
      e.back() = b.back();
      for (std::size_t i = 1; i < b.size(); ++i) {
        const double t = static_cast<double>(i) / static_cast<double>(d + 1);
        e[i] = t * b[i - 1] + (1.0 - t) * b[i];
      }
      b = std::move(e);
    }
  return from_bezier_pieces(degree, pieces, c.breakpoints());
}

double meeting_tolerance(const AABB& box) {
  constexpr double kJoinGapRel = 1e-9;
  return kJoinGapRel * (box.diagonal() + std::max(box.min.cwiseAbs().maxCoeff(), box.max.cwiseAbs().maxCoeff()));
}

Centerline join(const Centerline& first, const Centerline& second) {
  const int p = std::max(first.degree(), second.degree());
  const Centerline a = elevated(clamped(first), p), b = elevated(clamped(second), p);
  const Vec3 end = a.control_points().back(), start = b.control_points().front();
  AABB box;
  for (const Centerline* c : {&a, &b})
    for (const Vec3& q : c->control_points()) box.extend(q);
  if ((end - start).norm() > meeting_tolerance(box))
    throw std::invalid_argument("consecutive segments do not meet: one ends at " + full_precision(end) +
                                ", the next starts at " + full_precision(start) + " (gap " +
                                full_precision((end - start).norm()) + ")");
  const std::size_t q = static_cast<std::size_t>(p);
  const auto& ka = a.knots();
  const auto& kb = b.knots();
  const double shift = ka.back() - kb.front();
  std::vector<double> knots(ka.begin(), ka.end() - 1);  // a's knots with its end knot p times
  for (std::size_t i = q + 1; i < kb.size(); ++i) knots.push_back(kb[i] + shift);
  std::vector<Vec3> cps = a.control_points();
  cps.insert(cps.end(), b.control_points().begin() + 1, b.control_points().end());
  return Centerline(p, std::move(knots), std::move(cps));
}

}  // namespace loom
