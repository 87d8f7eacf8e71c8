#include "examples/generator/number_text.hpp"

#include <array>
#include <charconv>
#include <stdexcept>

namespace loom::examples {

std::string num(double v) {
  if (v == 0.0) return "0";  // also turns -0 into 0
  std::array<char, 64> buf{};
  const auto r = std::to_chars(buf.data(), buf.data() + buf.size(), v);
  if (r.ec != std::errc()) throw std::logic_error("num: cannot format number");
  return std::string(buf.data(), r.ptr);
}

}  // namespace loom::examples
