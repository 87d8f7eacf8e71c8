// `loom audit SCENE [--routes FILE] [--method certified|discrete] [--no-index] [--spacing L]
// [--tolerance T] [--per-cable] [--threads N] [--out DIR] [--render-size WxH] [--json] [--quiet]`: clash,
// bend and clearance audit of a harness in its scene; writes DIR/report.json (DESIGN §4),
// DIR/view.html and DIR/render.png. Progress bars on stderr when it is a terminal.
#include "app/audit_mpi.hpp"
#include "app/motion_summary.hpp"
#include "app/support_summary.hpp"
#include "app/commands.hpp"
#include "app/option_checks.hpp"

#include "core/error.hpp"
#include "core/io/atomic_file.hpp"
#include "core/io/kbl_write.hpp"
#include "core/io/output_set.hpp"
#include "app/progress_bar.hpp"
#include "routing/audit/audit.hpp"
#include "routing/curve/cable_limit.hpp"
#include "routing/view/render.hpp"
#include "core/io/json_text.hpp"
#include "routing/audit/report_json.hpp"
#include "routing/view/view_html.hpp"

#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <string>

namespace loom::app {

namespace {

/// Flags of `loom audit`.
struct AuditFlags {
  std::string scene;
  std::string routes;
  std::string method = "certified";
  bool method_given = false;
  bool no_index = false;
  bool per_cable = false;  ///< certified: every cable on its own, not at the bundle level
  double spacing = 0.0;    ///< 0: the default (a given value is > 0, checked on the option)
  double tolerance = 0.0;  ///< 0: the default (a given value is > 0, checked on the option)
  int threads = 0;
  std::string out = "loom-audit";
  std::string render_size = default_render_size();
  bool json = false;
  bool quiet = false;
  std::string max_memory;  ///< sharded audits: most bytes one rank may need (empty: no limit)
};

/// Most clashes listed on the terminal (the report has them all).
constexpr std::size_t kListedClashes = 20;

void print_summary(const AuditReport& rep, const std::filesystem::path& report_path) {
  const ClashResult& r = rep.result;
  const char* u = rep.units.c_str();
  std::printf("audit %s: %zu cables (%zu checked), %zu parts, %zu triangles\n", rep.scene.c_str(), rep.cables.size(),
              rep.check_ids.size(), rep.part_names.size(), rep.triangles);
  if (rep.method == ClashMethod::Certified)
    std::printf("method certified, tolerance %.4g %s (%s), free-space distances within %g%%, index %s\n", r.tolerance,
                u, r.tolerance_source.c_str(), 100.0 * r.distance_rel_error, rep.index_name.c_str());
  else
    std::printf("method discrete (%s), not certified\n", rep.use_index ? "indexed" : "brute force, no index");
  std::size_t n = 0;
  for (const ClashEntry& e : r.clashes) {
    if (n++ == kListedClashes) {
      std::printf("  ... %zu more in the report\n", r.clashes.size() - kListedClashes);
      break;
    }
    const std::string& cable = rep.check_ids[static_cast<std::size_t>(e.cable)];
    if (e.kind == ClashKind::CableStructure)
      std::printf("  clash  %-12s %-8s part %-20s clearance %9.4f %s at s = %.2f%s%s\n", cable.c_str(),
                  e.keep_out ? "keep-out" : "", rep.part_names[static_cast<std::size_t>(e.part)].c_str(), e.clearance,
                  u, e.s, e.inside ? " (inside)" : "", "");
    else
      std::printf("  clash  %-12s %-8s %-25s clearance %9.4f %s at s = %.2f / %.2f\n", cable.c_str(),
                  clash_kind_name(e.kind), rep.check_ids[static_cast<std::size_t>(e.other)].c_str(), e.clearance, u,
                  e.s, e.s_other);
  }
  for (const Violation& v : r.violations) {
    const std::string& cable = rep.check_ids[static_cast<std::size_t>(v.cable)];
    if (v.kind == ViolationKind::BendRadius)
      std::printf("  bend   %-12s radius %.4g < %.4g %s at s = %.2f\n", cable.c_str(), v.value, v.limit, u, v.s);
    else
      std::printf("  gap    %-12s part %-20s clearance %.4f < %.4g %s at s = %.2f\n", cable.c_str(),
                  rep.part_names[static_cast<std::size_t>(v.part)].c_str(), v.value, v.limit, u, v.s);
  }
  const std::size_t more = print_support_findings(rep, kListedClashes);
  const std::size_t moving = print_motion_clashes(rep, kListedClashes);
  for (const auto& note : rep.notes) std::printf("  note: %s\n", note.c_str());
  std::printf("%zu clashes, %zu violations; load %.0f ms, index %.1f ms, check %.1f ms, %lld distance queries\n",
              r.clashes.size() + moving, r.violations.size() + more, rep.load_ms, rep.index_ms, rep.check_ms,
              static_cast<long long>(r.counters.distance_queries));
  std::printf("report: %s\n", report_path.string().c_str());
}

/// The summary (or --json report) of a finished audit, as every way of running it prints it.
void print_outcome(const AuditFlags& f, const AuditReport& rep, const nlohmann::json& report) {
  if (f.json)
    std::cout << json_text(report, 2) << "\n";
  else if (!f.quiet)
    print_summary(rep, std::filesystem::path(f.out) / "report.json");
}

/// `mpirun -np K loom audit`: every rank runs this; rank 0 writes report.json (and
/// routed.kbl) and prints. view.html and render.png need every part in one process and
/// are not written; stale ones from an earlier run are removed so that none describes
/// another report.
int run_sharded_audit_command(const AuditFlags& f, AuditOptions opt) {
  const double max_memory = f.max_memory.empty() ? 0.0 : byte_size_value(f.max_memory);
  MpiWorld mpi;
  try {
    std::optional<OutputSet> outputs;
    const auto report_path = std::filesystem::path(f.out) / "report.json";
    mpi.collective([&] {
      if (mpi.root()) outputs.emplace(f.out, std::vector<std::filesystem::path>{report_path,
                                                                                std::filesystem::path(f.out) / kRoutedKblName});
    });
    ProgressBar bar(stderr, f.quiet || f.json || !mpi.root());
    opt.progress = bar.fn();
    ShardedAudit res = sharded_audit(mpi, f.scene, opt, max_memory);
    int code = 0;
    nlohmann::json report;
    mpi.collective([&] {
      if (!mpi.root()) return;
      res.report.notes.push_back("sharded over " + std::to_string(mpi.size()) +
                                 " MPI rank" + std::string(mpi.size() == 1 ? "" : "s") + ": view.html and render.png are not written (run `loom render` "
                                 "where the whole scene fits)");
      report = audit_report_json(res.report);
      for (const ShardSummary& r : res.ranks)
        report["shards"].push_back({{"rank", r.rank}, {"parts", r.parts}, {"triangles", r.triangles},
                                    {"estimated_bytes", r.estimated_bytes}, {"peak_bytes", r.peak_bytes},
                                    {"load_ms", r.load_ms}, {"index_ms", r.index_ms}, {"check_ms", r.check_ms}});
      write_file_atomic(outputs->staging() / "report.json", json_text(report, 2) + "\n");
      if (res.scene.harness.kbl) write_harness_kbl(res.scene.harness, outputs->staging() / kRoutedKblName);
      outputs->commit();
      for (const auto& stale : view_output_files(f.out)) std::filesystem::remove(stale);
      code = res.report.exit_code();
    });
    code = mpi.broadcast(code);
    if (mpi.root()) {
      print_outcome(f, res.report, report);
      if (!f.json && !f.quiet)
        for (const ShardSummary& r : res.ranks)
          std::printf("  rank %d: %zu parts, %zu triangles (estimated %.0f MiB, peak %.0f MiB); load %.0f ms, index "
                      "%.1f ms, check %.1f ms\n",
                      r.rank, r.parts, r.triangles, r.estimated_bytes / 1048576.0, r.peak_bytes / 1048576.0, r.load_ms,
                      r.index_ms, r.check_ms);
    }
    return code;
  } catch (const ShardFailure& e) {
    // Every rank stops here; rank 0 says why (main prints it, exit 2).
    if (!mpi.root()) return 2;
    if (e.input_error()) throw InputError({"", 0, ""}, e.what());
    throw;
  }
}

int run_audit_command(const AuditFlags& f) {
  // The flags first: a usage error creates no output directory.
  AuditOptions opt;
  if (f.method == "certified") {
    opt.check.method = ClashMethod::Certified;
  } else if (f.method == "discrete") {
    opt.check.method = ClashMethod::Discrete;
  } else {
    throw InputError({"", 0, "--method"}, "unknown method '" + f.method + "' (use certified or discrete)");
  }
  if (f.no_index) {
    if (f.method_given && opt.check.method == ClashMethod::Certified)
      throw InputError({"", 0, "--no-index"}, "--no-index is the brute-force discrete baseline; it cannot be certified");
    opt.check.method = ClashMethod::Discrete;
    opt.check.use_index = false;
  }
  // Each method has its own accuracy setting; the other's would be ignored without a word.
  // (A given value is > 0: the options' checks refuse 0, their "not given" value.)
  if (f.tolerance > 0.0 && opt.check.method == ClashMethod::Discrete)
    throw InputError({"", 0, "--tolerance"}, "applies to the certified method only; the discrete method" +
                                                 std::string(f.no_index ? " (--no-index)" : "") +
                                                 " is not certified and samples at --spacing");
  if (f.spacing > 0.0 && opt.check.method == ClashMethod::Certified)
    throw InputError({"", 0, "--spacing"}, "applies to the discrete method only (--method discrete or --no-index); "
                                           "the certified method places its samples to meet --tolerance");
  if (f.per_cable && opt.check.method == ClashMethod::Discrete)
    throw InputError({"", 0, "--per-cable"}, "applies to the certified method only; the discrete method" +
                                                 std::string(f.no_index ? " (--no-index)" : "") +
                                                 " always checks every cable on its own");
  opt.check.per_cable = f.per_cable;
  opt.check.spacing = f.spacing;
  opt.check.tolerance = f.tolerance;
  opt.check.threads = f.threads;
  if (!f.routes.empty()) opt.routes = f.routes;
  RenderOptions render;
  parse_render_size(f.render_size, "--render-size", render);
  if (launched_by_mpi()) return run_sharded_audit_command(f, opt);
  if (!f.max_memory.empty())
    throw InputError({"", 0, "--max-memory"}, "applies to a sharded audit (mpirun -np K loom audit) only");
  auto targets = view_output_files(f.out);
  targets.push_back(std::filesystem::path(f.out) / "report.json");
  targets.push_back(std::filesystem::path(f.out) / kRoutedKblName);  // written for a KBL harness
  OutputSet outputs(f.out, targets);  // every target checked before any work; all replaced together
  ProgressBar bar(stderr, f.quiet || f.json);
  opt.progress = bar.fn();
  render.progress = bar.fn();
  Scene scene;
  const AuditReport rep = audit_scene_file(f.scene, opt, &scene);
  const nlohmann::json report = audit_report_json(rep);
  naming_cable_errors(scene.harness, [&] {  // a tube refused names its cable's element
    return write_view_outputs(outputs.staging(), scene, scene.harness, report, render);  // view.html, render.png
  });
  write_audit_report(rep, outputs.staging() / "report.json");
  if (scene.harness.kbl) write_harness_kbl(scene.harness, outputs.staging() / kRoutedKblName);
  outputs.commit();
  print_outcome(f, rep, report);
  return rep.exit_code();
}

}  // namespace

void add_audit_command(CLI::App& app, int& exit_code) {
  auto* cmd = app.add_subcommand("audit", "Check a harness for clashes, bend and clearance violations; write report.json");
  auto f = std::make_shared<AuditFlags>();
  cmd->add_option("SCENE", f->scene, "Scene file (TOML)")->required();
  cmd->add_option("--routes", f->routes, "Routed harness XML replacing the scene's harness");
  auto* m = cmd->add_option("--method", f->method, "certified (exact to --tolerance) or discrete (the paper's sampling)")
                ->check(CLI::IsMember({"certified", "discrete"}))
                ->capture_default_str();
  cmd->add_flag("--no-index", f->no_index, "Brute-force discrete baseline: every sample against every triangle");
  cmd->add_option("--spacing", f->spacing, "Discrete sample spacing (default: each cable's diameter)")
      ->check(finite_number(0.0, false));
  cmd->add_option("--tolerance", f->tolerance, "Certified accuracy (default: smallest cable radius / 100)")
      ->check(finite_number(0.0, false));
  cmd->add_flag("--per-cable", f->per_cable,
                "Certified: check every cable on its own (the reference) instead of each shared segment once");
  cmd->add_option("--threads", f->threads, "Worker threads (default: all cores)")
      ->check(whole_number(1, kMaxThreads));
  cmd->add_option("--out", f->out, "Output directory for report.json")->check(non_empty_path())->capture_default_str();
  cmd->add_option("--render-size", f->render_size, "Size of render.png, WIDTHxHEIGHT")->capture_default_str();
  cmd->add_option("--max-memory", f->max_memory,
                  "Sharded audit (mpirun): most memory one rank may need, e.g. 24G; a plan that needs more is refused")
      ->check(byte_size());
  cmd->add_flag("--json", f->json, "Print the report as JSON instead of the summary");
  cmd->add_flag("--quiet", f->quiet, "Print nothing (exit status and report only)");
  cmd->callback([f, m, &exit_code]() {
    f->method_given = m->count() > 0;
    exit_code = run_audit_command(*f);
  });
}

}  // namespace loom::app
