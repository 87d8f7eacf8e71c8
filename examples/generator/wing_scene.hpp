#pragma once
/// The scene TOML (DESIGN §3) of the wing-section example: every part placed from the
/// generated STEP files with transforms (repeated parts share one file), the keep-out
/// envelope of the actuator, the harness file and the routing and α-SIM settings.

#include <string>

namespace loom::examples {

/// Required cable-to-structure clearance written to [routing], mm.
constexpr double kSceneClearance = 3.0;
/// Extra clearance asked for around the actuator (moving, hot), mm.
constexpr double kActuatorExtraClearance = 5.0;
/// α-SIM level of detail written to [simplify], mm: rivet holes (Ø4), slots (3 mm) and the
/// rod's thread rings vanish; lightening holes (Ø110) and receptacle bores (Ø22) stay.
constexpr double kSceneDimPre = 8.0;

/// Planner iterations per segment written to [routing], so that `loom demo` gives the same
/// routed.xml every run. Measured on the demo (seed 1, Release, 2 cores): 500 routes 24/24
/// with 0 clashes and 0 violations, planning in ~0.35 s against ~0.5 s without a budget, the
/// longest plan ~0.2 s of the 0.5 s time limit; 200 is also clean but ~1% longer.
constexpr int kSceneIterations = 500;

/// Longest unsupported stretch written to [routing] clamp_spacing, mm: `route` pulls the
/// trunk to structure and places clamps at most this far apart (AC 43.13-1B allows 610 mm).
constexpr double kSceneClampSpacing = 450.0;

/// The scene.toml text; file names are relative to the scene file's directory.
std::string wing_scene_toml();

}  // namespace loom::examples
