// Segregation of cable classes (DESIGN §5).
#include "routing/audit/segregation.hpp"

#include "index/triangle_distance.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_map>

namespace loom {

namespace {

/// Most chords one cable is flattened into for this check (a finer request is coarsened).
constexpr double kMaxChords = 1e6;

/// A cable flattened into chords: points[i] at arc length s[i].
struct Chords {
  std::vector<Vec3> points;
  std::vector<double> s;
};

Chords flatten(const CableInput& c, double step) {
  const double len = c.curve.length();
  Chords out;
  for (const auto& [s, p] : c.curve.sample_by_arc_length(std::max(step, len / kMaxChords))) {
    out.s.push_back(s);
    out.points.push_back(p);
  }
  return out;
}

/// The bundle segment `c` runs in at arc length s, or −1.
int segment_at(const CableInput& c, double s) {
  for (const auto& r : c.segments)
    if (s >= r.s0 && s <= r.s1) return r.segment;
  return -1;
}

/// Grid cell key of a point.
std::int64_t cell_key(const Vec3& p, double cell, int dx = 0, int dy = 0, int dz = 0) {
  const auto i = static_cast<std::int64_t>(std::floor(p.x() / cell)) + dx;
  const auto j = static_cast<std::int64_t>(std::floor(p.y() / cell)) + dy;
  const auto k = static_cast<std::int64_t>(std::floor(p.z() / cell)) + dz;
  return (i * 73856093) ^ (j * 19349663) ^ (k * 83492791);
}

/// The finding stretches of one pair of cables (a < b) closer than `required`.
void check_pair(const std::vector<CableInput>& cables, int a, int b, double required,
                std::vector<SegregationFinding>& out) {
  const CableInput& ca = cables[static_cast<std::size_t>(a)];
  const CableInput& cb = cables[static_cast<std::size_t>(b)];
  // Shared bundle segments: a finding each, and their chords are not compared again.
  std::vector<int> shared;
  for (const auto& ra : ca.segments)
    for (const auto& rb : cb.segments)
      if (ra.segment == rb.segment) {
        shared.push_back(ra.segment);
        SegregationFinding f{a, b, 0.0, required, 0.5 * (ra.s0 + ra.s1), 0.5 * (rb.s0 + rb.s1),
                             ca.curve.position(ca.curve.parameter_at_length(0.5 * (ra.s0 + ra.s1))), ra.segment};
        out.push_back(f);
      }
  const auto in_shared = [&](const CableInput& c, double s) {
    const int seg = segment_at(c, s);
    return seg >= 0 && std::find(shared.begin(), shared.end(), seg) != shared.end();
  };
  const double step = std::min({required / 8.0, ca.radius, cb.radius});
  const Chords pa = flatten(ca, step), pb = flatten(cb, step);
  const double reach = required + ca.radius + cb.radius;  // centreline distance that is too close
  const double cell = reach + 2.0 * step;
  std::unordered_map<std::int64_t, std::vector<std::size_t>> grid;
  for (std::size_t j = 0; j + 1 < pb.points.size(); ++j)
    grid[cell_key(0.5 * (pb.points[j] + pb.points[j + 1]), cell)].push_back(j);
  std::vector<std::size_t> near;
  bool open = false;
  for (std::size_t i = 0; i + 1 < pa.points.size(); ++i) {
    const Vec3 mid = 0.5 * (pa.points[i] + pa.points[i + 1]);
    double best = std::numeric_limits<double>::infinity();
    SegmentSegmentResult hit;
    std::size_t hit_j = 0;
    if (!in_shared(ca, 0.5 * (pa.s[i] + pa.s[i + 1]))) {
      near.clear();
      for (int dx = -1; dx <= 1; ++dx)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dz = -1; dz <= 1; ++dz)
            if (auto it = grid.find(cell_key(mid, cell, dx, dy, dz)); it != grid.end())
              near.insert(near.end(), it->second.begin(), it->second.end());
      for (std::size_t j : near) {
        if (in_shared(cb, 0.5 * (pb.s[j] + pb.s[j + 1]))) continue;
        const SegmentSegmentResult r = closest_segment_segment(pa.points[i], pa.points[i + 1], pb.points[j], pb.points[j + 1]);
        if (r.dist2 < best) best = r.dist2, hit = r, hit_j = j;
      }
    }
    const double d = std::sqrt(best) - ca.radius - cb.radius;
    if (!(d < required)) {
      open = false;
      continue;
    }
    const double s = pa.s[i] + hit.s * (pa.s[i + 1] - pa.s[i]);
    const double t = pb.s[hit_j] + hit.t * (pb.s[hit_j + 1] - pb.s[hit_j]);
    if (!open) out.push_back({a, b, d, required, s, t, 0.5 * (hit.p + hit.q), -1});
    open = true;
    SegregationFinding& f = out.back();
    if (d < f.distance) f.distance = d, f.s = s, f.s_other = t, f.point = 0.5 * (hit.p + hit.q);
  }
}

}  // namespace

std::vector<SegregationFinding> check_segregation(const std::vector<CableInput>& cables, const SeparationFn& separation) {
  std::vector<SegregationFinding> out;
  for (std::size_t a = 0; a < cables.size(); ++a)
    for (std::size_t b = a + 1; b < cables.size(); ++b) {
      const double required = separation(static_cast<int>(a), static_cast<int>(b));
      if (required > 0.0) check_pair(cables, static_cast<int>(a), static_cast<int>(b), required, out);
    }
  std::sort(out.begin(), out.end(), [](const SegregationFinding& x, const SegregationFinding& y) {
    return std::tie(x.cable, x.other, x.s) < std::tie(y.cable, y.other, y.s);
  });
  return out;
}

}  // namespace loom
