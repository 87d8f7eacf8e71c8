#include "routing/scan/scan_centerline.hpp"
#include "core/stopwatch.hpp"

#include "core/error.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <nanoflann.hpp>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <numeric>
#include <random>
#include <stdexcept>
#include <unordered_map>

namespace loom {

const char* to_string(ScanStatus s) {
  switch (s) {
    case ScanStatus::Ok: return "ok";
    case ScanStatus::TooFewPoints: return "too-few-points";
    case ScanStatus::NotATube: return "not-a-tube";
  }
  return "unknown";
}

const char* to_string(ScanMethod m) { return m == ScanMethod::Axis ? "axis" : "graph"; }

namespace {

// ---- tolerances (all relative to the tube radius r or diameter d) ------------------------
/// A block needs this many points to fit centre, direction, bend and radius reliably.
constexpr std::size_t kMinBlockPoints = 20;
/// Robust scale floor (fraction of r): below it, residuals are treated as noise-free.
constexpr double kSigmaFloor = 0.005;
/// Huber and Tukey tuning constants (95 % efficiency under Gaussian noise).
constexpr double kHuber = 1.345, kTukey = 4.685;
/// Accepted iterations with Huber weights before switching to Tukey (which rejects outliers).
constexpr int kHuberIterations = 3;
/// Mean-shift ball radius for contracting the cloud onto the axis (× d).
constexpr double kContractRadius = 1.25;
/// Seed grid cell / node merge radius (× d).
constexpr double kSeedCell = 1.0, kMergeRadius = 0.4;
/// A point farther than this from the ordering curve is not on the cable (× d).
constexpr double kOutlierDistance = 1.25;
/// A block whose fitted centre moved farther than this from its start (× d) is rejected.
constexpr double kMaxCentreShift = 1.0;
/// Points used for neighbourhood statistics (diameter estimate, contraction).
constexpr std::size_t kNeighbourhoodPoints = 8192;
/// Block fits iterate on at most this many points, then polish on all of them.
constexpr std::size_t kFitSubsample = 384;
constexpr int kPolishIterations = 2;
/// A segment of the ordering curve longer than this (× d) bridges a gap in the scan.
constexpr double kBridgeLength = 2.5;
/// A bridge over a gap must carry on from the runs either side: its direction may turn from
/// theirs (measured over kBridgeTangentLength × d) by at most this (radians). The chord of
/// a gap of length g in a cable bent to radius R turns by g / 2R from the ends' tangents;
/// 80° is a gap of 0.9 R·π, beyond which a gap cannot be told from two cables lying side by
/// side, whose bridge joins their ends across (≥ 90°).
constexpr double kMaxBridgeTurn = 80.0 * M_PI / 180.0;
constexpr double kBridgeTangentLength = 2.0;
/// A given diameter may differ from the one the cloud's cross-sections fit by this fraction
/// of it (nominal against measured sheath); beyond, the given one is refused.
constexpr double kGivenDiameterTolerance = 0.25;
/// Around its axis a block's inliers must fill kMinArcSectors of kArcSectors equal sectors
/// (120°: a scanner sees about half of a cable, a line or a plane one or two sectors), each
/// with at least kSectorShare of them.
constexpr std::size_t kArcSectors = 12;
constexpr int kMinArcSectors = 4;
constexpr double kSectorShare = 0.02;
/// Fraction of a block's inliers ignored at each end when locating the cable's ends.
constexpr double kEndQuantile = 0.02;
/// Points may project this far (× d) beyond the ends of the ordering curve.
constexpr double kEndOvershoot = 1.0;
/// Relative step (× r) below which a block fit has converged.
constexpr double kConverged = 1e-5;
/// Neighbourhood radius of the coarse diameter estimate (× d), and its slab half-width (× ρ).
constexpr double kEstimateScale = 2.5, kEstimateSlab = 0.25;
/// Neighbours searched for the nearest one at a non-zero distance (repeated points).
constexpr std::size_t kSpacingNeighbours = 16;
/// Scale steps of the diameter estimate: enough to double from 10⁻⁶ of the cloud's size to
/// all of it (20) and then settle.
constexpr int kEstimateIterations = 24;

struct CloudAdaptor {
  const std::vector<Vec3>& pts;
  std::size_t kdtree_get_point_count() const { return pts.size(); }
  double kdtree_get_pt(std::size_t i, std::size_t dim) const { return pts[i][static_cast<int>(dim)]; }
  template <class B>
  bool kdtree_get_bbox(B&) const { return false; }
};
using KdTree =
    nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, CloudAdaptor>, CloudAdaptor, 3, std::uint32_t>;

/// Radius-search result set that only sums the points (no allocation).
struct SumResultSet {
  double radius2;
  const std::vector<Vec3>& pts;
  Vec3 sum = Vec3::Zero();
  std::size_t n = 0;
  std::size_t size() const { return n; }
  bool full() const { return true; }
  bool addPoint(double dist2, std::uint32_t i) {
    if (dist2 < radius2) {
      sum += pts[i];
      ++n;
    }
    return true;
  }
  double worstDist() const { return radius2; }
};

void frame(const Vec3& a, Vec3& e1, Vec3& e2) {
  const Vec3 t = std::abs(a.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
  e1 = (t - t.dot(a) * a).normalized();
  e2 = a.cross(e1);
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

// ---- block fit: tube of radius R around c + t·a + ½t²·b ---------------------------------

struct FitConfig {
  bool curved = true;       ///< fit the bend b (else a straight cylinder, the paper's line)
  bool robust = true;       ///< IRLS Huber → Tukey (else plain least squares)
  bool free_radius = false; ///< fit R too
  double radius = 1.0;      ///< nominal / starting radius
  std::optional<Vec3> prior;  ///< smoothness: preferred direction (paper's E_ext)
  double prior_weight = 0.0;
  int max_iter = 40;
};

struct FitOut {
  Vec3 c = Vec3::Zero(), a = Vec3::UnitX(), b = Vec3::Zero();
  double r = 0.0, rms = 0.0, max_res = 0.0, sq_sum = 0.0;
  double t_min = 0.0, t_max = 0.0;  ///< robust extent of the inliers along the axis (quantiles)
  std::size_t inliers = 0;
  bool ok = false;
  /// The inliers cover fewer than kMinArcSectors of the kArcSectors sectors around the axis:
  /// the cross-section is not determined (points on a line or a surface fit any tube).
  bool thin = false;
  Vec3 at(double t) const { return c + t * a + 0.5 * t * t * b; }
};

class BlockFitter {
 public:
  BlockFitter(const Vec3* pts, std::size_t n, const FitConfig& cfg) : p_(pts), n_(n), cfg_(cfg) {
    res_.resize(n);
    nrm_.resize(n);
    t_.resize(n);
    w_.assign(n, 1.0);
    trial_res_.resize(n);
    trial_nrm_.resize(n);
    trial_t_.resize(n);
  }

  /// Fits from a start (centre, direction; bend and radius too when `warm`). A warm start
  /// goes straight to Tukey weights (the start is already close).
  FitOut run(FitOut f, bool warm = false) {
    f.a.normalize();
    if (!warm) {
      f.b.setZero();
      f.r = cfg_.radius;
    }
    if (!cfg_.free_radius) f.r = cfg_.radius;
    if (!cfg_.curved) f.b.setZero();
    const int np = 4 + (cfg_.curved ? 2 : 0) + (cfg_.free_radius ? 1 : 0);
    const int ib = 4, ir = cfg_.curved ? 6 : 4;
    evaluate(f, res_, nrm_, t_);
    int accepted = warm ? kHuberIterations : 0;
    update_weights(accepted);
    double cost = cost_of(f, res_);
    double lambda = 1e-4;
    for (int it = 0; it < cfg_.max_iter; ++it) {
      Vec3 e1, e2;
      frame(f.a, e1, e2);
      Eigen::Matrix<double, 7, 7> H = Eigen::Matrix<double, 7, 7>::Zero();
      Eigen::Matrix<double, 7, 1> g = Eigen::Matrix<double, 7, 1>::Zero();
      Eigen::Matrix<double, 7, 1> J;
      for (std::size_t i = 0; i < n_; ++i) {
        if (w_[i] <= 0.0) continue;
        const double n1 = nrm_[i].dot(e1), n2 = nrm_[i].dot(e2), t = t_[i];
        J.setZero();
        J(0) = -n1;
        J(1) = -n2;
        J(2) = -t * n1;
        J(3) = -t * n2;
        if (cfg_.curved) {
          J(ib) = -0.5 * t * t * n1;
          J(ib + 1) = -0.5 * t * t * n2;
        }
        if (cfg_.free_radius) J(ir) = -1.0;
        H.noalias() += w_[i] * J * J.transpose();
        g.noalias() += w_[i] * res_[i] * J;
      }
      if (cfg_.prior) {
        const double pw = prior_scale();
        const Vec3 d = f.a - *cfg_.prior;
        H(2, 2) += pw;
        H(3, 3) += pw;
        g(2) += pw * d.dot(e1);
        g(3) += pw * d.dot(e2);
      }
      // Solve in parameters made dimensionless by the nominal radius (centre and radius
      // in radii, bend in 1/radii): the damping floor below compares the diagonal entries,
      // which otherwise scale as 1, L² and L⁴ and freeze the centre (huge clouds) or the
      // bend (tiny ones).
      const Eigen::VectorXd S = parameter_scales(np, ib, ir);
      auto Hs = (S.asDiagonal() * H.topLeftCorner(np, np) * S.asDiagonal()).eval();
      const double tr = std::max(Hs.trace() / np, std::numeric_limits<double>::min());
      for (int k = 0; k < np; ++k) Hs(k, k) += lambda * std::max(Hs(k, k), 1e-9 * tr);
      Eigen::VectorXd delta = Hs.ldlt().solve(-(S.asDiagonal() * g.head(np)).eval());
      delta = (S.asDiagonal() * delta).eval();
      if (!delta.allFinite()) break;
      // Keep each step within the trust of the linearisation.
      const double R = std::max(f.r, 1e-12 * cfg_.radius);
      const double step_c = std::hypot(delta(0), delta(1)), step_a = std::hypot(delta(2), delta(3));
      double shrink = 1.0;
      if (step_c > 0.5 * R) shrink = std::min(shrink, 0.5 * R / step_c);
      if (step_a > 0.3) shrink = std::min(shrink, 0.3 / step_a);
      delta *= shrink;
      FitOut trial = f;
      trial.c += delta(0) * e1 + delta(1) * e2;
      trial.a = (f.a + delta(2) * e1 + delta(3) * e2).normalized();
      if (cfg_.curved) {
        trial.b += delta(ib) * e1 + delta(ib + 1) * e2;
        trial.b -= trial.b.dot(trial.a) * trial.a;
      }
      if (cfg_.free_radius) trial.r = std::max(f.r + delta(ir), 0.05 * cfg_.radius);
      evaluate(trial, trial_res_, trial_nrm_, trial_t_);
      const double trial_cost = cost_of(trial, trial_res_);
      if (trial_cost <= cost) {
        f = trial;
        res_.swap(trial_res_);
        nrm_.swap(trial_nrm_);
        t_.swap(trial_t_);
        lambda = std::max(lambda / 4.0, 1e-9);
        ++accepted;
        const double move = std::hypot(step_c, R * step_a) * shrink;
        update_weights(accepted);
        cost = cost_of(f, res_);
        if (move < kConverged * R && accepted > kHuberIterations) break;
      } else {
        lambda *= 8.0;
        if (lambda > 1e8) break;
      }
    }
    // Statistics over inliers.
    double sq = 0.0, mx = 0.0;
    std::size_t k = 0;
    std::vector<double> ts;
    ts.reserve(n_);
    for (std::size_t i = 0; i < n_; ++i) {
      if (w_[i] <= 0.0) continue;
      sq += res_[i] * res_[i];
      mx = std::max(mx, std::abs(res_[i]));
      ts.push_back(t_[i]);
      ++k;
    }
    f.thin = arc_sectors(f) < kMinArcSectors;
    if (!ts.empty()) {
      // Extent along the axis, ignoring the outermost kEndQuantile of the inliers (a stray
      // point beyond the cable end must not stretch the curve).
      const auto q = std::min(ts.size() - 1, static_cast<std::size_t>(kEndQuantile * static_cast<double>(ts.size())));
      std::nth_element(ts.begin(), ts.begin() + static_cast<std::ptrdiff_t>(q), ts.end());
      f.t_min = ts[q];
      std::nth_element(ts.begin(), ts.end() - 1 - static_cast<std::ptrdiff_t>(q), ts.end());
      f.t_max = ts[ts.size() - 1 - q];
    }
    f.inliers = k;
    f.sq_sum = sq;
    f.rms = k ? std::sqrt(sq / static_cast<double>(k)) : 0.0;
    f.max_res = mx;
    f.ok = k >= kMinBlockPoints / 2 && f.c.allFinite() && f.a.allFinite() && f.b.allFinite() && std::isfinite(f.r) &&
           f.r > 0.0;
    if (!f.ok) {
      f.t_min = f.t_max = 0.0;
    }
    return f;
  }

  const std::vector<double>& weights() const { return w_; }

 private:
  const Vec3* p_;
  std::size_t n_;
  FitConfig cfg_;
  std::vector<double> res_, t_, w_, trial_res_, trial_t_;
  std::vector<Vec3> nrm_, trial_nrm_;

  /// Number of the kArcSectors equal sectors around the axis that hold at least
  /// kSectorShare of the inliers (directions of the points from their foot on the axis).
  int arc_sectors(const FitOut& f) const {
    Vec3 e1, e2;
    frame(f.a, e1, e2);
    std::vector<std::size_t> count(kArcSectors, 0);
    std::size_t total = 0;
    for (std::size_t i = 0; i < n_; ++i) {
      if (w_[i] <= 0.0) continue;
      const double ang = std::atan2(nrm_[i].dot(e2), nrm_[i].dot(e1)) + M_PI;  // 0 .. 2π
      const auto k = std::min<std::size_t>(kArcSectors - 1, static_cast<std::size_t>(ang / (2.0 * M_PI) * kArcSectors));
      ++count[k];
      ++total;
    }
    const double need = std::max(1.0, kSectorShare * static_cast<double>(total));
    return static_cast<int>(std::count_if(count.begin(), count.end(), [&](std::size_t c) { return static_cast<double>(c) >= need; }));
  }

  /// Per-parameter unit of the LM step (centre, direction, bend, radius): the nominal
  /// radius to the power that makes each parameter dimensionless.
  Eigen::VectorXd parameter_scales(int np, int ib, int ir) const {
    Eigen::VectorXd S = Eigen::VectorXd::Ones(np);
    S(0) = S(1) = cfg_.radius;
    if (cfg_.curved) S(ib) = S(ib + 1) = 1.0 / cfg_.radius;
    if (cfg_.free_radius) S(ir) = cfg_.radius;
    return S;
  }

  /// Paper's normalisation: the data term is Σ w·res² / (m r²); the smoothness term μ|a − ā|²
  /// is therefore weighted by μ·m·r² against the raw weighted squares.
  double prior_scale() const {
    return cfg_.prior_weight * static_cast<double>(n_) * cfg_.radius * cfg_.radius;
  }

  double cost_of(const FitOut& f, const std::vector<double>& res) const {
    double c = 0.0;
    for (std::size_t i = 0; i < n_; ++i) c += w_[i] * res[i] * res[i];
    if (cfg_.prior) c += prior_scale() * (f.a - *cfg_.prior).squaredNorm();
    return c;
  }

  void evaluate(const FitOut& f, std::vector<double>& res, std::vector<Vec3>& nrm, std::vector<double>& tt) const {
    const bool bent = cfg_.curved && f.b.squaredNorm() > 0.0;
    Vec3 e1, e2;
    frame(f.a, e1, e2);
    for (std::size_t i = 0; i < n_; ++i) {
      const Vec3 q = p_[i] - f.c;
      double t = q.dot(f.a);
      Vec3 foot = f.c + t * f.a, tan = f.a;
      if (bent) {
        for (int k = 0; k < 2; ++k) {  // Newton on (p − f(t))·f'(t) = 0
          foot = f.at(t);
          tan = f.a + t * f.b;
          const Vec3 w = p_[i] - foot;
          const double gp = -tan.squaredNorm() + w.dot(f.b);
          if (std::abs(gp) < 1e-12) break;
          t -= w.dot(tan) / gp;
        }
        foot = f.at(t);
        tan = (f.a + t * f.b).normalized();
      }
      Vec3 w = p_[i] - foot;
      w -= w.dot(tan) * tan;
      const double rho = w.norm();
      nrm[i] = rho > 1e-300 ? Vec3(w / rho) : e1;
      res[i] = rho - f.r;
      tt[i] = t;
    }
  }

  void update_weights(int accepted) {
    if (!cfg_.robust) return;  // plain least squares: all weights 1
    std::vector<double> a(n_);
    for (std::size_t i = 0; i < n_; ++i) a[i] = std::abs(res_[i]);
    const double sigma = std::max(1.4826 * median(a), kSigmaFloor * cfg_.radius);
    const bool tukey = accepted >= kHuberIterations;
    for (std::size_t i = 0; i < n_; ++i) {
      const double u = a[i];
      if (tukey) {
        const double c = kTukey * sigma;
        const double z = u / c;
        w_[i] = z < 1.0 ? (1 - z * z) * (1 - z * z) : 0.0;
      } else {
        const double k = kHuber * sigma;
        w_[i] = u <= k ? 1.0 : k / u;
      }
    }
  }
};

// ---- circle fit in a plane (for the coarse diameter estimate) ---------------------------

std::optional<double> fit_circle_radius(const std::vector<Eigen::Vector2d>& uv) {
  if (uv.size() < 8) return std::nullopt;
  // Kåsa: u² + v² + D u + E v + F = 0 by linear least squares.
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  Eigen::Vector3d y = Eigen::Vector3d::Zero();
  for (const auto& p : uv) {
    const Eigen::Vector3d row(p.x(), p.y(), 1.0);
    const double rhs = -(p.squaredNorm());
    A += row * row.transpose();
    y += rhs * row;
  }
  const Eigen::Vector3d s = A.ldlt().solve(y);
  Eigen::Vector2d c(-0.5 * s(0), -0.5 * s(1));
  double r2 = c.squaredNorm() - s(2);
  if (!(r2 > 0) || !std::isfinite(r2)) return std::nullopt;
  double r = std::sqrt(r2);
  // Geometric refinement with Tukey weights.
  std::vector<double> res(uv.size());
  for (int it = 0; it < 8; ++it) {
    for (std::size_t i = 0; i < uv.size(); ++i) res[i] = (uv[i] - c).norm() - r;
    std::vector<double> a(res.size());
    for (std::size_t i = 0; i < res.size(); ++i) a[i] = std::abs(res[i]);
    const double sigma = std::max(1.4826 * median(a), kSigmaFloor * r);
    Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
    Eigen::Vector3d g = Eigen::Vector3d::Zero();
    for (std::size_t i = 0; i < uv.size(); ++i) {
      const double z = std::abs(res[i]) / (kTukey * sigma);
      if (z >= 1.0) continue;
      const double w = (1 - z * z) * (1 - z * z);
      const Eigen::Vector2d d = uv[i] - c;
      const double n = d.norm();
      if (n < 1e-300) continue;
      const Eigen::Vector3d J(-d.x() / n, -d.y() / n, -1.0);
      H += w * J * J.transpose();
      g += w * res[i] * J;
    }
    const Eigen::Vector3d delta = H.ldlt().solve(-g);
    if (!delta.allFinite()) return std::nullopt;
    c += delta.head<2>();
    r += delta(2);
    if (!(r > 0)) return std::nullopt;
    if (delta.norm() < 1e-9 * r) break;
  }
  double sq = 0.0;
  for (const auto& p : uv) sq += std::pow((p - c).norm() - r, 2);
  if (std::sqrt(sq / static_cast<double>(uv.size())) > 0.3 * r) return std::nullopt;  // not a circle
  return r;
}

std::optional<double> coarse_diameter(const std::vector<Vec3>& pts, const KdTree& tree, std::uint64_t seed) {
  if (pts.size() < 2 * kMinBlockPoints) return std::nullopt;
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<std::size_t> pick(0, pts.size() - 1);
  // Median nearest-neighbour spacing h sets the smallest meaningful neighbourhood. The
  // nearest neighbour at a non-zero distance: a cloud whose points are repeated (merged
  // scans, re-exported files) would otherwise give h = 0 and start the search far below
  // the tube's scale.
  std::vector<double> nn;
  std::uint32_t idx[kSpacingNeighbours];
  double d2[kSpacingNeighbours];
  for (int i = 0; i < 200; ++i) {
    const Vec3& p = pts[pick(rng)];
    const std::size_t got = tree.knnSearch(p.data(), kSpacingNeighbours, idx, d2);
    for (std::size_t k = 1; k < got; ++k)
      if (d2[k] > 0.0) {
        nn.push_back(std::sqrt(d2[k]));
        break;
      }
  }
  const double h = median(nn);
  AABB box;
  for (const auto& p : pts) box.extend(p);
  const double diag = box.diagonal();
  if (!(diag > 0)) return std::nullopt;
  double rho = std::max(12.0 * h, 1e-6 * diag);
  std::optional<double> best;
  std::vector<std::pair<std::uint32_t, double>> found;
  for (int iter = 0; iter < kEstimateIterations && rho <= diag; ++iter) {
    std::vector<double> radii;
    for (int sidx = 0; sidx < 48; ++sidx) {
      const Vec3& p = pts[pick(rng)];
      tree.radiusSearch(p.data(), rho * rho, found, nanoflann::SearchParams(32, 0.0f, false));
      if (found.size() < 2 * kMinBlockPoints) continue;
      Vec3 mean = Vec3::Zero();
      for (const auto& f : found) mean += pts[f.first];
      mean /= static_cast<double>(found.size());
      Eigen::Matrix3d C = Eigen::Matrix3d::Zero();
      for (const auto& f : found) {
        const Vec3 q = pts[f.first] - mean;
        C += q * q.transpose();
      }
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(C);
      const Eigen::Vector3d ev = es.eigenvalues();  // ascending
      if (!(ev(2) > 3.0 * ev(1))) continue;          // not elongated: a surface patch or a blob
      const Vec3 axis = es.eigenvectors().col(2), u = es.eigenvectors().col(1), v = es.eigenvectors().col(0);
      std::vector<Eigen::Vector2d> uv;
      for (const auto& f : found) {
        const Vec3 q = pts[f.first] - p;
        if (std::abs(q.dot(axis)) > kEstimateSlab * rho) continue;
        uv.emplace_back(q.dot(u), q.dot(v));
      }
      if (auto r = fit_circle_radius(uv); r && *r < rho) radii.push_back(*r);
    }
    if (radii.size() < 5) {
      rho *= 2.0;
      continue;
    }
    const double r = median(radii);
    best = 2.0 * r;
    const double rho_new = kEstimateScale * 2.0 * r;
    if (std::abs(rho_new - rho) < 0.1 * rho) break;
    rho = std::clamp(rho_new, 0.25 * rho, 4.0 * rho);
  }
  return best;
}

// ---- ordering along the cable (Graph method) ---------------------------------------------

struct Chain {
  std::vector<Vec3> nodes;
  std::vector<double> s;     ///< cumulative arc length
  std::vector<char> bridge;  ///< per segment (i, i+1): spans a gap in the scan
  Vec3 at(double si) const {
    if (nodes.size() == 1) return nodes[0];
    auto it = std::upper_bound(s.begin(), s.end(), si);
    std::size_t j = static_cast<std::size_t>(std::clamp<std::ptrdiff_t>(it - s.begin(), 1, static_cast<std::ptrdiff_t>(s.size() - 1)));
    const double len = s[j] - s[j - 1];
    const double u = len > 0 ? (si - s[j - 1]) / len : 0.0;  // extrapolates beyond the ends
    return nodes[j - 1] + u * (nodes[j] - nodes[j - 1]);
  }
};

/// floor(v / cell) as an integer, clamped to ±2^62: a cell far below the scan's scale (a
/// diameter given in the wrong units) gives quotients beyond any integer type, and
/// converting those is undefined.
std::int64_t grid_index(double v, double cell) {
  return static_cast<std::int64_t>(std::clamp(std::floor(v / cell), -0x1p62, 0x1p62));
}

/// Hash key of the grid cell of p: its indices wrapped to 21 bits each (far cells may
/// share a key; callers compare the points themselves).
std::int64_t cell_key(const Vec3& p, double cell) {
  const std::int64_t ix = grid_index(p.x(), cell) & 0x1FFFFF;
  const std::int64_t iy = grid_index(p.y(), cell) & 0x1FFFFF;
  const std::int64_t iz = grid_index(p.z(), cell) & 0x1FFFFF;
  return (ix << 42) | (iy << 21) | iz;
}

struct UnionFind {
  std::vector<int> parent;
  explicit UnionFind(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  int find(int x) {
    while (parent[static_cast<std::size_t>(x)] != x) x = parent[static_cast<std::size_t>(x)] = parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(x)])];
    return x;
  }
  bool unite(int a, int b) {
    a = find(a);
    b = find(b);
    if (a == b) return false;
    parent[static_cast<std::size_t>(a)] = b;
    return true;
  }
};

/// Unit direction of the run of `path` that ends (step −1: the run before node i, pointing
/// towards it) or starts (step +1: the run after node i, pointing away) at node i, over about
/// `length`; nullopt when the run is shorter than half of that (a lone node).
std::optional<Vec3> run_direction(const std::vector<Vec3>& path, const std::vector<char>& bridge, std::size_t i, int step,
                                  double length) {
  std::size_t j = i;
  double acc = 0.0;
  while (acc < length) {
    if (step < 0 ? (j == 0 || bridge[j - 1]) : (j + 1 >= path.size() || bridge[j])) break;
    const std::size_t k = step < 0 ? j - 1 : j + 1;
    acc += (path[k] - path[j]).norm();
    j = k;
  }
  if (acc < 0.5 * length) return std::nullopt;
  const Vec3 v = step < 0 ? Vec3(path[i] - path[j]) : Vec3(path[j] - path[i]);
  return v.normalized();
}

/// Contracts the cloud onto its axis and orders the contracted nodes by the longest path of
/// their minimum spanning tree. Returns false (with a reason) if nothing tube-like is found.
bool build_chain(const std::vector<Vec3>& pts, const std::vector<Vec3>& sub, const KdTree& tree, double d, Chain& chain,
                 std::string& why) {
  // Seeds: one point per grid cell of size d.
  const double cell = kSeedCell * d;
  std::unordered_map<std::int64_t, std::pair<std::uint32_t, std::uint32_t>> first;  // cell → (first point, count)
  first.reserve(pts.size() / 8 + 16);
  for (std::uint32_t i = 0; i < pts.size(); ++i) {
    auto [it, fresh] = first.emplace(cell_key(pts[i], cell), std::make_pair(i, 0u));
    (void)fresh;
    ++it->second.second;
  }
  std::vector<std::pair<std::uint32_t, std::uint32_t>> seed_cells;
  seed_cells.reserve(first.size());
  for (const auto& kv : first) seed_cells.push_back(kv.second);
  std::sort(seed_cells.begin(), seed_cells.end());  // deterministic order
  std::vector<std::uint32_t> seeds(seed_cells.size());
  for (std::size_t k = 0; k < seeds.size(); ++k) seeds[k] = seed_cells[k].first;
  // Mean shift onto the axis.
  std::vector<Vec3> node(seeds.size());
  std::vector<std::size_t> support(seeds.size(), 0);
  const double rad2 = std::pow(kContractRadius * d, 2);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, seeds.size(), 16), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t k = r.begin(); k != r.end(); ++k) {
      Vec3 x = pts[seeds[k]];
      std::size_t n = 0;
      for (int it = 0; it < 8; ++it) {
        SumResultSet rs{rad2, sub};
        tree.radiusSearchCustomCallback(x.data(), rs, nanoflann::SearchParams(32, 0.0f, false));
        n = rs.n;
        if (n == 0) break;
        const Vec3 nx = rs.sum / static_cast<double>(n);
        const double mv = (nx - x).norm();
        x = nx;
        if (mv < 0.01 * d) break;
      }
      node[k] = x;
      support[k] = n;
    }
  });
  // Drop specks (outliers): support far below the typical. "Typical" is the median over
  // points, not over seeds: scattered outliers occupy one cell each and can outnumber the
  // cable's cells, but not its points.
  double sup_med = 0.0;
  {
    std::vector<std::size_t> order(seeds.size());
    std::iota(order.begin(), order.end(), 0);
    std::sort(order.begin(), order.end(), [&](std::size_t x, std::size_t y) { return support[x] < support[y]; });
    std::size_t acc = 0;
    for (std::size_t k : order) {
      acc += seed_cells[k].second;
      if (2 * acc >= pts.size()) {
        sup_med = static_cast<double>(support[k]);
        break;
      }
    }
  }
  // Merge nodes that converged to the same place (greedy, hash grid of the merge radius).
  const double mr = kMergeRadius * d;
  std::unordered_map<std::int64_t, std::vector<int>> grid;
  std::vector<Vec3> merged_sum;
  std::vector<double> merged_w;
  std::vector<Vec3> merged;
  for (std::size_t k = 0; k < node.size(); ++k) {
    if (static_cast<double>(support[k]) < 0.2 * sup_med || support[k] < 3) continue;
    const Vec3& x = node[k];
    const std::int64_t ix = grid_index(x.x(), mr), iy = grid_index(x.y(), mr), iz = grid_index(x.z(), mr);
    int hit = -1;
    for (int dx = -1; dx <= 1 && hit < 0; ++dx)
      for (int dy = -1; dy <= 1 && hit < 0; ++dy)
        for (int dz = -1; dz <= 1 && hit < 0; ++dz) {
          auto it = grid.find(cell_key(Vec3((ix + dx + 0.5) * mr, (iy + dy + 0.5) * mr, (iz + dz + 0.5) * mr), mr));
          if (it == grid.end()) continue;
          for (int m : it->second)
            if ((merged[static_cast<std::size_t>(m)] - x).squaredNorm() < mr * mr) {
              hit = m;
              break;
            }
        }
    const double w = static_cast<double>(support[k]);
    if (hit < 0) {
      grid[cell_key(x, mr)].push_back(static_cast<int>(merged.size()));
      merged.push_back(x);
      merged_sum.push_back(w * x);
      merged_w.push_back(w);
    } else {
      merged_sum[static_cast<std::size_t>(hit)] += w * x;
      merged_w[static_cast<std::size_t>(hit)] += w;
    }
  }
  const std::size_t n = merged.size();
  for (std::size_t k = 0; k < n; ++k) merged[k] = merged_sum[k] / merged_w[k];
  if (n < 2) {
    why = "the cloud contracts to fewer than two axis nodes";
    return false;
  }
  // Minimum spanning tree over the k-nearest-neighbour graph.
  CloudAdaptor nad{merged};
  KdTree ntree(3, nad, nanoflann::KDTreeSingleIndexAdaptorParams(10));
  const std::size_t K = std::min<std::size_t>(8, n);
  struct Edge {
    double w;
    int a, b;
  };
  std::vector<Edge> edges;
  edges.reserve(n * K);
  std::vector<std::uint32_t> idx(K);
  std::vector<double> d2(K);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t got = ntree.knnSearch(merged[i].data(), K, idx.data(), d2.data());
    for (std::size_t j = 0; j < got; ++j)
      if (idx[j] > i) edges.push_back({std::sqrt(d2[j]), static_cast<int>(i), static_cast<int>(idx[j])});
  }
  std::sort(edges.begin(), edges.end(), [](const Edge& x, const Edge& y) { return x.w < y.w; });
  UnionFind uf(n);
  std::vector<std::vector<std::pair<int, double>>> adj(n);
  auto add_edge = [&](const Edge& e) {
    adj[static_cast<std::size_t>(e.a)].push_back({e.b, e.w});
    adj[static_cast<std::size_t>(e.b)].push_back({e.a, e.w});
  };
  for (const auto& e : edges)
    if (uf.unite(e.a, e.b)) add_edge(e);
  // Components: drop specks of fewer than 3 nodes, then bridge the rest (gaps in the scan)
  // by their shortest connections between tree leaves.
  std::unordered_map<int, std::vector<int>> comps;
  for (std::size_t i = 0; i < n; ++i) comps[uf.find(static_cast<int>(i))].push_back(static_cast<int>(i));
  std::vector<char> alive(n, 1);
  if (comps.size() > 1) {
    std::size_t largest = 0;
    for (const auto& c : comps) largest = std::max(largest, c.second.size());
    for (const auto& c : comps)
      if (c.second.size() < 3 && c.second.size() < largest)
        for (int v : c.second) alive[static_cast<std::size_t>(v)] = 0;
    std::vector<int> ends;
    for (std::size_t i = 0; i < n; ++i)
      if (alive[i] && adj[i].size() <= 1) ends.push_back(static_cast<int>(i));
    std::vector<Edge> bridge;
    for (std::size_t x = 0; x < ends.size(); ++x)
      for (std::size_t y = x + 1; y < ends.size(); ++y) {
        const int a = ends[x], b = ends[y];
        if (uf.find(a) == uf.find(b)) continue;
        bridge.push_back({(merged[static_cast<std::size_t>(a)] - merged[static_cast<std::size_t>(b)]).norm(), a, b});
      }
    std::sort(bridge.begin(), bridge.end(), [](const Edge& x, const Edge& y) { return x.w < y.w; });
    for (const auto& e : bridge)
      if (uf.unite(e.a, e.b)) add_edge(e);
  }
  // Longest path of the tree containing the most nodes (two farthest-node sweeps).
  auto farthest = [&](int src, std::vector<int>& parent) {
    std::vector<double> dist(n, -1.0);
    parent.assign(n, -1);
    std::vector<int> stack{src};
    dist[static_cast<std::size_t>(src)] = 0.0;
    int best = src;
    while (!stack.empty()) {
      const int v = stack.back();
      stack.pop_back();
      if (dist[static_cast<std::size_t>(v)] > dist[static_cast<std::size_t>(best)]) best = v;
      for (const auto& [u, w] : adj[static_cast<std::size_t>(v)]) {
        if (!alive[static_cast<std::size_t>(u)] || dist[static_cast<std::size_t>(u)] >= 0.0) continue;
        dist[static_cast<std::size_t>(u)] = dist[static_cast<std::size_t>(v)] + w;
        parent[static_cast<std::size_t>(u)] = v;
        stack.push_back(u);
      }
    }
    return best;
  };
  int start = -1;
  {
    std::size_t best_size = 0;
    std::unordered_map<int, std::size_t> size_of;
    for (std::size_t i = 0; i < n; ++i)
      if (alive[i]) ++size_of[uf.find(static_cast<int>(i))];
    for (std::size_t i = 0; i < n; ++i)
      if (alive[i] && size_of[uf.find(static_cast<int>(i))] > best_size) {
        best_size = size_of[uf.find(static_cast<int>(i))];
        start = static_cast<int>(i);
      }
  }
  if (start < 0) {
    why = "no connected axis nodes";
    return false;
  }
  std::vector<int> parent;
  const int a = farthest(start, parent);
  const int b = farthest(a, parent);
  std::vector<Vec3> path;
  for (int v = b; v >= 0; v = parent[static_cast<std::size_t>(v)]) path.push_back(merged[static_cast<std::size_t>(v)]);
  if (path.size() < 2) {
    why = "the axis nodes do not form a path";
    return false;
  }
  // Segments much longer than the node spacing bridge gaps in the scan.
  std::vector<char> bridge(path.size() - 1, 0);
  for (std::size_t i = 0; i + 1 < path.size(); ++i) bridge[i] = (path[i + 1] - path[i]).norm() > kBridgeLength * d;
  // Light smoothing (1-2-1; ends and gap edges fixed) removes the zig-zag of contracted nodes.
  for (int pass = 0; pass < 2; ++pass) {
    std::vector<Vec3> sm = path;
    for (std::size_t i = 1; i + 1 < path.size(); ++i)
      if (!bridge[i - 1] && !bridge[i]) sm[i] = 0.25 * path[i - 1] + 0.5 * path[i] + 0.25 * path[i + 1];
    path.swap(sm);
  }
  // A bridge joins two scanned stretches of one cable only if it carries on from both:
  // pieces joined at a sharp turn are separate cables (or a cable and something else).
  for (std::size_t i = 0; i + 1 < path.size(); ++i) {
    if (!bridge[i]) continue;
    const Vec3 across = path[i + 1] - path[i];
    const auto before = run_direction(path, bridge, i, -1, kBridgeTangentLength * d);
    const auto after = run_direction(path, bridge, i + 1, +1, kBridgeTangentLength * d);
    double turn = 0.0;
    for (const auto& dir : {before, after})
      if (dir) turn = std::max(turn, std::acos(std::clamp(dir->dot(across.normalized()), -1.0, 1.0)));
    if (turn > kMaxBridgeTurn) {
      why = "the cloud holds separate pieces that do not continue each other (a gap of " +
            std::to_string(across.norm()) + " between them turns by " + std::to_string(turn * 180.0 / M_PI) +
            " degrees): more than one cable, or a cable and another object";
      return false;
    }
  }
  chain.bridge = std::move(bridge);
  chain.nodes = std::move(path);
  chain.s.assign(chain.nodes.size(), 0.0);
  for (std::size_t i = 1; i < chain.nodes.size(); ++i)
    chain.s[i] = chain.s[i - 1] + (chain.nodes[i] - chain.nodes[i - 1]).norm();
  return true;
}

