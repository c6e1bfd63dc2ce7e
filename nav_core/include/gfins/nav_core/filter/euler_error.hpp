// Euler angles (Z-Y-X: roll φ_r, pitch θ, yaw ψ) against the attitude error φ_n of eq. (7), for
// the published 1σ of roll, pitch and heading and for the heading update.
//
// The navigation-frame rate of a Z-Y-X attitude is ω_n = E [φ̇_r θ̇ ψ̇]ᵀ with
//   E = [cψcθ  −sψ  0;  sψcθ  cψ  0;  −sθ  0  1],
// so a small rotation ε applied in the n frame (C ← exp([ε×]) C) changes the angles by E⁻¹ ε:
//   E⁻¹ = [cψ/cθ  sψ/cθ  0;  −sψ  cψ  0;  cψ tθ  sψ tθ  1].
// The computed attitude is Ĉ = exp(−[φ×]) C (eq. (7)), so
//   [δφ_r δθ δψ]ᵀ = (euler(Ĉ) − euler(C)) = J φ,   J = −E⁻¹(ψ̂, θ̂),
// and Cov(Euler error) = J P_φφ Jᵀ. J is singular at θ = ±90° (gimbal lock): the roll and yaw
// σ grow without bound there, which is the truth about those angles.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "gfins/nav_core/filter/measurement.hpp"

namespace gfins::nav {

/// J = ∂(Euler error)/∂φ at the attitude q_nb (rows roll, pitch, yaw).
template <typename T>
Mat3<T> euler_error_jacobian(const Quat<T>& q_nb) {
  // cos θ, sin θ, cos ψ, sin ψ of euler_from_quat's angles, read off C = C_n^b ᵀ's first column
  // [cψ cθ, sψ cθ, −sθ] (no trigonometric function: cθ ≥ 0 for θ in [−90°, 90°]). At gimbal
  // lock ψ is atan2(0, 0) = 0 there, and cθ is kept at the scalar's ε so J stays finite (huge).
  const Mat3<T> m = q_nb.toRotationMatrix();
  const T h = std::sqrt(m(0, 0) * m(0, 0) + m(1, 0) * m(1, 0));
  const T cp = std::max(h, std::numeric_limits<T>::epsilon());
  const T tp = std::clamp(-m(2, 0), T(-1), T(1)) / cp;
  const T cy = h > T(0) ? m(0, 0) / h : T(1);
  const T sy = h > T(0) ? m(1, 0) / h : T(0);
  Mat3<T> j;
  j << -cy / cp, -sy / cp, T(0),  //
      sy, -cy, T(0),              //
      -cy * tp, -sy * tp, T(-1);
  return j;
}

/// Wraps an angle difference into (−π, π].
template <typename T>
T wrap_pi(T a) {
  constexpr T kPi = T(3.14159265358979323846);
  while (a > kPi) a -= T(2) * kPi;
  while (a <= -kPi) a += T(2) * kPi;
  return a;
}

/// An external heading (dual-antenna GNSS, magnetometer): yaw from north, its 1σ and the instant
/// it was valid (the filter compares it with its own heading at that instant, from the history).
template <typename T>
struct HeadingFix {
  std::int64_t t_valid_ns = 0;
  T yaw_rad = T(0);
  T sigma_rad = T(1);
};

/// External heading (yaw, rad from north, 1σ sigma_rad): y = ψ̂ − ψ = J_yaw φ − n, 1-D.
template <typename T>
Measurement<T, 1> heading_measurement(const Quat<T>& q_nb, T yaw_rad, T sigma_rad) {
  Measurement<T, 1> m;
  m.y(0) = wrap_pi(euler_from_quat(q_nb).z() - yaw_rad);
  m.h.template block<1, 3>(0, filt_idx::kPhi) = euler_error_jacobian(q_nb).row(2);
  m.r(0, 0) = sigma_rad * sigma_rad;
  return m;
}

}  // namespace gfins::nav
