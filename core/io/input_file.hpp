#pragma once
/// The check every reader makes before it opens an input file.

#include <cstddef>
#include <filesystem>
#include <limits>
#include <string>

namespace loom {

/// Throws InputError naming `path` unless it is an existing regular file that opens for
/// reading: "<what> not found", "not a regular file" (a directory reads as nothing, a device
/// such as /dev/zero or a pipe never ends), "cannot access <what>: <why>" (a symbolic link
/// loop, say), or "cannot read <what>". `what` names the kind
/// of file ("scene file", "harness file", ...).
void require_input_file(const std::filesystem::path& path, const std::string& what);

/// The bytes of a file, at most `limit` of them from its start ("" for a file that does not
/// open): for the readers' checks made before a library reads the file.
std::string file_bytes(const std::filesystem::path& path,
                       std::size_t limit = std::numeric_limits<std::size_t>::max());

/// `t` with every byte outside printable ASCII written as \xNN, for a message that names a
/// corrupt token (a NUL would end the message where it is printed).
std::string printable(const std::string& t);

}  // namespace loom
