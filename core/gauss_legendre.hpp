#pragma once
/// 8-point Gauss–Legendre quadrature on [−1, 1] (exact for polynomials of degree ≤ 15):
/// the one table behind arc length (core/centerline) and bending energy (routing/fairing).
/// ∫_a^b f ≈ h Σ w_i f(m + h x_i) with m = (a + b)/2, h = (b − a)/2.

#include <array>

namespace loom::gauss_legendre8 {

/// Nodes x_i on [−1, 1], ascending.
constexpr std::array<double, 8> kNodes = {-0.9602898564975363, -0.7966664774136267, -0.5255324099163290,
                                          -0.1834346424956498, 0.1834346424956498,  0.5255324099163290,
                                          0.7966664774136267,  0.9602898564975363};
/// Weights w_i (sum 2).
constexpr std::array<double, 8> kWeights = {0.1012285362903763, 0.2223810344533745, 0.3137066458778873,
                                            0.3626837833783620, 0.3626837833783620, 0.3137066458778873,
                                            0.2223810344533745, 0.1012285362903763};

}  // namespace loom::gauss_legendre8
