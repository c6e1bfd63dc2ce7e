// Fault detection, isolation and exclusion for a redundant accelerometer array (N ≥ 7), from the
// residual of the array's least-squares solve (parity space; docs/redundancy.md).
//
// The array equations are s = H [ω̇; f] + c(ω) + n (geometry.hpp) with n white, σ per sensor and
// sample, the same for every sensor. The solver takes [ω̇; f] = M (s − c(ω)) with M = pinv(H) over
// the active sensors, so the residual
//   r = s − H M (s − c(ω)) − c(ω) = P (s − c(ω)),   P = I − H M
// is what no rigid-body motion explains. P is symmetric and idempotent of rank d = N_active − 6
// (the parity space), so without a fault r ~ N(0, σ² P) and rᵀr/σ² is χ² with d degrees of
// freedom. A fault b on sensor j adds b·P e_j: visible when P_jj > 0 (N ≥ 7), and attributable to
// j only if P e_j is not parallel to another column (N ≥ 8 in a suitable geometry; for N = 7 every
// column of P is parallel to the one parity vector, so no isolation is possible).
//
// Decisions come every W samples (disjoint windows, running sums only). Two statistics, each
// tested at α/2 (Bonferroni), α the false-alarm probability per window from the stated rate per
// hour, α = FA/h · W / (3600 · f_s):
//   mean:    t_m = ‖r̄‖² / σ_m²,  σ_m² = σ²/W + σ_floor²   χ²(d) without a fault: biases, steps,
//            ramps, stuck and dead channels under motion. σ_floor is the per-sensor residual that
//            does not average down (calibration error of the geometry), added as if white.
//   scatter: t_s = Σ_k ‖r_k − r̄‖² / σ²               χ²((W−1) d) without a fault: noisy channels.
// Isolation (a fault in exactly one channel, equal prior on each): for the mean, the likelihood
// ratio of a bias b_j on channel j maximised over b_j is exp(w_j²/2), w_j² = r̄_j² / (σ_m² P_jj)
// (Baarda's normalised residual); for the scatter, that of an extra variance along P e_j,
// maximised over the variance, is exp(½(z_j − n − n ln(z_j/n))) for z_j > n, z_j =
// Σ_k (r_kj − r̄_j)² / (σ² P_jj), n = W − 1. The posterior of channel j is its ratio over their sum;
// the test that raised the alarm picks the channel. Channels whose columns of P are (nearly)
// parallel, |P_jk| / √(P_jj P_kk) ≥ kIndistinguishable, give the same residual for a fault on
// either: an ambiguity group, whose members share the group's best likelihood, so none of them
// reaches a posterior above 1/(group size) — otherwise a rounding difference (float32 P s carries
// ~1e-5 m/s² at 1 g) or a calibration error would pick one of them with certainty. A channel
// whose posterior reaches the
// configured probability is suspected; suspected in `confirm_windows` consecutive alarm windows,
// its exclusion is requested: the owner builds the solver without it (ArraySolver::create_subset, a
// channel mask) and hands it to set_solver() here and to the integrator, which keep navigating
// on the remaining N − 1 ≥ 6 sensors.
//
// What the fault did before its exclusion stays in the navigation state (a gyro-free INS
// integrates ω̇ once for ω and twice for attitude). A fault f_j(t) on sensor j enters [ω̇; f] as
// M e_j f_j, and E[r_kj] = P_jj f_j(t_k), so the monitor also sums the suspect's residuals from
// the window before the streak's first alarm to the exclusion: ∫ f_j dt ≈ dt Σ r_kj / P_jj and
// ∫ f_j (t_now − t) dt ≈ dt² Σ r_kj (k_now − k) / P_jj (FaultTransient), for any shape of fault
// (step, ramp, stuck), without knowing its onset. correct_for_excluded_fault (exclusion.hpp)
// removes their effect on ω, attitude, velocity and position.
//
// Static storage, float32 on the board, no heap: an N×N projector and 2N running sums.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>

#include "gfins/nav_core/filter/chi_square.hpp"
#include "gfins/nav_core/geometry.hpp"
#include "gfins/nav_core/geometry_impl.hpp"  // ArraySolver for any N
#include "gfins/nav_core/redundancy/parity_projector.hpp"
#include "gfins/status/status.hpp"

