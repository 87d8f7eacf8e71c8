#include "core/io/input_file.hpp"

#include "core/error.hpp"

#include <algorithm>
#include <fstream>
#include <system_error>

namespace loom {

void require_input_file(const std::filesystem::path& path, const std::string& what) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) {
    // exists() is false with an error too: a symbolic link loop, a directory that may not be
    // searched. "not found" would send the user looking for a file that is there.
    if (ec && ec != std::errc::no_such_file_or_directory && ec != std::errc::not_a_directory)
      throw InputError({path.string(), 0, ""}, "cannot access " + what + ": " + ec.message());
    throw InputError({path.string(), 0, ""}, what + " not found");
  }
  if (!std::filesystem::is_regular_file(path, ec)) throw InputError({path.string(), 0, ""}, "not a regular file");
  std::ifstream probe(path, std::ios::binary);
  if (!probe) throw InputError({path.string(), 0, ""}, "cannot read " + what);
}

std::string file_bytes(const std::filesystem::path& path, std::size_t limit) {
  std::ifstream in(path, std::ios::binary);
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  std::string s(ec ? 0 : static_cast<std::size_t>(std::min<std::uintmax_t>(size, limit)), '\0');
  in.read(s.data(), static_cast<std::streamsize>(s.size()));
  s.resize(static_cast<std::size_t>(std::max<std::streamsize>(in.gcount(), 0)));
  return s;
}

std::string printable(const std::string& t) {
  static const char* kHex = "0123456789abcdef";
  std::string out;
  for (const unsigned char c : t) {
    if (c >= 0x20 && c < 0x7f) {
      out += static_cast<char>(c);
    } else {
      out += "\\x";
      out += kHex[c >> 4];
      out += kHex[c & 15];
    }
  }
  return out;
}

}  // namespace loom
