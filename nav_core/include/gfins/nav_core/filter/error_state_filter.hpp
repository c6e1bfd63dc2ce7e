// Error-state (indirect) Kalman filter of the aided gyro-free strapdown (docs/math.md, "Aided
// navigation: the error-state filter").
//
// State (measurement.hpp): x = [φ, δr, δv, δω, δβ_ω̇, δβ_f], 18 errors. The navigation block of
// the process model is the linear error model of paper §3 (eqs. (7)-(13)) as error_model.hpp
// derives it (ErrorModel::navigation_continuous: eq. (8) φ̇ = −C δω, eq. (10), eq. (12) with the
// K J(ω) centripetal coupling and the gravity gradient, eq. (13)); the bias is the fixed 6-D bias
// of the array's solution [ω̇; f] (Carlsson, Skog, Hendeby, Jaldén 2022) instead of N
// per-sensor biases, which are not observable: only β = M b reaches the navigation.
//   ẋ_nav = F_nav x_nav + G_u (δβ + M n),  G_u = ∂ẋ_nav/∂δ[ω̇; f] (ErrorModel::array_input_matrix)
//   δβ̇ = w_β,  Cov(M n) = M diag(σ² h) Mᵀ,  Cov(w_β) = M diag(q_rw) Mᵀ   (correlated 6×6)
// Propagation runs at a decimated rate (every D samples, dt = D/rate): Φ = I + F h + F² h²/2 from
// F at the current navigation state, Q_d by Van Loan's series to h³ (as ErrorModel does), every
// product with F or Φ block-sparse (block_sparse.hpp: F has 8 non-zero 3×3 blocks of 36, Φ 18).
// Updates: generic linearised update with a χ² innovation gate (NIS against the configured
// quantile for the measurement's dimension), Joseph form (as rank-M corrections), symmetrisation, a
// floor and a check on the diagonal (non-finite or negative → covariance reset to the initial one,
// counted), and closed-loop feedback into the Strapdown (apply_correction, set_bias), after which x
// = 0.
//
// Static allocation (P, 18×18, is 1.3 kB in float; the history HistoryCapacity entries of
// attitude, rate, velocity and position), no heap, no
// exceptions; float on the board, double as the reference (explicit instantiations in
// src/error_state_filter.cpp).
#pragma once

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>

#include "gfins/nav_core/error_model.hpp"
#include "gfins/nav_core/filter/block_sparse.hpp"
#include "gfins/nav_core/filter/chi_square.hpp"
#include "gfins/nav_core/filter/euler_error.hpp"
#include "gfins/nav_core/filter/gnss_update.hpp"
#include "gfins/nav_core/filter/measurement.hpp"
#include "gfins/nav_core/filter/nav_history.hpp"
#include "gfins/nav_core/filter/zero_update.hpp"
#include "gfins/nav_core/integrator.hpp"
#include "gfins/status/status.hpp"

namespace gfins::nav {

template <typename T>
struct FilterConfig {
  T sample_rate_hz = T(1000);  // rate of the samples the noise σ refers to
  // Per-sensor white noise σ (per sample), bias random walk (m/s²/√s) and random-constant bias σ
  // (m/s²): mapped through M into the 6-D bias and noise of [ω̇; f].
  SensorNoiseSpec<T, kNumSensors> noise{};
  // Initial 1σ of the navigation errors (after static alignment).
  T init_sigma_tilt_rad = T(0.01);     // φ_N, φ_E
  T init_sigma_heading_rad = T(0.05);  // φ_D when the heading is given
  bool heading_known = true;           // false: φ_D variance π² until the GNSS track aligns it
  T init_sigma_pos_m = T(1);
  T init_sigma_vel_mps = T(0.05);
  T init_sigma_rate_rps = T(1e-3);
  // Covariance hygiene: every diagonal element is kept at or above this (SI units squared).
  T variance_floor = T(1e-14);
  // Innovation gate: probability of the χ² quantile (per measurement dimension).
  T gate_probability = T(0.999);
  bool innovation_gate = true;  // false: every finite innovation is applied (tests only)
  // Standstill pseudo-measurements, 1σ.
  T zupt_sigma_mps = T(0.01);
  T zaru_sigma_rps = T(1e-3);
  // GNSS antenna lever arm, m, body FRD from the array centre.
  Vec3<T> gnss_lever_arm_b = Vec3<T>::Zero();
  // Lock-out recovery: after this many consecutive rejected fixes of one kind (GNSS position or
  // velocity) the filter's own covariance is what is wrong (the gate keeps out every fix of a
  // navigation solution that has drifted outside its stated σ, so it would never come back): the
  // quantity is set from the fix, and the attitude, rate and bias covariance go back to their
  // initial values (counted in FilterCounters::gnss_lockout_resets). 0: never.
  std::uint32_t gnss_lockout_fixes = 25;
  // Heading from the GNSS track once the horizontal speed exceeds this (heading_known = false).
  T track_min_speed_mps = T(3);
  // A land vehicle moves along its body x axis (no side slip): above track_min_speed_mps every
  // GNSS velocity fix also gives the heading, atan2(v_E, v_N) of the array's velocity (the
  // antenna's minus ω × l), with 1σ² = (σ_v / speed)² + this², the side slip's 1σ. It is the only
  // heading information at constant speed: an accelerometer array's rate error grows with the
  // ω̇ bias, and the heading with it, while GNSS velocity sees the heading only under horizontal
  // acceleration. 0: off (a handheld or walking board, whose x axis need not point where it goes).
  T track_heading_sigma_rad = T(0);
  // Divergence: the linear error model holds for small errors only, and an accelerometer
  // array's rate error feeds itself through the centripetal terms (ω̇ error ∝ ω δω + δω²), so a
  // solution that has gone far (a long outage) runs away in finite time. When the tilt 1σ exceeds
  // diverged_sigma_tilt_rad or |ω̂| exceeds max_rate_rps the filter restarts (counted in
  // FilterCounters::divergence_restarts): the rate is set to zero with restart_sigma_rate_rps,
  // the tilt 1σ to half diverged_sigma_tilt_rad, the heading unknown until the GNSS track or a
  // heading sets it again, the bias to its prior. The output is then not valid until the σ come
  // back below the validity horizons.
  T diverged_sigma_tilt_rad = T(0.35);  // 20°
  T max_rate_rps = T(10);
  T restart_sigma_rate_rps = T(0.3);
  // The roll and pitch rate 1σ (body x and y) of an in-motion start (lose_attitude): the rate the
  // strapdown starts from is zero, so its error is the vehicle's own rate at power-up, a few °/s
  // about a land vehicle's x and y axes (0.05 rad/s: 2.9°/s). The yaw rate keeps
  // restart_sigma_rate_rps (a turn).
  T in_motion_sigma_tilt_rate_rps = T(0.05);
  // An aiding kind counts in mode() for this long after its last accepted update.
  T aiding_timeout_s = T(2);
  // Validity horizons: a quantity is valid while aligned and its 1σ is at or below these.
  T valid_sigma_tilt_rad = T(0.0175);     // 1°
  T valid_sigma_heading_rad = T(0.0524);  // 3°
  T valid_sigma_vel_mps = T(0.5);
  T valid_sigma_pos_m = T(10);
};

/// Bits of NavAccuracy::mode: which aiding was accepted within FilterConfig::aiding_timeout_s
/// (none set: unaided).
namespace filter_mode {
inline constexpr std::uint8_t kStandstill = 1u << 0;  // ZUPT or ZARU
inline constexpr std::uint8_t kGnss = 1u << 1;        // GNSS position or velocity
inline constexpr std::uint8_t kHeading = 1u << 2;     // external heading
}  // namespace filter_mode

/// Bits of NavAccuracy::valid.
namespace filter_valid {
inline constexpr std::uint8_t kRollPitch = 1u << 0;
inline constexpr std::uint8_t kHeading = 1u << 1;
inline constexpr std::uint8_t kVelocity = 1u << 2;
inline constexpr std::uint8_t kPosition = 1u << 3;
}  // namespace filter_valid

/// 1σ of the published quantities, from the filter covariance (never an optimistic guess); NaN
/// where the covariance does not describe the error (before the filter starts; after a
/// divergence restart or an in-motion start, until a fix sets the quantity).
template <typename T>
struct NavAccuracy {
  Vec3<T> euler_sigma_rad = Vec3<T>::Zero();  // roll, pitch, heading
  Vec3<T> vel_sigma_mps = Vec3<T>::Zero();    // N, E, D
  Vec3<T> pos_sigma_m = Vec3<T>::Zero();      // N, E, D
  std::uint8_t mode = 0;                      // filter_mode bits
  std::uint8_t valid = 0;                     // filter_valid bits
};

enum class UpdateStatus : std::uint8_t {
  kAccepted,  // applied and fed back
  kRejected,  // innovation outside the χ² gate: not applied
  kInvalid,   // bad input (σ ≤ 0, non-finite, outside the history) or not started: not applied
  kReset,     // before heading alignment: the fix reset the quantity instead of an update
};

struct UpdateOutcome {
  UpdateStatus status = UpdateStatus::kInvalid;
  float nis = 0;  // νᵀ S⁻¹ ν (0 when not computed); float whatever T (no double on the board)
};

struct FilterCounters {
  std::array<std::uint32_t, kAidingKinds> accepted{};
  std::array<std::uint32_t, kAidingKinds> rejected{};
  std::array<std::uint32_t, kAidingKinds> invalid{};
  std::uint32_t propagations = 0;
  std::uint32_t covariance_resets = 0;    // non-finite or negative diagonal found and reset
  std::uint32_t gnss_lockout_resets = 0;  // FilterConfig::gnss_lockout_fixes reached
  std::uint32_t divergence_restarts = 0;  // FilterConfig::diverged_sigma_tilt_rad, max_rate_rps
  std::uint32_t rest_relevels = 0;        // relevel_at_rest
};

template <typename T, int HistoryCapacity = 32>
class ErrorStateFilter {
 public:
  static constexpr int kStates = filt_idx::kStates;
  using StateVec = Eigen::Matrix<T, kStates, 1>;
  using StateMat = Eigen::Matrix<T, kStates, kStates>;
  using Model = ErrorModel<T, kNumSensors>;
  using Nav = Strapdown<T, kNumSensors>;

