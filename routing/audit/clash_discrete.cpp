// The seed paper's discrete-point method, with an index and as its brute-force O(n·m)
// baseline (clash_context.hpp, clash_check.hpp for the contract).
#include "routing/audit/clash_context.hpp"
#include "routing/audit/pair_contacts.hpp"

#include "core/error.hpp"
#include "index/brute_force_index.hpp"
#include "index/triangle_distance.hpp"
#include "routing/curve/cable_limit.hpp"

#include <algorithm>
#include <cmath>
#include <mutex>
#include <stdexcept>
#include <string>
#include <unordered_map>

namespace loom::audit {

namespace {

/// Nearest part to p by brute force over every triangle, and every closed part holding p
/// strictly (winding number > 1/2, and off its surface by more than its rounding, as
/// parts_holding decides).
struct BruteHit {
  int part = -1;
  double dist = kInf;
  std::vector<int> inside;  ///< ascending
};

BruteHit brute_point(const Context& ctx, const Vec3& p) {
  BruteHit best;
  for (std::size_t q = 0; q < ctx.parts.size(); ++q) {
    const Mesh& m = ctx.parts[q].mesh;
    double d2 = kInf;
    double wind = 0.0;
    const bool closed = ctx.info[q].closed;
    for (std::size_t t = 0; t < m.triangles.size(); ++t) {
      const auto c = m.corners(t);
      d2 = std::min(d2, closest_point_on_triangle(p, c[0], c[1], c[2]).dist2);
      if (closed) wind += triangle_solid_angle(p, c[0], c[1], c[2]);
    }
    const double d = std::sqrt(d2);
    if (closed && std::abs(wind) > 2.0 * M_PI && d > surface_rounding(ctx.info[q].box))  // winding number > 1/2
      best.inside.push_back(static_cast<int>(q));
    if (d < best.dist) {
      best.dist = d;
      best.part = static_cast<int>(q);
    }
  }
  return best;
}

/// Side of the discrete method's grid cells: the largest contact distance over all cables.
double sample_cell(const std::vector<CableInput>& cables) {
  double rmax = 0.0;
  for (const auto& c : cables) rmax = std::max(rmax, c.radius);
  return std::max(2.0 * rmax, 1e-12);
}

/// "sample spacing L (--spacing)" or "(its diameter)", for refusals.
std::string spacing_words(const ClashRequest& req, double l) {
  return "sample spacing " + full_precision(l) + (req.spacing > 0.0 ? " (--spacing)" : " (its diameter)");
}

}  // namespace

void check_discrete_work(const Context& ctx) {
  const ClashRequest& req = ctx.req;
  // A spacing far below the cable's length is a request mistake: name the cable and where
  // the spacing came from.
  for (const auto& c : ctx.cables) {
    const double l = discrete_spacing(req, c);
    const double n = std::ceil(c.curve.length() / l);
    if (n > Centerline::kMaxArcSamples)
      throw CableLimitError(c.id, "cable '" + c.id + "': " + spacing_words(req, l) + " gives " + full_precision(n) +
                                      " samples over its length " + full_precision(c.curve.length()) +
                                      ", more than the " + full_precision(Centerline::kMaxArcSamples) +
                                      " the discrete method takes");
  }
  if (!req.use_index || (!req.check_cable_cable && !req.check_self)) return;
  // The grid of discrete_cable_pairs hands every sample (and midpoint) the samples of the 27
  // cells around its own, which hold at least the samples of its own cable within half a
  // cell of arc length (chords are no longer than their arcs): a lower bound on the pairs
  // that its own count, made once the samples exist, can only exceed.
  const double reach = 0.5 * sample_cell(ctx.cables);
  double total = 0.0, most = -1.0;
  std::size_t worst = 0;
  for (std::size_t c = 0; c < ctx.cables.size(); ++c) {
    const double L = ctx.cables[c].curve.length();
    const double intervals = std::max(1.0, std::ceil(L / discrete_spacing(req, ctx.cables[c])));
    const double samples = intervals + 1.0;
    const double near = std::min(samples, std::floor(reach / (L / intervals)) + 1.0);
    const double pairs = 2.0 * samples * near;
    total += pairs;
    if (pairs > most) {
      most = pairs;
      worst = c;
    }
  }
  if (!(total > static_cast<double>(req.limits.max_sample_pairs))) return;
  const CableInput& c = ctx.cables[worst];
  throw CableLimitError(c.id, "cable '" + c.id + "': " + spacing_words(req, discrete_spacing(req, c)) +
                                  " puts samples so close that the discrete method would compare at least " +
                                  full_precision(total) + " pairs of samples, more than the " +
                                  full_precision(static_cast<double>(req.limits.max_sample_pairs)) +
                                  " it takes (each sample meets those within " + full_precision(reach) +
                                  " of it along the cable)");
}

void discrete_structure(Context& ctx, int cable, const DiscreteSamples& ds, StretchTracker& tr) {
  const double r = ctx.cables[cable].radius;
  ClashCounters count;
  std::vector<int> inside;             // the closed parts holding a sample (reused)
  std::vector<PartObservation> obs;  // what one sample sees (reused)
  for (std::size_t k = 0; k < ds.p.size(); ++k) {
    const Vec3& p = ds.p[k];
    const double s0 = k == 0 ? 0.0 : 0.5 * (ds.s[k - 1] + ds.s[k]);
    const double s1 = k + 1 == ds.p.size() ? ds.s[k] : 0.5 * (ds.s[k] + ds.s[k + 1]);
    // A sample inside closed parts clashes with each of them (parts modelled through each
    // other, a keep-out zone around a box); else with the nearest part, within its band.
    obs.clear();
    auto observe = [&](int part, double key, bool in) {
      PartObservation o;
      o.point = p;
      o.s = ds.s[k];
      o.part = part;
      o.key = key;
      o.inside = in;
      if (o.key < ctx.info[part].required) obs.push_back(o);
    };
    if (ctx.req.use_index) {
      ++count.inside_queries;
      ctx.index->inside_parts(p, inside);
      for (const int q : inside) observe(q, -r, true);
      if (inside.empty()) {
        ++count.distance_queries;
        const ClosestHit h = ctx.index->closest(p, r + ctx.band);
        if (h.found()) observe(h.part, h.distance - r, false);
      }
    } else {
      ++count.distance_queries;
      ++count.inside_queries;
      const BruteHit h = brute_point(ctx, p);
      for (const int q : h.inside) observe(q, -r, true);
      if (h.inside.empty() && h.part >= 0) observe(h.part, h.dist - r, false);
    }
    tr.step(obs, s0, s1);
  }
  tr.flush();
  ctx.counters.add(count);
}

/// Cable–cable (min sample distance < r₁ + r₂) and self (non-adjacent samples < 2r, then
/// the midpoint test) contacts, through a uniform grid or all pairs (no index).
void discrete_cable_pairs(Context& ctx, const std::vector<DiscreteSamples>& ds, std::vector<ClashEntry>& out) {
  if (!ctx.req.check_cable_cable && !ctx.req.check_self) return;
  const auto& cables = ctx.cables;
  std::vector<PairContact> contacts;
  std::mutex mu;
  // Test point k of cable a (or the midpoint of k, k+1 when mid) against sample m of b.
  auto test = [&](int a, std::size_t k, bool mid, int b, std::size_t m, std::vector<PairContact>& local,
                  std::int64_t& tests) {
    const bool self = a == b;
    if (self) {
      // Non-adjacent samples (|k − m| ≥ 2, the paper at l = 2r) and midpoints of pairs away
      // from the judged point; at a finer spacing also |s − t| ≥ π r (DESIGN §5), else
      // every pair of neighbours closer than 2r would count.
      const long dk = static_cast<long>(m) - static_cast<long>(k);
      if (!mid && dk < 2) return;  // each unordered pair once
      if (mid && dk >= -1 && dk <= 2) return;
      const double sk = mid ? 0.5 * (ds[a].s[k] + ds[a].s[k + 1]) : ds[a].s[k];
      if (std::abs(ds[b].s[m] - sk) < M_PI * cables[a].radius) return;
    } else if (a > b) {
      return;
    }
    const Vec3 p = mid ? Vec3(0.5 * (ds[a].p[k] + ds[a].p[k + 1])) : ds[a].p[k];
    const Vec3& q = ds[b].p[m];
    ++tests;
    const double d = (p - q).norm();
    const double limit = cables[a].radius + cables[b].radius;
    if (!(d < limit)) return;
    const double s = mid ? 0.5 * (ds[a].s[k] + ds[a].s[k + 1]) : ds[a].s[k];
    const double t = ds[b].s[m];
    if (self ? self_excused_at_node(cables[a], p, q) : excused(cables[a], s, p, cables[b], t, q)) return;
    const double ha = ds[a].spacing, hb = ds[b].spacing;
    local.push_back(PairContact::ordered(a, s, s - ha, s + ha, p, b, t, t - hb, t + hb, q, d));
    if (local.size() > ctx.req.limits.max_pair_contacts) refuse_contacts(ctx, local, "samples");
  };
  auto merge = [&](std::vector<PairContact>& local) {
    std::lock_guard<std::mutex> lock(mu);
    contacts.insert(contacts.end(), local.begin(), local.end());
    if (contacts.size() > ctx.req.limits.max_pair_contacts) refuse_contacts(ctx, contacts, "samples");
  };
  auto want = [&](int a, int b) { return a == b ? ctx.req.check_self : ctx.req.check_cable_cable; };
  if (!ctx.req.use_index) {
    // The paper: every sample pair of every cable pair.
    parallel_indices(cables.size(), ctx.req.threads, [&](std::size_t ai) {
      const int a = static_cast<int>(ai);
      std::vector<PairContact> local;
      std::int64_t tests = 0;
      for (int b = a; b < static_cast<int>(cables.size()); ++b) {
        if (!want(a, b)) continue;
        for (std::size_t k = 0; k < ds[a].p.size(); ++k) {
          for (std::size_t m = 0; m < ds[b].p.size(); ++m) {
            test(a, k, false, b, m, local, tests);
            if (a == b && k + 1 < ds[a].p.size()) test(a, k, true, b, m, local, tests);
          }
        }
      }
      ctx.counters.pairs += tests;
      if (!local.empty()) merge(local);
    });
  } else {
    // Uniform grid of samples, cell = the largest contact distance.
    const double cell = sample_cell(cables);
    auto key = [&](const Vec3& p) {
      const std::int64_t x = static_cast<std::int64_t>(std::floor(p.x() / cell));
      const std::int64_t y = static_cast<std::int64_t>(std::floor(p.y() / cell));
      const std::int64_t z = static_cast<std::int64_t>(std::floor(p.z() / cell));
      return std::array<std::int64_t, 3>{x, y, z};
    };
    struct KeyHash {
      std::size_t operator()(const std::array<std::int64_t, 3>& k) const {
        return static_cast<std::size_t>(k[0] * 73856093LL ^ k[1] * 19349663LL ^ k[2] * 83492791LL);
      }
    };
    std::unordered_map<std::array<std::int64_t, 3>, std::vector<std::pair<int, std::size_t>>, KeyHash> grid;
    for (std::size_t c = 0; c < cables.size(); ++c)
      for (std::size_t k = 0; k < ds[c].p.size(); ++k) grid[key(ds[c].p[k])].emplace_back(static_cast<int>(c), k);
    // Bound the work before doing it: every sample (and midpoint) meets the samples of the
    // 27 cells around its own. Routes stay far below the limit; one folding back on itself
    // thousands of times packs its samples into a few cells.
    double candidates = 0.0, worst = -1.0;
    int worst_cable = 0;  // a cable in the most crowded neighbourhood, for the message
    for (const auto& [k, members] : grid) {
      double near = 0.0;
      for (int dx = -1; dx <= 1; ++dx)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dz = -1; dz <= 1; ++dz) {
            const auto it = grid.find({k[0] + dx, k[1] + dy, k[2] + dz});
            if (it != grid.end()) near += static_cast<double>(it->second.size());
          }
      candidates += 2.0 * static_cast<double>(members.size()) * near;
      if (near > worst) {
        worst = near;
        worst_cable = members.front().first;
      }
    }
    if (candidates > static_cast<double>(ctx.req.limits.max_sample_pairs))
      throw CableLimitError(cables[worst_cable].id,
                            "the discrete method would compare about " + full_precision(std::round(candidates)) +
                                " pairs of samples (limit " +
                                full_precision(static_cast<double>(ctx.req.limits.max_sample_pairs)) + "; cable '" +
                                cables[worst_cable].id + "' among them): " + kFoldBack);
    parallel_indices(cables.size(), ctx.req.threads, [&](std::size_t ai) {
      const int a = static_cast<int>(ai);
      std::vector<PairContact> local;
      std::int64_t tests = 0;
      for (std::size_t k = 0; k < ds[a].p.size(); ++k) {
        for (int mid = 0; mid < 2; ++mid) {
          if (mid && k + 1 >= ds[a].p.size()) continue;
          const Vec3 p = mid ? Vec3(0.5 * (ds[a].p[k] + ds[a].p[k + 1])) : ds[a].p[k];
          const auto kk = key(p);
          for (int dx = -1; dx <= 1; ++dx)
            for (int dy = -1; dy <= 1; ++dy)
              for (int dz = -1; dz <= 1; ++dz) {
                auto it = grid.find({kk[0] + dx, kk[1] + dy, kk[2] + dz});
                if (it == grid.end()) continue;
                for (const auto& e : it->second) {
                  if (mid && e.first != a) continue;  // the midpoint test is for self only
                  if (!want(a, e.first)) continue;
                  test(a, k, mid != 0, e.first, e.second, local, tests);
                }
              }
        }
      }
      ctx.counters.pairs += tests;
      if (!local.empty()) merge(local);
    });
  }
  ctx.counters.pair_contacts = as_i64(contacts.size());
  group_pair_contacts(contacts, cables, out);
}

}  // namespace loom::audit
