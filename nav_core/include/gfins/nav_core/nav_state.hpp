// The navigation state the core produces once per sample.
#pragma once

#include <cstdint>

#include "gfins/nav_core/math.hpp"

namespace gfins::nav {

/// Bits of NavState::status.
namespace nav_status {
inline constexpr std::uint32_t kAligned = 1u << 0;       // initial attitude set (alignment done)
inline constexpr std::uint32_t kSampleGap = 1u << 1;     // sample counter jumped before this step
inline constexpr std::uint32_t kInputInvalid = 1u << 2;  // a sample was rejected (flags, NaN)
inline constexpr std::uint32_t kCompensated = 1u << 3;   // misalignment compensation active
}  // namespace nav_status

/// Everything refers to one instant, t_ns: the sampling instant of the sample that produced it
/// (docs/math.md, "Timestamps"). Frames: b = body (FRD, array centre o_b), n = local-level NED
/// fixed at the alignment point.
template <typename T>
struct NavState {
  std::int64_t t_ns = 0;     // sampling instant, CLOCK_MONOTONIC ns (or scenario time in sim)
  std::uint32_t seq = 0;     // sample counter of the ADC frame
  std::uint32_t status = 0;  // nav_status bits
  Quat<T> q_nb = Quat<T>::Identity();  // body-to-navigation rotation
  Vec3<T> w_b = Vec3<T>::Zero();       // angular rate ω_nb^b, rad/s
  Vec3<T> wdot_b = Vec3<T>::Zero();    // angular acceleration, rad/s²
  Vec3<T> f_b = Vec3<T>::Zero();       // specific force at o_b, m/s²
  Vec3<T> a_n = Vec3<T>::Zero();       // kinematic acceleration of o_b, m/s², NED
  Vec3<T> v_n = Vec3<T>::Zero();       // velocity, m/s, NED
  Vec3<T> r_n = Vec3<T>::Zero();       // position from the alignment point, m, NED

  template <typename U>
  NavState<U> cast() const {
    NavState<U> o;
    o.t_ns = t_ns;
    o.seq = seq;
    o.status = status;
    o.q_nb = q_nb.template cast<U>();
    o.w_b = w_b.template cast<U>();
    o.wdot_b = wdot_b.template cast<U>();
    o.f_b = f_b.template cast<U>();
    o.a_n = a_n.template cast<U>();
    o.v_n = v_n.template cast<U>();
    o.r_n = r_n.template cast<U>();
    return o;
  }
};

}  // namespace gfins::nav
