// The vehicle frame (docs/firmware.md, "Mounting"): the board may sit rotated in the vehicle;
// navigation runs in the board's frame and what is published is the vehicle's.
#pragma once

#include <array>

#include "gfins/nav_core/nav_state.hpp"

namespace gfins::app {

/// q_vb of the board's orientation in the vehicle frame (FRD) from roll, pitch, yaw in degrees
/// (ZYX: C_vb = Rz(yaw) Ry(pitch) Rx(roll), the convention of q_nb's Euler angles): a vector
/// x_b in the board's axes is q_vb x_b in the vehicle's.
nav::Quat<float> mounting_rotation(const std::array<double, 3>& rpy_deg);

/// Whether q_vb rotates at all: mounting_rotation of all zeros is the identity exactly, and then
/// nothing is rotated (every published value stays the core's bit for bit).
inline bool mounted(const nav::Quat<float>& q_vb) {
  return q_vb.coeffs() != nav::Quat<float>::Identity().coeffs();
}

/// `n` as the vehicle sees it: attitude q_nv = q_nb q_vb* (C_nv = C_nb C_bv), and the body
/// vectors (angular rate, angular acceleration, specific force) rotated into the vehicle's axes.
/// The NED quantities (velocity, position, acceleration in n) do not change: the board and the
/// vehicle share them (the lever arm between the two origins is not applied).
void to_vehicle_frame(nav::NavState<float>& n, const nav::Quat<float>& q_vb);

}  // namespace gfins::app
