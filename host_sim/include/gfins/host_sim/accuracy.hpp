// Navigation accuracy of one run against its truth, accumulated sample by sample (a streamed run
// keeps no series): the errors at chosen instants, RMS over the run after a settling time, the
// worst errors, the errors inside and after chosen windows (GNSS outages), and, when the aiding
// filter runs, how often each error lies within 3σ of the filter's own covariance (the
// consistency a user relies on when reading the σ off the bus). docs/navigation-accuracy.md.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "gfins/host_sim/scenario.hpp"

namespace gfins::sim {

/// The errors of one sample, in the units a user reads (degrees, m/s, m).
struct ErrorSnapshot {
  double t_s = 0;
  double tilt_deg = 0;     // max(|roll error|, |pitch error|)
  double heading_deg = 0;  // |heading error|
  double vel_mps = 0;      // |velocity error| (3-D)
  double pos_h_m = 0;      // horizontal position error
  double pos_v_m = 0;      // |down position error|
  bool seen = false;       // a sample at or after the instant was seen
};

/// The nine error components compared with 3σ: roll, pitch, heading, v N/E/D, r N/E/D.
inline constexpr std::size_t kConsistencyComponents = 9;
extern const std::array<const char*, kConsistencyComponents> kConsistencyNames;

/// How often each component's error lies within 3σ, over the samples that published that
/// component's σ (a σ the filter marks not available, NaN, is not counted: the quantity was
/// marked not available, which is what a user reading it sees).
class Coverage {
 public:
  void add(const std::array<double, kConsistencyComponents>& err,
           const std::array<double, kConsistencyComponents>& sigma);
  /// Samples offered, with or without σ.
  std::uint64_t offered() const { return all_; }
  /// Samples that published at least one σ.
  std::uint64_t samples() const { return any_; }
  /// Samples that published the σ of `component`.
  std::uint64_t published(std::size_t component) const;
  /// within / published for `component` (NaN when none was published).
  double fraction(std::size_t component) const;

 private:
  std::uint64_t all_ = 0;
  std::uint64_t any_ = 0;
  std::array<std::uint64_t, kConsistencyComponents> n_{};
  std::array<std::uint64_t, kConsistencyComponents> within_{};
};

/// The standstill detector's decisions against the truth, per window (docs/math.md,
/// "Standstill detection"): a window is at rest when the truth has zero velocity and zero rate
/// at every one of its samples, else it moves; it moves "like rest" when the body's kinematic
/// acceleration stays within kLikeRestAccel of the window's first sample and its angular
/// acceleration below kLikeRestWdot (a straight drive or a steady or slowly changing turn at
/// constant speed: every sensor's output constant, as at rest, which no accelerometer statistic
/// can tell apart; the ZUPT's gate and the GNSS veto handle it). A false alarm is a rest window
/// declared moving (the configured false_alarm is its probability); a missed detection is a moving
/// window declared at rest.
class DetectorTally {
 public:
  /// One sample's noise of the QA-1100 model (70 µg) and the per-sample σ of the array's ω̇ at
  /// ρ = 0.1 m (docs/math.md, "Standstill detection"): below these a change is not visible.
  static constexpr double kLikeRestAccel = 70e-6 * 9.80665;  // m/s²
  static constexpr double kLikeRestWdot = 5e-3;              // rad/s²

  void add(const SampleRecord& x);
  std::uint64_t rest_windows() const { return rest_; }
  std::uint64_t false_alarms() const { return false_alarms_; }
  std::uint64_t moving_windows() const { return moving_; }
  std::uint64_t missed() const { return missed_; }
  std::uint64_t moving_like_rest() const { return like_rest_; }
  std::uint64_t missed_like_rest() const { return missed_like_rest_; }
  /// Rest stretches of the truth and those with at least one rest window declared at rest (the
  /// standstill updates reached that stop; the stretch before the filter starts counts too).
  std::uint64_t stops() const { return stops_; }
  std::uint64_t stops_seen() const { return stops_seen_; }
  /// Windows that hold both rest and motion (a stop's first or last window), judged neither way,
  /// and of them those declared at rest.
  std::uint64_t mixed_windows() const { return mixed_; }
  std::uint64_t mixed_declared_rest() const { return mixed_rest_; }