namespace gfins::nav {

/// What the monitor knows of one channel.
enum class ChannelHealth : std::uint8_t {
  kOk = 0,         // no alarm attributed to it
  kSuspected = 1,  // the last alarm window isolated it
  kExcluded = 2,   // the solver no longer uses it
};

/// The outcome of one sample for the monitor.
enum class ParityVerdict : std::uint8_t {
  kPending = 0,     // the window is not complete
  kConsistent,      // window complete, no alarm
  kUnisolated,      // alarm, no channel reaches the isolation probability (always for N = 7)
  kSuspected,       // alarm isolated to suspect_channel()
  kExcludeRequest,  // suspect_channel() isolated in confirm_windows consecutive alarm windows
  kUnavailable,     // six active sensors: no parity space, nothing to test
};

/// Correlation of two columns of P above which their channels are not told apart. At 0.99, a fault
/// must make w² = b² P_jj / σ_m² exceed 2 ln(99) / (1 − 0.99²) ≈ 460 before the likelihoods of
/// the two channels differ by the 0.99 posterior, a size at which the geometry's own calibration
/// error, not the noise, decides.
inline constexpr double kIndistinguishable = 0.99;

/// The fault of an excluded channel, integrated from the window before its first alarm to the
/// exclusion (see above).
template <typename T>
struct FaultTransient {
  int channel = -1;           // −1: none
  T integral_mps = 0;         // ∫ f_j dt, m/s
  T moment_m = 0;             // ∫ f_j (t_now − t) dt, m
  std::uint32_t samples = 0;  // how many samples the sums cover
};

template <typename T>
struct ParityConfig {
  T white_sigma_mps2 = T(5e-4);  // per-sensor white noise σ per sample, m/s²
  T floor_sigma_mps2 = T(0);     // per-sensor residual that does not average down, m/s²
  std::uint32_t window = 100;    // W samples per decision
  T sample_rate_hz = T(1000);
  T false_alarms_per_hour = T(0.01);  // fault-free alarms per hour of operation, both tests
  T isolation_probability = T(0.99);  // posterior a channel needs to be suspected
  std::uint32_t confirm_windows = 3;  // consecutive windows isolating it before exclusion
  // 1σ per axis of the error of the rate ω handed to add() (rad/s): the centripetal term removed
  // with a wrong ω leaves P Q D(ω) δω in the residual, which grows with |ω| (see above). 0 only
  // for a rate known exactly (tests, a rate table).
  T rate_sigma_rps = T(0);
};

template <typename T, int N>
class ParityMonitor {
 public:
  using Solver = ArraySolver<T, N>;
  using Outputs = typename Solver::Outputs;
  using Projector = Eigen::Matrix<T, N, N>;

  /// Sets the noise model and thresholds and takes the solver's geometry and active sensors.
  [[nodiscard]] Status configure(const Solver& solver, const ParityConfig<T>& config) {
    if (config.window < 2 || config.confirm_windows < 1) {
      return Status(ErrorCode::kInvalidArgument,
                    "parity monitor: the window needs two samples and at least one confirmation");
    }
    if (!(config.white_sigma_mps2 > T(0)) || !std::isfinite(config.white_sigma_mps2) ||
        !(config.floor_sigma_mps2 >= T(0)) || !std::isfinite(config.floor_sigma_mps2) ||
        !(config.sample_rate_hz > T(0)) || !std::isfinite(config.sample_rate_hz) ||
        !(config.rate_sigma_rps >= T(0)) || !std::isfinite(config.rate_sigma_rps) ||
        !(config.isolation_probability > T(0) && config.isolation_probability < T(1))) {
      return Status(ErrorCode::kInvalidArgument,
                    "parity monitor: positive finite sigma and rate, isolation probability in "
                    "(0, 1) required");
    }
    const T windows_per_hour = T(3600) * config.sample_rate_hz / static_cast<T>(config.window);
    const T alpha = config.false_alarms_per_hour / windows_per_hour;
    if (!(alpha > T(0) && alpha < T(1))) {
      return Status(ErrorCode::kInvalidArgument,
                    "parity monitor: false alarms per hour must be positive and below one per "
                    "decision window");
    }
    config_ = config;
    alpha_ = alpha;
    health_.fill(ChannelHealth::kOk);
    windows_ = 0;
    alarms_ = 0;
    exclusions_ = 0;
    rejected_samples_ = 0;
    nonfinite_run_.fill(0);
    const Status st = set_solver(solver);
    exclusions_ = 0;  // sensors the first solver leaves out were never excluded by the monitor
    return st;
  }