  /// Checks and takes the configuration, and zeroes the counters (they only grow between
  /// configurations). On failure nothing changes. The process model is built at each propagation
  /// from the strapdown's own array solver and gravity (a new calibration is followed at once).
  [[nodiscard]] Status configure(const FilterConfig<T>& config) {
    if (!(config.sample_rate_hz > T(0)) || !std::isfinite(config.sample_rate_hz)) {
      return Status(ErrorCode::kInvalidArgument, "filter: sample rate must be positive");
    }
    if (!(config.gate_probability > T(0) && config.gate_probability < T(1))) {
      return Status(ErrorCode::kInvalidArgument, "filter: gate probability must be in (0, 1)");
    }
    if (!(config.zupt_sigma_mps > T(0)) || !(config.zaru_sigma_rps > T(0)) ||
        !(config.init_sigma_tilt_rad > T(0)) || !(config.init_sigma_heading_rad > T(0)) ||
        !(config.init_sigma_pos_m > T(0)) || !(config.init_sigma_vel_mps > T(0)) ||
        !(config.init_sigma_rate_rps > T(0)) || !(config.variance_floor > T(0)) ||
        !(config.diverged_sigma_tilt_rad > T(0)) || !(config.max_rate_rps > T(0)) ||
        !(config.restart_sigma_rate_rps > T(0)) || !(config.in_motion_sigma_tilt_rate_rps > T(0))) {
      return Status(ErrorCode::kInvalidArgument, "filter: every sigma must be positive");
    }
    config_ = config;
    gate_1_ = chi_square_quantile(config.gate_probability, 1);
    gate_3_ = chi_square_quantile(config.gate_probability, 3);
    counters_ = FilterCounters{};  // a new configuration is a new filter
    configured_ = true;
    started_ = false;
    return Status::ok();
  }

  /// Starts estimating at the strapdown's current (aligned) solution: P ← P0, the bias estimate
  /// of the strapdown to zero, history cleared, heading aligned when the configuration gives it.
  void start(Nav& nav);

  /// An in-motion start (the board powered up on a moving vehicle, NavPipeline), after start():
  /// everything the static alignment would have measured is unknown, as after a divergence
  /// restart (restart_after_divergence, not counted as one) but with the roll and pitch rate 1σ
  /// in_motion_sigma_tilt_rate_rps: tilt 1σ half the divergence limit, heading unknown, every σ
  /// not available until the GNSS fixes re-level the tilt, set the heading from the track and
  /// reset velocity and position.
  void lose_attitude(Nav& nav) { forget(nav, false); }

  /// The covariance the filter starts from and resets to.
  StateMat initial_covariance() const;

  /// The continuous process model at the strapdown's current state: F = [F_nav G_u; 0 0] and
  /// Q_c = [G_u Cov(M n) G_uᵀ 0; 0 Cov(w_β)], from ErrorModel on the strapdown's own solver and
  /// gravity.
  void process_model(const Nav& strapdown, StateMat& f, StateMat& qc) const;

  /// F of process_model alone.
  void transition_model(const Nav& strapdown, StateMat& f) const;

  /// A measurement valid at t_valid_ns, before the strapdown's current time (a GNSS fix's
  /// latency): h (rows × kStates, column-major, rows ≤ 3) is turned from the error at t_valid
  /// into the error now, H ← H Φ(now, t_v)⁻¹ with Φ⁻¹ ≈ I − F Δt + F² Δt²/2 at the current state.
  /// Nothing happens for Δt ≤ 0.
  void refer_to_now(T* h, int rows, const Nav& strapdown, std::int64_t t_valid_ns) const;

  /// The blocks of F that process_model can fill (block_sparse.hpp: 0 φ, 1 δr, 2 δv, 3 δω,
  /// 4 δβ_ω̇, 5 δβ_f): eq. (8) φ̇ = −C δω; eq. (10) δṙ = δv; eq. (12) δv̇ from φ, from δr (the
  /// gravity gradient), from δω (the centripetal term) and from δβ_f; eq. (13) δω̇ from δω and
  /// from δβ_ω̇. The bias rows are zero (random walk). A test checks every other entry of F is
  /// zero at random states.
  static constexpr blocks::Mask kFMask = blocks::bit(0, 3) | blocks::bit(1, 2) | blocks::bit(2, 0) |
                                         blocks::bit(2, 1) | blocks::bit(2, 3) | blocks::bit(2, 5) |
                                         blocks::bit(3, 3) | blocks::bit(3, 4);
  /// The blocks of Φ = I + F h + F² h²/2.
  static constexpr blocks::Mask kPhiMask =
      blocks::identity() | kFMask | blocks::product(kFMask, kFMask);

  /// One covariance step over dt_s (the D samples since the previous call) at the strapdown's
  /// current state, which is also stored in the history. F, the noise through M and the gravity
  /// gradient come from ErrorModel on the strapdown's own solver and gravity.
  Status propagate(const Nav& strapdown, T dt_s);

  /// FilterConfig's divergence test (call after propagate): true when it fired and the filter
  /// restarted (the strapdown's rate zeroed, the covariance widened, the heading unknown).
  bool restart_if_diverged(Nav& nav) {
    if (!started_ || !diverged(nav)) return false;
    restart_after_divergence(nav);
    return true;
  }

  // ---- Updates: each returns what became of it; only kAccepted (and kReset) change the state --

  /// Zero velocity at standstill (3-D).
  UpdateOutcome update_zupt(Nav& nav);

  /// Zero angular rate at standstill (3-D).
  UpdateOutcome update_zaru(Nav& nav);

  /// At rest with the tilt lost (a divergence restart, an in-motion start) or far off
  /// (relevel_wanted()), where a ZUPT cannot help: the linear update would converge to a wrong
  /// attitude, and after a drive on accelerometers alone its gate refuses a velocity error of
  /// hundreds of m/s. The mean specific force of a window at rest is gravity's reaction,
  /// [0, 0, −g] in NED (the static alignment's levelling, alignment.hpp), so the attitude is
  /// turned to put Ĉ f̄_b on the down axis, the heading kept (turn_onto); velocity and rate are
  /// set to zero with the ZUPT's and ZARU's variances. The tilt is the bias seen through the level
  /// plus the window mean's noise var_f_mean / |f̄|² per axis, with its correlations (below). Unless
  /// the velocity is lost, the ZUPT's χ² gate on the filter's own velocity comes first (kRejected,
  /// counted: a straight drive at constant speed reads like rest). Counted as an accepted ZUPT
  /// (it sets the velocity) and in FilterCounters::rest_relevels. The caller says the board is at
  /// rest (the standstill detector, no GNSS saying it moves). kInvalid when no re-level is wanted,
  /// f̄_b is not finite, or it points exactly up.
  UpdateOutcome relevel_at_rest(Nav& nav, const Vec3<T>& f_mean_b, T var_f_mean);

  /// The tilt is lost (a divergence restart or an in-motion start) until a re-level finds it.
  bool tilt_lost() const { return (lost_ & filter_valid::kRollPitch) != 0; }
  /// A standstill should re-level rather than update (relevel_at_rest): the tilt is lost, or its
  /// 1σ is above the validity horizon valid_sigma_tilt_rad (roll and pitch not published). A
  /// tilt that far off is outside the linear model a ZUPT works through (after 35 s of driving
  /// on accelerometers alone the error was 26° with a 1σ under the divergence limit, and the
  /// ZUPTs at the stop that followed were accepted and left it there), and one window's level
  /// is far better than it.
  bool relevel_wanted() const {
    using namespace filt_idx;
    const T horizon = config_.valid_sigma_tilt_rad * config_.valid_sigma_tilt_rad;
    return tilt_lost() || !(p_(kPhi, kPhi) <= horizon && p_(kPhi + 1, kPhi + 1) <= horizon);
  }

  /// GNSS antenna position valid at fix.t_valid_ns (≤ now, within the history).
  UpdateOutcome update_gnss_position(Nav& nav, const GnssFix<T>& fix);

  /// GNSS antenna velocity valid at fix.t_valid_ns. Before heading alignment it sets the velocity
  /// and, above track_min_speed_mps, the heading from the track.
  UpdateOutcome update_gnss_velocity(Nav& nav, const GnssFix<T>& fix);

  /// External heading valid at fix.t_valid_ns (≤ now, within the history): the innovation is
  /// taken against the filter's heading at that instant, so a heading that is 200 ms old on a
  /// board turning at 30°/s is not read as a 6° error. Before heading alignment it sets the
  /// heading (the offset found at that instant, applied now).
  UpdateOutcome update_heading(Nav& nav, const HeadingFix<T>& fix);

  // ---- Outputs --------------------------------------------------------------------------------

