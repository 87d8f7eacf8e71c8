// libFuzzer entry point: a routes file (a routed harness XML) applied to a scene and
// audited, as `loom audit SCENE --routes FILE` does (audit_scene_file, then the report as
// JSON text). The scene is tests/data/audit/clean.toml: a 10 mm box and one 2 mm cable C1
// from J1 to J2, so a routes file must route that cable (check_routes_match) for the audit
// to run. The routes reader takes a path only: each input is written to routes.xml in a
// scratch directory. One worker thread: the fuzzer runs beside other work.
#include "fuzz_support.hpp"

#include "core/io/json_text.hpp"
#include "core/io/mesh_read.hpp"
#include "core/io/mesh_write.hpp"
#include "routing/audit/audit.hpp"
#include "routing/audit/report_json.hpp"

#include <cstddef>
#include <cstdint>
#include <string>

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  // The box goes in as binary PLY: Assimp's OBJ reader clears a 16 MB buffer for every file,
  // which under ASan costs a third of a second per execution, ten times the audit.
  const auto dir = loom::fuzz::scratch_dir();
  loom::write_mesh(dir / "box.ply", loom::read_mesh_file(loom::fuzz::copy_test_data("audit/box.obj", "box.obj")));
  loom::fuzz::copy_test_data("audit/harness_clear.xml", "harness_clear.xml");
  std::string scene = loom::fuzz::read_test_data("audit/clean.toml");
  const std::size_t at = scene.find("\"box.obj\"");
  if (at == std::string::npos) loom::fuzz::finding("tests/data/audit/clean.toml no longer names \"box.obj\"");
  scene.replace(at, 9, "\"box.ply\"");
  loom::fuzz::write_text(dir / "scene.toml", scene);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto routes = loom::fuzz::scratch_dir() / "routes.xml";
  loom::fuzz::write_bytes(routes, data, size);
  loom::fuzz::expect_only_input_errors([&] {
    loom::AuditOptions opt;
    opt.routes = routes;
    opt.check.threads = 1;
    const loom::AuditReport report = loom::audit_scene_file(loom::fuzz::scratch_dir() / "scene.toml", opt);
    loom::json_text(loom::audit_report_json(report), 2);
  });
  return 0;
}