  /// Takes a new solver (the same geometry with fewer active sensors after an exclusion, or a
  /// new calibration): recomputes P and the thresholds, marks sensors the solver does not use as
  /// excluded, and starts a new window. Health and counters are kept.
  [[nodiscard]] Status set_solver(const Solver& solver) {
    const ChannelMask active = solver.active();
    const int d = channel_count(active) - 6;
    if (d < 0) {
      return Status(ErrorCode::kInvalidArgument, "parity monitor: fewer than six active sensors");
    }
    const Projector p = parity_projector(solver);
    for (int j = 0; j < N; ++j) {
      auto& h = health_[static_cast<std::size_t>(j)];
      if (!is_active(active, j) && h != ChannelHealth::kExcluded) {
        h = ChannelHealth::kExcluded;
        ++exclusions_;
      } else if (is_active(active, j) && h == ChannelHealth::kExcluded) {
        h = ChannelHealth::kOk;  // back in use (a repaired channel, a new calibration)
      }
    }
    p_ = p;
    pq_ = p * centripetal_matrix(solver);
    solver_ = solver;
    dof_ = d;
    for (int j = 0; j < N; ++j) {
      ChannelMask group = 0;
      for (int k = 0; k < N; ++k) {
        if (!usable(j) || !usable(k)) continue;
        if (std::abs(p(j, k)) >= T(kIndistinguishable) * std::sqrt(p(j, j) * p(k, k))) {
          group |= ChannelMask{1} << static_cast<unsigned>(k);
        }
      }
      group_[static_cast<std::size_t>(j)] = group;
    }
    const auto w = static_cast<int>(config_.window);
    const T a = alpha_ / T(2);
    threshold_mean_ = d > 0 ? chi_square_upper_quantile(a, d) : std::numeric_limits<T>::quiet_NaN();
    // (W − 1)·d degrees of freedom: exact up to 200, Wilson–Hilferty's upper-tail form above
    // (chi_square.hpp; below 0.1 % off).
    threshold_scatter_ =
        d > 0 ? chi_square_upper_quantile(a, (w - 1) * d) : std::numeric_limits<T>::quiet_NaN();
    if (d > 0 && !(std::isfinite(threshold_mean_) && std::isfinite(threshold_scatter_))) {
      return Status(ErrorCode::kInvalidArgument,
                    "parity monitor: no finite threshold for this false-alarm probability per "
                    "window in this scalar type");
    }
    sigma2_mean_ = config_.white_sigma_mps2 * config_.white_sigma_mps2 / static_cast<T>(w) +
                   config_.floor_sigma_mps2 * config_.floor_sigma_mps2;
    sigma2_ = config_.white_sigma_mps2 * config_.white_sigma_mps2;
    streak_ = 0;
    suspect_ = -1;
    reset_window();
    return Status::ok();
  }

  /// One sample: the outputs s (m/s², the ones the solver gets) and the angular rate ω (rad/s,
  /// body) the integrator uses for the centripetal term. A sample with a non-finite residual is
  /// skipped and counted.
  ParityVerdict add(const Outputs& s, const Vec3<T>& w_b) {
    if (dof_ == 0) return ParityVerdict::kUnavailable;
    const Outputs c = solver_.predict(Vec3<T>::Zero(), Vec3<T>::Zero(), w_b);
    const Outputs r = p_ * (s - c);
    if (!std::isfinite(r.squaredNorm())) {
      ++rejected_samples_;
      return nonfinite_sample(s);
    }
    nonfinite_run_.fill(0);
    sum_w_ += w_b;
    if (n_ == 0) r_ref_ = r;
    win_r_ += r;
    win_kr_ += static_cast<T>(n_) * r;
    const Outputs dr = r - r_ref_;  // about the window's first residual: float sums keep digits
    sum_ += dr;
    sum2_ += dr.cwiseProduct(dr);
    if (++n_ < config_.window) return ParityVerdict::kPending;
    const ParityVerdict v = decide();
    reset_window();
    return v;
  }

  /// The suspect's fault integrated over the streak (valid after kExcludeRequest; channel −1
  /// otherwise).
  FaultTransient<T> transient() const {
    FaultTransient<T> t;
    if (suspect_ < 0 || streak_ == 0) return t;
    const T dt = T(1) / config_.sample_rate_hz;
    const T pjj = p_(suspect_, suspect_);
    const T k_now = static_cast<T>(trans_samples_);
    t.channel = suspect_;
    t.integral_mps = dt * trans_r_(suspect_) / pjj;
    t.moment_m = dt * dt * (k_now * trans_r_(suspect_) - trans_kr_(suspect_)) / pjj;
    t.samples = trans_samples_;
    return t;
  }