 private:
  std::uint32_t last_windows_ = 0;
  bool window_moves_ = false, window_rests_ = false, window_dynamic_ = false;
  bool window_first_ = true;
  Vec3d a_b0_ = Vec3d::Zero();
  std::uint64_t mixed_ = 0, mixed_rest_ = 0;
  bool in_stop_ = false, stop_seen_ = false;
  std::uint64_t rest_ = 0, false_alarms_ = 0, moving_ = 0, missed_ = 0;
  std::uint64_t like_rest_ = 0, missed_like_rest_ = 0, stops_ = 0, stops_seen_ = 0;
};

class AccuracyTracker {
 public:
  /// checkpoints_s: instants whose errors are kept (the first sample at or after each);
  /// rms_from_s: RMS and worst values over t ≥ this; windows: [start, end) spans (outages) whose
  /// worst error inside and error `after_s` past their end are kept.
  AccuracyTracker(std::vector<double> checkpoints_s, double rms_from_s,
                  const std::vector<std::pair<double, double>>& windows = {},
                  double after_s = 10.0);

  void add(const SampleRecord& x);

  const std::vector<ErrorSnapshot>& checkpoints() const { return at_; }
  double rms_from_s() const { return rms_from_s_; }
  std::uint64_t rms_samples() const { return n_; }
  double tilt_rms_deg() const;

  /// Roll and pitch each: the error's RMS and the filter's own 1σ RMS over the samples that
  /// published it (what its covariance predicts for that error, given the sensor model and the
  /// aiding), over t ≥ rms_from_s outside the windows and the after_s past each (all of t ≥
  /// rms_from_s without windows). NaN where there is no sample.
  struct RollPitch {
    double roll_rms_deg = 0, pitch_rms_deg = 0;
    double roll_sigma_rms_deg = 0, pitch_sigma_rms_deg = 0;
  };
  RollPitch roll_pitch() const;
  double heading_rms_deg() const;
  double vel_rms_mps() const;
  double pos_h_rms_m() const;
  /// The same RMS without the windows and the after_s past each (the error with GNSS), and the
  /// samples it covers (0 without windows: then it is the RMS above).
  std::uint64_t rms_outside_samples() const { return n_out_; }
  ErrorSnapshot rms_outside() const;
  const ErrorSnapshot& worst() const { return worst_; }  // each field its own worst (t: tilt's)

  struct Window {
    double start_s = 0, end_s = 0;
    ErrorSnapshot worst_inside;  // each field its own worst inside [start, end)
    ErrorSnapshot after;         // at end + after_s
    Coverage inside;             // 3σ coverage inside [start, end), t ≥ rms_from_s
  };
  const std::vector<Window>& windows() const { return windows_; }

  /// Samples (t ≥ rms_from_s) that carried the filter's σ, and of those that published each
  /// component's σ, the share with the error within 3σ.
  std::uint64_t sigma_samples() const { return coverage_.samples(); }
  double within_3sigma(std::size_t component) const { return coverage_.fraction(component); }
  const Coverage& coverage() const { return coverage_; }

  const DetectorTally& detector() const { return detector_; }

  /// One-line summaries for a terminal (what `gfins-sim aided` prints).
  std::string describe_rms() const;

 private:
  static ErrorSnapshot snapshot(const SampleRecord& x);
  static void keep_worst(ErrorSnapshot& w, const ErrorSnapshot& e);

  std::vector<double> checkpoints_s_;
  std::vector<ErrorSnapshot> at_;
  double rms_from_s_;
  double after_s_;
  std::vector<Window> windows_;
  std::uint64_t n_ = 0;
  double tilt2_ = 0, heading2_ = 0, vel2_ = 0, pos2_ = 0;
  std::uint64_t n_out_ = 0;
  double tilt2_out_ = 0, heading2_out_ = 0, vel2_out_ = 0, pos2_out_ = 0;
  ErrorSnapshot worst_{};
  Coverage coverage_;
  DetectorTally detector_;
  std::uint64_t rp_n_ = 0, rp_sigma_n_ = 0;
  double roll2_ = 0, pitch2_ = 0, roll_sigma2_ = 0, pitch_sigma2_ = 0;
};

}  // namespace gfins::sim
