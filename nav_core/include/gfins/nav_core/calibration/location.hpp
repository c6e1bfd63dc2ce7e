// Location calibration (paper §4.2, eqs. (19)-(21)): the position errors Δρ_j of the six
// accelerometers from rate-table runs, by weighted linear least squares with covariance.
//
// Model. Scale factor, bias and orientation errors are known from the multi-attitude calibration
// (§4.1), so each raw output P_aj of eq. (21) is first converted to s*_j = P_aj/SF_aj − b_aj (in
// m/s²), the specific force along the calibrated axis θ*_j. On a table spinning at a constant rate
// ω (body axes) about an axis through the point p_m of the body frame (p_m = 0 when the axis
// passes through o_b), sensor j at ρ*_j = ρ_j + Δρ_j (eq. (19)) senses (eq. (20), with its
// misprint ω×ω×ρ read as ω×(ω×ρ)):
//
//   s*_j = θ*_j·(−g_b + ω×(ω×(ρ_j + Δρ_j − p_m)))
//
// where g_b is gravity in body axes (constant when the table axis is vertical; for a tilted axis
// the mean over whole revolutions). Everything but Δρ_j (and p_m) is known, so each run gives one
// linear equation per sensor:
//
//   y_j = s*_j − θ*_j·(−g_b + ω×(ω×ρ_j)) = a_jᵀ (Δρ_j − p_m),   a_j = [ω×]² θ*_j
//                                        = (θ*_j·ω) ω − |ω|² θ*_j.
//
// Observability (docs/compensator.md). a_j is −|ω|² times the part of θ*_j perpendicular to ω.
// Every Table 1 axis has one zero component, the one along its own position ρ_j (θ_1 = (1,1,0)/√2
// at ρ_1 = (0,0,−ρ), ...). For ω about x, y or z that component stays zero in a_j, so the radial
// component ρ̂_j·Δρ_j of every sensor is unobservable from x/y/z runs; only the calibrated tilt of
// θ*_j (a few 1e-2 rad) leaks it in, with about 1e-3 of the information of the other components.
// Runs about axes with mixed components fix it; the fewest well-conditioned ones are two
// face-diagonal mountings, e.g. ω along (1,1,0)/√2 and (1,0,1)/√2 (radial sensitivity
// 0.35 |ω|² for every sensor); three body diagonals also work, a single generic axis works but
// weakly (at most 0.087 |ω|²). The solver reports, per sensor, which direction it cannot see.
//
// Table axis offset. A table axis through p_m ≠ 0 adds −p_m to every Δρ_j in that mounting's
// equations; with kThroughCentre the estimates absorb it (errors of the size of p_m). With
// kEstimatePerMounting the per-mounting offsets are unknowns too. A common shift c of all Δρ_j
// and all p_m changes no output (it only moves the reference point), so the gauge Σ_j Δρ_j = 0 is
// imposed (o_b := centroid of the true sensor positions; the compensated solver then reports the
// specific force there) together with u_m·p_m = 0 (the offset along the spin axis u_m has no
// effect).
//
// Base uncertainty. drho_cov_m2 is the runs' noise alone (N'⁺ N N'⁺). SF, b and θ*_j come from
// the multi-attitude calibration and carry its errors; base_jacobian holds the first-order
// sensitivity of Δρ to them, per sensor as three generic perturbations (an offset c and a gain
// k of s*_j, a tilt δθ of θ*_j): N dx = Σ_r w_r (a_r (dy_r − da_rᵀ(Δρ_j − p_m)) + da_r e_r)
// with dy_r = c, k s*_r or −h_rᵀδθ (h_r = −g_b + [ω×]²ρ_j) and da_r = [ω×]² δθ, solved with
// the same truncated inverse as x. The caller maps its parameters onto (c, k, δθ) (eq. (21) for
// SF and b, eqs. (14)/(15) for the angles) and adds base_covariance() (docs/calibration.md, §5).
//
// No heap: the normal equations are accumulated in fixed-size matrices (computed in double for
// float and double inputs); runs are read once from a span. Failure modes are Status values.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "gfins/nav_core/geometry.hpp"
#include "gfins/nav_core/math.hpp"
#include "gfins/status/status.hpp"