  /// Health of channel j (0 ≤ j < N).
  ChannelHealth health(int j) const { return health_[static_cast<std::size_t>(j)]; }
  /// The sensors in use.
  ChannelMask active() const { return solver_.active(); }
  /// The channel of the last isolated alarm, −1 if none.
  int suspect_channel() const { return suspect_; }
  /// Posterior probability of the most likely faulty channel in the last alarm window (NaN when
  /// the last window had no alarm).
  T isolation_probability() const { return isolation_p_; }
  /// Estimated fault on the suspect channel (m/s², the mean test's b̂ = r̄_j / P_jj; NaN if none).
  T suspect_bias_mps2() const { return suspect_bias_; }
  /// Last window's statistics and their thresholds (NaN without parity space).
  T mean_statistic() const { return t_mean_; }
  T scatter_statistic() const { return t_scatter_; }
  T mean_threshold() const { return threshold_mean_; }
  T scatter_threshold() const { return threshold_scatter_; }
  /// RMS of the last window's mean residual over the active sensors, m/s² (NaN if none).
  T residual_rms_mps2() const { return residual_rms_; }
  /// Degrees of freedom of the parity space (N_active − 6).
  int dof() const { return dof_; }
  /// False-alarm probability per window (both tests together).
  T window_false_alarm_probability() const { return alpha_; }
  const Projector& projector() const { return p_; }
  std::uint32_t windows() const { return windows_; }
  std::uint32_t alarms() const { return alarms_; }
  std::uint32_t exclusions() const { return exclusions_; }
  std::uint32_t rejected_samples() const { return rejected_samples_; }

 private:
  static bool is_active(ChannelMask mask, int j) {
    return ((mask >> static_cast<unsigned>(j)) & 1U) != 0U;
  }

  /// A sample with a non-finite residual: skipped; when exactly one active channel is not finite
  /// for `window` · `confirm_windows` samples in a row, its exclusion is requested directly (a
  /// channel stuck at inf or NaN would otherwise only ever be skipped).
  ParityVerdict nonfinite_sample(const Outputs& s) {
    int bad = -1;
    int count = 0;
    for (int j = 0; j < N; ++j) {
      if (is_active(solver_.active(), j) && !std::isfinite(s(j))) {
        bad = j;
        ++count;
      }
    }
    for (int j = 0; j < N; ++j) {
      if (count != 1 || j != bad) nonfinite_run_[static_cast<std::size_t>(j)] = 0;
    }
    if (count != 1) return ParityVerdict::kPending;
    auto& run = nonfinite_run_[static_cast<std::size_t>(bad)];
    if (++run < config_.window * config_.confirm_windows) return ParityVerdict::kPending;
    run = 0;
    suspect_ = bad;
    streak_ = 0;  // no residual sums: transient() has nothing to report
    isolation_p_ = T(1);
    suspect_bias_ = std::numeric_limits<T>::quiet_NaN();
    health_[static_cast<std::size_t>(bad)] = ChannelHealth::kSuspected;
    return ParityVerdict::kExcludeRequest;
  }

  void reset_window() {
    sum_w_.setZero();
    prev_r_ = win_r_;
    prev_kr_ = win_kr_;
    prev_samples_ = n_;
    win_r_.setZero();
    win_kr_.setZero();
    n_ = 0;
    sum_.setZero();
    sum2_.setZero();
  }

  /// Posterior of each active channel from its log-likelihood ratio (stable softmax), the members
  /// of an ambiguity group all taking the group's best; returns the best channel and its
  /// probability in `p_best`.
  int most_likely(const Outputs& raw_llr, T& p_best) const {
    Outputs llr = raw_llr;
    for (int j = 0; j < N; ++j) {
      for (int k = 0; k < N; ++k) {
        if (is_active(group_[static_cast<std::size_t>(j)], k))
          llr(j) = std::max(llr(j), raw_llr(k));
      }
    }
    int best = -1;
    for (int j = 0; j < N; ++j) {
      if (usable(j) && (best < 0 || llr(j) > llr(best))) best = j;
    }
    if (best < 0) {
      p_best = T(0);
      return -1;
    }
    if (!std::isfinite(llr(best))) {
      // A fault so large that its likelihood overflows T: the channels sharing the infinite
      // value (one, or an ambiguity group) share the posterior.
      int tied = 0;
      for (int j = 0; j < N; ++j) tied += usable(j) && llr(j) == llr(best) ? 1 : 0;
      p_best = T(1) / static_cast<T>(tied);
      return best;
    }
    T z = T(0);
    for (int j = 0; j < N; ++j) {
      if (usable(j)) z += std::exp(llr(j) - llr(best));
    }
    p_best = T(1) / z;
    return best;
  }

