#pragma once
/// Checks of an ASCII STL file made before Assimp reads it.

#include <cstddef>
#include <filesystem>

namespace loom {

/// Longest solid name Assimp 5.2 accepts (its AI_MAXLEN is 1024 with the terminator).
constexpr std::size_t kMaxStlSolidName = 1023;

/// Throws InputError naming the file, the line and the facet when an ASCII STL file (one
/// Assimp reads as text: it starts with `solid` and its size is not that of a binary STL
/// of the count at byte 80) is not a sequence of solids of complete facets:
/// `facet normal x y z`, optionally `outer loop`, exactly three `vertex x y z`, optionally
/// `endloop`, `endfacet`; numbers are decimal numbers (a missing or blank one is not 0).
/// Why: Assimp reads a facet without its normal, with fewer vertices or a file ending
/// inside one, and then rejects the file, leaking the solid it was building (each refusal
/// costs ~2.5 kB for the life of the process); it drops a fourth vertex and reads a word as
/// 0 without a word. Binary STL and text that does not start with `solid` pass unchanged
/// (Assimp reports those itself). One pass; memory is the file's bytes.
void check_stl_file(const std::filesystem::path& path);

}  // namespace loom
