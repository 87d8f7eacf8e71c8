#pragma once
/// A scene: parts, the harness, and the settings for routing, simplification and
/// tessellation. Every resolution that is not given is derived from the scene and the
/// derivation is recorded (DESIGN §7: model no more than a scene needs).

#include "core/harness.hpp"
#include "core/part.hpp"
#include "core/units.hpp"

#include <map>
#include <string>
#include <utility>
#include <vector>

namespace loom {

/// A numeric setting together with where its value came from.
struct Setting {
  double value = 0.0;
  std::string source;  ///< "scene file" or the derivation rule, e.g. "smallest cable radius / 10"
};

/// Largest iteration budget per plan ([routing] iterations, `loom route --iterations`). Far
/// above what any time limit lets a planner reach (a planner iteration costs microseconds to
/// milliseconds here): a larger budget could only be ended by the time limit, which is what
/// the budget is there to avoid.
constexpr long long kMaxPlanIterations = 100'000'000;
/// Most [simplify] planes beyond the three axis planes (each adds a projection's work).
constexpr std::size_t kMaxSimplifyPlanes = 16;

/// [routing] of the scene file.
/// The OMPL geometric planners that a scene's routing.planner may name, sorted. The scene
/// loader refuses any other name (file and line); loom::route maps each to its OMPL class.
const std::vector<std::string>& routing_planner_names();

struct RoutingSettings {
  Setting clearance;       ///< required gap between cable surface and structure
  /// One of routing_planner_names(); default the portfolio (RRT-Connect's corridor, then
  /// Informed RRT* within the budget: routing/route/planner_portfolio.hpp).
  std::string planner = "portfolio";
  Setting time_limit;      ///< seconds per cable or bundle
  unsigned seed = 1;
  /// Planner iterations per cable or bundle, 1..kMaxPlanIterations; 0 = none (the planners
  /// stop on the time limit or on time-based convergence, so runs differ). With a budget,
  /// a seeded route is reproducible unless the time limit ends a plan first.
  Setting iterations;
  /// Longest stretch of cable between two supports (ports or clamps within reach of
  /// structure), scene units; default 450 mm (AC 43.13-1B allows 610 mm).
  Setting clamp_spacing;
  /// Largest gap between a clamped bundle's surface and the structure part the clamp is
  /// fixed to, scene units; default 25 mm. The reach from the centreline adds the bundle radius.
  Setting clamp_reach;
  /// Extra planning cost per unit length of a route farther than clamp_reach (+ bundle
  /// radius) from structure, relative to its length cost (PlanObjective::support_weight);
  /// used when `supports`. Default 0: on the wing section weight 1 made planning ~10× slower
  /// for one point more of length within reach, while pull_to_structure, which always runs
  /// when `supports`, removes every unsupported span at no planning cost (docs/route.md).
  Setting support_weight;
  /// True when the scene sets clamp_spacing: only then are supports audited (unsupported-span)
  /// and clamps placed after routing, so scenes written without supports in mind do not change.
  bool supports = false;
  /// [routing.separation]: least distance between the surfaces of cables of two classes,
  /// scene units, keyed by the class pair in ascending order (symmetric).
  std::map<std::pair<std::string, std::string>, double> separation;
  /// The separation required between cables of classes a and b, or 0 when none is given.
  double separation_between(const std::string& a, const std::string& b) const;
};

/// [simplify] of the scene file (α-SIM level of detail).
struct SimplifySettings {
  Setting dim_pre;  ///< features smaller than this vanish; default smallest cable diameter
  /// `planes`: normals of projection planes beyond XY, XZ and YZ (need not be unit; none by
  /// default). Parts turned off the axes simplify better seen along their own axes.
  std::vector<Vec3> planes;
  /// `split`: a part whose projections hide a feature is split into pieces (default true).
  bool split = true;
};

/// [tessellation]: how finely STEP/IGES B-reps are meshed.
struct TessellationSettings {
  Setting linear_deflection;  ///< max chord deviation; default smallest cable radius / 10
  Setting angular_deflection_deg;
  /// Tessellation by need (`loom audit`): CAD parts are meshed at `coarse_deflection` first
  /// and again at `linear_deflection` only where a cable comes within reach of them.
  bool by_need = false;
  Setting coarse_deflection;  ///< default kCoarseDeflectionFactor × linear_deflection
};

/// Default coarse deflection of tessellation by need, in fine deflections: coarse enough
/// that curved housings cost a few thousand triangles, fine enough that the reach it adds
/// to the need test (the coarse deflection) selects few parts the fine mesh would not.
constexpr double kCoarseDeflectionFactor = 20.0;

/// Everything a command needs about the problem.
struct Scene {
  std::string name;
  Unit units = Unit::Millimetre;
  std::string source_file;  ///< the TOML file
  std::vector<Part> parts;
  Harness harness;
  bool has_harness = false;
  RoutingSettings routing;
  SimplifySettings simplify;
  TessellationSettings tessellation;

  /// Bounding box of all parts and ports.
  AABB bounds() const;
  /// Total triangle count over all parts.
  std::size_t triangle_count() const;
  /// Index of a part by name, or -1.
  int find_part(const std::string& name) const;
};

}  // namespace loom