/// Arc-length coordinate of each point along the chain, and its distance to it.
void project_on_chain(const std::vector<Vec3>& pts, const Chain& chain, double d, std::vector<double>& s,
                      std::vector<double>& dist) {
  CloudAdaptor cad{chain.nodes};
  KdTree ctree(3, cad, nanoflann::KDTreeSingleIndexAdaptorParams(10));
  s.resize(pts.size());
  dist.resize(pts.size());
  const std::size_t m = chain.nodes.size();
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, pts.size(), 1024), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t i = r.begin(); i != r.end(); ++i) {
      std::uint32_t j;
      double d2;
      ctree.knnSearch(pts[i].data(), 1, &j, &d2);
      double best = std::numeric_limits<double>::infinity(), bs = chain.s[j];
      for (int side = -1; side <= 0; ++side) {
        const std::ptrdiff_t k0 = static_cast<std::ptrdiff_t>(j) + side;
        if (k0 < 0 || k0 + 1 >= static_cast<std::ptrdiff_t>(m)) continue;
        const auto a = static_cast<std::size_t>(k0), b = a + 1;
        const Vec3 seg = chain.nodes[b] - chain.nodes[a];
        const double L2 = seg.squaredNorm();
        double u = L2 > 0 ? (pts[i] - chain.nodes[a]).dot(seg) / L2 : 0.0;
        const bool open_lo = a == 0, open_hi = b == m - 1;  // extrapolate past the chain ends
        const double over = L2 > 0 ? kEndOvershoot * d / std::sqrt(L2) : 0.0;
        u = std::max(u, open_lo ? -over : 0.0);
        u = std::min(u, open_hi ? 1.0 + over : 1.0);
        // A bridge over a gap holds points only near its ends (the sides of the gap).
        if (chain.bridge[a] && u > over && u < 1.0 - over) u = u < 0.5 ? over : 1.0 - over;
        const double dd = (pts[i] - (chain.nodes[a] + u * seg)).squaredNorm();
        if (dd < best) {
          best = dd;
          bs = chain.s[a] + u * std::sqrt(L2);
        }
      }
      if (!std::isfinite(best)) best = d2;
      s[i] = bs;
      dist[i] = std::sqrt(best);
    }
  });
}

