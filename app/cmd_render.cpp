// `loom render SCENE [--routes FILE] [--report FILE] [--out FILE] [--render-size WxH] [--quiet]`:
// a PNG of the scene, its cables and (with --report) the report's clashes, ray-cast on the CPU.
#include "app/commands.hpp"
#include "app/option_checks.hpp"

#include "core/error.hpp"
#include "core/io/atomic_file.hpp"
#include "core/io/scene_load.hpp"
#include "app/progress_bar.hpp"
#include "core/units.hpp"
#include "routing/audit/audit.hpp"
#include "routing/curve/cable_limit.hpp"
#include "routing/view/render.hpp"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <string>

namespace loom::app {

namespace {

struct RenderFlags {
  std::string scene;
  std::string routes;
  std::string report;
  std::string out = "render.png";
  std::string size = default_render_size();
  bool quiet = false;
};

/// The parts of a --report that the picture uses, checked as it is read: an object whose
/// "clashes" and "violations" (each optional) are arrays of objects, each with an optional
/// "kind" string and "point" of three finite numbers. Anything else is an input error
/// naming the file and the entry, not a picture silently without its markers.
void check_report_markers(const nlohmann::json& report, const std::string& file) {
  if (!report.is_object()) throw InputError({file, 0, ""}, "expected a JSON object (a loom report.json)");
  for (const char* key : {"clashes", "violations"}) {
    if (!report.contains(key)) continue;
    const nlohmann::json& list = report[key];
    if (!list.is_array()) throw InputError({file, 0, key}, "expected an array");
    for (std::size_t i = 0; i < list.size(); ++i) {
      const nlohmann::json& e = list[i];
      const std::string where = std::string(key) + "[" + std::to_string(i) + "]";
      if (!e.is_object()) throw InputError({file, 0, where}, "expected an object");
      if (e.contains("kind") && !e["kind"].is_string()) throw InputError({file, 0, where + ".kind"}, "expected a string");
      if (!e.contains("point")) continue;
      const nlohmann::json& p = e["point"];
      bool ok = p.is_array() && p.size() == 3;
      for (std::size_t k = 0; ok && k < 3; ++k) ok = p[k].is_number() && std::isfinite(p[k].get<double>());
      if (!ok) throw InputError({file, 0, where + ".point"}, "expected an array of 3 finite numbers");
    }
  }
}

int run_render(const RenderFlags& f) {
  check_output_targets({f.out});
  RenderOptions opt;
  parse_render_size(f.size, "--render-size", opt);
  ProgressBar bar(stderr, f.quiet);
  SceneLoadOptions lo;
  lo.progress = bar.fn();
  opt.progress = bar.fn();
  Scene scene = load_scene(f.scene, lo);
  if (!f.routes.empty()) apply_matching_routes(scene, f.routes);
  nlohmann::json report = nlohmann::json::object();
  if (!f.report.empty()) {
    std::ifstream in(f.report);
    if (!in) throw InputError({f.report, 0, ""}, "cannot open the report");
    try {
      report = nlohmann::json::parse(in);
    } catch (const nlohmann::json::parse_error& e) {
      throw InputError({f.report, 0, ""}, std::string("not JSON: ") + e.what());
    }
    check_report_markers(report, f.report);
  }
  RenderStats st;
  // A cable whose tube cannot be meshed is refused at its element of the harness file.
  const Image img = naming_cable_errors(scene.harness, [&] { return render_scene(scene, scene.harness, report, opt, &st); });
  write_png(f.out, img);
  if (!f.quiet)
    std::printf("render %s: %dx%d, %zu rays, %zu tube triangles, %zu markers, %.0f ms -> %s\n", f.scene.c_str(),
                img.width, img.height, st.rays, st.tube_triangles, st.markers, st.ms, f.out.c_str());
  return 0;
}

}  // namespace

std::string default_render_size() {
  const RenderOptions d;
  return std::to_string(d.width) + "x" + std::to_string(d.height);
}

void add_render_command(CLI::App& app, int& exit_code) {
  auto* cmd = app.add_subcommand("render", "Ray-cast a PNG of the scene, its cables and a report's clashes");
  auto f = std::make_shared<RenderFlags>();
  cmd->add_option("SCENE", f->scene, "Scene file (TOML)")->required();
  cmd->add_option("--routes", f->routes, "Routed harness XML replacing the scene's harness");
  cmd->add_option("--report", f->report, "report.json whose clashes and violations are marked");
  cmd->add_option("--out", f->out, "Output PNG")->check(non_empty_path())->capture_default_str();
  cmd->add_option("--render-size", f->size, "Image size WIDTHxHEIGHT")->capture_default_str();
  cmd->add_flag("--quiet", f->quiet, "Print nothing");
  cmd->callback([f, &exit_code]() { exit_code = run_render(*f); });
}

}  // namespace loom::app
