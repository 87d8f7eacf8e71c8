#pragma once
/// Refusals that concern one cable of a harness (its chords, samples, tube rings or pairs in
/// contact would exceed what loom takes) raised by code that knows the cable by id only, and
/// their translation, where the harness is known, into an InputError naming the harness file
/// and the line of the cable's element (DESIGN §4).

#include "core/error.hpp"
#include "core/harness.hpp"

#include <stdexcept>
#include <string>
#include <utility>

namespace loom {

/// A cable asks more work of a stage than it takes, or a resolution it cannot give. what()
/// is the whole reason and names the cable; cable() is its id. A std::invalid_argument, so
/// callers without a harness file to name see the refusal they always saw.
class CableLimitError : public std::invalid_argument {
 public:
  /// `cable`: the id of the cable; `reason`: the message (naming the cable).
  CableLimitError(std::string cable, const std::string& reason)
      : std::invalid_argument(reason), cable_(std::move(cable)) {}
  /// Id of the cable the refusal is about.
  const std::string& cable() const { return cable_; }

 private:
  std::string cable_;
};

/// The refusal `e` as an InputError at the cable's element of `h` (h.source_file and the
/// cable's line; the file alone when the harness has no such cable).
inline InputError cable_input_error(const Harness& h, const CableLimitError& e) {
  const int c = h.find_cable(e.cable());
  const int line = c >= 0 ? h.cables[static_cast<std::size_t>(c)].line : 0;
  return InputError({h.source_file, line, ""}, e.what());
}

/// Runs f() and returns what it returns; a CableLimitError it throws is rethrown as
/// cable_input_error(h, e).
template <class F>
decltype(auto) naming_cable_errors(const Harness& h, F&& f) {
  try {
    return f();
  } catch (const CableLimitError& e) {
    throw cable_input_error(h, e);
  }
}

}  // namespace loom
