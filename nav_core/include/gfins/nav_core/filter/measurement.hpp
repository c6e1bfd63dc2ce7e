// The error state of the aided filter and the form every measurement model takes.
//
// x = [φ (3), δr_n (3), δv_n (3), δω_b (3), δβ_ω̇ (3), δβ_f (3)]  (18 states)
//   φ, δr, δv, δω   estimate − truth, as error_model.hpp defines them (φ of eq. (7))
//   δβ = [δβ_ω̇; δβ_f] the bias of the array's solution [ω̇; f] (rad/s², m/s², body) that the
//        navigation still sees: β − β̂, with β = M b the per-sensor biases b mapped through the
//        solve (docs/math.md, "Bias: six states whatever N"). Feedback adds it to β̂.
// A measurement z = h(x_true) + n, n ~ N(0, R), is linearised as y = ẑ − z = H x − n, with ẑ
// the prediction from the navigation solution (the sign convention of "estimate − truth").
#pragma once

#include "gfins/nav_core/math.hpp"

namespace gfins::nav {

namespace filt_idx {
inline constexpr int kPhi = 0;        // φ, rad, n frame
inline constexpr int kPos = 3;        // δr_n, m
inline constexpr int kVel = 6;        // δv_n, m/s
inline constexpr int kRate = 9;       // δω_b, rad/s
inline constexpr int kBiasWdot = 12;  // δβ_ω̇, rad/s², body
inline constexpr int kBiasF = 15;     // δβ_f, m/s², body
inline constexpr int kStates = 18;
}  // namespace filt_idx

/// One linearised measurement of dimension M: residual y = ẑ − z, Jacobian H = ∂y/∂x and the
/// noise covariance R.
template <typename T, int M>
struct Measurement {
  Eigen::Matrix<T, M, 1> y = Eigen::Matrix<T, M, 1>::Zero();
  Eigen::Matrix<T, M, filt_idx::kStates> h = Eigen::Matrix<T, M, filt_idx::kStates>::Zero();
  Eigen::Matrix<T, M, M> r = Eigen::Matrix<T, M, M>::Zero();
};

/// Kinds of aiding, for the per-kind counters and the mode bits.
enum class AidingKind : std::uint8_t { kZupt, kZaru, kGnssPosition, kGnssVelocity, kHeading };
inline constexpr int kAidingKinds = 5;

}  // namespace gfins::nav