/// True if a pass-1 block fit (free radius) measures the cable's diameter, nominally d: a
/// radius beyond d is a failed fit, and so is one whose points lie farther from the fitted
/// surface, on average, than the radius itself. Why the second: a start radius far below
/// the cloud's (a diameter of 1e-300 given for a 2 mm cable) keeps the least-squares steps,
/// scaled by it, too small to move; the fit then ends where it began, its radius "agreeing"
/// with the given one while every point is millimetres off.
bool measures_diameter(const FitOut& f, double d) { return f.ok && f.r < d && f.rms <= f.r; }

}  // namespace

std::optional<double> estimate_tube_diameter(const std::vector<Vec3>& cloud, std::uint64_t seed) {
  if (cloud.size() < 2 * kMinBlockPoints) return std::nullopt;
  CloudAdaptor ad{cloud};
  KdTree tree(3, ad, nanoflann::KDTreeSingleIndexAdaptorParams(16));
  return coarse_diameter(cloud, tree, seed);
}

namespace {

/// A block of the cable: an interval of the ordering coordinate, within one run.
struct Span {
  double s0, s1;
  bool run_first, run_last;
  double run0, run1;  ///< extent of the run (stretch between gaps) the block belongs to
};

/// One run of extract_centerline: the cloud, the options and what the stages share. Each
/// stage returns false once it has settled the result (fail()); run() calls them in order.
class CenterlineExtraction {
 public:
  CenterlineExtraction(const std::vector<Vec3>& cloud_in, const ScanOptions& opt_in);
  /// Runs the stages and returns the result.
  ScanResult run();

