// libFuzzer entry point for one mesh format (LOOM_FUZZ_MESH_EXT, e.g. ".stl"): the input is
// the mesh file of a one-part scene, loaded by load_scene as `loom info` loads it, so it
// passes loom's own pre-checks (check_mesh_file_structure), Assimp and the part's
// post-processing (units, topology, orientation). The readers take a path only: each input
// is written to part<ext> in a scratch directory.
#include "fuzz_support.hpp"

#include "core/io/scene_load.hpp"

#include <cstddef>
#include <cstdint>
#include <string>

#ifndef LOOM_FUZZ_MESH_EXT
#error "LOOM_FUZZ_MESH_EXT (the mesh file extension, e.g. \".stl\") must be defined"
#endif

namespace {
const std::string kPartFile = std::string("part") + LOOM_FUZZ_MESH_EXT;
}

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  loom::fuzz::write_text(loom::fuzz::scratch_dir() / "scene.toml",
                         "[scene]\nunits = \"mm\"\n\n[[part]]\nfile = \"" + kPartFile + "\"\n");
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  loom::fuzz::keep_recent(data, size);
  loom::fuzz::write_bytes(loom::fuzz::scratch_dir() / kPartFile, data, size);
  loom::fuzz::expect_only_input_errors([] {
    loom::SceneLoadOptions opt;
    opt.use_cache = false;
    loom::SceneLoadReport report;
    loom::load_scene(loom::fuzz::scratch_dir() / "scene.toml", opt, &report);
  });
  return 0;
}