namespace gfins::calib {

/// Most distinct table mountings (fixture poses) one calibration may use.
inline constexpr int kMaxLocationMountings = 8;

/// One constant-rate run on the rate table.
template <typename T>
struct LocationRun {
  nav::Vec3<T> w_b =
      nav::Vec3<T>::Zero();  // table rate in body axes, rad/s (constant over the run)
  nav::Vec3<T> g_b = nav::Vec3<T>::Zero();  // gravity in body axes, m/s² (mean over the run)
  int mounting = 0;  // fixture pose 0..kMaxLocationMountings−1; runs sharing it share p_m
  nav::Vec6<T> s_mean = nav::Vec6<T>::Zero();  // mean s*_j per sensor, m/s² (SF, bias removed)
  nav::Vec6<T> sigma = nav::Vec6<T>::Zero();  // per-sample standard deviation of each sensor, m/s²
  std::uint32_t count = 0;                    // samples averaged into s_mean
};

/// How the rate-table axis is placed relative to o_b.
enum class AxisOffsetModel : std::uint8_t {
  kThroughCentre = 0,       // the axis passes through o_b in every mounting (p_m = 0)
  kEstimatePerMounting = 1  // p_m ⊥ u_m estimated per mounting; gauge Σ_j Δρ_j = 0
};

struct LocationOptions {
  AxisOffsetModel axis_offset = AxisOffsetModel::kThroughCentre;
  /// Directions of the unknowns whose information (eigenvalue of the normal matrix) is below this
  /// fraction of the largest are declared unobservable and held at zero: their standard deviation
  /// would exceed 1/√fraction = 10× that of the best-determined direction, and their estimate
  /// would rest on the orientation errors' small leak rather than on the geometry.
  double min_relative_information = 1e-2;
  /// Runs slower than this (rad/s) are rejected: the centripetal signal |ω|²·|Δρ| of a few mm
  /// would be below 1e-5 m/s², far under any accelerometer noise, so the run is a mistake.
  double min_rate_rad_s = 0.1;
};

enum class Observability : std::uint8_t { kObservable = 0, kUnobservable = 1 };

template <typename T>
struct LocationCalibration {
  std::array<nav::Vec3<T>, nav::kNumSensors> drho_b{};       // Δρ_j, m, body (eq. (19))
  std::array<nav::Mat3<T>, nav::kNumSensors> drho_cov_m2{};  // covariance of Δρ_j, m²
  std::array<Observability, nav::kNumSensors> verdict{};
  /// Unit direction of sensor j along which Δρ_j cannot be determined (zero when observable);
  /// the estimate is held at zero along it and the covariance excludes it.
  std::array<nav::Vec3<T>, nav::kNumSensors> unobservable_dir_b{};
  std::array<int, nav::kNumSensors> unobservable_dims{};  // 0..3
  /// Table-axis offsets p_m (m, body) of the mountings used (zero with kThroughCentre).
  std::array<nav::Vec3<T>, kMaxLocationMountings> axis_offset_b{};
  std::array<nav::Mat3<T>, kMaxLocationMountings> axis_offset_cov_m2{};
  int num_mountings = 0;  // 1 + largest mounting index used
  double chi2 = 0.0;      // Σ (residual/σ_mean)² at the estimate
  int dof = 0;            // equations − determined unknowns; chi2/dof ≈ 1 if σ is right
  /// First-order sensitivity of Δρ_i to the base (multi-attitude) calibration of sensor j:
  /// base_jacobian[i][j] = ∂Δρ_i/∂q_j, q_j = (c_j, k_j, δθ*_j) the generic base perturbations
  /// of sensor j (kBaseOffset, kBaseGain, kBaseAxis; see base_covariance()). Zero for i ≠ j with
  /// kThroughCentre (sensors share no unknown); the table-axis offsets couple them otherwise.
  /// drho_cov_m2 above counts the runs' noise only; add base_covariance() for the total.
  std::array<std::array<Eigen::Matrix<T, 3, 5>, nav::kNumSensors>, nav::kNumSensors>
      base_jacobian{};

