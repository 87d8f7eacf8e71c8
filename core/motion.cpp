#include "core/motion.hpp"

#include <algorithm>
#include <cmath>

namespace loom {

namespace {
constexpr double kDegToRad = M_PI / 180.0;
/// Most poses pose_samples() returns: a finer envelope than this is not worth its meshes.
constexpr std::size_t kMaxPoseSamples = 4096;
}  // namespace

const char* motion_kind_name(MotionKind k) { return k == MotionKind::Rotate ? "rotate" : "translate"; }

Eigen::Isometry3d Motion::pose(double q) const {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  if (kind == MotionKind::Translate) {
    t.translation() = axis * q;
    return t;
  }
  // Rotation about the line through c: x ↦ R (x − c) + c.
  const Eigen::Matrix3d r = Eigen::AngleAxisd(q * kDegToRad, axis).toRotationMatrix();
  t.linear() = r;
  t.translation() = axis_point - r * axis_point;
  return t;
}

double Motion::max_point_speed(const Mesh& m) const {
  if (kind == MotionKind::Translate) return 1.0;
  double rmax = 0.0;
  for (const Vec3& v : m.vertices) rmax = std::max(rmax, axis.cross(v - axis_point).norm());
  return rmax * kDegToRad;
}

std::string Motion::pose_unit(const std::string& units) const { return kind == MotionKind::Rotate ? "deg" : units; }

void validate_motion(Motion& m, const std::string& file, int line, const std::string& where) {
  const auto fail = [&](const std::string& why) { throw InputError({file, line, where}, why); };
  if (!m.axis_point.allFinite() || !m.axis.allFinite() || !std::isfinite(m.from) || !std::isfinite(m.to))
    fail("every value must be finite");
  const double n = m.axis.norm();
  if (!(n > 0.0) || !std::isfinite(n))
    fail(std::string(m.kind == MotionKind::Rotate ? "axis" : "direction") + " must not be zero");
  m.axis /= n;
  const char* lo = m.kind == MotionKind::Rotate ? "from_deg" : "from";
  const char* hi = m.kind == MotionKind::Rotate ? "to_deg" : "to";
  if (m.from > m.to)
    fail(std::string(lo) + " " + full_precision(m.from) + " is greater than " + hi + " " + full_precision(m.to));
  if (m.kind == MotionKind::Rotate && (std::abs(m.from) > kMaxMotionDegrees || std::abs(m.to) > kMaxMotionDegrees))
    fail("angles must be within ±360 degrees, got " + full_precision(m.from) + " .. " + full_precision(m.to));
}

Mesh posed_mesh(const Mesh& m, const Motion& motion, double q) {
  Mesh out = m;
  const Eigen::Isometry3d t = motion.pose(q);
  for (Vec3& v : out.vertices) v = t * v;
  return out;
}

std::vector<double> pose_samples(const Motion& motion, const Mesh& m, double max_gap, double* gap) {
  const double range = motion.to - motion.from;
  if (gap) *gap = 0.0;
  if (!(range > 0.0)) return {motion.from};
  const double travel = motion.max_point_speed(m) * range;
  const double want = max_gap > 0.0 ? std::ceil(travel / max_gap) : 1.0;
  const std::size_t steps = static_cast<std::size_t>(std::clamp(want, 1.0, double(kMaxPoseSamples - 1)));
  std::vector<double> q(steps + 1);
  for (std::size_t i = 0; i <= steps; ++i) q[i] = motion.from + range * double(i) / double(steps);
  q.back() = motion.to;
  if (gap) *gap = travel / double(steps);
  return q;
}

}  // namespace loom
