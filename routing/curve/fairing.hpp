#pragma once
/// Fairing of an interpolating cable centerline (seed: cable-bspline-interpolation-and-
/// fairing §III): the energy method (α∫κ²ds + Σβᵢ‖pᵢ − qᵢ‖², α halved until
/// max‖pᵢ − qᵢ‖ ≤ ε) and the selected-point method (bad points from curvature sign changes,
/// ranked by third-derivative jumps, moved toward a re-fit by at most ε).
/// All lengths in scene units; curves in world coordinates.

#include "core/centerline.hpp"

#include <vector>

namespace loom {

/// Which control points of the curve a fairing may not move.
enum class FairingEnds {
  Free,                ///< nothing fixed (ends move like any key point)
  Position,            ///< the end points stay where they are
  PositionAndTangent,  ///< the end points and the end tangents (a cable leaves its port straight)
};

/// How a fairing ended.
enum class FairingStatus {
  Faired,         ///< a fairer curve within ε was found
  AlreadyFair,    ///< (selected-point) no bad point: the input is returned unchanged
  Interpolant,    ///< (energy) no α > 0 within ε after max_iterations halvings: the interpolant (α = 0)
  IterationLimit, ///< (selected-point) bad points remain after max_iterations revisions
  ToleranceLimit, ///< (selected-point) bad points remain that cannot move further within ε
};

/// Parameters of both fairing methods.
struct FairingOptions {
  double tolerance = 0.0;   ///< ε: largest allowed distance of a key point from the faired curve, scene units (> 0)
  double alpha = 0.0;       ///< (energy) first smoothing factor α, scene units³; 0 = derived from the curve
  std::vector<double> weights;  ///< (energy) βᵢ per key point (dimensionless); empty = all 1
  int max_iterations = 60;  ///< halvings of α (energy) or point revisions (selected-point)
  FairingEnds ends = FairingEnds::PositionAndTangent;
};

/// What a fairing produced. The bending energies ∫κ²ds before and after are not computed
/// here (they cost about a third of a fairing and a routing pipeline does not read them):
/// bending_energy(input curve) and bending_energy(result.curve) give them on demand.
struct FairingResult {
  Centerline curve;              ///< the faired curve (same knots as the input for the energy method)
  FairingStatus status = FairingStatus::Faired;
  double alpha = 0.0;            ///< (energy) the α used; 0 for the interpolant / selected-point
  double max_deviation = 0.0;    ///< max ‖pᵢ − q(uᵢ)‖ over the key points, scene units
  int iterations = 0;            ///< α values tried / revisions made
  std::vector<Vec3> points;      ///< the faired key points qᵢ = q(uᵢ) (one per input key point)
};

/// ∫κ²ds of a curve (Gauss–Legendre per knot span), 1/scene units.
double bending_energy(const Centerline& c);

/// Energy-method fairing of an interpolating cubic (built by Centerline::interpolate: its
/// key parameters and key points qᵢ = C(uᵢ) are the data). Keeps the knots; minimises
/// α∫|q''|²du + Σβᵢ‖q(uᵢ) − pᵢ‖² (parameters are in chord-length units, so ∫|q''|²du ≈
/// ∫κ²ds) starting at `alpha` and halving it until max‖pᵢ − qᵢ‖ ≤ ε. Throws
/// std::invalid_argument if the curve has no key parameters, is not cubic, or ε ≤ 0.
FairingResult fair_energy(const Centerline& interpolant, const FairingOptions& opt);

/// Selected-point fairing of the key points `points` (interpolated with `interp`): finds
/// bad points (relative curvature of the XY or ZX projection changes sign before and after
/// them, seed eq. 4), revises the one with the largest third-derivative jump (eq. 5) toward
/// the curve re-fitted without it (eqs. 6–7), never moving any point more than ε from where
/// it started, and repeats. Throws std::invalid_argument on bad input (as interpolate).
FairingResult fair_selected_points(const std::vector<Vec3>& points, const InterpolationOptions& interp,
                                   const FairingOptions& opt);

}  // namespace loom
