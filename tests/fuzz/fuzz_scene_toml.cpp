// libFuzzer entry point: the scene TOML reader (load_scene, the whole of it as `loom info`
// runs it). load_scene takes a path only, so each input is written to scene.toml in a
// scratch directory that also holds box.obj and harness.xml (from tests/data/audit) for
// [[part]] and [harness] entries to refer to. The tessellation cache is off: the fuzzer
// must not write outside its scratch directory.
#include "fuzz_support.hpp"

#include "core/io/scene_load.hpp"

#include <cstddef>
#include <cstdint>

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  loom::fuzz::copy_test_data("audit/box.obj", "box.obj");
  loom::fuzz::copy_test_data("audit/harness_clear.xml", "harness.xml");
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto scene = loom::fuzz::scratch_dir() / "scene.toml";
  loom::fuzz::write_bytes(scene, data, size);
  loom::fuzz::expect_only_input_errors([&] {
    loom::SceneLoadOptions opt;
    opt.use_cache = false;
    loom::SceneLoadReport report;
    loom::load_scene(scene, opt, &report);
  });
  return 0;
}