  /// 1σ, mode and validity at the navigation state `nav` (the strapdown's current one).
  NavAccuracy<T> accuracy(const NavState<T>& nav) const;

  const StateMat& covariance() const { return p_; }
  const FilterCounters& counters() const { return counters_; }
  const FilterConfig<T>& config() const { return config_; }
  bool started() const { return started_; }
  bool heading_aligned() const { return heading_aligned_; }
  /// Instant of the last accepted update of `kind` (INT64_MIN when none).
  std::int64_t last_accepted_ns(AidingKind kind) const {
    return last_accepted_ns_[static_cast<std::size_t>(kind)];
  }
  /// Instant of the last accepted aiding update of any kind (INT64_MIN when none).
  std::int64_t last_aiding_ns() const {
    std::int64_t t = kNever;
    for (const std::int64_t v : last_accepted_ns_) t = v > t ? v : t;
    return t;
  }
  /// The χ² thresholds the gates use (dimension 1 and 3).
  T gate_threshold(int dim) const { return dim == 1 ? gate_1_ : gate_3_; }

 private:
  static constexpr std::int64_t kNever = INT64_MIN;

  bool recent(AidingKind kind, std::int64_t now_ns) const {
    const std::int64_t t = last_accepted_ns(kind);
    if (t == kNever) return false;
    return from_int64<T>(now_ns - t) * T(1e-9) <= config_.aiding_timeout_s;
  }

  UpdateOutcome invalid(AidingKind kind) {
    ++counters_.invalid[static_cast<std::size_t>(kind)];
    return UpdateOutcome{UpdateStatus::kInvalid, 0.0F};
  }

  bool fix_usable(const Nav& nav, const GnssFix<T>& fix, HistoryEntry<T>& at) const {
    return started_ && fix.value_n.allFinite() && (fix.sigma.array() > T(0)).all() &&
           fix.sigma.allFinite() && history_.at(fix.t_valid_ns, nav.state(), at);
  }

  /// The innovation test of every update: S = H P Hᵀ + R, positive definite (Cholesky as the
  /// test; M ≤ 3, so its inverse is closed-form), NIS = yᵀ S⁻¹ y against `gate`. kAccepted: it
  /// passes (P Hᵀ and S⁻¹ left for the gain); kRejected counted; kInvalid counted.
  template <int M>
  UpdateOutcome innovation_test(const Measurement<T, M>& m, AidingKind kind, T gate,
                                Eigen::Matrix<T, kStates, M>& pht, Eigen::Matrix<T, M, M>& s_inv) {
    pht = p_.lazyProduct(m.h.transpose());
    Eigen::Matrix<T, M, M> s = m.h.lazyProduct(pht) + m.r;
    s = (s + s.transpose()) / T(2);
    const Eigen::LLT<Eigen::Matrix<T, M, M>> llt(s);
    if (llt.info() != Eigen::Success) return invalid(kind);
    s_inv = s.inverse();
    const T nis = m.y.dot(s_inv * m.y);
    if (!std::isfinite(nis)) return invalid(kind);
    if (config_.innovation_gate && nis > gate) {
      ++counters_.rejected[static_cast<std::size_t>(kind)];
      return UpdateOutcome{UpdateStatus::kRejected, static_cast<float>(nis)};
    }
    return UpdateOutcome{UpdateStatus::kAccepted, static_cast<float>(nis)};
  }

  /// The linearised update: gate, gain, Joseph form, feedback.
  /// t_valid_ns: when the measurement was valid (refer_to_now).
  template <int M>
  UpdateOutcome apply(Measurement<T, M> m, AidingKind kind, T gate, Nav& nav,
                      std::int64_t t_valid_ns) {
    const auto k_idx = static_cast<std::size_t>(kind);
    if (!m.y.allFinite()) return invalid(kind);
    refer_to_now(m.h.data(), M, nav, t_valid_ns);
    Eigen::Matrix<T, kStates, M> pht;
    Eigen::Matrix<T, M, M> s_inv;
    const UpdateOutcome tested = innovation_test(m, kind, gate, pht, s_inv);
    if (tested.status != UpdateStatus::kAccepted) return tested;
    const Eigen::Matrix<T, kStates, M> k = pht.lazyProduct(s_inv);
    StateVec dx = k * m.y;
    if (!heading_aligned_) dx(filt_idx::kPhi + 2) = T(0);  // heading is not estimated yet
    // Joseph form: P = (I − KH) P (I − KH)ᵀ + K R Kᵀ, symmetric and positive for any K. I − KH
    // differs from I by a rank-M term, so its two products are taken as rank-M corrections, the
    // same products re-associated (18·18·M multiply-adds each instead of 18³):
    //   A P = P − K (H P), H P = (P Hᵀ)ᵀ;   (A P) Aᵀ = A P − ((A P) Hᵀ) Kᵀ.
    p_.noalias() -= k.lazyProduct(pht.transpose());
    const Eigen::Matrix<T, kStates, M> aph = p_.lazyProduct(m.h.transpose());
    p_.noalias() -= aph.lazyProduct(k.transpose());
    p_.noalias() += k.lazyProduct(m.r).lazyProduct(k.transpose());
    if (!heading_aligned_) decouple_heading();
    condition_covariance();
    feed_back(dx, nav);
    found(kind);
    ++counters_.accepted[k_idx];
    last_accepted_ns_[k_idx] = nav.state().t_ns;
    return UpdateOutcome{UpdateStatus::kAccepted, tested.nis};
  }

  /// An accepted fix of `kind` sets the quantity it measures again after a divergence restart:
  /// its σ describe its error from now on (lost_).
  void found(AidingKind kind) {
    if (kind == AidingKind::kGnssPosition)
      lost_ &= static_cast<std::uint8_t>(~filter_valid::kPosition);
    if (kind == AidingKind::kGnssVelocity || kind == AidingKind::kZupt) {
      lost_ &= static_cast<std::uint8_t>(~filter_valid::kVelocity);
    }
  }

  /// Closed loop: the estimated errors leave the strapdown (and the history), x returns to 0.
  void feed_back(const StateVec& dx, Nav& nav) {
    using namespace filt_idx;
    const Vec3<T> phi = dx.template segment<3>(kPhi);
    const Vec3<T> dr = dx.template segment<3>(kPos);
    const Vec3<T> dv = dx.template segment<3>(kVel);
    const Vec3<T> dw = dx.template segment<3>(kRate);
    nav.apply_correction(phi, dr, dv, dw);
    nav.set_bias(nav.bias_wdot() + dx.template segment<3>(kBiasWdot),
                 nav.bias_f() + dx.template segment<3>(kBiasF));
    history_.shift(phi, dr, dv);
  }

  UpdateOutcome accepted_reset(AidingKind kind, const Nav& nav) {
    const auto k_idx = static_cast<std::size_t>(kind);
    found(kind);
    ++counters_.accepted[k_idx];
    last_accepted_ns_[k_idx] = nav.state().t_ns;
    condition_covariance();
    return UpdateOutcome{UpdateStatus::kReset, 0.0F};
  }

  /// A fix's age, now − t_valid, and the strapdown whose F carries it to now (set_at_fix).
  struct FixAge {
    const Nav* nav = nullptr;
    T dt_s = T(0);
  };
  static FixAge age_of(const Nav& nav, std::int64_t t_valid_ns) {
    return FixAge{&nav, from_int64<T>(nav.state().t_ns - t_valid_ns) * T(1e-9)};
  }

  /// Replaces rows/columns [i, i+3) of P: each state set from a fix (set_at_fix).
  void reset_block(int i, const Vec3<T>& var, const FixAge& age) {
    for (int k = 0; k < 3; ++k) set_at_fix(i + k, var(k), age);
  }

  /// State i set from a fix valid age.dt_s ago, with variance var then: x_i(t_v) is the fix's
  /// error, independent of the rest, and x_i(now) = x_i(t_v) + Δt F_i x (F_ii = 0 for φ, δr and
  /// δv, the states a fix sets), so row i of P becomes Δt F_i P and P_ii = var + Δt² F_i P F_iᵀ.
  /// Set as if valid now, a heading taken 100 ms ago in a turn that the rate error (0.3 rad/s
  /// after an in-motion start) has moved by 1.7° since would keep the fix's 0.6°.
  void set_at_fix(int i, T var, const FixAge& age) {
    set_uncorrelated(i, var);
    if (!(age.dt_s > T(0)) || age.nav == nullptr) return;
    StateMat f;  // F at the current state; a reset is rare, so F is not kept between calls
    transition_model(*age.nav, f);
    T row[kStates];
    for (int j = 0; j < kStates; ++j) {
      T sum = T(0);
      for (int k = 0; k < kStates; ++k) sum += f(i, k) * p_(k, j);
      row[j] = age.dt_s * sum;  // row[i] = 0: column i of P is zero but for P_ii, and F_ii = 0
    }
    T extra = T(0);
    for (int k = 0; k < kStates; ++k) extra += f(i, k) * row[k];
    for (int j = 0; j < kStates; ++j) {
      p_(i, j) = row[j];
      p_(j, i) = row[j];
    }
    p_(i, i) = var + age.dt_s * extra;
  }

  /// State i uncorrelated with every other, of variance var: row and column i zeroed. A loop, not
  /// Eigen's row/column expressions: those unroll into one store per element (18 or 54 of them
  /// per call site; 1 KB of flash for reset_block alone on the Cortex-M4F at -Os).
  void set_uncorrelated(int i, T var) {
    for (int r = 0; r < kStates; ++r) {
      p_(i, r) = T(0);
      p_(r, i) = T(0);
    }
    p_(i, i) = var;
  }

