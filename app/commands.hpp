#pragma once
/// The `loom` subcommands. Each add_*_command registers one subcommand on the CLI11 app;
/// its callback runs the command and stores the exit status (DESIGN §4: 0 clean,
/// 1 clashes/violations, 2 bad input, 3 unroutable cable) in `exit_code`.

namespace CLI {
class App;
}

namespace loom::app {

void add_info_command(CLI::App& app, int& exit_code);

}  // namespace loom::app
