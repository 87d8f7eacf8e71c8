#pragma once
/// Checks of numeric command-line values, applied to the options themselves (CLI11
/// validators), so that a bad given value is a usage error (exit 2, the option named)
/// before any work — and never mistaken for an option's "not given" value.

#include <CLI/CLI.hpp>

namespace loom::app {

/// Accepts a finite number ≥ min (min_allowed) or > min (!min_allowed); rejects NaN,
/// ±inf and text that is not a whole number. The message names the limit and the value.
CLI::Validator finite_number(double min, bool min_allowed);

/// Accepts a whole number in [min, max] written in decimal digits (an optional sign); rejects
/// fractions, exponents, text and values out of range (e.g. `--threads 0`, `--threads -1`,
/// or a `--seed` beyond the 32-bit seed the planner takes, which would be cut to another).
/// The message names the range and the value.
CLI::Validator whole_number(long long min, long long max);

/// Bytes in a size written as a positive finite number with an optional binary suffix
/// K, M, G or T (KiB…TiB; "G", "GiB" and "GB" alike mean 2³⁰), e.g. "24G", "1.5T",
/// "4096". 0 for text that is not one.
double byte_size_value(const std::string& text);

/// Accepts what byte_size_value reads; the message names the form and the value.
CLI::Validator byte_size();

/// Accepts a non-empty path. Why: an empty `--out ""` would otherwise write into the current
/// directory, which the user did not name.
CLI::Validator non_empty_path();

}  // namespace loom::app
