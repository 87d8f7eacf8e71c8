#pragma once
/// Deterministic STEP output: one named product per file, a fixed header (no wall-clock
/// time stamp, no absolute path) so that regenerating gives byte-identical files.

#include <TopoDS_Shape.hxx>

#include <filesystem>
#include <string>

namespace loom::examples {

/// The fixed FILE_NAME time stamp written into every generated STEP file.
constexpr const char* kStepTimeStamp = "2026-01-01T00:00:00";

/// Writes `shape` (mm) as an AP214 STEP file whose single product is named `product`
/// (through XCAF, so readers keep the name). The header's FILE_NAME carries the file's
/// base name and kStepTimeStamp. Throws std::runtime_error if OpenCASCADE fails.
void write_named_step(const TopoDS_Shape& shape, const std::string& product, const std::filesystem::path& file);

}  // namespace loom::examples
