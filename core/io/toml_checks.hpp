#pragma once
/// Checks of a TOML text made before toml++ parses it, for what toml++ 3 does not bound.

#include <cstddef>
#include <string>

namespace loom {

/// Deepest nesting of tables, arrays and inline tables accepted in a TOML file, counting every
/// key of a dotted key or table header (`[a.b.c]` is three levels). toml++ bounds arrays and
/// inline tables at 256 nested values (TOML_MAX_NESTED_VALUES) but not dotted keys or table
/// headers, and it builds and destroys the tables recursively: a header 50,000 keys deep
/// (100 kB) overflowed the stack. The same 256 bounds all of them here; a scene nests 3 deep.
constexpr std::size_t kMaxTomlNesting = 256;

/// Throws InputError naming `file` and the line where the nesting of `text` first exceeds
/// kMaxTomlNesting. Linear in the text; malformed TOML is left to the parser, which reports it.
void check_toml_nesting(const std::string& text, const std::string& file);

}  // namespace loom
