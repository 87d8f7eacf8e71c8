#pragma once
/// The `loom` subcommands. Each add_*_command registers one subcommand on the CLI11 app;
/// its callback runs the command and stores the exit status (DESIGN §4: 0 clean,
/// 1 clashes/violations, 2 bad input, 3 unroutable cable) in `exit_code`.

#include <string>

namespace CLI {
class App;
}

namespace loom::app {

/// Most worker threads `--threads` takes (route, audit). Far above any machine's cores, and
/// far below the task-arena size at which TBB itself crashes: `--threads 100000` (a TBB
/// arena of 10⁵ slots) ended in a segmentation fault inside tbb::task_arena::terminate.
constexpr int kMaxThreads = 1024;

void add_info_command(CLI::App& app, int& exit_code);
/// `loom simplify`: α-SIM per part → DIR/<part>.stl + DIR/simplify.json.
void add_simplify_command(CLI::App& app, int& exit_code);
/// `loom scan`: centerline, tube and deviation report of a scanned cable (DESIGN §4).
void add_scan_command(CLI::App& app, int& exit_code);
/// `loom audit`: clash, bend and clearance audit of a harness (DESIGN §4).
void add_audit_command(CLI::App& app, int& exit_code);
/// `loom info`: prints the scene summary (text or JSON); returns the exit status.
int run_info(const std::string& scene, bool json, bool quiet);

/// Flags of `loom route`.
struct RouteCommandOptions {
  std::string out = "loom-route";
  std::string render_size;   ///< render.png "WxH"; empty: default_render_size()
  std::string planner;       ///< empty: the scene's
  double time_limit = -1.0;  ///< < 0: the scene's
  long seed = -1;            ///< < 0: the scene's
  long long iterations = -1; ///< planner iterations per segment; < 0: the scene's
  int threads = 0;
  bool simplify = false;     ///< plan among α-simplified parts
  bool voxel_layer = false;  ///< a voxel distance map in front of Embree while planning
  bool json = false;
  bool quiet = false;
};
void add_route_command(CLI::App& app, int& exit_code);
/// Adds `--iterations K` (1..kMaxPlanIterations, checked as a usage error) to `cmd`, storing
/// it in `iterations` (route, demo).
void add_iterations_option(CLI::App& cmd, long long& iterations);
/// `loom route`: routes, audits and writes the outputs; returns the DESIGN §4 exit status.
int run_route(const std::string& scene, const RouteCommandOptions& options);

void add_demo_command(CLI::App& app, int& exit_code);
/// `loom render`: a ray-cast PNG of a scene, its cables and a report's clashes.
void add_render_command(CLI::App& app, int& exit_code);
/// The size of render.png when --render-size is not given, as "WxH" (RenderOptions' default).
std::string default_render_size();
/// Path of the bundled demo scene ($LOOM_EXAMPLES_DIR overrides the built-in path).
std::string demo_scene_path();

}  // namespace loom::app