  /// Before heading alignment: position set from the fix. The lever arm is rotated with an
  /// unknown heading, so its length is added to the variance of each axis.
  UpdateOutcome reset_position(Nav& nav, const GnssFix<T>& fix, const HistoryEntry<T>& at) {
    const Vec3<T> dr = at.r_n + at.q_nb * config_.gnss_lever_arm_b - fix.value_n;
    nav.apply_correction(Vec3<T>::Zero(), dr, Vec3<T>::Zero(), Vec3<T>::Zero());
    history_.shift(Vec3<T>::Zero(), dr, Vec3<T>::Zero());
    start_heading_legs(at.r_n - dr);  // the displacement with the unknown heading starts here
    const T l2 = config_.gnss_lever_arm_b.squaredNorm();
    reset_block(filt_idx::kPos, fix.sigma.cwiseProduct(fix.sigma) + Vec3<T>::Constant(l2),
                age_of(nav, fix.t_valid_ns));
    return accepted_reset(AidingKind::kGnssPosition, nav);
  }

  /// What relevel_from_gnss did.
  enum class Relevel : std::uint8_t {
    kNotNeeded,  // the tilt is not lost
    kDone,       // re-levelled
    kNotYet,     // no previous velocity fix since the restart: the next fix may re-level
    kUnable,     // the two fixes cannot be differenced (too far apart for the history, dt out
                 // of 0.05-2 s, f too small or the result no better than the restart's tilt σ)
  };

  /// Before heading alignment: velocity set from the fix; above the speed threshold the heading
  /// is the track atan2(v_E, v_N) (the vehicle moves along its x axis: no side slip; the body x
  /// axis projects on the horizontal at the yaw angle whatever roll and pitch), with
  /// σ_ψ = σ_v,horizontal / speed, σ_v that of the array's velocity (array_velocity_variance).
  /// relevel: what relevel_from_gnss did with this fix (at is read after it).
  UpdateOutcome reset_velocity_and_track(Nav& nav, const GnssFix<T>& fix, const HistoryEntry<T>& at,
                                         Relevel relevel) {
    // The re-levelled attitude at the fix instant is read back for the track's heading. While the
    // tilt is lost (a divergence restart) the heading waits one fix for the re-levelling: a track
    // heading on a body tilted by tens of degrees would start the linear filter outside its
    // model. When the re-levelling cannot be made (a receiver slower than the history spans) the
    // heading is taken from the track as without it, and roll and pitch stay not available until
    // two fixes can be differenced.
    const FixAge age = age_of(nav, fix.t_valid_ns);
    const bool tilt_known = relevel != Relevel::kNotYet;
    using namespace filt_idx;
    const Vec3<T> v = array_velocity(fix, at);
    const Vec3<T> var = array_velocity_variance(fix, at, !heading_aligned_);
    const T speed = v.template head<2>().norm();
    const bool track = tilt_known && speed >= config_.track_min_speed_mps;
    Vec3<T> phi = Vec3<T>::Zero();
    if (track) {
      const T course = std::atan2(v.y(), v.x());
      // A rotation about the down axis changes the yaw by its angle whatever roll and pitch, and
      // the yaw error is −φ_D there (euler_error.hpp): φ_D = course − ψ̂ at the fix instant.
      phi.z() = wrap_pi(course - euler_from_quat(at.q_nb).z());
    }
    // The velocity error at the fix instant, then rotated with the heading correction.
    const Vec3<T> dv = at.v_n - v;
    nav.apply_correction(phi, Vec3<T>::Zero(), dv, Vec3<T>::Zero());
    history_.shift(phi, Vec3<T>::Zero(), dv);
    reset_block(kVel, var, age);
    if (track) {
      set_heading_variance(nav.state(), std::sqrt(var.template head<2>().maxCoeff()) / speed, age);
    }
    return accepted_reset(AidingKind::kGnssVelocity, nav);
  }

  /// The array's velocity from a fix of the antenna's: the antenna moves with Ĉ(ω̂ × l) beside
  /// it (at the fix's instant). One body: the image has one copy.
  Vec3<T> array_velocity(const GnssFix<T>& fix, const HistoryEntry<T>& at) const;

  /// Per axis, the variance of array_velocity: the fix's, plus |l|² tr P_ωω for ω̂'s error
  /// (after a start in motion or a restart, the vehicle's own rate) and, when the attitude is in
  /// doubt (the heading unknown, a lock-out), |l|² |ω̂|² for Ĉ turned by anything
  /// (|a × l| ≤ |a| |l|).
  Vec3<T> array_velocity_variance(const GnssFix<T>& fix, const HistoryEntry<T>& at,
                                  bool attitude_in_doubt) const {
    using namespace filt_idx;
    const T rate_var = p_(kRate, kRate) + p_(kRate + 1, kRate + 1) + p_(kRate + 2, kRate + 2);
    const T lever_var = config_.gnss_lever_arm_b.squaredNorm() *
                        (rate_var + (attitude_in_doubt ? at.w_b.squaredNorm() : T(0)));
    return fix.sigma.cwiseProduct(fix.sigma) + Vec3<T>::Constant(lever_var);
  }

  /// After a divergence restart the tilt can be tens of degrees off, outside what the linear
  /// update can bring back (it then converges to a wrong attitude with a small σ). Two GNSS
  /// velocity fixes dt apart give the mean specific force in the true n frame, f_n = Δv/dt − g,
  /// and the strapdown's own velocity over the same span gives it in the estimated frame,
  /// f̂_n = Δv̂/dt − g (Δv̂ is the integral of Ĉ f_b + g; the resets in between shift v̂ as a
  /// whole and leave it). The heading is unknown too, so f̂_n is first turned about the down axis
  /// to f_n's azimuth (a heading change, which the track then sets anyway); what remains is a
  /// rotation about a horizontal axis, the tilt error, so a heading error never becomes tilt.
  /// Both are applied, with the tilt 1σ that the fixes' noise gives, σ = √2 σ_v / (dt |f|), unless
  /// that σ is no better than the restart's own (half the divergence limit).
  Relevel relevel_from_gnss(Nav& nav, const GnssFix<T>& fix, const HistoryEntry<T>& at,
                            const FixAge& age) {
    if ((lost_ & filter_valid::kRollPitch) == 0) return Relevel::kNotNeeded;
    if (prev_vel_t_ns_ == kNever) return Relevel::kNotYet;
    const T dt = from_int64<T>(fix.t_valid_ns - prev_vel_t_ns_) * T(1e-9);
    HistoryEntry<T> before;
    if (!(dt >= T(0.05) && dt <= T(2)) || !history_.at(prev_vel_t_ns_, nav.state(), before)) {
      return Relevel::kUnable;
    }
    const Vec3<T> g = nav.gravity().g_n(at.r_n);
    const Vec3<T> f_est = (at.v_n - before.v_n) / dt - g;
    const Vec3<T> f_true = (fix.value_n - prev_vel_n_) / dt - g;
    const T sigma_tilt = T(1.41421356) * fix.sigma.maxCoeff() / dt / f_true.norm();
    if (!(sigma_tilt < config_.diverged_sigma_tilt_rad / T(2))) return Relevel::kUnable;
    // The heading is kept when the track or an external heading sets it (heading_from_track_
    // after an in-motion start; heading_aligned_ when a heading came before the tilt was found).
    const bool keep_heading = heading_from_track_ || heading_aligned_;
    if (!turn_onto(nav, f_est, f_true, keep_heading)) return Relevel::kUnable;
    // A turn to f's azimuth is a new heading, as unknown as the old one: the displacement driven
    // along the old one keeps its error, the next leg gets its own.
    if (!keep_heading) close_heading_leg(nav.state());
    using namespace filt_idx;
    for (int i = 0; i < 2; ++i) {
      set_at_fix(kPhi + i, sigma_tilt * sigma_tilt, age);
    }
    lost_ &= static_cast<std::uint8_t>(~filter_valid::kRollPitch);
    return Relevel::kDone;
  }