 private:
  /// The nominal diameter: given, or estimated on a strided subset of the cloud.
  bool estimate_diameter();
  /// The ordering coordinate of every point, the blocks along it, and the points bucketed
  /// into the blocks.
  bool order_points();
  /// Block fits: pass 1 (free radius), the diameter check, pass 2 (nominal radius,
  /// smoothness prior).
  bool fit_blocks();
  /// One pass of block fits (in parallel), warm-started from `init` when given.
  void run_pass(bool free_radius, double radius, const std::vector<std::optional<Vec3>>& priors,
                const std::vector<FitOut>* init);
  /// Key points in order along the cable, the spline through them, the gaps along it.
  bool key_points_and_spline();
  /// Settles the result with `st` and `msg`; returns false.
  bool fail(ScanStatus st, std::string msg);

  const ScanOptions& opt;
  const Stopwatch t_start;
  Stopwatch t0;
  ScanResult res;
  std::vector<Vec3> finite;                    ///< the finite points, when some are not
  const std::vector<Vec3>* cloud_ptr = nullptr;  ///< the points worked on
  std::vector<Vec3> sub_storage;
  const std::vector<Vec3>* sub_ptr = nullptr;  ///< the neighbourhood subset
  std::unique_ptr<CloudAdaptor> adaptor;
  std::unique_ptr<KdTree> tree;                ///< over the subset
  double d = 0.0;                              ///< nominal diameter
  const bool graph;                            ///< ScanMethod::Graph
  std::vector<double> s;                       ///< ordering coordinate per point
  std::vector<char> use;                       ///< per point: takes part in the fits
  Chain chain;
  Vec3 axis_dir = Vec3::UnitX();
  int axis_k = 0;
  std::vector<Span> spans;
  std::size_t m = 0;                           ///< blocks
  std::vector<std::size_t> start;              ///< block b's points: sorted[start[b], start[b + 1])
  std::vector<Vec3> sorted;
  std::vector<FitOut> fits;
  std::vector<Vec3> c0, a0;                    ///< initial centre and direction per block
  std::vector<FitOut> pass1;
};

CenterlineExtraction::CenterlineExtraction(const std::vector<Vec3>& cloud_in, const ScanOptions& opt_in)
    : opt(opt_in), graph(opt_in.method == ScanMethod::Graph) {
  if (opt.diameter && !(std::isfinite(*opt.diameter) && *opt.diameter > 0.0))
    throw std::invalid_argument("extract_centerline: diameter must be positive and finite");
  if (!(std::isfinite(opt.block_length) && opt.block_length >= 0.0))
    throw std::invalid_argument("extract_centerline: block length must be >= 0 and finite");
  res.method = opt.method;
  res.points = cloud_in.size();
  // Work on finite points only.
  cloud_ptr = &cloud_in;
  if (!std::all_of(cloud_in.begin(), cloud_in.end(), [](const Vec3& p) { return p.allFinite(); })) {
    for (const auto& p : cloud_in)
      if (p.allFinite()) finite.push_back(p);
    cloud_ptr = &finite;
  }
}

bool CenterlineExtraction::fail(ScanStatus st, std::string msg) {
  res.status = st;
  res.message = std::move(msg);
  return false;
}

ScanResult CenterlineExtraction::run() {
  const std::vector<Vec3>& pts = *cloud_ptr;
  if (pts.size() < 2 * kMinBlockPoints)
    fail(ScanStatus::TooFewPoints, "the cloud has " + std::to_string(pts.size()) + " finite points; at least " +
                                       std::to_string(2 * kMinBlockPoints) + " are needed");
  else if (estimate_diameter() && order_points() && fit_blocks() && key_points_and_spline())
    fail(ScanStatus::Ok, "");
  res.timing.total_ms = t_start.ms();
  return res;
}

bool CenterlineExtraction::estimate_diameter() {
  const std::vector<Vec3>& pts = *cloud_ptr;
  t0.restart();
  // Neighbourhood statistics (diameter estimate, contraction onto the axis) only need a
  // bounded, evenly strided subset of the cloud.
  sub_ptr = &pts;
  if (pts.size() > kNeighbourhoodPoints) {
    const double stride = static_cast<double>(pts.size()) / static_cast<double>(kNeighbourhoodPoints);
    sub_storage.reserve(kNeighbourhoodPoints);
    for (std::size_t k = 0; k < kNeighbourhoodPoints; ++k)
      sub_storage.push_back(pts[static_cast<std::size_t>(static_cast<double>(k) * stride)]);
    sub_ptr = &sub_storage;
  }
  const std::vector<Vec3>& sub = *sub_ptr;
  adaptor = std::make_unique<CloudAdaptor>(CloudAdaptor{sub});
  tree = std::make_unique<KdTree>(3, *adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(16));
  if (opt.diameter) {
    d = *opt.diameter;
  } else {
    const Stopwatch tdia;
    auto est = coarse_diameter(sub, *tree, opt.seed);
    res.timing.diameter_ms = tdia.ms();
    if (!est) return fail(ScanStatus::NotATube, "cannot estimate a diameter: no neighbourhood has a circular cross-section");
    d = *est;
    res.diameter_estimated = true;
  }
  res.diameter = d;
  return true;
}

bool CenterlineExtraction::order_points() {
  const std::vector<Vec3>& pts = *cloud_ptr;
  // Ordering coordinate s per point and which points take part.
  s.assign(pts.size(), 0.0);
  use.assign(pts.size(), 1);
  if (opt.method == ScanMethod::Graph) {
    std::string why;
    if (!build_chain(pts, *sub_ptr, *tree, d, chain, why)) return fail(ScanStatus::NotATube, why);
    std::vector<double> dist;
    project_on_chain(pts, chain, d, s, dist);
    for (std::size_t i = 0; i < pts.size(); ++i) use[i] = dist[i] <= kOutlierDistance * d;
  } else {
    AABB box;
    for (const auto& p : pts) box.extend(p);
    box.size().maxCoeff(&axis_k);
    axis_dir = Vec3::Unit(axis_k);
    for (std::size_t i = 0; i < pts.size(); ++i) s[i] = pts[i][axis_k];
  }
  std::vector<double> su;
  su.reserve(pts.size());
  for (std::size_t i = 0; i < pts.size(); ++i)
    if (use[i]) su.push_back(s[i]);
  if (su.size() < 2 * kMinBlockPoints) return fail(ScanStatus::TooFewPoints, "too few points near the cable axis");
  std::sort(su.begin(), su.end());
  const double span = su.back() - su.front();
  const double L_nom = opt.block_length > 0.0
                           ? opt.block_length
                           : std::max(2.0 * d, static_cast<double>(opt.target_block_points) * span /
                                                   static_cast<double>(su.size()));
  // Runs of the cable separated by gaps (stretches without points longer than a block);
  // each run is split into blocks of about L_nom, so that no block straddles a gap.
  {
    const double gap_thr = std::max(L_nom, d);
    std::size_t a = 0;
    for (std::size_t i = 1; i <= su.size(); ++i) {
      if (i < su.size() && su[i] - su[i - 1] <= gap_thr) continue;
      if (i < su.size()) {
        ++res.gaps;
        res.largest_gap = std::max(res.largest_gap, su[i] - su[i - 1]);
      }
      const double r0 = su[a], r1 = su[i - 1];
      const std::size_t mr = static_cast<std::size_t>(std::max(1.0, std::round((r1 - r0) / L_nom)));
      const double Lr = (r1 - r0) / static_cast<double>(mr);
      for (std::size_t k = 0; k < mr; ++k)
        spans.push_back({r0 + static_cast<double>(k) * Lr, k + 1 == mr ? r1 : r0 + static_cast<double>(k + 1) * Lr,
                         k == 0, k + 1 == mr, r0, r1});
      a = i;
    }
  }
  m = spans.size();
  // Bucket the points into blocks (counting sort on the block index).
  start.assign(m + 1, 0);
  std::vector<std::uint32_t> blk_of(pts.size());
  std::vector<double> span_begin(m);
  for (std::size_t b = 0; b < m; ++b) span_begin[b] = spans[b].s0;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    if (!use[i]) continue;
    const auto it = std::upper_bound(span_begin.begin(), span_begin.end(), s[i]);
    const auto b = static_cast<std::size_t>(std::max<std::ptrdiff_t>(it - span_begin.begin() - 1, 0));
    blk_of[i] = static_cast<std::uint32_t>(b);
    ++start[b + 1];
  }
  for (std::size_t b = 0; b < m; ++b) start[b + 1] += start[b];
  sorted.assign(start[m], Vec3::Zero());
  {
    std::vector<std::size_t> fill(start.begin(), start.end() - 1);
    for (std::size_t i = 0; i < pts.size(); ++i)
      if (use[i]) sorted[fill[blk_of[i]]++] = pts[i];
  }
  res.timing.ordering_ms = t0.ms();
  return true;
}