  bool fully_observable() const {
    for (const auto v : verdict) {
      if (v != Observability::kObservable) return false;
    }
    return true;
  }
};

/// The base perturbations of one sensor, the columns of LocationCalibration::base_jacobian, in
/// units of s*_j (m/s²): s*_j → (1 + k) s*_j + c in every run, θ*_j → θ*_j + δθ (body, unitless).
/// A scale-factor error SF → SF(1 + ε) of eq. (21) is k = −ε, c = −ε·b·g; a bias error δb (g) is
/// c = −g·δb; an orientation angle moves θ*_j along ∂θ*_j/∂angle (eqs. (14)/(15)).
inline constexpr int kBaseOffset = 0;  // c, m/s²
inline constexpr int kBaseGain = 1;    // k, unitless
inline constexpr int kBaseAxis = 2;    // δθ*_j, 3 components (2..4)
inline constexpr int kNumBaseParams = 5;

/// The part of the Δρ covariance that comes from the base calibration (first order):
/// Σ_j J_ij C_j J_ijᵀ with J = solution.base_jacobian and C_j the 5×5 covariance of sensor j's
/// base perturbations (kBaseOffset, kBaseGain, kBaseAxis order); the base calibrations of
/// different sensors are independent (multi_attitude.hpp: no unknown is shared). Add it to
/// drho_cov_m2 for the total.
template <typename T>
std::array<nav::Mat3<T>, nav::kNumSensors> base_covariance(
    const LocationCalibration<T>& solution,
    const std::array<Eigen::Matrix<T, kNumBaseParams, kNumBaseParams>, nav::kNumSensors>&
        base_cov) {
  std::array<nav::Mat3<T>, nav::kNumSensors> out{};
  for (std::size_t i = 0; i < static_cast<std::size_t>(nav::kNumSensors); ++i) {
    out[i] = nav::Mat3<T>::Zero();
    for (std::size_t j = 0; j < static_cast<std::size_t>(nav::kNumSensors); ++j) {
      const Eigen::Matrix<T, 3, kNumBaseParams>& jac = solution.base_jacobian[i][j];
      out[i] += jac * base_cov[j] * jac.transpose();
    }
  }
  return out;
}

/// Row a = [ω×]² θ of the location equation y = aᵀ(Δρ − p) (see the file comment).
template <typename T>
nav::Vec3<T> location_design_row(const nav::Vec3<T>& theta_b, const nav::Vec3<T>& w_b) {
  return w_b.cross(w_b.cross(theta_b));
}

/// Estimates Δρ_j of the six sensors. `calibrated` holds the nominal positions ρ_j (Table 1) and
/// the calibrated axes θ*_j (e.g. misaligned_geometry with zero Δρ). Fails with kInvalidArgument
/// for fewer than three runs, a rate below options.min_rate_rad_s, a non-finite value, σ ≤ 0 or
/// count = 0, or (with kEstimatePerMounting) runs of one mounting about different axes; with
/// kOutOfRange for a mounting index outside 0..kMaxLocationMountings−1. Unobservable directions
/// are not an error: they are reported per sensor in the result.
template <typename T>
Result<LocationCalibration<T>> calibrate_location(
    const nav::ArrayGeometry<T, nav::kNumSensors>& calibrated, std::span<const LocationRun<T>> runs,
    const LocationOptions& options = {});

extern template Result<LocationCalibration<float>> calibrate_location<float>(
    const nav::ArrayGeometry<float, nav::kNumSensors>&, std::span<const LocationRun<float>>,
    const LocationOptions&);
extern template Result<LocationCalibration<double>> calibrate_location<double>(
    const nav::ArrayGeometry<double, nav::kNumSensors>&, std::span<const LocationRun<double>>,
    const LocationOptions&);

}  // namespace gfins::calib
