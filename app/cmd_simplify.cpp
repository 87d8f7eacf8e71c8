// `loom simplify SCENE [--dim-pre X] [--out DIR] [--quiet]`: α-SIM per part.
// Writes DIR/<part>.stl and DIR/simplify.json (DESIGN §4 fields, plus status and reason).
#include "app/commands.hpp"
#include "app/option_checks.hpp"

#include "core/stopwatch.hpp"
#include "core/io/atomic_file.hpp"
#include "core/io/output_set.hpp"
#include "core/io/file_stems.hpp"
#include "core/io/mesh_write.hpp"
#include "core/io/scene_load.hpp"
#include "app/progress_bar.hpp"
#include "index/embree_index.hpp"
#include "index/simplify/alpha_sim.hpp"
#include "core/io/json_text.hpp"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace loom::app {

namespace {

struct SimplifyCommandOptions {
  std::string scene;
  double dim_pre = 0.0;         ///< used when dim_pre_given
  bool dim_pre_given = false;   ///< --dim-pre was on the command line (else the scene's value)
  std::string out = "simplify-out";
  bool quiet = false;
  bool step = false;
};

double finite_or_zero(double v) { return std::isfinite(v) ? v : 0.0; }

/// A split part's tree for simplify.json, depth first.
nlohmann::json pieces_json(const std::vector<AlphaSimPiece>& pieces) {
  nlohmann::json out = nlohmann::json::array();
  for (const AlphaSimPiece& p : pieces)
    out.push_back({{"id", p.id},
                   {"cut", p.cut},
                   {"box_min", {p.box.min.x(), p.box.min.y(), p.box.min.z()}},
                   {"box_max", {p.box.max.x(), p.box.max.y(), p.box.max.z()}},
                   {"leaf", p.leaf},
                   {"status", alpha_sim_status_name(p.status)},
                   {"reason", p.reason},
                   {"triangles_before", p.triangles_before},
                   {"triangles_after", p.triangles_after},
                   {"containment", finite_or_zero(p.containment)},
                   {"lost_space_radius", finite_or_zero(p.lost_space_radius)}});
  return out;
}

/// Bytes of an Embree index over `parts` (the BVH and the triangles it holds).
std::size_t index_bytes(const std::vector<Part>& parts) {
  return parts.empty() ? 0 : EmbreeIndex(parts).memory_bytes();
}

/// The targets this run did not stage (no STEP for a part whose original is kept, no STL for
/// an empty part) that an earlier run left in the output directory. They are removed once
/// the new set is in place: a directory must not mix this run's files with an earlier run's.
std::vector<std::filesystem::path> stale_targets(const std::vector<std::filesystem::path>& targets,
                                                 const std::filesystem::path& staging) {
  std::vector<std::filesystem::path> stale;
  std::error_code ec;
  for (const auto& t : targets)
    if (!std::filesystem::exists(staging / t.filename(), ec) && std::filesystem::exists(t, ec)) stale.push_back(t);
  return stale;
}

int run_simplify(const SimplifyCommandOptions& o) {
  ProgressBar bar(stderr, o.quiet);
  SceneLoadOptions lo;
  lo.progress = bar.fn();
  Scene scene = load_scene(o.scene, lo);
  const bool given = o.dim_pre_given;
  const double dim_pre = given ? o.dim_pre : scene.simplify.dim_pre.value;
  // Both are finite and > 0: a given --dim-pre is checked on the option, the scene's by load_scene.
  const std::filesystem::path out_dir(o.out);
  // One file stem per part, as simplify_parts names the STEP files; every target is
  // checked before any work.
  std::vector<std::string> part_names;
  for (const auto& p : scene.parts) part_names.push_back(p.name);
  const std::vector<std::string> stems = output_file_stems(part_names);
  std::vector<std::filesystem::path> targets{out_dir / "simplify.json"};
  for (const auto& stem : stems) {
    targets.push_back(out_dir / (stem + ".stl"));
    if (o.step) targets.push_back(out_dir / (stem + ".step"));
  }
  OutputSet outputs(out_dir, targets);  // every target checked before any work; all replaced together

  AlphaSimOptions opt;
  opt.dim_pre = dim_pre;
  opt.scene_size = scene.bounds().diagonal();
  opt.extra_planes = scene.simplify.planes;
  opt.split_blocked = scene.simplify.split;
  if (o.step) opt.step_dir = outputs.staging();
  opt.progress = bar.fn();
  const double tolerance = opt.containment_tolerance_factor * opt.scene_size;
  if (!o.quiet)
    std::fprintf(stderr,
                 "loom simplify: %zu parts, dim_pre %g %s (%s): alpha %g, L_max %g, containment tolerance %.3g %s\n",
                 scene.parts.size(), dim_pre, unit_name(scene.units),
                 given ? "--dim-pre" : scene.simplify.dim_pre.source.c_str(), opt.alpha_factor * dim_pre,
                 opt.sampling_factor * dim_pre, tolerance, unit_name(scene.units));
  const Stopwatch t_start;
  std::vector<AlphaSimResult> results;
  const std::vector<Part> simple = simplify_parts(scene.parts, opt, &results);

  using nlohmann::json;
  json parts = json::array();
  for (std::size_t i = 0; i < simple.size(); ++i) {
    const AlphaSimResult& r = results[i];
    const std::string& stem = stems[i];
    if (!simple[i].mesh.empty()) write_mesh(outputs.staging() / (stem + ".stl"), simple[i].mesh);
    const bool step_written = o.step && std::filesystem::exists(outputs.staging() / (stem + ".step"));
    json projections = json::array();
    for (const auto& p : r.projections)
      projections.push_back({{"plane", p.plane},
                             {"status", projection_status_name(p.status)},
                             {"points", p.points},
                             {"kept_triangles", p.kept_triangles},
                             {"area", finite_or_zero(p.area)},
                             {"hull_area", finite_or_zero(p.hull_area)},
                             {"edge_on_triangles", p.edge_on_triangles},
                             {"edge_on_segments", p.edge_on_segments},
                             {"exact_triangles", p.exact_triangles},
                             {"exact_gaps", p.exact_gaps},
                             {"polygon_vertices", p.polygon_vertices},
                             {"holes", p.holes}});
    parts.push_back({{"name", r.name},
                     {"file", stem + ".stl"},
                     {"triangles_before", r.triangles_before},
                     {"triangles_after", r.triangles_after},
                     {"faces_before", r.faces_before},
                     {"faces_after", r.faces_after},
                     {"volume_before", finite_or_zero(r.volume_before)},
                     {"volume_after", finite_or_zero(r.volume_after)},
                     {"closed_before", r.closed_before},
                     {"closed_after", r.closed_after},
                     {"containment", finite_or_zero(r.containment)},
                     {"containment_samples", r.containment_samples},
                     {"hausdorff", finite_or_zero(r.hausdorff)},
                     {"float_rounding", finite_or_zero(r.float_rounding)},
                     {"lost_space_radius", finite_or_zero(r.lost_space_radius)},
                     {"time_ms", finite_or_zero(r.time_ms)},
                     {"fallback", alpha_sim_fallback_name(r.fallback)},
                     {"status", alpha_sim_status_name(r.status)},
                     {"reason", r.reason},
                     {"copy_of", r.copy_of},
                     {"prisms_absorbed", r.prisms_absorbed},
                     {"booleans", r.booleans},
                     {"booleans_by", r.booleans_by},
                     {"booleans_note", r.booleans_note},
                     {"projections", projections}});
    if (!r.pieces.empty()) parts.back()["pieces"] = pieces_json(r.pieces);
    // Only a simplified part (not split) has a STEP solid; a part kept as it was has none.
    if (o.step) parts.back()["step_file"] = step_written ? stem + ".step" : "";
    if (!o.quiet) {
      // Below the containment tolerance a distance is rounding (a part kept as it was).
      const double hausdorff = r.hausdorff < r.tolerance ? 0.0 : r.hausdorff;
      const std::string when = r.copy_of.empty() ? std::to_string(static_cast<long long>(std::lround(r.time_ms))) + " ms"
                                                 : "copy of " + r.copy_of;
      const double pct = r.triangles_before > 0 ? 100.0 * r.triangles_after / r.triangles_before : 0.0;
      std::fprintf(stderr, "  %-20s %8zu -> %6zu triangles (%5.1f%%)  hausdorff %-8.4g %-18s %s%s%s\n",
                   r.name.c_str(), r.triangles_before, r.triangles_after, pct, hausdorff, when.c_str(),
                   alpha_sim_status_name(r.status), r.reason.empty() ? "" : ": ", r.reason.c_str());
    }
  }
  std::size_t before = 0, after = 0, split = 0, blocked = 0;
  for (const auto& r : results) {
    before += r.triangles_before;
    after += r.triangles_after;
    split += !r.pieces.empty() && r.fallback != AlphaSimFallback::Original;
    blocked += r.status == AlphaSimStatus::Blocked;
  }
  // What planning on the simplified parts saves in memory: both indices as `route` builds them.
  const std::size_t bytes_exact = index_bytes(scene.parts), bytes_simplified = index_bytes(simple);
  json j = {{"scene", scene.name},
            {"units", unit_name(scene.units)},
            {"dim_pre", dim_pre},
            {"dim_pre_source", given ? std::string("--dim-pre") : scene.simplify.dim_pre.source},
            {"alpha", opt.alpha_factor * dim_pre},
            {"l_max", opt.sampling_factor * dim_pre},
            {"tolerance", tolerance},
            {"triangles_before", before},
            {"triangles_after", after},
            {"parts_split", split},
            {"parts_blocked", blocked},
            {"index_bytes_exact", bytes_exact},
            {"index_bytes_simplified", bytes_simplified},
            {"parts", parts}};
  targets.erase(targets.begin());  // simplify.json (the first target) is written below
  const std::vector<std::filesystem::path> stale = stale_targets(targets, outputs.staging());
  j["removed"] = json::array();  // files of an earlier run that this run has no counterpart for
  for (const auto& t : stale) j["removed"].push_back(t.filename().string());
  write_file_atomic(outputs.staging() / "simplify.json", json_text(j, 2) + "\n");
  outputs.commit();
  for (const auto& t : stale) {
    std::error_code ec;
    std::filesystem::remove(t, ec);
    if (ec) throw std::runtime_error(t.string() + ": cannot remove the earlier run's file: " + ec.message());
  }
  if (!o.quiet)
    std::fprintf(stderr,
                 "loom simplify: %zu -> %zu triangles (%.1f%%) in %.2f s; %zu parts split, %zu blocked; "
                 "index %.1f -> %.1f MB; wrote %s\n",
                 before, after, before > 0 ? 100.0 * after / before : 0.0, t_start.seconds(), split, blocked,
                 bytes_exact / 1e6, bytes_simplified / 1e6, (out_dir / "simplify.json").string().c_str());
  return 0;
}

}  // namespace

void add_simplify_command(CLI::App& app, int& exit_code) {
  auto* cmd = app.add_subcommand("simplify", "α-SIM: simplify every part to the level of detail a cable needs");
  auto o = std::make_shared<SimplifyCommandOptions>();
  cmd->add_option("SCENE", o->scene, "Scene file (TOML)")->required();
  auto* dim = cmd->add_option("--dim-pre", o->dim_pre, "Features smaller than this vanish (default: the scene's dim_pre)")
                  ->check(finite_number(0.0, false));
  cmd->add_option("--out", o->out, "Output directory (DIR/<part>.stl, DIR/simplify.json)")->check(non_empty_path());
  cmd->add_flag("--step", o->step, "Also write DIR/<part>.step (OpenCASCADE)");
  cmd->add_flag("--quiet", o->quiet, "Print nothing");
  cmd->callback([o, dim, &exit_code]() {
    o->dim_pre_given = dim->count() > 0;
    exit_code = run_simplify(*o);
  });
}

}  // namespace loom::app
