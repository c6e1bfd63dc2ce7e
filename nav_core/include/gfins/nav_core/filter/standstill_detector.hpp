// Standstill detector of the gyro-free array: a GLRT-like test on the array's own solution
// (docs/math.md, "Standstill detection"). No gyro, so the energies used are those of the specific
// force about its window mean and of the angular acceleration.
//
// Over a window of W samples of [ω̇_k; f_k] (ω = 0 assumed: the linear part M s),
//   T = (1/W) Σ_k [ ‖f_k − f̄‖² / σ_f² + ‖ω̇_k − ω̇̄‖² / σ_ω̇² ],   f̄, ω̇̄ the window means,
// with σ_f², σ_ω̇² the per-axis variances of the white sensor noise mapped through M
// (σ² M Mᵀ; for Table 1 it is diag(σ_ω̇² I, σ_f² I) exactly, so the components are independent
// with those variances). Under H0 (at rest: f and ω̇ constant) W·T is χ² with 6(W − 1) degrees
// of freedom (each mean takes 3), so the threshold for a false alarm probability p_fa (a window
// at rest declared moving) is
//   γ = χ²_{1−p_fa}(6W − 6) / W   (chi_square.hpp: Wilson–Hilferty, < 0.01 % off for 6W−6 ≥ 100).
// A window is "at rest" when T ≤ γ, | ‖f̄‖ − g | ≤ gravity_tolerance and ‖ω̇̄‖ ≤ the ω̇
// tolerance. The ω̇ mean is tested against a tolerance, not inside T: at rest it is the array's
// ω̇ bias (0.45 mg of sensor drift makes ~0.03 rad/s², about 6 σ_ω̇ per sample for the QA-1100
// array), which no statistic of the window can tell from a real constant angular acceleration;
// the aiding sets the tolerance from what its bias estimate leaves unknown (aiding.hpp).
// Windows are consecutive and disjoint (a decision every W samples), so no W-sized buffer is
// needed: running sums only. The f sums are taken about the window's first sample (f_k − f_ref),
// so float32 does not cancel g² against g²: Σ‖f_k − f̄‖² = Σ‖d_k‖² − W ‖d̄‖², d = f − f_ref.
#pragma once

#include <cmath>
#include <cstdint>

#include "gfins/nav_core/filter/chi_square.hpp"
#include "gfins/nav_core/geometry.hpp"
#include "gfins/status/status.hpp"

namespace gfins::nav {

template <typename T>
struct StandstillConfig {
  std::uint32_t window = 100;           // W samples per decision
  T false_alarm_probability = T(0.01);  // P(rest window declared moving)
  T white_sigma_mps2 = T(1e-3);         // per-sensor white noise σ per sample (m/s²)
  T gravity_mps2 = T(kStandardGravity);
  T gravity_tolerance_mps2 = T(0.05);  // | ‖f̄‖ − g | allowed at rest
  // ‖mean ω̇‖ allowed at rest, rad/s²: at rest the mean is the array's ω̇ bias, which the
  // statistic cannot tell from a real angular acceleration; the aiding narrows this to what the
  // filter's bias estimate leaves unknown (set_wdot_tolerance).
  T wdot_mean_tolerance_rps2 = T(0.02);
};

template <typename T>
class StandstillDetector {
 public:
  /// σ_f² and σ_ω̇² are the mean per-axis variances of σ² M Mᵀ of `solver`.
  [[nodiscard]] Status configure(const ArraySolver<T, kNumSensors>& solver,
                                 const StandstillConfig<T>& config) {
    if (config.window < 2) {
      return Status(ErrorCode::kInvalidArgument, "standstill: window must hold two samples");
    }
    if (!(config.false_alarm_probability > T(0) && config.false_alarm_probability < T(1)) ||
        !(config.white_sigma_mps2 > T(0)) || !(config.gravity_tolerance_mps2 > T(0))) {
      return Status(ErrorCode::kInvalidArgument,
                    "standstill: probability in (0, 1) and positive sigmas required");
    }
    const typename ArraySolver<T, kNumSensors>::MapMatrix m = solver.m();
    const Mat6<T> mmt = m * m.transpose() * (config.white_sigma_mps2 * config.white_sigma_mps2);
    var_wdot_ = mmt.template topLeftCorner<3, 3>().trace() / T(3);
    var_f_ = mmt.template bottomRightCorner<3, 3>().trace() / T(3);
    const auto w = static_cast<int>(config.window);
    // Two scatters about their window means (f and ω̇): 6W − 6 degrees of freedom under H0.
    threshold_ =
        chi_square_quantile(T(1) - config.false_alarm_probability, 6 * w - 6) / static_cast<T>(w);
    config_ = config;
    wdot_tolerance_ = config.wdot_mean_tolerance_rps2;
    reset();
    return Status::ok();
  }

