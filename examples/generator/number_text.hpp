#pragma once
/// Locale-independent, shortest round-trip text for the numbers the generator writes.

#include <string>

namespace loom::examples {

/// `v` as the shortest decimal text that reads back to the same double ("85", "1.3").
std::string num(double v);

}  // namespace loom::examples
