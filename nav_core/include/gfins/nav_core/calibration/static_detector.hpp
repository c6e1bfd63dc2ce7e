// Static-interval detector: turns a continuous recording of the board held in several poses into
// the per-pose means the multi-attitude solver needs (multi_attitude.hpp).
//
// Streaming and fixed memory (O(1) per sample, no sample buffer): the stream is cut into
// consecutive windows of window_s; each window's per-channel mean and variance are accumulated
// with Welford's update. Consecutive windows whose means stay within max_mean_step_v (plus 5σ of
// the window mean's own noise) of the pose (the mean of its still windows so far, or the previous
// window before the first still one) form a segment; a change beyond it is a motion and closes
// the segment. A window is still when every channel's standard deviation is at most max_std_v.
// When a segment closes it is classified:
//
//   shorter than min_pose_s                        → a transition, not reported;
//   no still window, or the span between its first
//     and last still windows has pooled std beyond
//     max_std_v on some channel                    → rejected pose, kTooNoisy;
//   still span shorter than min_still_s            → rejected pose, kTooShort;
//   otherwise                                      → a StaticInterval over that still span.
//
// Leading and trailing non-still windows, and trim_windows still windows at each end (the end of
// the motion into the pose and the start of the motion out of it, slow enough to look still),
// are left out of the interval, so its mean holds only settled samples. Boundaries are known to one
// window. A slow drift (creep) stays in one pose until it has moved the mean by max_mean_step_v;
// keep that at a few max_std_v (the default is 3×).
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>

#include "gfins/nav_core/calibration/multi_attitude.hpp"
#include "gfins/nav_core/geometry.hpp"
#include "gfins/status/status.hpp"

namespace gfins::calib {

inline constexpr std::size_t kDetectorChannels = 6;
inline constexpr std::uint32_t kMaxTrimWindows = 4;

template <typename T>
struct StaticDetectorConfig {
  T sample_rate_hz = T(0);  // Hz, > 0
  T window_s = T(0.1);      // variance window, s (≥ 2 samples)
  // Largest standard deviation of a still channel, V. Set it to about 2-3× the sensor noise in
  // volts (noise in g × SF).
  std::array<T, kDetectorChannels> max_std_v{};
  // Largest change of a window mean within one pose, V; 0 means 3 × max_std_v.
  std::array<T, kDetectorChannels> max_mean_step_v{};
  T min_still_s = T(2);   // a pose must be still at least this long to be used, s
  T min_pose_s = T(0.5);  // steady stretches shorter than this are transitions, s
  // Still windows dropped at each end of a pose (settling into it, starting to leave it):
  // 0..kMaxTrimWindows.
  std::uint32_t trim_windows = 1;
};

/// One still interval: samples [start_index, end_index) of the stream.
template <typename T>
struct StaticInterval {
  std::uint64_t start_index = 0;
  std::uint64_t end_index = 0;  // one past the last sample
  std::uint32_t count = 0;      // end_index − start_index
  std::array<T, kDetectorChannels> mean_v{};
  std::array<T, kDetectorChannels> std_v{};  // sample standard deviation per channel
};

enum class PoseRejection : std::uint8_t {
  kTooShort = 0,  // still, but for less than min_still_s
  kTooNoisy,      // steady mean, but a channel's std beyond max_std_v
};

const char* to_string(PoseRejection r);

/// A pose that was held but cannot be used, and why.
template <typename T>
struct RejectedPose {
  std::uint64_t start_index = 0;
  std::uint64_t end_index = 0;
  std::uint32_t count = 0;
  PoseRejection reason = PoseRejection::kTooShort;
  std::uint8_t noisy_channels = 0;  // bit c: channel c over max_std_v (kTooNoisy)
  std::array<T, kDetectorChannels> mean_v{};
  std::array<T, kDetectorChannels> std_v{};
};

/// Running mean and sum of squared deviations of six channels (Welford; Chan et al. to merge).
template <typename T>
struct ChannelMoments {
  std::uint32_t n = 0;
  std::array<T, kDetectorChannels> mean{};
  std::array<T, kDetectorChannels> m2{};

  void add(const std::array<T, kDetectorChannels>& x) {
    ++n;
    const T inv_n = T(1) / static_cast<T>(n);
    for (std::size_t c = 0; c < kDetectorChannels; ++c) {
      const T d = x[c] - mean[c];
      mean[c] += d * inv_n;
      m2[c] += d * (x[c] - mean[c]);
    }
  }
  void merge(const ChannelMoments& o) {
    if (o.n == 0) return;
    if (n == 0) {
      *this = o;
      return;
    }
    const T na = static_cast<T>(n);
    const T nb = static_cast<T>(o.n);
    const T nt = na + nb;
    for (std::size_t c = 0; c < kDetectorChannels; ++c) {
      const T d = o.mean[c] - mean[c];
      mean[c] += d * nb / nt;
      m2[c] += o.m2[c] + d * d * na * nb / nt;
    }
    n += o.n;
  }
  T std_dev(std::size_t c) const { return n > 1 ? std::sqrt(m2[c] / static_cast<T>(n - 1)) : T(0); }
};

template <typename T, std::size_t MaxIntervals = kMaxAttitudes, std::size_t MaxRejected = 32>
class StaticDetector {
 public:
  StaticDetector() = default;

