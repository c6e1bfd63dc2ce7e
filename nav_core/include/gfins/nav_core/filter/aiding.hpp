// Aided navigation inside the pipeline: the error-state filter, the standstill detector and the
// decimation between them (docs/math.md, "Aided navigation: the error-state filter").
//
// Per integrated sample the pipeline calls after_step():
//   - the standstill detector takes the sample's [ω̇; f] (a decision every W samples);
//   - every D samples (FilterConfig's propagation interval, AidingConfig::decimation) the filter
//     propagates its covariance over the time since the previous propagation, and at the first
//     propagation after a detector decision of "at rest" it applies the zero-velocity update
//     (ZUPT) and, only when the ZUPT was accepted, the zero-rate update (ZARU), each through its
//     χ² gate: once per decision, about the window just seen; when the filter's tilt is lost or
//     past its validity horizon the decision re-levels the board from the window's mean specific
//     force instead (ErrorStateFilter::relevel_at_rest). Holding a decision over the next
//     window applied ZUPTs up to a window into the motion that ends a stop (the board starting
//     off, 0.15 m/s at 1.5 m/s² after 0.1 s, claimed 0 within the ZUPT's σ): the velocity σ was
//     optimistic after every stop (NEES 1.36 per state over 100 runs of urban-stop-and-go,
//     `gfins-sim consistency`; 1.0 once per decision). The
//     detector sees accelerometers only, and a straight drive at constant speed reads like rest
//     (constant specific force, no angular acceleration); the ZUPT's gate, against the filter's
//     own velocity, is what tells them apart. A ZARU alone would pass its gate through a gentle
//     turn at speed (a few mrad/s) and pull the rate to zero: it is vetoed with the ZUPT
//     (counted, motion_vetoes()). A GNSS velocity fix faster than
//     AidingConfig::gnss_moving_speed_mps vetoes both until the board is known to have slowed
//     (once the filter's velocity σ is large, as in an outage, the ZUPT's gate alone would let a
//     cruise at 30 m/s be set to zero).
// External aiding (GNSS position and velocity, heading) enters through the offer_*() calls with
// the measurement's own time of validity.
//
// Disabled (the default), nothing here runs and the per-sample path of the pipeline is the
// unaided one (one branch).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "gfins/nav_core/filter/error_state_filter.hpp"
#include "gfins/nav_core/filter/standstill_detector.hpp"
#include "gfins/nav_core/geometry.hpp"
#include "gfins/nav_core/integrator.hpp"
#include "gfins/status/status.hpp"

namespace gfins::nav {

template <typename T>
struct AidingConfig {
  bool enabled = false;
  std::uint32_t decimation = 10;  // filter propagation every D integrated samples (100 Hz at 1 kHz)
  bool standstill_updates = true;  // ZUPT + ZARU while the detector says "at rest"
  // A GNSS velocity fix faster than this (horizontal, m/s) says the board moves: no standstill
  // update, whatever the detector says, until a slower fix comes or the navigation's own
  // horizontal speed is below this by 2σ (it braked during an outage). A constant-speed straight
  // drive reads like rest to accelerometers, and once the filter's velocity σ has grown (an
  // outage) the ZUPT's own gate no longer refuses it.
  T gnss_moving_speed_mps = T(0.5);
  FilterConfig<T> filter{};
  StandstillConfig<T> standstill{};
};

template <typename T>
class Aiding {
 public:
  using Nav = Strapdown<T, kNumSensors>;

  /// Builds the filter and the detector for `solver` (the one the strapdown uses; the filter
  /// takes its process model from the strapdown at each propagation). Disabled: only remembers
  /// that. On failure nothing changes.
  [[nodiscard]] Status configure(const ArraySolver<T, kNumSensors>& solver,
                                 const AidingConfig<T>& config);

  bool enabled() const { return config_.enabled; }
  bool started() const { return started_; }

  /// At the end of alignment: the filter starts at the strapdown's solution.
  void start(Nav& nav);
  /// After start() at an in-motion alignment: the attitude, rate and heading unknown
  /// (ErrorStateFilter::lose_attitude); the GNSS fixes that follow align it.
  void lose_attitude(Nav& nav) {
    if (started_) filter_.lose_attitude(nav);
  }

  /// After each integrated sample (dt_s: the step it integrated, gaps included).
  void after_step(Nav& nav, T dt_s);

  UpdateOutcome offer_gnss_position(Nav& nav, const GnssFix<T>& fix);
  UpdateOutcome offer_gnss_velocity(Nav& nav, const GnssFix<T>& fix);
  UpdateOutcome offer_heading(Nav& nav, const HeadingFix<T>& fix);

  /// 1σ, mode and validity; only meaningful when started().
  NavAccuracy<T> accuracy(const NavState<T>& nav) const;
  /// The last standstill decision (false before the first window).
  bool at_rest() const { return still_; }
  const ErrorStateFilter<T>& filter() const { return filter_; }
  const StandstillDetector<T>& detector() const { return detector_; }
  const AidingConfig<T>& config() const { return config_; }
  std::uint32_t propagation_errors() const { return propagation_errors_; }
  /// Standstill decisions not applied because the board moves: vetoed by GNSS, or
  /// the ZUPT (or the re-level's velocity gate) was rejected (no ZARU then either).
  std::uint32_t motion_vetoes() const { return motion_vetoes_; }

