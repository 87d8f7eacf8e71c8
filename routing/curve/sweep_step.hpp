#pragma once
/// STEP export of a swept cable through OpenCASCADE: a closed solid whose lateral face is
/// a NURBS surface — exact rational circles around, a cubic through the sweep's
/// cross-sections along — capped by two planar discs. Built directly from the sections (no
/// BRepOffsetAPI_MakePipeShell, which can hang on some spines: DESIGN §9).

#include "core/centerline.hpp"
#include "routing/curve/sweep.hpp"

#include <filesystem>
#include <string>

namespace loom {

/// How a STEP export ended.
enum class StepExportStatus {
  Written,       ///< the file holds a valid closed solid
  InvalidShape,  ///< OpenCASCADE rejected the solid (BRepCheck); nothing written
  WriteFailed,   ///< the STEP writer or the file system failed; nothing written
};

/// What a STEP export produced.
struct StepExportResult {
  StepExportStatus status = StepExportStatus::WriteFailed;
  std::string message;   ///< empty when Written, else the reason
  double volume = 0.0;   ///< volume of the solid, scene units³
  double area = 0.0;     ///< surface area of the solid, scene units²
  int sections = 0;      ///< cross-sections the lateral surface interpolates
};

/// Writes the tube of radius r around `c` as a STEP (AP214) solid to `path` (atomically:
/// temporary file, then rename). Section spacing comes from opt.chord_tolerance as in
/// sweep_tube; `length_unit` is the STEP unit name of scene units ("MM", "M", "INCH").
/// Throws std::invalid_argument on bad input (as sweep_tube).
StepExportResult write_tube_step(const Centerline& c, double radius, const std::filesystem::path& path,
                                 const SweepOptions& opt = {}, const std::string& length_unit = "MM");

}  // namespace loom
