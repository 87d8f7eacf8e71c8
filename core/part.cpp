#include "core/part.hpp"

namespace loom {

const char* role_name(PartRole r) { return r == PartRole::KeepOut ? "keep_out" : "structure"; }

}  // namespace loom
