#include "examples/generator/wing_section.hpp"

#include "examples/generator/step_export.hpp"
#include "examples/generator/wing_harness.hpp"
#include "examples/generator/wing_parts.hpp"
#include "examples/generator/wing_scene.hpp"

#include "core/io/atomic_file.hpp"

namespace loom::examples {

std::vector<std::string> generate_wing_section(const std::filesystem::path& outdir) {
  std::filesystem::create_directories(outdir);
  std::vector<std::string> written;
  for (const auto& p : make_wing_parts()) {
    write_named_step(p.shape, p.product, outdir / p.file);
    written.push_back(p.file);
  }
  write_file_atomic(outdir / "harness.xml", wing_harness_xml());
  written.push_back("harness.xml");
  write_file_atomic(outdir / "scene.toml", wing_scene_toml());
  written.push_back("scene.toml");
  return written;
}

}  // namespace loom::examples
