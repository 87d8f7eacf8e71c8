#pragma once
/// A harness read from KBL written back as KBL: the file it was read from, with loom's
/// geometry in place of the file's — node positions, centre curves in the file's convention
/// (kbl_curve.hpp: one uniform single-span curve per knot span of loom's curve), Virtual_length,
/// Start_vector and End_vector of every segment with a curve, and the DMU length of every
/// wire, multicore and core whose route is complete. Everything else in the file is kept.
/// KBL → loom → KBL → loom is the identity on the topology and on the geometry to rounding.

#include "core/harness.hpp"

#include <filesystem>
#include <string>

namespace loom {

/// The file `route --out` and `audit --out` write beside their other outputs when the
/// harness was read from KBL.
constexpr const char* kRoutedKblName = "routed.kbl";

/// The KBL text of `h` (read from KBL: Harness::kbl is set). Throws std::invalid_argument when
/// `h` was not read from KBL or no longer has that file's nodes and segments.
std::string harness_to_kbl(const Harness& h);

/// Writes harness_to_kbl(h) atomically.
void write_harness_kbl(const Harness& h, const std::filesystem::path& path);

}  // namespace loom