void CenterlineExtraction::run_pass(bool free_radius, double radius, const std::vector<std::optional<Vec3>>& priors,
                                    const std::vector<FitOut>* init) {
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, m, 1), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t b = r.begin(); b != r.end(); ++b) {
      const std::size_t cnt = start[b + 1] - start[b];
      if (cnt < kMinBlockPoints) {
        fits[b] = FitOut{};
        continue;
      }
      FitConfig cfg;
      cfg.curved = graph;
      cfg.robust = graph;
      cfg.free_radius = free_radius;
      cfg.radius = radius;
      cfg.prior = priors[b];
      cfg.prior_weight = opt.smoothness;
      const bool warm = init && (*init)[b].ok;
      FitOut f0;
      if (warm) {
        f0 = (*init)[b];
      } else {
        f0.c = c0[b];
        f0.a = a0[b];
      }
      const Vec3* bp = sorted.data() + start[b];
      if (cnt > kFitSubsample) {
        // Converge on an evenly strided subset, then polish on every point of the block.
        std::vector<Vec3> few;
        few.reserve(kFitSubsample + 1);
        const double stride = static_cast<double>(cnt) / static_cast<double>(kFitSubsample);
        for (std::size_t k = 0; k < kFitSubsample; ++k) few.push_back(bp[static_cast<std::size_t>(static_cast<double>(k) * stride)]);
        BlockFitter coarse(few.data(), few.size(), cfg);
        const FitOut fc = coarse.run(f0, warm);
        if (fc.ok) {
          f0 = fc;
          cfg.max_iter = kPolishIterations;
        }
        BlockFitter full(bp, cnt, cfg);
        fits[b] = full.run(f0, fc.ok || warm);
      } else {
        BlockFitter fitter(bp, cnt, cfg);
        fits[b] = fitter.run(f0, warm);
      }
      if (fits[b].ok && (fits[b].c - c0[b]).norm() > kMaxCentreShift * d) fits[b].ok = false;
      if (fits[b].ok && fits[b].thin) fits[b].ok = false;
    }
  });
}