  /// Fails with kInvalidArgument when the rate, durations or thresholds are not positive and
  /// finite, or the window is shorter than two samples.
  static Result<StaticDetector> create(const StaticDetectorConfig<T>& cfg) {
    if (!(cfg.sample_rate_hz > T(0)) || !std::isfinite(cfg.sample_rate_hz) ||
        !(cfg.window_s > T(0)) || !(cfg.min_still_s >= T(0)) || !(cfg.min_pose_s >= T(0)) ||
        cfg.trim_windows > kMaxTrimWindows) {
      return Status(ErrorCode::kInvalidArgument,
                    "static detector: rate, window and durations must be positive, trim_windows "
                    "at most kMaxTrimWindows");
    }
    StaticDetector d;
    d.cfg_ = cfg;
    for (std::size_t c = 0; c < kDetectorChannels; ++c) {
      if (!(cfg.max_std_v[c] > T(0)) || !std::isfinite(cfg.max_std_v[c]) ||
          !(cfg.max_mean_step_v[c] >= T(0))) {
        return Status(ErrorCode::kInvalidArgument,
                      "static detector: max_std_v must be positive for every channel");
      }
      if (cfg.max_mean_step_v[c] == T(0)) d.cfg_.max_mean_step_v[c] = T(3) * cfg.max_std_v[c];
    }
    const T window = std::round(cfg.window_s * cfg.sample_rate_hz);
    if (!(window >= T(2)) || !(window < T(1e9))) {
      return Status(ErrorCode::kInvalidArgument,
                    "static detector: window_s must span at least two samples");
    }
    d.window_n_ = static_cast<std::uint32_t>(window);
    d.min_still_n_ = static_cast<std::uint64_t>(std::ceil(cfg.min_still_s * cfg.sample_rate_hz));
    d.min_pose_n_ = static_cast<std::uint64_t>(std::ceil(cfg.min_pose_s * cfg.sample_rate_hz));
    return d;
  }

  /// Feeds one sample (V per channel). Non-finite samples end the current pose (they cannot be
  /// still). Returns kResourceExhausted when an interval or rejection had to be dropped because
  /// its list is full (the counts of dropped entries keep growing); ok otherwise.
  Status push(const std::array<T, kDetectorChannels>& v) {
    bool finite = true;
    for (const T x : v) finite = finite && std::isfinite(x);
    Status s = Status::ok();
    if (!finite) {
      // Discard the partial window and close the segment: the sample index still advances.
      window_ = {};
      s = close_segment();
      ++index_;
      window_start_ = index_;
      return s;
    }
    window_.add(v);
    ++index_;
    if (window_.n == window_n_) {
      s = end_window();
      window_ = {};
      window_start_ = index_;
    }
    return s;
  }

  /// Ends the recording: classifies the open pose (a partial last window is discarded).
  Status finish() {
    window_ = {};
    return close_segment();
  }

  std::span<const StaticInterval<T>> intervals() const { return {intervals_.data(), n_intervals_}; }
  std::span<const RejectedPose<T>> rejected() const { return {rejected_.data(), n_rejected_}; }
  std::uint64_t samples_seen() const { return index_; }
  std::uint32_t window_samples() const { return window_n_; }
  std::size_t dropped() const { return dropped_; }
  const StaticDetectorConfig<T>& config() const { return cfg_; }

 private:
  bool window_is_still(const ChannelMoments<T>& w) const {
    for (std::size_t c = 0; c < kDetectorChannels; ++c) {
      if (!(w.std_dev(c) <= cfg_.max_std_v[c])) return false;
    }
    return true;
  }

  // A window belongs to the pose when its mean differs from the pose's by no more than
  // max_mean_step_v plus what the window's own noise explains: 5σ of a difference of two means,
  // 5·√2·std/√n (a shaken pose must not fragment into "motions"; a turn's windows still differ by
  // their whole ramp step, about 25× this allowance).
  bool window_is_steady(const ChannelMoments<T>& w) const {
    const std::array<T, kDetectorChannels>& ref =
        still_all_.n > 0 ? still_all_.mean : last_window_mean_;
    const T k = T(7.07) / std::sqrt(static_cast<T>(w.n));
    for (std::size_t c = 0; c < kDetectorChannels; ++c) {
      if (!(std::abs(w.mean[c] - ref[c]) <= cfg_.max_mean_step_v[c] + k * w.std_dev(c))) {
        return false;
      }
    }
    return true;
  }