  /// The attitude turned so that f_est (a specific force in the estimated n frame) lies along
  /// f_true (the same in the true n frame); only the directions count. Without keep_heading f_est
  /// is first turned about the down axis to f_true's azimuth (a heading change); what remains is a
  /// rotation about a horizontal axis, the tilt error, so a heading error never becomes tilt. With
  /// keep_heading the yaw angle is the same after as before. False (nothing changed) when the two
  /// are 90° or more apart (a difference of two noisy GNSS velocities), or with any_angle (at rest:
  /// f̄ is exact, and a lost tilt can be past 90°) only when they are exactly opposite (no axis).
  /// One body for the re-level from GNSS and at rest.
  bool turn_onto(Nav& nav, const Vec3<T>& f_est, const Vec3<T>& f_true, bool keep_heading,
                 bool any_angle = false) {
    // The turn about down from f̂'s azimuth to f's: c = cos, s = sin of it (none when either has
    // no horizontal part).
    const T c = f_est.x() * f_true.x() + f_est.y() * f_true.y();
    const T s = f_est.x() * f_true.y() - f_est.y() * f_true.x();
    const T r = std::sqrt(c * c + s * s);
    Vec3<T> f_turned = f_est;
    Vec3<T> yaw = Vec3<T>::Zero();
    if (r > T(0) && !keep_heading) {
      f_turned.x() = (c * f_est.x() - s * f_est.y()) / r;
      f_turned.y() = (s * f_est.x() + c * f_est.y()) / r;
      yaw.z() = std::atan2(s, c);
    }
    // Horizontal when the two share an azimuth; with the heading from the track its vertical part
    // is dropped instead: in a turn, f's horizontal part is a few degrees of the vertical, the
    // size of the tilt error, so its azimuth says nothing about the heading.
    Vec3<T> axis = f_turned.cross(f_true);
    if (keep_heading) axis.z() = T(0);
    const T sin_a = axis.norm();
    const T cos_a = f_turned.dot(f_true);
    if (!std::isfinite(sin_a) || !std::isfinite(cos_a)) return false;
    if (!(cos_a > T(0)) && !(any_angle && sin_a > T(0))) return false;
    const Vec3<T> tilt =
        sin_a > T(0) ? Vec3<T>(axis * (std::atan2(sin_a, cos_a) / sin_a)) : Vec3<T>::Zero();
    // q ← exp(tilt) ⊗ exp(yaw) ⊗ q̂; a kept heading is then put back: a turn of tens of degrees
    // about a horizontal axis moves the yaw angle too (by about roll × pitch: 5° for 30° and 20°).
    const T yaw_kept = euler_from_quat(nav.state().q_nb).z();
    Vec3<T> back = Vec3<T>::Zero();
    for (int step = 0; step < 3; ++step) {
      if (step == 2 && keep_heading)
        back.z() = wrap_pi(yaw_kept - euler_from_quat(nav.state().q_nb).z());
      const Vec3<T>& phi = step == 0 ? yaw : step == 1 ? tilt : back;
      nav.apply_correction(phi, Vec3<T>::Zero(), Vec3<T>::Zero(), Vec3<T>::Zero());
      history_.shift(phi, Vec3<T>::Zero(), Vec3<T>::Zero());
    }
    return true;
  }

  /// The heading of the GNSS track (FilterConfig::track_heading_sigma_rad), valid at the fix's
  /// instant; counted as a heading update. Below the speed threshold nothing happens (kInvalid,
  /// not counted: there is no track to read).
  UpdateOutcome update_track_heading(Nav& nav, const GnssFix<T>& fix, const HistoryEntry<T>& at) {
    const Vec3<T> v = array_velocity(fix, at);
    const T speed = v.template head<2>().norm();
    if (!(speed >= config_.track_min_speed_mps)) return UpdateOutcome{};
    // The array's velocity is the antenna's minus Ĉ(ω̂ × l): ω̂'s error moves the course too
    // (|l|² tr P_ωω, as in array_velocity_variance), and the heading update has no rate column to
    // take it: after an in-motion start in a turn ω̂'s error is the vehicle's rate.
    const T sv =
        std::sqrt(array_velocity_variance(fix, at, false).template head<2>().maxCoeff()) / speed;
    const T sigma =
        std::sqrt(sv * sv + config_.track_heading_sigma_rad * config_.track_heading_sigma_rad);
    return apply(heading_measurement(at.q_nb, std::atan2(v.y(), v.x()), sigma),
                 AidingKind::kHeading, gate_1_, nav, fix.t_valid_ns);
  }

  /// FilterConfig's divergence test, after each propagation.
  bool diverged(const Nav& nav) const {
    using namespace filt_idx;
    const T limit = config_.diverged_sigma_tilt_rad * config_.diverged_sigma_tilt_rad;
    const NavState<T>& x = nav.state();
    return !(p_(kPhi, kPhi) <= limit && p_(kPhi + 1, kPhi + 1) <= limit) ||
           !(x.w_b.norm() <= config_.max_rate_rps) || !x.v_n.allFinite() || !x.r_n.allFinite();
  }

  /// The restart of FilterConfig (diverged_sigma_tilt_rad).
  void restart_after_divergence(Nav& nav) { forget(nav, true); }

  /// The attitude, rate and heading unknown, the position and velocity covariance kept (never
  /// below P0), every group lost until a fix sets it: a divergence restart (counted; rate 1σ
  /// restart_sigma_rate_rps) or an in-motion start (lose_attitude; roll and pitch rate 1σ
  /// in_motion_sigma_tilt_rate_rps). One body for both: the image has one copy.
  void forget(Nav& nav, bool divergence);

  /// Counts consecutive rejections of a GNSS kind; at FilterConfig::gnss_lockout_fixes the
  /// quantity is set from this fix (as before heading alignment, the lever arm's length added to
  /// the position variance because the attitude is in doubt) and the attitude, rate and bias
  /// covariance return to the initial one, decorrelated, the heading variance never below what it
  /// was. The outcome stays kRejected: the fix was not applied as a measurement.
  UpdateOutcome after_gnss(UpdateOutcome o, AidingKind kind, Nav& nav, const GnssFix<T>& fix,
                           const HistoryEntry<T>& at) {
    std::uint32_t& run = gnss_rejected_run_[kind == AidingKind::kGnssPosition ? 0 : 1];
    if (o.status != UpdateStatus::kRejected) {
      run = 0;
      return o;
    }
    if (config_.gnss_lockout_fixes == 0 || ++run < config_.gnss_lockout_fixes) return o;
    run = 0;
    ++counters_.gnss_lockout_resets;
    using namespace filt_idx;
    const StateMat p0 = initial_covariance();
    const T heading_var = std::max(p_(kPhi + 2, kPhi + 2), p0(kPhi + 2, kPhi + 2));
    const Vec3<T> pos_var = p_.template block<3, 3>(kPos, kPos).diagonal();
    const Vec3<T> vel_var = p_.template block<3, 3>(kVel, kVel).diagonal();
    p_ = p0;
    p_(kPhi + 2, kPhi + 2) = heading_var;
    const T l2 = config_.gnss_lever_arm_b.squaredNorm();
    const Vec3<T> fix_var = fix.sigma.cwiseProduct(fix.sigma);
    // The quantity kept first, then the one set from the fix with its correlations (set_at_fix).
    const FixAge now;
    const FixAge age = age_of(nav, fix.t_valid_ns);
    if (kind == AidingKind::kGnssPosition) {
      const Vec3<T> dr = at.r_n + at.q_nb * config_.gnss_lever_arm_b - fix.value_n;
      nav.apply_correction(Vec3<T>::Zero(), dr, Vec3<T>::Zero(), Vec3<T>::Zero());
      history_.shift(Vec3<T>::Zero(), dr, Vec3<T>::Zero());
      reset_block(kVel, vel_var.cwiseMax(p0.template block<3, 3>(kVel, kVel).diagonal()), now);
      reset_block(kPos, fix_var + Vec3<T>::Constant(l2), age);
    } else {
      // The array's velocity, as for a reset before the heading is known (P_ωω is P0's here).
      const Vec3<T> dv = at.v_n - array_velocity(fix, at);
      nav.apply_correction(Vec3<T>::Zero(), Vec3<T>::Zero(), dv, Vec3<T>::Zero());
      history_.shift(Vec3<T>::Zero(), Vec3<T>::Zero(), dv);
      reset_block(kPos, pos_var.cwiseMax(p0.template block<3, 3>(kPos, kPos).diagonal()), now);
      reset_block(kVel, array_velocity_variance(fix, at, true), age);
    }
    condition_covariance();
    return o;
  }

  /// Heading set directly (before alignment): dyaw = ψ̂ − ψ removed by the rotation about the
  /// down axis φ = [0, 0, −dyaw] (the yaw error is −φ_D, euler_error.hpp).
  void set_heading(Nav& nav, T dyaw, T sigma_rad, const FixAge& age) {
    const Vec3<T> phi(T(0), T(0), -dyaw);
    nav.apply_correction(phi, Vec3<T>::Zero(), Vec3<T>::Zero(), Vec3<T>::Zero());
    history_.shift(phi, Vec3<T>::Zero(), Vec3<T>::Zero());
    set_heading_variance(nav.state(), sigma_rad, age);
  }

  /// x: the state the heading is set at. The position gained while the heading was unknown points
  /// along the old heading: its variance for a heading error anywhere (accuracy()) goes into P
  /// before the heading is set, when the heading's decoupled variance stops standing for it.
  void set_heading_variance(const NavState<T>& x, T sigma_rad, const FixAge& age) {
    if (!heading_aligned_) {
      const T var = unknown_heading_pos_var(x);
      for (int i = 0; i < 2; ++i) p_(filt_idx::kPos + i, filt_idx::kPos + i) += var;
    }
    start_heading_legs(x.r_n);
    set_at_fix(filt_idx::kPhi + 2, sigma_rad * sigma_rad, age);
    heading_aligned_ = true;
    // The tilt stays lost: only a re-level finds it (relevel_from_gnss). An external heading
    // after a divergence restart says nothing about a tilt tens of degrees off.
    lost_ &= static_cast<std::uint8_t>(~filter_valid::kHeading);
  }

  /// Per horizontal axis, the variance of a horizontal velocity v̂_h whose direction is off by a
  /// heading error anywhere (accuracy()): 1.5 |v̂_h|².
  static T unknown_heading_vel_var(const NavState<T>& x) {
    return T(1.5) * x.v_n.template head<2>().squaredNorm();
  }

  /// The same for the horizontal position: the displacement d since heading_anchor_r_ turns with
  /// the heading error, 1.5 |d_h|² per axis for one leg. Legs driven along different heading
  /// errors (heading_legs_m_) add up by length: the per-axis error is a sum of the legs' errors,
  /// and by Minkowski's inequality its RMS is at most the sum of theirs, √1.5 Σ|d_k,h|, whatever
  /// the correlation of the heading errors (docs/math.md).
  T unknown_heading_pos_var(const NavState<T>& x) const {
    const T d = heading_legs_m_ + (x.r_n - heading_anchor_r_).template head<2>().norm();
    return T(1.5) * d * d;
  }

