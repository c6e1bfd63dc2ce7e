// GNSS position and velocity of the antenna, with the lever arm l_b (m, body FRD, from the array
// centre o_b to the antenna phase centre).
//
// Position: z = r_n + C_b^n l_b + n. With Ĉ = (I − [φ×]) C (eq. (7)), Ĉ l − C l = −φ × (C l) =
// [(C l)×] φ, so
//   y = r̂ + Ĉ l − z = δr + [(Ĉ l)×] φ − n        H = [[(Ĉl)×]  I  0  0  0  0]
// Velocity: z = v_n + C_b^n (ω × l) + n. (Ĉ − C)(ω × l) = [(C(ω×l))×] φ and
// C(δω × l) = −C [l×] δω, so
//   y = v̂ + Ĉ(ω̂ × l) − z = δv + [(Ĉ(ω̂×l))×] φ − Ĉ [l×] δω − n
//                                               H = [[(Ĉ(ω̂×l))×]  0  I  −Ĉ[l×]  0  0]
// (Ĉ, ω̂ for C, ω in H: the difference is second order.) R = diag(σ²) from the receiver's stated
// 1σ per NED axis. The navigation values are those of the fix's validity instant (NavHistory;
// ω̂ is the current rate, see nav_history.hpp).
#pragma once

#include "gfins/nav_core/filter/measurement.hpp"
#include "gfins/nav_core/filter/nav_history.hpp"

namespace gfins::nav {

/// A GNSS fix in the navigation frame: antenna position (m, NED from the alignment point) or
/// velocity (m/s, NED), its 1σ per axis, and the instant it is valid at.
template <typename T>
struct GnssFix {
  std::int64_t t_valid_ns = 0;
  Vec3<T> value_n = Vec3<T>::Zero();
  Vec3<T> sigma = Vec3<T>::Ones();
};

template <typename T>
Measurement<T, 3> gnss_position_measurement(const HistoryEntry<T>& nav, const Vec3<T>& lever_b,
                                            const GnssFix<T>& fix) {
  Measurement<T, 3> m;
  const Vec3<T> cl = nav.q_nb * lever_b;
  m.y = nav.r_n + cl - fix.value_n;
  m.h.template block<3, 3>(0, filt_idx::kPhi) = skew<T>(cl);
  m.h.template block<3, 3>(0, filt_idx::kPos).setIdentity();
  m.r.diagonal() = fix.sigma.cwiseProduct(fix.sigma);
  return m;
}

template <typename T>
Measurement<T, 3> gnss_velocity_measurement(const HistoryEntry<T>& nav, const Vec3<T>& lever_b,
                                            const GnssFix<T>& fix) {
  Measurement<T, 3> m;
  const Mat3<T> c = nav.q_nb.toRotationMatrix();
  const Vec3<T> cwl = c * nav.w_b.cross(lever_b);
  m.y = nav.v_n + cwl - fix.value_n;
  m.h.template block<3, 3>(0, filt_idx::kPhi) = skew<T>(cwl);
  m.h.template block<3, 3>(0, filt_idx::kVel).setIdentity();
  m.h.template block<3, 3>(0, filt_idx::kRate) = -c * skew<T>(lever_b);
  m.r.diagonal() = fix.sigma.cwiseProduct(fix.sigma);
  return m;
}

}  // namespace gfins::nav
