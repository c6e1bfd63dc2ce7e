// The paper's misalignment model: orientation errors of the sensitive axes (eqs. (14)/(15),
// used by (16) and (23)/(24)) and location errors of the sensors (eq. (19)).
//
// The six sensors form two sets, each calibrated as a unit: set β = {2, 3, 5} and set
// α = {1, 4, 6} (1-based numbers of Table 1). Within a set the outputs with orientation errors
// are s* = C s (eq. (23), and eq. (24) with its right side read as s1, s4, s6 — misprint), where
// s are the outputs along the ideal axes and C is the matrix of eq. (14)/(15):
//
//        [ 1     Δxz   −Δxy ]
//   C =  [ −Δyz  1      Δyx ]
//        [ Δzy   −Δzx   1   ]
//
// Equivalently sensor i of the set senses along θ*_i = Σ_k C_ik θ_k (not exactly a unit vector),
// which is what the exact compensator inverts.
#pragma once

#include <array>
#include <cstddef>

#include "gfins/nav_core/geometry.hpp"

namespace gfins::nav {

/// Order of the six angles of one set, as in Table 6: xy, xz, yx, yz, zx, zy.
enum class AngleIndex : std::size_t { kXy = 0, kXz, kYx, kYz, kZx, kZy };

/// 0-based sensor indices of the two calibration sets (paper §4: [θ2 θ3 θ5] and [θ1 θ4 θ6]).
inline constexpr std::array<int, 3> kSetBeta = {1, 2, 4};
inline constexpr std::array<int, 3> kSetAlpha = {0, 3, 5};

template <typename T>
struct OrientationErrors {
  std::array<T, 6> beta{};  // rad, set {2,3,5}: Δβ_xy, Δβ_xz, Δβ_yx, Δβ_yz, Δβ_zx, Δβ_zy
  std::array<T, 6> alpha{};  // rad, set {1,4,6}: Δα_xy, Δα_xz, Δα_yx, Δα_yz, Δα_zx, Δα_zy
};

/// The matrix C of eq. (14)/(15) from the six angles of one set (rad).
template <typename T>
Mat3<T> set_matrix(const std::array<T, 6>& d) {
  const auto a = [&d](AngleIndex i) { return d[static_cast<std::size_t>(i)]; };
  Mat3<T> c;
  c << T(1), a(AngleIndex::kXz), -a(AngleIndex::kXy),  //
      -a(AngleIndex::kYz), T(1), a(AngleIndex::kYx),   //
      a(AngleIndex::kZy), -a(AngleIndex::kZx), T(1);
  return c;
}

/// Misalignment of a six-sensor array: orientation (eqs. (14)/(15)) and location (eq. (19)).
/// A default-constructed value is "no misalignment" (all angles and offsets zero).
template <typename T>
struct Misalignment {
  OrientationErrors<T> orientation{};
  std::array<Vec3<T>, kNumSensors> drho_b = zero_vectors<T, kNumSensors>();  // Δρ_j, m, body
};

/// The geometry the array really has: θ*_i = Σ_k C_ik θ_k within each set, ρ*_j = ρ_j + Δρ_j.
template <typename T>
ArrayGeometry<T, kNumSensors> misaligned_geometry(const ArrayGeometry<T, kNumSensors>& nominal,
                                                  const Misalignment<T>& m) {
  ArrayGeometry<T, kNumSensors> g = nominal;
  const auto apply_set = [&](const std::array<int, 3>& set, const std::array<T, 6>& angles) {
    const Mat3<T> c = set_matrix(angles);
    for (int i = 0; i < 3; ++i) {
      Vec3<T> th = Vec3<T>::Zero();
      for (int k = 0; k < 3; ++k) {
        th += c(i, k) * nominal.theta_b[static_cast<std::size_t>(set[static_cast<std::size_t>(k)])];
      }
      g.theta_b[static_cast<std::size_t>(set[static_cast<std::size_t>(i)])] = th;
    }
  };
  apply_set(kSetBeta, m.orientation.beta);
  apply_set(kSetAlpha, m.orientation.alpha);
  for (std::size_t j = 0; j < kNumSensors; ++j) g.rho_b[j] = nominal.rho_b[j] + m.drho_b[j];
  return g;
}

}  // namespace gfins::nav