  /// A channel whose fault the parity space sees at all (P_jj well above rounding).
  bool usable(int j) const { return is_active(solver_.active(), j) && p_(j, j) > T(1e-4); }

 public:
  /// The channels the parity space cannot tell apart from channel j (j itself included; empty
  /// when j is excluded or invisible to the parity space).
  ChannelMask ambiguity_group(int j) const { return group_[static_cast<std::size_t>(j)]; }

 private:
  ParityVerdict decide() {
    ++windows_;
    const T w = static_cast<T>(n_);
    const Outputs mean_dr = sum_ / w;
    const Outputs mean_r = r_ref_ + mean_dr;
    // Σ_k (r_kj − r̄_j)² = Σ_k d_kj² − W d̄_j², per channel; clamp the rounding below zero.
    const Outputs scatter = (sum2_ - w * mean_dr.cwiseProduct(mean_dr)).cwiseMax(T(0));
    // The rate's error leaves P Q D(ω̄) δω in the mean residual: its covariance is bounded by
    // σ_ω² ‖P Q D(ω̄)‖²_F in every direction (the Frobenius norm bounds the largest singular
    // value), added to the white part: conservative, the false-alarm rate stays at or below the
    // stated one.
    const Vec3<T> mean_w = sum_w_ / w;
    const T rate_var = config_.rate_sigma_rps * config_.rate_sigma_rps *
                       (pq_ * centripetal_jacobian(mean_w)).squaredNorm();
    const T sigma2_mean = sigma2_mean_ + rate_var;
    t_mean_ = mean_r.squaredNorm() / sigma2_mean;
    // The residual lies in the parity space, so its scatter per window is the sum over sensors.
    t_scatter_ = scatter.sum() / sigma2_;
    residual_rms_ = std::sqrt(mean_r.squaredNorm() / static_cast<T>(channel_count(active())));
    const bool mean_alarm = t_mean_ > threshold_mean_;
    const bool scatter_alarm = t_scatter_ > threshold_scatter_;
    for (auto& h : health_) {
      if (h == ChannelHealth::kSuspected) h = ChannelHealth::kOk;
    }
    if (!mean_alarm && !scatter_alarm) {
      streak_ = 0;
      suspect_ = -1;
      isolation_p_ = std::numeric_limits<T>::quiet_NaN();
      suspect_bias_ = std::numeric_limits<T>::quiet_NaN();
      return ParityVerdict::kConsistent;
    }
    ++alarms_;
    Outputs llr = Outputs::Zero();
    const T n = w - T(1);
    // The mean test's w_j² = r̄_j² / (σ_m² P_jj) is formed as (r̄_j / m)² / P_jj times (m/σ_m)²
    // with m the largest |r̄_j|, so a huge fault (a channel at 1e16 m/s² in float) does not
    // overflow every channel's likelihood to inf alike.
    T m = T(0);
    for (int j = 0; j < N; ++j) {
      if (usable(j)) m = std::max(m, std::abs(mean_r(j)));
    }
    for (int j = 0; j < N; ++j) {
      if (!usable(j)) continue;
      if (mean_alarm) {
        const T x = m > T(0) ? mean_r(j) / m : T(0);
        llr(j) = x * x / p_(j, j);
      } else {
        const T z = scatter(j) / (sigma2_ * p_(j, j));
        llr(j) = z > n ? (z - n - n * std::log(z / n)) / T(2) : T(0);
        if (!std::isfinite(llr(j))) llr(j) = std::numeric_limits<T>::max();
      }
    }
    if (mean_alarm) {
      // Scale by (m/σ_m)²/2, capped so that the largest log-likelihood is at most 1e4: beyond
      // that the evidence is overwhelming either way, and the order (and exact ties) are kept.
      const T largest = llr.maxCoeff();
      const T scale = (m / std::sqrt(sigma2_mean)) * (m / std::sqrt(sigma2_mean)) / T(2);
      if (largest > T(0))
        llr *= std::isfinite(scale) ? std::min(scale, T(1e4) / largest) : T(1e4) / largest;
    }
    T p_best = T(0);
    const int best = most_likely(llr, p_best);
    isolation_p_ = p_best;
    if (best < 0 || !(p_best >= config_.isolation_probability)) {
      streak_ = 0;
      suspect_ = -1;
      suspect_bias_ = std::numeric_limits<T>::quiet_NaN();
      return ParityVerdict::kUnisolated;
    }
    if (best == suspect_ && streak_ > 0) {
      // Sample m of the sums counts from the start of the window before the first alarm.
      trans_r_ += win_r_;
      trans_kr_ += win_kr_ + static_cast<T>(trans_samples_) * win_r_;
      trans_samples_ += n_;
    } else {
      trans_r_ = prev_r_ + win_r_;
      trans_kr_ = prev_kr_ + win_kr_ + static_cast<T>(prev_samples_) * win_r_;
      trans_samples_ = prev_samples_ + n_;
    }
    streak_ = best == suspect_ ? streak_ + 1 : 1U;
    suspect_ = best;
    suspect_bias_ = mean_r(best) / p_(best, best);
    health_[static_cast<std::size_t>(best)] = ChannelHealth::kSuspected;
    return streak_ >= config_.confirm_windows ? ParityVerdict::kExcludeRequest
                                              : ParityVerdict::kSuspected;
  }