 private:
  /// ‖mean ω̇‖ the detector allows at rest: 3σ of what the filter does not know of the ω̇ bias
  /// (the strapdown's ω̇ has the estimate removed) plus the window mean's own noise, per axis
  /// at its largest, times √3 for the norm of three axes.
  T wdot_tolerance() const {
    using namespace filt_idx;
    const auto& p = filter_.covariance();
    T var = T(0);
    for (int i = 0; i < 3; ++i) var = std::max(var, p(kBiasWdot + i, kBiasWdot + i));
    var += detector_.sigma2_wdot() / static_cast<T>(config_.standstill.window);
    return T(3) * std::sqrt(T(3) * var);
  }

  static UpdateOutcome not_started() { return UpdateOutcome{UpdateStatus::kInvalid, 0.0f}; }

  AidingConfig<T> config_{};
  ErrorStateFilter<T> filter_{};
  StandstillDetector<T> detector_{};
  std::uint32_t pending_ = 0;
  T pending_dt_s_ = T(0);
  bool still_ = false;
  bool fresh_ = false;  // a detector decision since the last propagation
  bool started_ = false;
  std::uint32_t propagation_errors_ = 0;
  std::uint32_t motion_vetoes_ = 0;
  bool moving_ = false;  // the last GNSS velocity fix said "moving" (AidingConfig)
};

// ---- Aiding: member functions defined outside the class, so not inline: a translation unit
// that uses the extern instantiation below calls them instead of instantiating them again
// to inline them (nav_core/src instantiates each once per scalar type).

template <typename T>
Status Aiding<T>::configure(const ArraySolver<T, kNumSensors>& solver,
                            const AidingConfig<T>& config) {
  if (!config.enabled) {
    config_ = config;
    started_ = false;
    return Status::ok();
  }
  if (config.decimation < 1 || config.decimation > 10000) {
    return Status(ErrorCode::kInvalidArgument, "aiding: decimation must be 1..10000 samples");
  }
  ErrorStateFilter<T> filter;
  const Status fs = filter.configure(config.filter);
  if (!fs.is_ok()) return fs;
  StandstillDetector<T> detector;
  const Status ds = detector.configure(solver, config.standstill);
  if (!ds.is_ok()) return ds;
  config_ = config;
  filter_ = filter;
  detector_ = detector;
  started_ = false;
  return Status::ok();
}

template <typename T>
void Aiding<T>::start(Nav& nav) {
  if (!config_.enabled) return;
  filter_.start(nav);
  detector_.reset();
  detector_.set_wdot_tolerance(wdot_tolerance());
  pending_ = 0;
  pending_dt_s_ = T(0);
  still_ = false;
  moving_ = false;
  started_ = true;
}

template <typename T>
void Aiding<T>::after_step(Nav& nav, T dt_s) {
  if (!started_) return;
  const NavState<T>& st = nav.state();
  if (detector_.add(st.wdot_b, st.f_b)) {
    still_ = detector_.at_rest();
    fresh_ = true;
    detector_.set_wdot_tolerance(wdot_tolerance());
  }
  pending_dt_s_ += dt_s;
  if (++pending_ < config_.decimation) return;
  // A decision is used at this propagation or dropped (a failed propagation, a restart): never
  // applied later, about samples it did not see.
  const bool fresh = fresh_;
  fresh_ = false;
  const Status s = filter_.propagate(nav, pending_dt_s_);
  pending_ = 0;
  pending_dt_s_ = T(0);
  if (!s.is_ok()) {
    ++propagation_errors_;
    return;
  }
  if (filter_.restart_if_diverged(nav)) return;
  if (moving_) {
    using namespace filt_idx;
    const auto& p = filter_.covariance();
    const T sigma_h = std::sqrt(std::max(p(kVel, kVel), p(kVel + 1, kVel + 1)));
    const T speed = nav.state().v_n.template head<2>().norm();
    if (speed + T(2) * sigma_h <= config_.gnss_moving_speed_mps) moving_ = false;
  }
  if (!fresh || !still_ || !config_.standstill_updates) return;
  if (moving_) {
    ++motion_vetoes_;
    return;
  }
  if (filter_.relevel_wanted()) {
    // No ZUPT brings a lost or far-off tilt back: the window's mean specific force levels it.
    const UpdateOutcome o = filter_.relevel_at_rest(
        nav, detector_.mean_f(), detector_.sigma2_f() / static_cast<T>(config_.standstill.window));
    if (o.status == UpdateStatus::kRejected) ++motion_vetoes_;
    return;
  }
  if (filter_.update_zupt(nav).status != UpdateStatus::kAccepted) {
    ++motion_vetoes_;
    return;
  }
  (void)filter_.update_zaru(nav);
}

template <typename T>
UpdateOutcome Aiding<T>::offer_gnss_position(Nav& nav, const GnssFix<T>& fix) {
  if (!started_) return not_started();
  return filter_.update_gnss_position(nav, fix);
}

template <typename T>
UpdateOutcome Aiding<T>::offer_gnss_velocity(Nav& nav, const GnssFix<T>& fix) {
  if (!started_) return not_started();
  if (fix.value_n.allFinite()) {
    moving_ = fix.value_n.template head<2>().norm() > config_.gnss_moving_speed_mps;
  }
  return filter_.update_gnss_velocity(nav, fix);
}

template <typename T>
UpdateOutcome Aiding<T>::offer_heading(Nav& nav, const HeadingFix<T>& fix) {
  if (!started_) return not_started();
  return filter_.update_heading(nav, fix);
}

template <typename T>
NavAccuracy<T> Aiding<T>::accuracy(const NavState<T>& nav) const {
  return filter_.accuracy(nav);
}

extern template class Aiding<float>;
extern template class Aiding<double>;

}  // namespace gfins::nav