  /// The heading changes while it stays unknown (a restart, a re-level's turn about down): the leg
  /// driven since the anchor keeps its heading's error, the next one gets another.
  void close_heading_leg(const NavState<T>& x) {
    heading_legs_m_ += (x.r_n - heading_anchor_r_).template head<2>().norm();
    heading_anchor_r_ = x.r_n;
  }

  /// The displacement with an unknown heading counts from r on (the start; the position or the
  /// heading set).
  void start_heading_legs(const Vec3<T>& r) {
    heading_anchor_r_ = r;
    heading_legs_m_ = T(0);
  }

  /// While the heading is unknown its error is a nuisance of variance π² outside the linear
  /// model: its correlations are dropped so no update moves it or is moved by it.
  void decouple_heading() {
    constexpr int kD = filt_idx::kPhi + 2;
    set_uncorrelated(kD, p_(kD, kD));
  }

  /// Symmetrise, floor the diagonal, and reset to P0 on a non-finite value or a negative
  /// diagonal (counted): the filter never NaNs out.
  void condition_covariance() {
    p_ = ((p_ + p_.transpose()) / T(2)).eval();
    bool bad = !p_.allFinite();
    for (int i = 0; i < kStates && !bad; ++i) {
      if (p_(i, i) < T(0)) bad = true;
      if (p_(i, i) < config_.variance_floor) p_(i, i) = config_.variance_floor;
    }
    if (bad) {
      p_ = initial_covariance();
      ++counters_.covariance_resets;
    }
  }

