#pragma once
/// The `loom` subcommands. Each add_*_command registers one subcommand on the CLI11 app;
/// its callback runs the command and stores the exit status (DESIGN §4: 0 clean,
/// 1 clashes/violations, 2 bad input, 3 unroutable cable) in `exit_code`.

#include <string>

namespace CLI {
class App;
}

namespace loom::app {

void add_info_command(CLI::App& app, int& exit_code);
/// `loom info`: prints the scene summary (text or JSON); returns the exit status.
int run_info(const std::string& scene, bool json, bool quiet);

void add_demo_command(CLI::App& app, int& exit_code);
/// Path of the bundled demo scene ($LOOM_EXAMPLES_DIR overrides the built-in path).
std::string demo_scene_path();

}  // namespace loom::app
