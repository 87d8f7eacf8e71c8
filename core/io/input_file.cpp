#include "core/io/input_file.hpp"

#include "core/error.hpp"

#include <fstream>
#include <system_error>

namespace loom {

void require_input_file(const std::filesystem::path& path, const std::string& what) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw InputError({path.string(), 0, ""}, what + " not found");
  if (!std::filesystem::is_regular_file(path, ec)) throw InputError({path.string(), 0, ""}, "not a regular file");
  std::ifstream probe(path, std::ios::binary);
  if (!probe) throw InputError({path.string(), 0, ""}, "cannot read " + what);
}

}  // namespace loom
