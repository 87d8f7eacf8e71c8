// loom — the command line. Thin: parses flags, calls the library, maps errors to exit codes.
#include "app/commands.hpp"
#include "core/error.hpp"
#include "core/io/mesh_read.hpp"
#include "core/io/scene_load.hpp"

#include <CLI/CLI.hpp>

#include <cstdio>
#include <exception>
#include <iostream>

#ifndef LOOM_VERSION
#define LOOM_VERSION "unknown"
#endif

int main(int argc, char** argv) {
  // stdout is the command's (reports, --json); OpenCASCADE's transfer statistics would mix in.
  loom::silence_opencascade_console();
  CLI::App app{"loom — automatic cable-harness routing and clash audits of large assemblies"};
  app.name("loom");
  app.set_version_flag("--version", std::string("loom ") + LOOM_VERSION);
  app.require_subcommand(1, 1);
  int exit_code = 0;
  loom::app::add_info_command(app, exit_code);
  loom::app::add_simplify_command(app, exit_code);
  loom::app::add_scan_command(app, exit_code);
  loom::app::add_audit_command(app, exit_code);
  loom::app::add_route_command(app, exit_code);
  loom::app::add_demo_command(app, exit_code);
  loom::app::add_render_command(app, exit_code);
  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {
    return app.exit(e);  // --help / --version
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return 2;
  } catch (const loom::InputError& e) {
    std::fprintf(stderr, "loom: error: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "loom: error: %s\n", e.what());
    return 2;
  }
  return exit_code;
}