  /// Drops the window under way (the last decision is kept).
  void reset() {
    n_ = 0;
    sum_d_.setZero();
    sum_d2_ = T(0);
    sum_w_.setZero();
    sum_wdot2_ = T(0);
  }

  /// The ‖mean ω̇‖ allowed at rest from now on (rad/s², positive).
  void set_wdot_tolerance(T tolerance_rps2) {
    if (tolerance_rps2 > T(0)) wdot_tolerance_ = tolerance_rps2;
  }
  T wdot_tolerance() const { return wdot_tolerance_; }

  /// One sample of the array's solution with ω = 0 (ω̇ rad/s², f m/s², body). Returns true when
  /// it completed a window (a new decision in at_rest() and statistic()).
  bool add(const Vec3<T>& wdot_b, const Vec3<T>& f_b) {
    if (n_ == 0) f_ref_ = f_b;
    const Vec3<T> d = f_b - f_ref_;
    sum_d_ += d;
    sum_d2_ += d.squaredNorm();
    sum_w_ += wdot_b;
    sum_wdot2_ += wdot_b.squaredNorm();
    if (++n_ < config_.window) return false;
    const T w = static_cast<T>(n_);
    const Vec3<T> mean_d = sum_d_ / w;
    const T scatter = sum_d2_ - w * mean_d.squaredNorm();  // Σ‖f_k − f̄‖²
    const Vec3<T> mean_w = sum_w_ / w;
    const T scatter_w = sum_wdot2_ - w * mean_w.squaredNorm();  // Σ‖ω̇_k − mean ω̇‖²
    statistic_ = (scatter / var_f_ + scatter_w / var_wdot_) / w;
    mean_f_ = f_ref_ + mean_d;
    const T g_err = std::abs(mean_f_.norm() - config_.gravity_mps2);
    at_rest_ = statistic_ <= threshold_ && g_err <= config_.gravity_tolerance_mps2 &&
               mean_w.norm() <= wdot_tolerance_;
    ++windows_;
    if (at_rest_) ++rest_windows_;
    reset();
    return true;
  }

  bool at_rest() const { return at_rest_; }
  T statistic() const { return statistic_; }
  T threshold() const { return threshold_; }
  /// The last complete window's mean specific force (body, m/s²).
  const Vec3<T>& mean_f() const { return mean_f_; }
  /// Per-axis variance of one sample's f (σ² M Mᵀ; the window mean's is this / W).
  T sigma2_f() const { return var_f_; }
  T sigma2_wdot() const { return var_wdot_; }
  std::uint32_t windows() const { return windows_; }
  std::uint32_t rest_windows() const { return rest_windows_; }

 private:
  StandstillConfig<T> config_{};
  T var_f_ = T(1);
  T var_wdot_ = T(1);
  T threshold_ = T(0);
  Vec3<T> f_ref_ = Vec3<T>::Zero();
  Vec3<T> mean_f_ = Vec3<T>::Zero();
  Vec3<T> sum_d_ = Vec3<T>::Zero();
  T sum_d2_ = T(0);
  Vec3<T> sum_w_ = Vec3<T>::Zero();
  T sum_wdot2_ = T(0);
  T wdot_tolerance_ = T(0.02);
  std::uint32_t n_ = 0;
  T statistic_ = T(0);
  bool at_rest_ = false;
  std::uint32_t windows_ = 0;
  std::uint32_t rest_windows_ = 0;
};

}  // namespace gfins::nav
