// Standstill updates: zero velocity (ZUPT) and zero angular rate (ZARU), each 3-D.
//
// At rest v_n = 0 and ω_b = 0 exactly, so the "measurement" is z = 0 with a small R that stands
// for the residual motion of a vehicle at rest (engine vibration, a person leaning on it).
//   ZUPT: ẑ = v̂_n, y = v̂_n − 0 = δv_n       H = [0 0 I 0 0 0]
//   ZARU: ẑ = ω̂_b, y = ω̂_b − 0 = δω_b       H = [0 0 0 I 0 0]
// Without a gyro ZARU is what bounds the rate error: ω is the integral of ω̇ (eq. (13)), so at
// rest it observes δω directly and, through its growth, the bias δβ_ω̇.
#pragma once

#include "gfins/nav_core/filter/measurement.hpp"
#include "gfins/nav_core/nav_state.hpp"

namespace gfins::nav {

template <typename T>
Measurement<T, 3> zupt_measurement(const NavState<T>& nav, T sigma_mps) {
  Measurement<T, 3> m;
  m.y = nav.v_n;
  m.h.template block<3, 3>(0, filt_idx::kVel).setIdentity();
  m.r.diagonal().setConstant(sigma_mps * sigma_mps);
  return m;
}

template <typename T>
Measurement<T, 3> zaru_measurement(const NavState<T>& nav, T sigma_rps) {
  Measurement<T, 3> m;
  m.y = nav.w_b;
  m.h.template block<3, 3>(0, filt_idx::kRate).setIdentity();
  m.r.diagonal().setConstant(sigma_rps * sigma_rps);
  return m;
}

}  // namespace gfins::nav