  FilterConfig<T> config_{};
  StateMat p_ = StateMat::Zero();
  Mat6<T> p0_bias_ = Mat6<T>::Zero();  // initial covariance of the 6-D bias, M diag(σ_b²) Mᵀ
  NavHistory<T, HistoryCapacity> history_{};
  FilterCounters counters_{};
  std::array<std::int64_t, kAidingKinds> last_accepted_ns_{};
  std::array<std::uint32_t, 2> gnss_rejected_run_{};  // consecutive rejections: position, velocity
  T gate_1_ = T(0);
  T gate_3_ = T(0);
  bool configured_ = false;
  bool started_ = false;
  bool heading_aligned_ = true;
  // While the heading is unknown: the position from which the board's displacement is along a
  // heading that may be off by any angle (the start, a restart, a re-level's turn about down, the
  // last GNSS position reset). The displacement since it, and the legs closed before it since the
  // position or the heading was last set, add to the position variance (accuracy()).
  Vec3<T> heading_anchor_r_ = Vec3<T>::Zero();
  // The horizontal lengths of the legs closed since then, each driven along its own unknown
  // heading (unknown_heading_pos_var()).
  T heading_legs_m_ = T(0);
  // filter_valid bits of the quantities whose σ are not available: after a divergence restart
  // the covariance no longer describes their errors (the linear model had failed before the test
  // fired, and the restart widens the attitude and rate only). Each comes back when a fix sets
  // it again: position and velocity with an accepted GNSS fix (or a ZUPT), the attitude with the
  // heading alignment that follows (the GNSS track or an external heading).
  std::uint8_t lost_ = 0;
  // The heading is the GNSS track's (an in-motion start), not unknown (a divergence restart): the
  // re-level then corrects the tilt alone (relevel_from_gnss).
  bool heading_from_track_ = false;
  // The previous usable GNSS velocity fix (relevel_from_gnss), kNever when none.
  Vec3<T> prev_vel_n_ = Vec3<T>::Zero();
  std::int64_t prev_vel_t_ns_ = kNever;
};

// ---- ErrorStateFilter: member functions defined outside the class, so not inline: a translation
// unit that uses the extern instantiation below calls them instead of instantiating them again to
// inline them (nav_core/src instantiates each once per scalar type).

template <typename T, int HistoryCapacity>
void ErrorStateFilter<T, HistoryCapacity>::forget(Nav& nav, bool divergence) {
  using namespace filt_idx;
  if (divergence) ++counters_.divergence_restarts;
  heading_from_track_ = !divergence;
  const NavState<T>& x = nav.state();
  const Vec3<T> dw = x.w_b.allFinite() ? x.w_b : Vec3<T>::Zero();
  nav.apply_correction(Vec3<T>::Zero(), Vec3<T>::Zero(), Vec3<T>::Zero(), dw);
  // The heading was unknown already: the displacement since the anchor keeps its error, and the
  // heading after the restart is another unknown one (accuracy()).
  if (heading_aligned_) {
    start_heading_legs(x.r_n);
  } else {
    close_heading_leg(x);
  }
  const Vec3<T> pos_var = p_.template block<3, 3>(kPos, kPos).diagonal();
  const Vec3<T> vel_var = p_.template block<3, 3>(kVel, kVel).diagonal();
  p_ = initial_covariance();
  // Half the limit: the restart must leave room before the test fires again.
  const T tilt2 = config_.diverged_sigma_tilt_rad * config_.diverged_sigma_tilt_rad / T(4);
  constexpr T kPi = T(3.14159265358979323846);
  p_(kPhi, kPhi) = tilt2;
  p_(kPhi + 1, kPhi + 1) = tilt2;
  p_(kPhi + 2, kPhi + 2) = kPi * kPi;
  heading_aligned_ = false;
  prev_vel_t_ns_ = kNever;  // a velocity difference across the diverged stretch means nothing
  lost_ = filter_valid::kRollPitch | filter_valid::kHeading | filter_valid::kVelocity |
          filter_valid::kPosition;
  const T rate2 = config_.restart_sigma_rate_rps * config_.restart_sigma_rate_rps;
  const T xy = divergence ? config_.restart_sigma_rate_rps : config_.in_motion_sigma_tilt_rate_rps;
  for (int i = 0; i < 3; ++i) {
    p_(kRate + i, kRate + i) = i < 2 ? xy * xy : rate2;
    p_(kPos + i, kPos + i) = std::max(p_(kPos + i, kPos + i), pos_var(i));
    p_(kVel + i, kVel + i) = std::max(p_(kVel + i, kVel + i), vel_var(i));
  }
  if (!p_.allFinite()) p_ = initial_covariance();
  gnss_rejected_run_.fill(0);
}

template <typename T, int HistoryCapacity>
void ErrorStateFilter<T, HistoryCapacity>::start(Nav& nav) {
  // Random-constant per-sensor biases seen through the solve: M diag(σ_b²) Mᵀ.
  p0_bias_ = Model(nav.solver(), nav.gravity()).array_noise(config_.noise.bias_sigma_mps2, T(1));
  p_ = initial_covariance();
  nav.set_bias(Vec3<T>::Zero(), Vec3<T>::Zero());
  history_.clear();
  history_.push(nav.state());
  heading_aligned_ = config_.heading_known;
  start_heading_legs(nav.state().r_n);
  last_accepted_ns_.fill(kNever);
  gnss_rejected_run_.fill(0);
  lost_ = 0;
  prev_vel_t_ns_ = kNever;
  started_ = configured_;
}

template <typename T, int HistoryCapacity>
typename ErrorStateFilter<T, HistoryCapacity>::StateMat
ErrorStateFilter<T, HistoryCapacity>::initial_covariance() const {
  using namespace filt_idx;
  StateMat p = StateMat::Zero();
  const T tilt2 = config_.init_sigma_tilt_rad * config_.init_sigma_tilt_rad;
  constexpr T kPi = T(3.14159265358979323846);
  p(kPhi, kPhi) = tilt2;
  p(kPhi + 1, kPhi + 1) = tilt2;
  p(kPhi + 2, kPhi + 2) = config_.heading_known
                              ? config_.init_sigma_heading_rad * config_.init_sigma_heading_rad
                              : kPi * kPi;
  for (int i = 0; i < 3; ++i) {
    p(kPos + i, kPos + i) = config_.init_sigma_pos_m * config_.init_sigma_pos_m;
    p(kVel + i, kVel + i) = config_.init_sigma_vel_mps * config_.init_sigma_vel_mps;
    p(kRate + i, kRate + i) = config_.init_sigma_rate_rps * config_.init_sigma_rate_rps;
  }
  p.template block<6, 6>(kBiasWdot, kBiasWdot) = p0_bias_;
  return p;
}

template <typename T, int HistoryCapacity>
void ErrorStateFilter<T, HistoryCapacity>::process_model(const Nav& strapdown, StateMat& f,
                                                         StateMat& qc) const {
  using namespace filt_idx;
  const Model model(strapdown.solver(), strapdown.gravity());
  transition_model(strapdown, f);
  const auto g = f.template block<err_idx::kNav, 6>(0, kBiasWdot);  // a view, not a copy
  qc.setZero();
  const Mat6<T> noise_u =
      model.array_noise(config_.noise.white_sigma_mps2, T(1) / config_.sample_rate_hz);
  qc.template topLeftCorner<err_idx::kNav, err_idx::kNav>() =
      g.lazyProduct(noise_u).lazyProduct(g.transpose());
  qc.template block<6, 6>(kBiasWdot, kBiasWdot) =
      model.array_noise(config_.noise.bias_rw_mps2_sqrt_s, T(1));
}

template <typename T, int HistoryCapacity>
Vec3<T> ErrorStateFilter<T, HistoryCapacity>::array_velocity(const GnssFix<T>& fix,
                                                             const HistoryEntry<T>& at) const {
  return fix.value_n - at.q_nb * at.w_b.cross(config_.gnss_lever_arm_b);
}

template <typename T, int HistoryCapacity>
void ErrorStateFilter<T, HistoryCapacity>::transition_model(const Nav& strapdown,
                                                            StateMat& f) const {
  using namespace filt_idx;
  const NavState<T>& nav = strapdown.state();
  const Model model(strapdown.solver(), strapdown.gravity());
  f.setZero();
  // Loops: Eigen's block assignments unroll into one load and store per element at -Os.
  const typename Model::NavMat fn = model.navigation_continuous(nav);
  const typename Model::NavInputMat g = model.array_input_matrix(nav);
  for (int r = 0; r < err_idx::kNav; ++r) {
    for (int c = 0; c < err_idx::kNav; ++c) f(r, c) = fn(r, c);
    for (int c = 0; c < 6; ++c) f(r, kBiasWdot + c) = g(r, c);
  }
}

template <typename T, int HistoryCapacity>
void ErrorStateFilter<T, HistoryCapacity>::refer_to_now(T* h, int rows, const Nav& strapdown,
                                                        std::int64_t t_valid_ns) const {
  // The error at t_v is Φ⁻¹ x_now (the process noise over Δt, a few ms of array noise, is left
  // out). Φ ≈ I matters: an in-motion start leaves δω at the vehicle's turn rate, 0.3 rad/s, and
  // 100 ms later φ has moved by 0.03 rad and δv by |f| φ Δt; with Φ ≈ I the published σ of the
  // first ten seconds were optimistic (tests/nav_core/pipeline_in_motion_long.cpp).
  const T dt = from_int64<T>(strapdown.state().t_ns - t_valid_ns) * T(1e-9);
  if (!(dt > T(0))) return;
  StateMat f;
  transition_model(strapdown, f);
  // hf = H F, then H ← H − Δt hf + Δt²/2 hf F. Loops, not Eigen products: one body for M = 1
  // and 3 in the image.
  T hf[3 * kStates];
  const auto mult = [&](const T* a, T* out) {  // out = a F (rows × kStates, column-major)
    for (int c = 0; c < kStates; ++c) {
      for (int r = 0; r < rows; ++r) {
        T sum = T(0);
        for (int k = 0; k < kStates; ++k) sum += a[k * rows + r] * f(k, c);
        out[c * rows + r] = sum;
      }
    }
  };
  mult(h, hf);
  T hff[3 * kStates];
  mult(hf, hff);
  for (int i = 0; i < rows * kStates; ++i) h[i] += -dt * hf[i] + dt * dt / T(2) * hff[i];
}

template <typename T, int HistoryCapacity>
Status ErrorStateFilter<T, HistoryCapacity>::propagate(const Nav& strapdown, T dt_s) {
  if (!started_) return Status(ErrorCode::kFailedPrecondition, "filter: not started");
  if (!(dt_s > T(0)) || !std::isfinite(dt_s)) {
    return Status(ErrorCode::kInvalidArgument, "filter: dt_s must be positive");
  }
  const NavState<T>& nav = strapdown.state();
  const T h = dt_s;
  StateMat f;
  StateMat qc;
  process_model(strapdown, f, qc);
  // Van Loan's series to h³ (error_model.hpp): Q_d = Q_c h + (F Q_c + Q_c Fᵀ) h²/2 +
  // F Q_c Fᵀ h³/3; Φ = I + F h + F² h²/2; P ← Φ P Φᵀ + Q_d. Every product has F or Φ on the
  // left and is block-sparse (block_sparse.hpp); a product with them on the right is taken as
  // the transpose of one on the left (Q_c and P are symmetric: Q_c Fᵀ = (F Q_c)ᵀ, and
  // Φ P Φᵀ = Φ (Φ P)ᵀ). Q_d is built in the storage of Q_c and Φ in that of F.
  StateMat tmp;
  StateMat tmp2;
  blocks::multiply(kFMask, f.data(), qc.data(), tmp.data());  // F Q_c
  qc = qc * h + (tmp + tmp.transpose()) * (h * h / T(2));
  tmp.transposeInPlace();                                       // Q_c Fᵀ
  blocks::multiply(kFMask, f.data(), tmp.data(), tmp2.data());  // F Q_c Fᵀ
  qc += tmp2 * (h * h * h / T(3));
  blocks::multiply(kFMask, f.data(), f.data(), tmp2.data());    // F²
  f = StateMat::Identity() + f * h + tmp2 * (h * h / T(2));     // Φ
  blocks::multiply(kPhiMask, f.data(), p_.data(), tmp.data());  // Φ P
  tmp.transposeInPlace();                                       // P Φᵀ
  blocks::multiply(kPhiMask, f.data(), tmp.data(), p_.data());  // Φ P Φᵀ
  p_ += qc;
  if (!heading_aligned_) decouple_heading();
  condition_covariance();
  history_.push(nav);
  ++counters_.propagations;
  return Status::ok();
}

template <typename T, int HistoryCapacity>
UpdateOutcome ErrorStateFilter<T, HistoryCapacity>::update_zupt(Nav& nav) {
  if (!started_) return invalid(AidingKind::kZupt);
  return apply(zupt_measurement(nav.state(), config_.zupt_sigma_mps), AidingKind::kZupt, gate_3_,
               nav, nav.state().t_ns);
}

template <typename T, int HistoryCapacity>
UpdateOutcome ErrorStateFilter<T, HistoryCapacity>::update_zaru(Nav& nav) {
  if (!started_) return invalid(AidingKind::kZaru);
  return apply(zaru_measurement(nav.state(), config_.zaru_sigma_rps), AidingKind::kZaru, gate_3_,
               nav, nav.state().t_ns);
}

template <typename T, int HistoryCapacity>
UpdateOutcome ErrorStateFilter<T, HistoryCapacity>::relevel_at_rest(Nav& nav,
                                                                    const Vec3<T>& f_mean_b,
                                                                    T var_f_mean) {
  using namespace filt_idx;
  // The window's f̄ is the strapdown's, taken with the centripetal term of its rate ω̂, which the
  // re-level sets to zero: levelled on f̄ as it was, the board would then see a horizontal
  // K_f m(ω̂) (ρ|ω̂|²: 0.6° of tilt at 1 rad/s on Table 1) that P does not hold. f at ω = 0:
  const Vec3<T> f0 =
      f_mean_b + (nav.solver().k() * centripetal_monomials(nav.state().w_b)).template tail<3>();
  const T g2 = f0.squaredNorm();
  if (!started_ || !relevel_wanted() || !f0.allFinite() || !(g2 > T(0)) || !(var_f_mean >= T(0))) {
    return invalid(AidingKind::kZupt);
  }
  const T vel_var = config_.zupt_sigma_mps * config_.zupt_sigma_mps;
  // The ZUPT's own innovation test, unless the velocity is lost: a straight drive at constant
  // speed reads like rest to accelerometers, and the filter's own velocity tells them apart.
  float nis = 0.0F;
  if ((lost_ & filter_valid::kVelocity) == 0) {
    Eigen::Matrix<T, kStates, 3> pht;
    Mat3<T> s_inv;
    const UpdateOutcome tested =
        innovation_test(zupt_measurement(nav.state(), config_.zupt_sigma_mps), AidingKind::kZupt,
                        gate_3_, pht, s_inv);
    if (tested.status != UpdateStatus::kAccepted) return tested;
    nis = tested.nis;
  }
  if (!turn_onto(nav, nav.state().q_nb * f0, Vec3<T>(T(0), T(0), T(-1)), true, true)) {
    return invalid(AidingKind::kZupt);
  }
  const Vec3<T> dv = nav.state().v_n;
  const Vec3<T> dw = nav.state().w_b;
  nav.apply_correction(Vec3<T>::Zero(), Vec3<T>::Zero(), dv, dw);
  history_.shift(Vec3<T>::Zero(), Vec3<T>::Zero(), dv);
  const T rate_var = config_.zaru_sigma_rps * config_.zaru_sigma_rps;
  for (int i = 0; i < 3; ++i) {
    set_uncorrelated(kVel + i, vel_var);
    set_uncorrelated(kRate + i, rate_var);
  }
  // The level absorbs the bias: at rest the filter's own model then gives no horizontal δv̇,
  // F_vφ φ_h + F_vβ δβ = 0 (rows N, E; φ_D does not enter them with f vertical), so
  // φ_h = A δβ + n with A = −F_vφ,h⁻¹ F_vβ, n the window mean's noise (σ_f²/W / |f̄|² per axis).
  // Taking φ uncorrelated with δβ instead let the ZUPTs that follow, which see g φ + δβ, narrow
  // the tilt σ below its error (1/1.4 of it over a long stop).
  StateMat f;
  transition_model(nav, f);
  Eigen::Matrix<T, 2, 2> fvp;
  Eigen::Matrix<T, 2, 6> fvb;
  for (int r = 0; r < 2; ++r) {
    for (int c = 0; c < 2; ++c) fvp(r, c) = f(kVel + r, kPhi + c);
    for (int c = 0; c < 6; ++c) fvb(r, c) = f(kVel + r, kBiasWdot + c);
  }
  // F_vφ,h is ±|f̄| times a rotation at rest (f vertical after the level); should it ever not be
  // invertible the tilt is taken uncorrelated, with the largest f-bias variance added instead.
  const bool coupled = std::abs(fvp.determinant()) > T(1e-6) * g2;
  const Eigen::Matrix<T, 2, 6> a =
      coupled ? Eigen::Matrix<T, 2, 6>(-fvp.inverse() * fvb) : Eigen::Matrix<T, 2, 6>::Zero();
  const T noise_var =
      (var_f_mean +
       (coupled ? T(0) : p_.template block<3, 3>(kBiasF, kBiasF).diagonal().maxCoeff())) /
      g2;
  // Rows of the tilt: A times the bias rows (the tilt's own columns last, from those rows).
  T row[2][kStates];
  for (int i = 0; i < 2; ++i) {
    for (int j = 0; j < kStates; ++j) {
      T sum = T(0);
      for (int k = 0; k < 6; ++k) sum += a(i, k) * p_(kBiasWdot + k, j);
      row[i][j] = sum;
    }
  }
  for (int i = 0; i < 2; ++i) {
    for (int l = 0; l < 2; ++l) {
      T sum = T(0);
      for (int k = 0; k < 6; ++k) sum += row[i][kBiasWdot + k] * a(l, k);
      row[i][kPhi + l] = sum + (i == l ? noise_var : T(0));
    }
  }
  for (int i = 0; i < 2; ++i) {
    for (int j = 0; j < kStates; ++j) {
      p_(kPhi + i, j) = row[i][j];
      p_(j, kPhi + i) = row[i][j];
    }
  }
  lost_ &= static_cast<std::uint8_t>(~filter_valid::kRollPitch);
  ++counters_.rest_relevels;
  UpdateOutcome out = accepted_reset(AidingKind::kZupt, nav);
  out.nis = nis;
  return out;
}

template <typename T, int HistoryCapacity>
UpdateOutcome ErrorStateFilter<T, HistoryCapacity>::update_gnss_position(Nav& nav,
                                                                         const GnssFix<T>& fix) {
  HistoryEntry<T> at;
  if (!fix_usable(nav, fix, at)) return invalid(AidingKind::kGnssPosition);
  if (!heading_aligned_) return reset_position(nav, fix, at);
  const UpdateOutcome o = apply(gnss_position_measurement(at, config_.gnss_lever_arm_b, fix),
                                AidingKind::kGnssPosition, gate_3_, nav, fix.t_valid_ns);
  return after_gnss(o, AidingKind::kGnssPosition, nav, fix, at);
}

template <typename T, int HistoryCapacity>
UpdateOutcome ErrorStateFilter<T, HistoryCapacity>::update_gnss_velocity(Nav& nav,
                                                                         const GnssFix<T>& fix) {
  HistoryEntry<T> at;
  if (!fix_usable(nav, fix, at)) return invalid(AidingKind::kGnssVelocity);
  // A lost tilt is re-levelled first (relevel_from_gnss), with the heading unknown or known (a
  // heading fix came first after a restart: it is kept); the state at the fix is read again.
  const Relevel relevel = relevel_from_gnss(nav, fix, at, age_of(nav, fix.t_valid_ns));
  if (relevel == Relevel::kDone) (void)history_.at(fix.t_valid_ns, nav.state(), at);
  UpdateOutcome out;
  if (!heading_aligned_) {
    out = reset_velocity_and_track(nav, fix, at, relevel);
  } else {
    const UpdateOutcome o = apply(gnss_velocity_measurement(at, config_.gnss_lever_arm_b, fix),
                                  AidingKind::kGnssVelocity, gate_3_, nav, fix.t_valid_ns);
    out = after_gnss(o, AidingKind::kGnssVelocity, nav, fix, at);
    if (config_.track_heading_sigma_rad > T(0)) {
      // The history entry was shifted by the velocity update's feedback: read it again.
      HistoryEntry<T> now_at;
      if (history_.at(fix.t_valid_ns, nav.state(), now_at))
        (void)update_track_heading(nav, fix, now_at);
    }
  }
  prev_vel_n_ = fix.value_n;  // relevel_from_gnss
  prev_vel_t_ns_ = fix.t_valid_ns;
  return out;
}

template <typename T, int HistoryCapacity>
UpdateOutcome ErrorStateFilter<T, HistoryCapacity>::update_heading(Nav& nav,
                                                                   const HeadingFix<T>& fix) {
  HistoryEntry<T> at;
  if (!started_ || !std::isfinite(fix.yaw_rad) || !(fix.sigma_rad > T(0)) ||
      !std::isfinite(fix.sigma_rad) || !history_.at(fix.t_valid_ns, nav.state(), at)) {
    return invalid(AidingKind::kHeading);
  }
  const Measurement<T, 1> m = heading_measurement(at.q_nb, fix.yaw_rad, fix.sigma_rad);
  if (!heading_aligned_) {
    // The horizontal velocity gained while the heading was unknown points along the old heading:
    // its variance for a heading error anywhere (accuracy()) goes into P before the heading is
    // set, when the heading's decoupled variance stops standing for it.
    const T var = unknown_heading_vel_var(nav.state());
    for (int i = 0; i < 2; ++i) p_(filt_idx::kVel + i, filt_idx::kVel + i) += var;
    set_heading(nav, m.y(0), fix.sigma_rad, age_of(nav, fix.t_valid_ns));
    return accepted_reset(AidingKind::kHeading, nav);
  }
  return apply(m, AidingKind::kHeading, gate_1_, nav, fix.t_valid_ns);
}

template <typename T, int HistoryCapacity>
NavAccuracy<T> ErrorStateFilter<T, HistoryCapacity>::accuracy(const NavState<T>& nav) const {
  using namespace filt_idx;
  NavAccuracy<T> a;
  const Mat3<T> j = euler_error_jacobian(nav.q_nb);
  const Mat3<T> ce = j * p_.template block<3, 3>(kPhi, kPhi) * j.transpose();
  // While the heading is unknown (variance π², decoupled: outside the linear model) so is the
  // direction of the horizontal velocity the board has gained since it was last set (a ZUPT at
  // rest, a GNSS fix): v = R(δψ) v̂ with δψ uniform, E|v̂ − v|² = 2 |v̂_h|², 1.5 |v̂_h|² along the
  // track and 0.5 |v̂_h|² across it, so 1.5 |v̂_h|² per axis is added (the whole v̂_h, not the part
  // gained since the last fix: wider after a GNSS velocity fix). Without it the N and E σ of a
  // board that re-levelled at a stop and drove off stayed at the ZUPT's while its velocity turned
  // with the heading error. The position likewise: 1.5 |r̂_h − r_anchor,h|² per axis for the
  // displacement since the last point the position was set or the heading lost.
  const T heading_vel_var = heading_aligned_ ? T(0) : unknown_heading_vel_var(nav);
  const T heading_pos_var = heading_aligned_ ? T(0) : unknown_heading_pos_var(nav);
  for (int i = 0; i < 3; ++i) {
    a.euler_sigma_rad(i) = std::sqrt(ce(i, i));
    a.vel_sigma_mps(i) = std::sqrt(p_(kVel + i, kVel + i) + (i < 2 ? heading_vel_var : T(0)));
    a.pos_sigma_m(i) = std::sqrt(p_(kPos + i, kPos + i) + (i < 2 ? heading_pos_var : T(0)));
  }
  constexpr T kNotAvailable = std::numeric_limits<T>::quiet_NaN();
  if (!started_) {  // nothing estimated yet: no σ, not a zero one
    a.euler_sigma_rad.setConstant(kNotAvailable);
    a.vel_sigma_mps.setConstant(kNotAvailable);
    a.pos_sigma_m.setConstant(kNotAvailable);
    return a;
  }
  if ((lost_ & filter_valid::kRollPitch) != 0) a.euler_sigma_rad.setConstant(kNotAvailable);
  if ((lost_ & filter_valid::kVelocity) != 0) a.vel_sigma_mps.setConstant(kNotAvailable);
  if ((lost_ & filter_valid::kPosition) != 0) a.pos_sigma_m.setConstant(kNotAvailable);
  // A NaN σ fails every comparison below: the quantity is not valid.
  const bool aligned = started_ && (nav.status & nav_status::kAligned) != 0;
  const bool located = aligned && heading_aligned_;
  if (aligned && a.euler_sigma_rad.template head<2>().maxCoeff() <= config_.valid_sigma_tilt_rad) {
    a.valid |= filter_valid::kRollPitch;
  }
  if (located && a.euler_sigma_rad(2) <= config_.valid_sigma_heading_rad) {
    a.valid |= filter_valid::kHeading;
  }
  if (located && a.vel_sigma_mps.maxCoeff() <= config_.valid_sigma_vel_mps) {
    a.valid |= filter_valid::kVelocity;
  }
  if (located && a.pos_sigma_m.maxCoeff() <= config_.valid_sigma_pos_m) {
    a.valid |= filter_valid::kPosition;
  }
  if (recent(AidingKind::kZupt, nav.t_ns) || recent(AidingKind::kZaru, nav.t_ns)) {
    a.mode |= filter_mode::kStandstill;
  }
  if (recent(AidingKind::kGnssPosition, nav.t_ns) || recent(AidingKind::kGnssVelocity, nav.t_ns)) {
    a.mode |= filter_mode::kGnss;
  }
  if (recent(AidingKind::kHeading, nav.t_ns)) a.mode |= filter_mode::kHeading;
  return a;
}

extern template class ErrorStateFilter<float>;
extern template class ErrorStateFilter<double>;

}  // namespace gfins::nav
