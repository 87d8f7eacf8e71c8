#pragma once
/// The tetrahedron glTF seed of the fuzz corpus (tests/fuzz/seeds/gltf/tetra.gltf), for
/// tests that build hostile variants of it.

#include "common/test_files.hpp"

#include <cstring>
#include <filesystem>
#include <string>

namespace loom::testing {

/// The seed's text: 4 positions (accessor 0), 12 unsigned-short indices (accessor 1), one
/// 72-byte buffer as a base64 data URI.
inline std::string tetra_gltf_text() {
  return slurp(std::filesystem::path(LOOM_SOURCE_DIR) / "tests/fuzz/seeds/gltf/tetra.gltf");
}

/// The seed's buffer: 48 bytes of float positions, then 24 of unsigned-short indices.
inline std::string tetra_gltf_buffer() {
  std::string bin;
  for (const float c : {0.f, 0.f, 0.f, 10.f, 0.f, 0.f, 0.f, 10.f, 0.f, 0.f, 0.f, 10.f}) {
    char b[4];
    std::memcpy(b, &c, 4);  // little-endian, as glTF and the machines loom runs on
    bin.append(b, 4);
  }
  for (const int i : {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3}) bin += std::string{static_cast<char>(i), '\0'};
  return bin;
}

}  // namespace loom::testing