  Status end_window() {
    Status s = Status::ok();
    if (segment_n_ > 0 && !window_is_steady(window_)) s = close_segment();
    if (segment_n_ == 0) segment_start_ = window_start_;
    segment_n_ += window_.n;
    segment_all_.merge(window_);
    const std::uint64_t w_end = window_start_ + window_.n;
    if (window_is_still(window_)) {
      if (still_all_.n == 0) still_first_start_ = window_start_;
      still_all_.merge(window_);
      still_last_end_ = w_end;
      if (lead_skipped_ < cfg_.trim_windows) {
        ++lead_skipped_;  // may still hold the end of the motion into the pose
      } else {
        if (n_tail_ == cfg_.trim_windows) commit_oldest_tail();
        if (cfg_.trim_windows == 0) {
          commit(window_, window_start_, w_end, ChannelMoments<T>{});
        } else {
          tail_[n_tail_++] = TailEntry{window_, window_start_, w_end, ChannelMoments<T>{}};
        }
      }
    } else if (n_tail_ > 0) {
      tail_[n_tail_ - 1].after.merge(window_);
    } else if (core_.n > 0) {
      pending_.merge(window_);
    }
    last_window_mean_ = window_.mean;
    return s;
  }

  // The still windows of the tail may hold the start of the motion out of the pose; a window
  // joins the interval only once trim_windows newer still windows have followed it.
  void commit_oldest_tail() {
    const TailEntry e = tail_[0];
    for (std::size_t k = 1; k < n_tail_; ++k) tail_[k - 1] = tail_[k];
    --n_tail_;
    commit(e.still, e.start, e.end, e.after);
  }

  void commit(const ChannelMoments<T>& still, std::uint64_t start, std::uint64_t end,
              const ChannelMoments<T>& after) {
    if (core_.n == 0) core_start_ = start;
    core_.merge(pending_);  // non-still windows between two still ones belong to the pose
    core_.merge(still);
    core_end_ = end;
    pending_ = after;
  }

  Status close_segment() {
    Status s = Status::ok();
    if (segment_n_ >= min_pose_n_ && segment_n_ > 0) {
      if (still_all_.n == 0) {
        s = reject(segment_start_, segment_start_ + segment_n_, segment_all_,
                   PoseRejection::kTooNoisy);
      } else if (core_.n == 0) {
        s = reject(still_first_start_, still_last_end_, still_all_, PoseRejection::kTooShort);
      } else {
        bool noisy = false;
        for (std::size_t c = 0; c < kDetectorChannels; ++c) {
          noisy = noisy || !(core_.std_dev(c) <= cfg_.max_std_v[c]);
        }
        if (noisy) {
          s = reject(core_start_, core_end_, core_, PoseRejection::kTooNoisy);
        } else if (core_.n < min_still_n_) {
          s = reject(core_start_, core_end_, core_, PoseRejection::kTooShort);
        } else {
          s = accept();
        }
      }
    }
    segment_n_ = 0;
    segment_all_ = {};
    still_all_ = {};
    core_ = {};
    pending_ = {};
    n_tail_ = 0;
    lead_skipped_ = 0;
    return s;
  }

  Status accept() {
    if (n_intervals_ == MaxIntervals) {
      ++dropped_;
      return Status(ErrorCode::kResourceExhausted, "static detector: interval list full");
    }
    StaticInterval<T>& it = intervals_[n_intervals_++];
    it.start_index = core_start_;
    it.end_index = core_end_;
    it.count = core_.n;
    for (std::size_t c = 0; c < kDetectorChannels; ++c) {
      it.mean_v[c] = core_.mean[c];
      it.std_v[c] = core_.std_dev(c);
    }
    return Status::ok();
  }

  Status reject(std::uint64_t start, std::uint64_t end, const ChannelMoments<T>& m,
                PoseRejection why) {
    if (n_rejected_ == MaxRejected) {
      ++dropped_;
      return Status(ErrorCode::kResourceExhausted, "static detector: rejected-pose list full");
    }
    RejectedPose<T>& r = rejected_[n_rejected_++];
    r.start_index = start;
    r.end_index = end;
    r.count = m.n;
    r.reason = why;
    for (std::size_t c = 0; c < kDetectorChannels; ++c) {
      r.mean_v[c] = m.mean[c];
      r.std_v[c] = m.std_dev(c);
      if (!(r.std_v[c] <= cfg_.max_std_v[c]))
        r.noisy_channels |= static_cast<std::uint8_t>(1u << c);
    }
    return Status::ok();
  }

