// Cable clearance to moving parts over their motion: branch and bound over the pose with
// the motion's Lipschitz bound, exact FCL distances per pose (motion_clearance.hpp).
#include "routing/audit/motion_clearance.hpp"

#include "index/fcl_index.hpp"
#include "routing/audit/clash_context.hpp"
#include "routing/curve/cable_limit.hpp"

#include <algorithm>
#include <cmath>
#include <queue>

namespace loom {

namespace {

/// Most poses one cable–part pair may take before the audit refuses it: a pose tolerance
/// this many times finer than the part's travel is a tolerance on the scale of rounding.
constexpr std::int64_t kMaxPosesPerPair = 2'000'000;

/// A solid cylinder holding the part at every pose of its motion: points within `rmax` of
/// the line through `o` along `d`, with axial coordinate in [zmin, zmax]. A rotation keeps
/// every point's distance from its axis and its axial coordinate; a translation along d
/// keeps the distance from a parallel line and shifts the axial coordinate.
struct SweptCylinder {
  Vec3 o = Vec3::Zero(), d = Vec3::UnitZ();
  double rmax = 0.0, zmin = 0.0, zmax = 0.0;

  SweptCylinder(const Mesh& m, const Motion& mo) : d(mo.axis) {
    if (mo.kind == MotionKind::Rotate) {
      o = mo.axis_point;
    } else {
      for (const Vec3& v : m.vertices) o += v;
      o /= double(std::max<std::size_t>(1, m.vertices.size()));
    }
    zmin = std::numeric_limits<double>::infinity();
    zmax = -zmin;
    // Distance from a line is convex and the axial coordinate linear: their extremes over
    // the part's hull are at vertices.
    for (const Vec3& v : m.vertices) {
      const double z = (v - o).dot(d);
      rmax = std::max(rmax, ((v - o) - z * d).norm());
      zmin = std::min(zmin, z);
      zmax = std::max(zmax, z);
    }
    if (mo.kind == MotionKind::Translate) zmin += mo.from, zmax += mo.to;
  }
  /// Distance from x to the cylinder (a lower bound on its distance to the part at any pose).
  double distance(const Vec3& x) const {
    const double z = (x - o).dot(d);
    const double dr = std::max(0.0, ((x - o) - z * d).norm() - rmax);
    const double dz = std::max({0.0, zmin - z, z - zmax});
    return std::hypot(dr, dz);
  }
};

/// False when no point of curve c comes within `cutoff` of the cylinder: each knot span lies
/// within its hull deviation of the chord joining its ends (convex hull property), and a
/// chord's distance is at least its midpoint's less half its length. Saves flattening the
/// cables that pass nowhere near a moving part (most of them).
bool may_come_within(const Centerline& c, const SweptCylinder& cyl, double cutoff) {
  const std::vector<double>& k = c.knots();
  double a = c.u_min();
  for (std::size_t i = 0; i < k.size() && a < c.u_max(); ++i) {
    const double b = std::min(k[i], c.u_max());
    if (!(b > a)) continue;
    const Vec3 pa = c.position(a), pb = c.position(b);
    const double lower = cyl.distance(0.5 * (pa + pb)) - 0.5 * (pb - pa).norm() - c.hull_bounds(a, b).deviation;
    if (lower <= cutoff) return true;
    a = b;
  }
  return false;
}

/// Distance from point p to box b (0 inside).
double box_distance(const AABB& b, const Vec3& p) {
  return (b.min - p).cwiseMax(p - b.max).cwiseMax(Vec3::Zero()).norm();
}

/// f(q) of one pose, with where it is reached.
struct PoseValue {
  double f = 0.0;
  std::size_t chord = 0;
  double t = 0.0;
  bool inside = false;
};

}  // namespace

MotionExtremum motion_min_distance(const Chords& ch, const FclIndex& fcl, int part, bool closed, const Motion& motion,
                                   double speed, const Mesh& mesh, double pose_tol, double cutoff) {
  MotionExtremum best;
  best.distance = std::numeric_limits<double>::infinity();
  if (ch.size() == 0) return best;
  const SweptCylinder swept(mesh, motion);
  std::vector<std::size_t> kept;
  for (std::size_t i = 0; i < ch.size(); ++i) {
    const Vec3 &a = ch.p[i], &b = ch.p[i + 1];
    if (swept.distance(0.5 * (a + b)) - 0.5 * (b - a).norm() <= cutoff) kept.push_back(i);
  }
  if (kept.empty()) {
    best.distance = cutoff;  // proven: at least cutoff at every pose
    best.pose = motion.from;
    return best;
  }
  // A chord left out is farther than cutoff > 0 from the part at every pose, so outside it;
  // the polyline is connected, so then no kept run lies wholly inside without crossing the
  // surface (distance 0). Only a polyline kept whole needs an inside test per pose.
  const bool needs_inside = closed && kept.size() == ch.size();
  const AABB rest_box = mesh.bounds();
  const double range = motion.to - motion.from;
  // Values are capped here: min(f, cap) is as Lipschitz as f, and the cap keeps the bound
  // of an interval from proving less than f itself could.
  const double cap = cutoff + speed * range + pose_tol;

  auto eval = [&](double q) {
    ++best.poses;
    const Eigen::Isometry3d to_rest = motion.pose(q).inverse();
    PoseValue v;
    v.f = cap;
    for (std::size_t i : kept) {
      const Vec3 a = to_rest * ch.p[i], b = to_rest * ch.p[i + 1];
      if (box_distance(rest_box, 0.5 * (a + b)) - 0.5 * (b - a).norm() >= v.f) continue;
      double t = 0.0;
      ++best.queries;
      const ClosestHit h = fcl.segment_closest_on_part(a, b, part, v.f, &t);
      if (h.found() && h.distance < v.f) v.f = h.distance, v.chord = i, v.t = t;
    }
    if (needs_inside && v.f > 0.0) {
      std::vector<int> held;
      fcl.inside_parts(to_rest * ch.p.front(), held);
      if (std::find(held.begin(), held.end(), part) != held.end()) v = PoseValue{0.0, 0, 0.0, true};
    }
    if (v.f < best.distance) {
      best.distance = v.f, best.pose = q, best.chord = v.chord, best.t = v.t, best.inside = v.inside;
    }
    return v.f;
  };

  struct Interval {
    double a, b, fa, fb, lower;
    bool operator>(const Interval& o) const { return lower > o.lower; }
  };
  // A distance is never negative: without the 0 floor, a stretch of poses where the cable
  // runs through the part (f = 0 at both ends) was split down to the pose tolerance for
  // nothing (on the wing section, 1,476× the static audit's time).
  auto make = [&](double a, double b, double fa, double fb) {
    return Interval{a, b, fa, fb, std::max(0.0, 0.5 * (fa + fb - speed * (b - a)))};
  };
  const double f0 = eval(motion.from);
  if (!(range > 0.0)) return best;
  const double f1 = eval(motion.to);
  std::priority_queue<Interval, std::vector<Interval>, std::greater<Interval>> open;
  open.push(make(motion.from, motion.to, f0, f1));
  // Below this width an interval cannot hide a value more than pose_tol under its ends.
  const double min_width = speed > 0.0 ? 2.0 * pose_tol / speed : range;
  while (!open.empty()) {
    const Interval iv = open.top();
    // The lowest bound of all: once it cannot beat the best, or cannot reach below the
    // cutoff, no interval can.
    if (iv.lower >= std::min(best.distance, cutoff)) break;
    open.pop();
    // Within the tolerance of the best and narrow: done. Splitting the intervals that could
    // still beat the best down to min_width (not only those beating it by pose_tol) puts the
    // reported pose within pose_tol / speed of a sharp minimum's.
    if (iv.lower >= best.distance - pose_tol && iv.b - iv.a <= min_width) continue;
    if (best.poses >= kMaxPosesPerPair)
      throw std::invalid_argument("more than " + std::to_string(kMaxPosesPerPair) +
                                  " poses needed: the tolerance is too fine for the part's travel");
    const double m = 0.5 * (iv.a + iv.b);
    const double fm = eval(m);
    open.push(make(iv.a, m, iv.fa, fm));
    open.push(make(m, iv.b, fm, iv.fb));
  }
  return best;
}

MotionAudit check_motion_clearance(const std::vector<CableInput>& cables, const std::vector<Part>& parts,
                                   double tolerance, int threads) {
  MotionAudit out;
  std::vector<int> moving;  // scene part index of each moving part
  std::vector<Part> rest;   // the moving parts, in their rest pose, for one FCL index
  for (std::size_t i = 0; i < parts.size(); ++i)
    if (parts[i].motion) moving.push_back(static_cast<int>(i)), rest.push_back(parts[i]);
  if (moving.empty() || cables.empty()) return out;
  const FclIndex fcl(rest);
  out.chord_error = 0.5 * tolerance;
  out.pose_tolerance = 0.5 * tolerance - fcl.accuracy().abs_error;
  if (!(out.pose_tolerance > 0.0))
    throw std::invalid_argument("motion audit: tolerance " + full_precision(tolerance) +
                                " is not above twice the FCL index's rounding");
  std::vector<double> speed(moving.size());
  std::vector<SweptCylinder> swept;
  for (std::size_t k = 0; k < moving.size(); ++k) {
    speed[k] = rest[k].motion->max_point_speed(rest[k].mesh);
    swept.emplace_back(rest[k].mesh, *rest[k].motion);
  }

  struct PerCable {
    std::vector<MotionClash> clashes;
    std::vector<std::string> notes;
    std::int64_t poses = 0, queries = 0;
  };
  std::vector<PerCable> per(cables.size());
  audit::parallel_indices(cables.size(), threads, [&](std::size_t c) {
    const CableInput& in = cables[c];
    Chords ch;  // flattened on first need
    for (std::size_t k = 0; k < moving.size(); ++k) {
      if (!may_come_within(in.curve, swept[k], in.radius)) continue;
      if (ch.p.empty())
        flatten(in.curve, in.curve.u_min(), in.curve.u_max(), out.chord_error, audit::kMaxChordRadii * in.radius,
                audit::kShortSpanRadii * in.radius, ch);
      const Part& p = parts[static_cast<std::size_t>(moving[k])];
      const bool attached = std::any_of(in.attachments.begin(), in.attachments.end(),
                                        [&](const PartAttachment& a) { return a.part == moving[k]; });
      if (attached) {
        // A connector on a moving part moves the cable end with it: the cable is not static there.
        per[c].notes.push_back("cable '" + in.id + "' has a port on moving part '" + p.name +
                               "': it moves with the part and is not checked against its motion");
        continue;
      }
      MotionExtremum e;
      try {
        e = motion_min_distance(ch, fcl, static_cast<int>(k), p.closed, *p.motion, speed[k], p.mesh,
                                out.pose_tolerance, in.radius);
      } catch (const std::invalid_argument& err) {
        throw CableLimitError(in.id, "cable '" + in.id + "' against moving part '" + p.name + "': " + err.what());
      }
      per[c].poses += e.poses;
      per[c].queries += e.queries;
      if (!(e.distance < in.radius)) continue;
      MotionClash m;
      m.cable = static_cast<int>(c);
      m.part = moving[k];
      m.clearance = e.distance - in.radius;
      m.pose = e.pose;
      m.inside = e.inside;
      m.motion = p.motion->kind;
      const Vec3 &a = ch.p[e.chord], &b = ch.p[e.chord + 1];
      m.point = a + e.t * (b - a);
      m.s = ch.s[e.chord] + e.t * (ch.s[e.chord + 1] - ch.s[e.chord]);
      per[c].clashes.push_back(m);
    }
  });
  for (auto& pc : per) {
    out.clashes.insert(out.clashes.end(), pc.clashes.begin(), pc.clashes.end());
    out.notes.insert(out.notes.end(), pc.notes.begin(), pc.notes.end());
    out.poses += pc.poses;
    out.distance_queries += pc.queries;
  }
  return out;
}

std::vector<std::string> moving_parts_interpenetrating(const std::vector<Part>& parts) {
  std::vector<std::string> out;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    if (!parts[i].motion) continue;
    for (std::size_t j = i + 1; j < parts.size(); ++j) {
      if (!parts[j].motion) continue;
      const AABB bi = parts[i].mesh.bounds(), bj = parts[j].mesh.bounds();
      if ((bi.min.array() > bj.max.array()).any() || (bj.min.array() > bi.max.array()).any()) continue;
      const FclIndex pair({parts[i], parts[j]});
      // Rounding of a crossing's distance, relative to the pair's size.
      const double eps = 1e-9 * std::max(bi.diagonal(), bj.diagonal());
      auto crosses = [&](std::size_t from, int into) {
        const Mesh& m = parts[from].mesh;
        std::vector<int> held;
        if (!m.vertices.empty()) pair.inside_parts(m.vertices.front(), held);
        if (std::find(held.begin(), held.end(), into) != held.end()) return true;
        for (const auto& t : m.triangles)
          for (int e = 0; e < 3; ++e)
            if (pair.segment_closest_on_part(m.vertices[t[e]], m.vertices[t[(e + 1) % 3]], into, eps).found())
              return true;
        return false;
      };
      if (crosses(i, 1) || crosses(j, 0))
        out.push_back("'" + parts[i].name + "' and '" + parts[j].name + "'" +
                      (parts[i].motion->name.empty() || parts[i].motion->name != parts[j].motion->name
                           ? ""
                           : " (both move with motion '" + parts[i].motion->name + "')"));
    }
  }
  return out;
}

}  // namespace loom
