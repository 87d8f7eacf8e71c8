#pragma once
/// File names for per-part outputs (`loom simplify`'s <stem>.stl and <stem>.step).
#include <cstddef>
#include <string>
#include <vector>

namespace loom {

/// Longest stem output_file_stems returns before a duplicate's "_N" (bytes): with an
/// extension it stays far below the 255-byte file-name limit of common file systems.
constexpr std::size_t kMaxFileStemLength = 96;

/// One file stem per name, in order: characters outside [A-Za-z0-9._-] (path separators,
/// spaces, control and non-ASCII bytes) become '_', an empty name becomes "part", a stem
/// that would start with '.' gets a leading '_' (no hidden files, no "." or ".."), a name
/// longer than kMaxFileStemLength is cut and ends in '-' and 16 hex digits of a hash of the
/// whole name, and later duplicates get "_2", "_3", … — so every stem is a valid, distinct
/// file name in one directory.
std::vector<std::string> output_file_stems(const std::vector<std::string>& names);

}  // namespace loom
