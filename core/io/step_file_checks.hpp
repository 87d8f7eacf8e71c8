#pragma once
/// Checks of a STEP file made before OpenCASCADE reads it, for what its transfer does not check.

#include <filesystem>

namespace loom {

/// Throws InputError naming the file, the line and the entity instance when an instance
/// refers to one the file does not define (`#90 = VECTOR('',#91,1.)` without a `#91`). Why:
/// OpenCASCADE's reader leaves such a reference null and its transfer follows it (SIGSEGV).
/// One pass over the file, strings and comments skipped; memory linear in the references.
void check_step_references(const std::filesystem::path& path);

}  // namespace loom
