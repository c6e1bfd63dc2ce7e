// The parameters the paper determined for its board (Table 6), in the order of Table 1's sensors
// (the paper lists them by calibration set). Used as realistic defaults by the simulation, the
// benchmarks and the bare-metal probe; the calibration's golden test keeps its own copy as the
// oracle it checks against.
#pragma once

#include <array>
#include <cstddef>
#include <numbers>

#include "gfins/nav_core/misalignment.hpp"

namespace gfins::nav::paper_table6 {

/// SF_aj, V/g, sensors 1..6.
inline constexpr std::array<double, 6> kScaleVPerG = {0.509874, 0.332572, 0.500242,
                                                      2.493301, 0.339215, 2.476663};
/// b_aj, g, sensors 1..6.
inline constexpr std::array<double, 6> kBiasG = {-0.000731, -0.000242, 0.000867,
                                                 -0.007977, -0.000891, -0.004691};
/// Δβ (set {2,3,5}) and Δα (set {1,4,6}), degrees as printed, order xy, xz, yx, yz, zx, zy.
inline constexpr std::array<double, 6> kBetaDeg = {1.117319,  -0.175730, -0.581196,
                                                   -0.738742, 2.454457,  2.482135};
inline constexpr std::array<double, 6> kAlphaDeg = {-2.654967, 2.596778, -0.838703,
                                                    -0.737387, 0.119537, -1.451107};

/// The Table 6 orientation errors in radians (location errors zero: the paper has none).
template <typename T>
Misalignment<T> misalignment() {
  constexpr double kDeg = std::numbers::pi / 180.0;
  Misalignment<T> m;
  for (std::size_t i = 0; i < 6; ++i) {
    m.orientation.beta[i] = static_cast<T>(kBetaDeg[i] * kDeg);
    m.orientation.alpha[i] = static_cast<T>(kAlphaDeg[i] * kDeg);
  }
  return m;
}

}  // namespace gfins::nav::paper_table6
