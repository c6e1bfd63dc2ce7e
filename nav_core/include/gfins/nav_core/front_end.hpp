// Front end: ADC counts → volts → specific force along each sensitive axis, per sensor.
//
// The QA-1100 output current through its load resistor gives a voltage P = SF (f·θ + b) with SF
// in V/g and b in g (paper eq. (21)); so f·θ = P/SF − b. The multi-attitude calibration (§4.1)
// takes |f| = 1 g in every pose, so "g" in V/g and in the bias is the LOCAL gravity of the
// calibration site (9.7894 m/s² at 24.8° latitude, 9.8322 at the poles), not the standard
// 9.80665: the result is converted to m/s² with that g (FrontEndParams::gravity_mps2, stored in
// the calibration file). Converting with standard gravity instead would scale every specific
// force by 9.80665/g_cal (+0.18 % for a board calibrated at 24.8°). Scale factor and bias are
// the calibrated ones; orientation and location errors are the compensator's job.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>

#include "gfins/nav_core/geometry.hpp"
#include "gfins/sample/raw_sample.hpp"
#include "gfins/status/status.hpp"

namespace gfins::nav {

template <typename T, int N = kNumSensors>
struct FrontEndParams {
  std::array<T, N> volts_per_count{};  // ADC LSB per channel, V (Vref / (gain · 2^23))
  std::array<T, N> scale_v_per_g{};    // SF_aj, V/g (paper Table 6)
  std::array<T, N> bias_g{};           // b_aj, g (paper Table 6)
  /// The g of the two lines above, m/s²: local gravity magnitude of the calibration site.
  T gravity_mps2 = static_cast<T>(kStandardGravity);

  template <typename U>
  FrontEndParams<U, N> cast() const {
    FrontEndParams<U, N> o;
    for (std::size_t j = 0; j < static_cast<std::size_t>(N); ++j) {
      o.volts_per_count[j] = static_cast<U>(volts_per_count[j]);
      o.scale_v_per_g[j] = static_cast<U>(scale_v_per_g[j]);
      o.bias_g[j] = static_cast<U>(bias_g[j]);
    }
    o.gravity_mps2 = static_cast<U>(gravity_mps2);
    return o;
  }
};

template <typename T, int N = kNumSensors>
class FrontEnd {
 public:
  using Outputs = Eigen::Matrix<T, N, 1>;

  FrontEnd() = default;

  /// Fails with kInvalidArgument when a scale factor, LSB, their gain or the calibration gravity
  /// is zero, negative or not finite (or the gain subnormal) in T.
  static Result<FrontEnd> create(const FrontEndParams<T, N>& p) {
    FrontEnd fe;
    const T g = p.gravity_mps2;  // local gravity of the calibration site: the g of V/g
    if (!(g > T(0)) || !std::isfinite(g)) {
      return Status(ErrorCode::kInvalidArgument,
                    "front end: the calibration gravity is not a positive finite number");
    }
    for (int j = 0; j < N; ++j) {
      const auto i = static_cast<std::size_t>(j);
      const T sf = p.scale_v_per_g[i];
      const T lsb = p.volts_per_count[i];
      const T gain = lsb * g / sf;
      if (!(sf > T(0)) || !(lsb > T(0)) || !std::isfinite(sf) || !std::isfinite(lsb) ||
          !std::isfinite(p.bias_g[i]) || !std::isnormal(gain)) {
        return Status(ErrorCode::kInvalidArgument,
                      "front end: a scale factor or ADC LSB, or their gain LSB*g/SF, is zero, "
                      "negative or not finite in the core's scalar type");
      }
      fe.gain_(j) = gain;
      fe.offset_(j) = p.bias_g[i] * g;
    }
    fe.params_ = p;
    return fe;
  }

  /// s**_j = (counts_j · LSB_j / SF_j − b_j) · g_cal (m/s²). Returns a mask of the channels whose
  /// code sits at the converter's full scale (saturated: the value is not a measurement).
  std::uint32_t convert(const std::array<std::int32_t, N>& counts, Outputs& s) const {
    // Conversion and the range of the codes in one branch-free loop (the compiler vectorises
    // it); the per-channel mask is built only when a code reaches a rail, which is rare.
    std::int32_t lo = counts[0];
    std::int32_t hi = counts[0];
    for (int j = 0; j < N; ++j) {
      const std::int32_t c = counts[static_cast<std::size_t>(j)];
      lo = std::min(lo, c);
      hi = std::max(hi, c);
      s(j) = gain_(j) * static_cast<T>(c) - offset_(j);
    }
    if (lo > kAdcCodeMin && hi < kAdcCodeMax) return 0;
    std::uint32_t saturated = 0;
    for (int j = 0; j < N; ++j) {
      const std::int32_t c = counts[static_cast<std::size_t>(j)];
      if (c >= kAdcCodeMax || c <= kAdcCodeMin) saturated |= 1u << j;
    }
    return saturated;
  }

  /// Inverse of convert (without rounding to integers): the counts a specific force gives.
  T counts_for(int j, T s_mps2) const { return (s_mps2 + offset_(j)) / gain_(j); }

  const FrontEndParams<T, N>& params() const { return params_; }

 private:
  Outputs gain_ = Outputs::Ones();    // m/s² per count
  Outputs offset_ = Outputs::Zero();  // m/s²
  FrontEndParams<T, N> params_{};
};

}  // namespace gfins::nav
