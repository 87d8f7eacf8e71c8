// `loom scan CLOUD [--diameter D] [--out DIR] [--method axis|graph] [--compare routed.xml
// --cable ID] [--quiet]`: centerline of a scanned cable (DESIGN §4) →
// DIR/centerline.xml (a harness with one routed segment), DIR/tube.ply, DIR/report.json.
#include "app/commands.hpp"
#include "app/option_checks.hpp"

#include "core/stopwatch.hpp"
#include "core/error.hpp"
#include "core/harness_topology.hpp"
#include "core/io/atomic_file.hpp"
#include "core/io/output_set.hpp"
#include "core/io/harness_xml.hpp"
#include "core/io/mesh_write.hpp"
#include "routing/curve/cable_geometry.hpp"
#include "core/io/point_cloud_io.hpp"
#include "core/io/json_text.hpp"
#include "routing/scan/scan_centerline.hpp"
#include "routing/curve/sweep.hpp"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>

namespace loom::app {

namespace {

/// Centerline samples in the report: at most half a diameter apart (DESIGN §4).
constexpr double kSampleSpacing = 0.5;
/// Deviation is evaluated along the designed cable at this spacing (× d).
constexpr double kDeviationSpacing = 0.5;
/// The scanned curve is approximated by a polyline this fine (× d) for distances; its
/// chord error is ≤ (h²/8)·κ, far below the scan's own noise.
constexpr double kDensePolyline = 0.125;
/// Chord tolerance of the swept tube (× d).
constexpr double kTubeChordTolerance = 0.01;

struct ScanCommandOptions {
  std::string cloud;
  double diameter = 0.0;  ///< 0 = estimate
  std::string out = "loom-scan";
  std::string method = "graph";
  std::string compare;
  std::string cable;
  bool quiet = false;
};

nlohmann::json vec_json(const Vec3& v) { return nlohmann::json::array({v.x(), v.y(), v.z()}); }

/// Closest point of a polyline to p: distance, arc length along it, the point.
struct Closest {
  double dist = std::numeric_limits<double>::infinity();
  double s = 0.0;
  Vec3 point = Vec3::Zero();
};

Closest closest_on_polyline(const std::vector<std::pair<double, Vec3>>& poly, const Vec3& p) {
  Closest best;
  for (std::size_t i = 1; i < poly.size(); ++i) {
    const Vec3& a = poly[i - 1].second;
    const Vec3 seg = poly[i].second - a;
    const double L2 = seg.squaredNorm();
    const double u = L2 > 0 ? std::clamp((p - a).dot(seg) / L2, 0.0, 1.0) : 0.0;
    const Vec3 q = a + u * seg;
    const double d = (p - q).norm();
    if (d < best.dist) best = {d, poly[i - 1].first + u * (poly[i].first - poly[i - 1].first), q};
  }
  if (poly.size() == 1) best = {(p - poly[0].second).norm(), poly[0].first, poly[0].second};
  return best;
}

/// The sample of `from` (arc length, point) farthest from the polyline `to`, and the sum of
/// the squared distances of all of them (scene units).
struct Farthest {
  double max = -1.0;
  double sum_sq = 0.0;
  double s = 0.0;  ///< arc length of the farthest sample on its own curve
  Vec3 p = Vec3::Zero();
  Closest on;  ///< its closest point on `to`
};

Farthest farthest_from(const std::vector<std::pair<double, Vec3>>& from, const std::vector<std::pair<double, Vec3>>& to) {
  Farthest f;
  for (const auto& [s, p] : from) {
    const Closest c = closest_on_polyline(to, p);
    f.sum_sq += c.dist * c.dist;
    if (c.dist > f.max) {
      f.max = c.dist;
      f.s = s;
      f.p = p;
      f.on = c;
    }
  }
  return f;
}

/// The one-cable harness that carries the recovered centerline as a routed segment.
Harness scan_harness(const ScanResult& r, const std::string& cloud_name, Unit units) {
  Harness h;
  h.name = "scan";
  h.units = units;
  const Centerline& c = r.centerline;
  Port a, b;
  a.id = "SCAN.A";
  b.id = "SCAN.B";
  a.position = c.position(c.u_min());
  b.position = c.position(c.u_max());
  Vec3 ta = c.derivative(c.u_min(), 1), tb = c.derivative(c.u_max(), 1);
  a.direction = ta.norm() > 0 ? Vec3(ta.normalized()) : Vec3::UnitX();
  b.direction = tb.norm() > 0 ? Vec3(-tb.normalized()) : Vec3(-Vec3::UnitX());  // leaves port B into the cable
  h.ports = {a, b};
  Cable cab;
  cab.id = "SCAN";
  cab.ports[0] = a.id;
  cab.ports[1] = b.id;
  cab.physical.type = "scanned:" + cloud_name;
  cab.physical.diameter = r.diameter;
  h.cables.push_back(cab);
  Segment seg;
  seg.from = a.id;
  seg.to = b.id;
  if (r.key_points.size() > 2) seg.path.assign(r.key_points.begin() + 1, r.key_points.end() - 1);
  seg.interp = Interp::BSpline;
  seg.bspline = BSplineData{c.degree(), c.knots(), c.control_points()};
  h.segments.push_back(seg);
  return h;
}

int run_scan(const ScanCommandOptions& o) {
  const std::filesystem::path out(o.out);
  const std::filesystem::path centerline_file = out / "centerline.xml", tube_file = out / "tube.ply",
                              report_file = out / "report.json";
  OutputSet outputs(out, {centerline_file, tube_file, report_file});  // checked now, replaced together
  using nlohmann::json;
  const Stopwatch t_start;
  const PointCloud pc = read_point_cloud(o.cloud);
  ScanOptions so;
  if (o.diameter > 0.0) so.diameter = o.diameter;
  so.method = o.method == "axis" ? ScanMethod::Axis : ScanMethod::Graph;
  const ScanResult r = extract_centerline(pc.points, so);
  if (r.status != ScanStatus::Ok)
    throw InputError(SourceLocation{o.cloud, 0, ""},
                     std::string("no cable centerline found (") + to_string(r.status) + "): " + r.message);
  const double d = r.diameter;

  // Optional comparison with the designed route.
  std::optional<Harness> design;
  json deviation;
  Unit units = Unit::Millimetre;
  if (!o.compare.empty()) {
    design = read_harness_xml(o.compare);
    units = design->units;
    const HarnessTopology topo(*design);
    const int ci = design->find_cable(o.cable);
    if (ci < 0) throw InputError(SourceLocation{o.compare, 0, "cable"}, "no cable with id '" + o.cable + "'");
    const auto designed = cable_centerline(topo, ci);
    if (!designed)
      throw InputError(SourceLocation{o.compare, design->cables[static_cast<std::size_t>(ci)].line, "cable " + o.cable},
                       "the cable is not routed (a segment of its chain has no position)");
    // Both ways: the design from the scan (where the cable was not laid as designed) and the
    // scan from the design (what was laid beyond the design: a slack loop, a longer run),
    // which the first cannot see.
    const auto along = designed->sample_by_arc_length(kDeviationSpacing * d);
    const Farthest fwd = farthest_from(along, r.centerline.sample_by_arc_length(kDensePolyline * d));
    const Farthest back = farthest_from(r.centerline.sample_by_arc_length(kDeviationSpacing * d),
                                        designed->sample_by_arc_length(kDensePolyline * d));
    const json where = {{"s", fwd.s}, {"point", vec_json(fwd.p)}, {"scanned_point", vec_json(fwd.on.point)},
                        {"scanned_s", fwd.on.s}};
    const json back_where = {{"scanned_s", back.s}, {"scanned_point", vec_json(back.p)},
                             {"point", vec_json(back.on.point)}, {"s", back.on.s}};
    deviation = {{"cable", o.cable},
                 {"routes", o.compare},
                 {"designed_length", designed->length()},
                 {"scanned_length", r.centerline.length()},
                 {"samples", along.size()},
                 {"spacing", kDeviationSpacing * d},
                 {"max", fwd.max},
                 {"rms", along.empty() ? 0.0 : std::sqrt(fwd.sum_sq / static_cast<double>(along.size()))},
                 {"where", where},
                 {"max_scan_to_design", back.max},
                 {"where_scan_to_design", back_where},
                 {"hausdorff", std::max(fwd.max, back.max)}};
  }

  // Tube and outputs (computed first, then written, so that a failure writes nothing).
  SweepOptions sw;
  sw.chord_tolerance = kTubeChordTolerance * d;
  SweepResult tube;
  try {
    tube = sweep_tube(r.centerline, 0.5 * d, sw);
  } catch (const std::invalid_argument& e) {
    throw InputError(SourceLocation{o.cloud, 0, ""},
                     std::string("cannot mesh a tube around the recovered centerline: ") + e.what());
  }
  const Harness h = scan_harness(r, std::filesystem::path(o.cloud).filename().string(), units);

  json j;
  j["cloud"] = o.cloud;
  j["format"] = to_string(pc.format);
  j["points_declared"] = pc.declared;
  j["points"] = pc.points.size();
  j["dropped_nonfinite"] = pc.dropped_nonfinite;
  j["units"] = unit_name(units);
  j["method"] = to_string(r.method);
  j["status"] = to_string(r.status);
  j["diameter"] = d;
  j["diameter_source"] = r.diameter_estimated ? "estimated" : "given";
  if (r.diameter_estimated) j["diameter_spread"] = r.diameter_spread;
  j["length"] = r.centerline.length();
  j["blocks"] = r.blocks.size();
  json keys = json::array();
  for (const auto& k : r.key_points) keys.push_back(vec_json(k));
  j["key_points"] = keys;
  const double spacing = kSampleSpacing * d;
  json samples = json::array();
  for (const auto& sp : r.centerline.sample_by_arc_length(spacing)) samples.push_back(vec_json(sp.second));
  j["centerline_sample_spacing"] = spacing;
  j["centerline_samples"] = samples;
  j["residuals"] = {{"rms", r.residual_rms}, {"max", r.residual_max}, {"inliers", r.inliers}, {"outliers", r.outliers}};
  j["gaps"] = {{"count", r.gaps}, {"largest", r.largest_gap}};
  j["tube"] = {{"file", "tube.ply"},
               {"triangles", tube.mesh.triangle_count()},
               {"rings", tube.rings},
               {"chord_tolerance", sw.chord_tolerance}};
  if (!deviation.is_null()) j["deviation"] = deviation;
  j["timing_ms"] = {{"diameter", r.timing.diameter_ms},
                    {"ordering", r.timing.ordering_ms},
                    {"fitting", r.timing.fitting_ms},
                    {"spline", r.timing.spline_ms},
                    {"extract", r.timing.total_ms},
                    {"total", t_start.ms()}};

  const std::string report_text = json_text(j, 2) + "\n";
  const std::string centerline_text = harness_to_xml(h);
  write_file_atomic(outputs.staging() / centerline_file.filename(), centerline_text);
  write_mesh(outputs.staging() / tube_file.filename(), tube.mesh);
  write_file_atomic(outputs.staging() / report_file.filename(), report_text);
  outputs.commit();

  if (!o.quiet) {
    std::printf("scan %s: %zu points (%s), method %s\n", o.cloud.c_str(), pc.points.size(), to_string(pc.format),
                to_string(r.method));
    std::printf("  diameter %.6g (%s), length %.6g, %zu blocks, residual rms %.3g max %.3g, %zu outliers, %d gap(s)\n", d,
                r.diameter_estimated ? "estimated" : "given", r.centerline.length(), r.blocks.size(), r.residual_rms,
                r.residual_max, r.outliers, r.gaps);
    if (!deviation.is_null())
      std::printf("  deviation from %s cable %s: max %.4g at s=%.4g, rms %.4g; scan from design max %.4g at scanned "
                  "s=%.4g\n",
                  o.compare.c_str(), o.cable.c_str(), deviation["max"].get<double>(), deviation["where"]["s"].get<double>(),
                  deviation["rms"].get<double>(), deviation["max_scan_to_design"].get<double>(),
                  deviation["where_scan_to_design"]["scanned_s"].get<double>());
    std::printf("  wrote %s/{centerline.xml, tube.ply, report.json} in %.0f ms\n", o.out.c_str(),
                j["timing_ms"]["total"].get<double>());
  }
  return 0;
}

}  // namespace

void add_scan_command(CLI::App& app, int& exit_code) {
  auto* cmd = app.add_subcommand("scan", "Centerline and tube of a scanned cable (PLY/XYZ/PCD point cloud)");
  auto o = std::make_shared<ScanCommandOptions>();
  cmd->add_option("CLOUD", o->cloud, "Point cloud of one cable (PLY, XYZ text, PCD)")->required();
  cmd->add_option("--diameter", o->diameter, "Nominal cable diameter (default: estimated from the cloud)")
      ->check(finite_number(0.0, false));
  cmd->add_option("--out", o->out, "Output directory")->check(non_empty_path())->capture_default_str();
  cmd->add_option("--method", o->method, "graph (blocks along the cable, robust) or axis (the paper's slabs)")
      ->check(CLI::IsMember({"graph", "axis"}))
      ->capture_default_str();
  auto* cmp = cmd->add_option("--compare", o->compare, "Routed harness XML to measure the deviation against");
  auto* cab = cmd->add_option("--cable", o->cable, "Cable id in the --compare harness");
  cmp->needs(cab);
  cab->needs(cmp);
  cmd->add_flag("--quiet", o->quiet, "Print nothing");
  cmd->callback([o, &exit_code]() { exit_code = run_scan(*o); });
}

}  // namespace loom::app