bool CenterlineExtraction::fit_blocks() {
  // Block fits: pass 1 (free radius when estimating), pass 2 (nominal radius, smoothness prior).
  t0.restart();
  fits.assign(m, FitOut{});
  c0.assign(m, Vec3::Zero());
  a0.assign(m, Vec3::Zero());
  for (std::size_t b = 0; b < m; ++b) {
    const double mid = 0.5 * (spans[b].s0 + spans[b].s1), half = 0.5 * (spans[b].s1 - spans[b].s0);
    if (graph) {
      c0[b] = chain.at(mid);
      // Initial direction from the ordering curve, within the block's run (not across a gap).
      const double h = std::max(half, 0.25 * d);
      Vec3 dir = chain.at(std::min(mid + h, spans[b].run1)) - chain.at(std::max(mid - h, spans[b].run0));
      a0[b] = dir.norm() > 0 ? Vec3(dir.normalized()) : Vec3::UnitX();
    } else {
      Vec3 cen = Vec3::Zero();
      for (std::size_t k = start[b]; k < start[b + 1]; ++k) cen += sorted[k];
      const std::size_t cnt = start[b + 1] - start[b];
      c0[b] = cnt ? Vec3(cen / static_cast<double>(cnt)) : Vec3::Zero();
      a0[b] = axis_dir;
    }
  }
  std::vector<std::optional<Vec3>> no_prior(m);
  // Pass 1 fits the radius too, also when a diameter is given: the cloud's own diameter
  // checks the given one (a wrong one moves every fitted axis by the difference of the
  // radii, and more where the scan saw one side) and the final fits use it.
  run_pass(true, 0.5 * d, no_prior, nullptr);
  std::vector<double> diam;
  for (const auto& f : fits)
    if (measures_diameter(f, d)) diam.push_back(2.0 * f.r);
  if (diam.size() < 2) {
    std::string why = "the block fits do not agree on a diameter";
    const std::size_t thin = static_cast<std::size_t>(
        std::count_if(fits.begin(), fits.end(), [](const FitOut& f) { return f.thin; }));
    if (thin > 0)
      why += ": in " + std::to_string(thin) + " of " + std::to_string(m) +
             " blocks the points cover less than " + std::to_string(kMinArcSectors * 360 / kArcSectors) +
             " degrees around the fitted axis (a line or a surface, not a tube)";
    else if (opt.diameter)
      why += " (is the given diameter " + full_precision(*opt.diameter) + " right?)";
    return fail(ScanStatus::NotATube, why);
  }
  const double fitted_d = median(diam);
  if (res.diameter_estimated) {
    d = fitted_d;
    std::vector<double> dev(diam.size());
    for (std::size_t i = 0; i < diam.size(); ++i) dev[i] = std::abs(diam[i] - d);
    res.diameter_spread = 1.4826 * median(dev);
    res.diameter = d;
  } else if (std::abs(fitted_d - d) > kGivenDiameterTolerance * d) {
    return fail(ScanStatus::NotATube, "the given diameter " + full_precision(d) +
                                            " does not match the cloud: its cross-sections fit a diameter of " +
                                            full_precision(fitted_d));
  }
  std::vector<std::optional<Vec3>> priors(m);
  if (!graph && opt.smoothness > 0.0) {  // the paper's E_ext; the graph method's curved blocks need none
    for (std::size_t b = 0; b < m; ++b) {
      if (!fits[b].ok) continue;
      Vec3 acc = Vec3::Zero();
      for (std::size_t nb : {b - 1, b + 1})  // b − 1 wraps to a huge index for b = 0; not across gaps
        if (nb < m && fits[nb].ok && spans[nb].run0 == spans[b].run0)
          acc += fits[nb].a.dot(fits[b].a) >= 0 ? fits[nb].a : Vec3(-fits[nb].a);
      if (acc.norm() > 0) priors[b] = acc.normalized();
    }
  }
  pass1 = fits;
  run_pass(false, 0.5 * fitted_d, priors, &pass1);
  res.timing.fitting_ms = t0.ms();
  return true;
}

