// `loom demo [--out DIR] [--render-size WxH] [--iterations K] [--quiet]`: the main job on the bundled
// wing-section example.
#include "app/commands.hpp"
#include "app/option_checks.hpp"

#include "routing/view/render.hpp"

#include <CLI/CLI.hpp>

#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#ifndef LOOM_EXAMPLES_DIR
#define LOOM_EXAMPLES_DIR "examples"
#endif

namespace loom::app {

/// The bundled example scene: $LOOM_EXAMPLES_DIR overrides the compiled-in source path.
std::string demo_scene_path() {
  if (const char* d = std::getenv("LOOM_EXAMPLES_DIR"); d && *d) return std::string(d) + "/wing-section/scene.toml";
  return std::string(LOOM_EXAMPLES_DIR) + "/wing-section/scene.toml";
}

void add_demo_command(CLI::App& app, int& exit_code) {
  auto* cmd = app.add_subcommand("demo", "Run loom on the bundled wing-section example");
  auto out = std::make_shared<std::string>("loom-demo");
  auto quiet = std::make_shared<bool>(false);
  auto render_size = std::make_shared<std::string>(default_render_size());
  auto iterations = std::make_shared<long long>(-1);  // < 0: the scene's
  cmd->add_option("--out", *out, "Output directory")->check(non_empty_path())->capture_default_str();
  cmd->add_option("--render-size", *render_size, "Size of render.png, WIDTHxHEIGHT")->capture_default_str();
  add_iterations_option(*cmd, *iterations);
  cmd->add_flag("--quiet", *quiet, "Print nothing (exit status only)");
  cmd->callback([out, quiet, render_size, iterations, &exit_code]() {
    // The main job on the bundled wing section: what is there, then route + exact audit.
    const std::string scene = demo_scene_path();
    RouteCommandOptions o;
    o.out = *out;
    o.quiet = *quiet;
    o.render_size = *render_size;
    o.iterations = *iterations;
    RenderOptions size_check;
    parse_render_size(o.render_size, "--render-size", size_check);  // a bad size fails before any work
    if (!*quiet) {
      run_info(scene, false, false);
      std::printf("\n");
    }
    exit_code = run_route(scene, o);
  });
}

}  // namespace loom::app