  StaticDetectorConfig<T> cfg_{};
  std::uint32_t window_n_ = 0;
  std::uint64_t min_still_n_ = 0;
  std::uint64_t min_pose_n_ = 0;

  std::uint64_t index_ = 0;         // samples seen
  std::uint64_t window_start_ = 0;  // index of the first sample of the open window
  ChannelMoments<T> window_{};
  std::array<T, kDetectorChannels> last_window_mean_{};

  std::uint64_t segment_start_ = 0;
  std::uint64_t segment_n_ = 0;      // samples in closed windows of the open segment
  ChannelMoments<T> segment_all_{};  // every window of the segment
  ChannelMoments<T> still_all_{};    // every still window of the segment (steadiness reference)
  std::uint64_t still_first_start_ = 0;
  std::uint64_t still_last_end_ = 0;
  std::uint32_t lead_skipped_ = 0;  // leading still windows trimmed so far
  struct TailEntry {
    ChannelMoments<T> still;
    std::uint64_t start;
    std::uint64_t end;
    ChannelMoments<T> after;  // non-still windows that followed it
  };
  std::array<TailEntry, kMaxTrimWindows> tail_{};  // the newest trim_windows still windows
  std::size_t n_tail_ = 0;
  ChannelMoments<T> core_{};     // committed: first to last committed still window
  ChannelMoments<T> pending_{};  // non-still windows after the last committed still one
  std::uint64_t core_start_ = 0;
  std::uint64_t core_end_ = 0;

  std::array<StaticInterval<T>, MaxIntervals> intervals_{};
  std::size_t n_intervals_ = 0;
  std::array<RejectedPose<T>, MaxRejected> rejected_{};
  std::size_t n_rejected_ = 0;
  std::size_t dropped_ = 0;
};

/// What the pose helper needs to read a specific force out of raw volts before calibration.
template <typename T>
struct PoseAssignmentConfig {
  std::array<Vec3<T>, 6> theta_b = nav::table1_geometry<T>(T(1)).theta_b;  // nominal axes
  std::array<T, 6> nominal_scale_v_per_g{};  // datasheet SF, V/g (sign matters), non-zero
  std::array<T, 6> nominal_bias_g{};         // g, usually 0
  /// An interval farther than this from every expected attitude is left unassigned (rad).
  T max_angle_rad = T(0.35);  // 20°: far beyond mounting errors, well below the 45° between
                              // neighbouring poses of Tables 2/3
};

/// Mean specific force (body, g) of an interval from nominal scale factors and biases: least
/// squares over the six axes, f = (ΘᵀΘ)⁻¹ Θᵀ s with s_j = mean_j/SF_j − b_j.
template <typename T>
Vec3<T> specific_force_estimate(const StaticInterval<T>& interval,
                                const PoseAssignmentConfig<T>& cfg);

/// Builds solver input from detected intervals. With expected attitudes (f_b_g in g, as the
/// solver wants them), each interval goes to the nearest one by angle and takes its exact vector;
/// attitude_of_interval[k] receives its index, or −1 when none is within max_angle_rad (that
/// interval is skipped). Without expected attitudes, each interval's own estimated direction
/// (unit, g) is used. The mean, sample std and count of every interval are copied. Returns the
/// number of observations written. Fails with kInvalidArgument when a nominal scale factor is
/// zero or not finite, or attitude_of_interval is shorter than intervals; kResourceExhausted
/// when `out` is too small.
template <typename T>
Result<std::size_t> intervals_to_observations(std::span<const StaticInterval<T>> intervals,
                                              std::span<const std::array<T, 3>> expected_f_b_g,
                                              const PoseAssignmentConfig<T>& cfg,
                                              std::span<AttitudeObservation<T>> out,
                                              std::span<int> attitude_of_interval);

extern template Vec3<float> specific_force_estimate<float>(const StaticInterval<float>&,
                                                           const PoseAssignmentConfig<float>&);
extern template Vec3<double> specific_force_estimate<double>(const StaticInterval<double>&,
                                                             const PoseAssignmentConfig<double>&);
extern template Result<std::size_t> intervals_to_observations<float>(
    std::span<const StaticInterval<float>>, std::span<const std::array<float, 3>>,
    const PoseAssignmentConfig<float>&, std::span<AttitudeObservation<float>>, std::span<int>);
extern template Result<std::size_t> intervals_to_observations<double>(
    std::span<const StaticInterval<double>>, std::span<const std::array<double, 3>>,
    const PoseAssignmentConfig<double>&, std::span<AttitudeObservation<double>>, std::span<int>);

}  // namespace gfins::calib