bool CenterlineExtraction::key_points_and_spline() {
  // Key points in order along the cable.
  t0.restart();
  double sq = 0.0;
  bool run_open = false;  // a run's start point has been emitted
  std::vector<std::pair<std::size_t, std::size_t>> gap_keys;  // key point indices either side of a gap
  std::size_t last_run_end = SIZE_MAX;
  for (std::size_t b = 0; b < m; ++b) {
    const FitOut& f = fits[b];
    if (spans[b].run_first) run_open = false;
    if (!f.ok) continue;
    ScanBlock blk;
    Vec3 key = f.c;
    Vec3 dir = f.a;
    if (!graph) {
      // The paper's key point: the fitted centre line at the slab's mid-plane.
      const double mid = 0.5 * (spans[b].s0 + spans[b].s1);
      if (std::abs(f.a[axis_k]) > 0.1) key = f.c + f.a * ((mid - f.c[axis_k]) / f.a[axis_k]);
      if (dir[axis_k] < 0) dir = -dir;
    } else if (dir.dot(a0[b]) < 0) {
      dir = -dir;
    }
    const bool forward = f.a.dot(dir) > 0;
    const double L = spans[b].s1 - spans[b].s0;
    if (graph && !run_open) {
      // Start of a run (the cable's end or the far side of a gap): the fitted axis at the
      // first inliers, so that the curve reaches the end of the scanned stretch.
      const double te = forward ? f.t_min : f.t_max;
      if (last_run_end != SIZE_MAX) gap_keys.emplace_back(last_run_end, res.key_points.size());
      if (std::abs(te) > 0.25 * L) res.key_points.push_back(f.at(te));
    }
    run_open = true;
    blk.center = key;
    blk.direction = dir;
    blk.radius = pass1[b].ok ? pass1[b].r : f.r;
    blk.s_begin = spans[b].s0;
    blk.s_end = spans[b].s1;
    blk.points = start[b + 1] - start[b];
    blk.inliers = f.inliers;
    blk.rms = f.rms;
    res.blocks.push_back(blk);
    res.key_points.push_back(key);
    // End of a run: the last ok block of the run closes it.
    bool last_ok = true;
    for (std::size_t nb = b + 1; nb < m && !spans[nb - 1].run_last; ++nb)
      if (fits[nb].ok) {
        last_ok = false;
        break;
      }
    if (graph && last_ok) {
      const double te = forward ? f.t_max : f.t_min;
      if (std::abs(te) > 0.25 * L) res.key_points.push_back(f.at(te));
      last_run_end = res.key_points.size() - 1;
    }
    sq += f.sq_sum;
    res.inliers += f.inliers;
    res.residual_max = std::max(res.residual_max, f.max_res);
  }
  res.outliers = res.points - res.inliers;
  res.residual_rms = res.inliers ? std::sqrt(sq / static_cast<double>(res.inliers)) : 0.0;
  if (res.blocks.size() < 2)
    return fail(res.blocks.empty() ? ScanStatus::TooFewPoints : ScanStatus::NotATube,
                  "fewer than two blocks gave a consistent tube fit");
  try {
    res.centerline = Centerline::interpolate(res.key_points, InterpolationOptions{});
  } catch (const std::invalid_argument& e) {
    return fail(ScanStatus::NotATube, std::string("interpolation failed: ") + e.what());
  }
  if (graph && !gap_keys.empty()) {
    // Gaps measured along the recovered curve, between the ends of the scanned stretches.
    const auto& kp = res.centerline.key_parameters();
    res.gaps = static_cast<int>(gap_keys.size());
    res.largest_gap = 0.0;
    for (const auto& [a, b] : gap_keys) {
      const double g = kp.size() == res.key_points.size()
                           ? res.centerline.arc_length_at(kp[b]) - res.centerline.arc_length_at(kp[a])
                           : (res.key_points[b] - res.key_points[a]).norm();
      res.largest_gap = std::max(res.largest_gap, g);
    }
  }
  res.timing.spline_ms = t0.ms();
  return true;
}

}  // namespace

ScanResult extract_centerline(const std::vector<Vec3>& cloud_in, const ScanOptions& opt) {
  return CenterlineExtraction(cloud_in, opt).run();
}

}  // namespace loom