  ParityConfig<T> config_{};
  Solver solver_{};
  Projector p_ = Projector::Zero();
  Eigen::Matrix<T, N, 6> pq_ = Eigen::Matrix<T, N, 6>::Zero();  // P Q: the rate's leak
  Vec3<T> sum_w_ = Vec3<T>::Zero();                             // Σ ω over the window
  std::array<std::uint32_t, static_cast<std::size_t>(N)> nonfinite_run_{};
  int dof_ = 0;
  T alpha_ = T(0);
  T sigma2_ = T(1);
  T sigma2_mean_ = T(1);
  T threshold_mean_ = T(0);
  T threshold_scatter_ = T(0);
  Outputs r_ref_ = Outputs::Zero();
  Outputs sum_ = Outputs::Zero();
  Outputs sum2_ = Outputs::Zero();
  std::uint32_t n_ = 0;
  T t_mean_ = std::numeric_limits<T>::quiet_NaN();
  T t_scatter_ = std::numeric_limits<T>::quiet_NaN();
  T residual_rms_ = std::numeric_limits<T>::quiet_NaN();
  T isolation_p_ = std::numeric_limits<T>::quiet_NaN();
  T suspect_bias_ = std::numeric_limits<T>::quiet_NaN();
  int suspect_ = -1;
  std::uint32_t streak_ = 0;
  // Σ r and Σ (sample index) r of this window and the last, and over the streak (transient()).
  Outputs win_r_ = Outputs::Zero();
  Outputs win_kr_ = Outputs::Zero();
  Outputs prev_r_ = Outputs::Zero();
  Outputs prev_kr_ = Outputs::Zero();
  std::uint32_t prev_samples_ = 0;
  Outputs trans_r_ = Outputs::Zero();
  Outputs trans_kr_ = Outputs::Zero();
  std::uint32_t trans_samples_ = 0;
  std::array<ChannelHealth, static_cast<std::size_t>(N)> health_{};
  std::array<ChannelMask, static_cast<std::size_t>(N)> group_{};
  std::uint32_t windows_ = 0;
  std::uint32_t alarms_ = 0;
  std::uint32_t exclusions_ = 0;
  std::uint32_t rejected_samples_ = 0;
};

/// The solver without sensor `channel` (the exclusion a monitor requested): same geometry, the
/// condition limit given (a solver does not remember the one it was built with: pass it again if
/// it was not the default); kInvalidArgument/kSingular when the rest cannot determine [ω̇; f].
template <typename T, int N>
Result<ArraySolver<T, N>> solver_without(const ArraySolver<T, N>& solver, int channel,
                                         T max_condition = T(kDefaultMaxCondition)) {
  if (channel < 0 || channel >= N) {
    return Status(ErrorCode::kInvalidArgument, "exclusion: no such channel");
  }
  return ArraySolver<T, N>::create_subset(
      solver.geometry(), max_condition,
      solver.active() & ~(ChannelMask{1} << static_cast<unsigned>(channel)));
}

}  // namespace gfins::nav
