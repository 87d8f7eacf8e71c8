// loom_consumer SCENE: audits a scene's harness through the installed library and prints
// one line per clash. Exit status as `loom audit`: 0 clean, 1 clashes or violations,
// 2 bad input, 3 some cable had no route to check.
#include "core/error.hpp"
#include "routing/audit/audit.hpp"

#include <cstdio>
#include <exception>

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: loom_consumer SCENE\n");
    return 2;
  }
  try {
    const loom::AuditReport report = loom::audit_scene_file(argv[1], loom::AuditOptions{});
    const loom::ClashResult& r = report.result;
    std::printf("%zu cables, %zu parts, %zu triangles: %zu clashes, %zu violations\n", report.cables.size(),
                report.part_names.size(), report.triangles, r.clashes.size(), r.violations.size());
    for (const loom::ClashEntry& c : r.clashes)
      std::printf("%s %s clearance %.6g at (%.6g, %.6g, %.6g)\n", loom::clash_kind_name(c.kind),
                  report.check_ids[static_cast<std::size_t>(c.cable)].c_str(), c.clearance, c.point.x(),
                  c.point.y(), c.point.z());
    return report.exit_code();
  } catch (const loom::InputError& e) {
    std::fprintf(stderr, "loom_consumer: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "loom_consumer: error: %s\n", e.what());
    return 2;
  }
}
