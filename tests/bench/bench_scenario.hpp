// Shared by the Google Benchmark program and the callgrind driver: a pipeline configuration with
// the paper's calibration (Table 6) and a buffer of ADC counts from a moving, rotating array, so
// every benchmarked step sees new, realistic inputs that the compiler cannot fold.
//
// The buffer holds kSamples samples (1 s at 1 kHz) of a motion that is periodic in ω over that
// second: ω(t) = [1.0 sin(2πt), 0.5 sin(4πt + 1), 0.8 sin(2πt + 2)] rad/s and a_n(t) =
// [2 sin(2πt), cos(2πt), 0.5 sin(4πt)] m/s², attitude integrated from ω (double, rotation-vector
// steps). Outputs come from the misaligned geometry the exact compensator models, converted to
// counts by the inverse front end, rounded. The benchmarks replay the buffer cyclically; its
// size is fixed, so its one-time cost cancels in callgrind's per-sample difference.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include "gfins/nav_core/paper_table6.hpp"
#include "gfins/nav_core/pipeline.hpp"

namespace gfins::bench {

namespace nav = gfins::nav;

inline constexpr int kSamples = 1000;
inline constexpr double kRateHz = 1000.0;
inline constexpr double kRhoM = 0.1;  // half-size of the cube, m

/// Pipeline configuration in T for a compensator: Table 6 scale factors, biases and orientation
/// errors, assumed location errors of about 1 mm, ADC full scale ±16 g per channel.
template <typename T>
nav::PipelineConfig<T> make_config(nav::CompensatorKind kind) {
  nav::PipelineConfig<T> c;
  c.nominal = nav::table1_geometry(static_cast<T>(kRhoM));
  namespace t6 = nav::paper_table6;
  constexpr double kFullScaleG = 16.0;
  constexpr double kCodes = 8388608.0;  // 2^23
  for (std::size_t j = 0; j < 6; ++j) {
    c.front_end.scale_v_per_g[j] = static_cast<T>(t6::kScaleVPerG[j]);
    c.front_end.bias_g[j] = static_cast<T>(t6::kBiasG[j]);
    c.front_end.volts_per_count[j] = static_cast<T>(t6::kScaleVPerG[j] * kFullScaleG / kCodes);
  }
  c.misalignment = t6::misalignment<T>();
  for (std::size_t j = 0; j < 6; ++j) {
    const double sgn = (j % 2 == 0) ? 1.0 : -1.0;
    c.misalignment.drho_b[j] = nav::Vec3<T>(static_cast<T>(0.001 * sgn), static_cast<T>(-0.0005),
                                            static_cast<T>(0.0008 * sgn));
  }
  c.compensator = kind;
  c.sample_rate_hz = kRateHz;
  return c;
}

struct Motion {
  Eigen::Vector3d w_b;
  Eigen::Vector3d wdot_b;
  Eigen::Vector3d a_n;
};

inline Motion motion_at(double t_s) {
  constexpr double k2Pi = 2.0 * std::numbers::pi;
  Motion m;
  m.w_b = {1.0 * std::sin(k2Pi * t_s), 0.5 * std::sin(2 * k2Pi * t_s + 1.0),
           0.8 * std::sin(k2Pi * t_s + 2.0)};
  m.wdot_b = {k2Pi * std::cos(k2Pi * t_s), 0.5 * 2 * k2Pi * std::cos(2 * k2Pi * t_s + 1.0),
              0.8 * k2Pi * std::cos(k2Pi * t_s + 2.0)};
  m.a_n = {2.0 * std::sin(k2Pi * t_s), std::cos(k2Pi * t_s), 0.5 * std::sin(2 * k2Pi * t_s)};
  return m;
}

using Counts = RawSample;

/// kSamples frames of counts for the array of make_config(kExact) (the misalignment is the
/// physical one whatever compensator reads the counts).
inline std::vector<Counts> make_counts() {
  const auto cfg = make_config<double>(nav::CompensatorKind::kExact);
  const auto truth =
      nav::ArraySolver<double>::create(nav::misaligned_geometry(cfg.nominal, cfg.misalignment));
  const auto fe = nav::FrontEnd<double, 6>::create(cfg.front_end);
  if (!truth.is_ok() || !fe.is_ok()) throw std::runtime_error("bench scenario: bad configuration");
  const Eigen::Vector3d g_n(0.0, 0.0, nav::kStandardGravity);
  const double h = 1.0 / kRateHz;
  Eigen::Quaterniond q_nb = Eigen::Quaterniond::Identity();
  std::vector<Counts> out(kSamples);
  for (int k = 0; k < kSamples; ++k) {
    const double t = k * h;
    const Motion m = motion_at(t);
    const Eigen::Vector3d f_b = q_nb.conjugate() * (m.a_n - g_n);
    const auto s = truth->predict(m.wdot_b, f_b, m.w_b);
    for (int j = 0; j < 6; ++j) {
      out[static_cast<std::size_t>(k)].counts[static_cast<std::size_t>(j)] =
          static_cast<std::int32_t>(std::lround(fe->counts_for(j, s(j))));
    }
    // Attitude to the next sample: rotation vector of ω at the midpoint.
    q_nb =
        (q_nb * nav::quat_from_rotation_vector<double>(motion_at(t + h / 2).w_b * h)).normalized();
  }
  return out;
}

inline nav::CompensatorKind parse_kind(const std::string& s) {
  if (s == "none") return nav::CompensatorKind::kNone;
  if (s == "paper") return nav::CompensatorKind::kPaper;
  if (s == "exact") return nav::CompensatorKind::kExact;
  throw std::invalid_argument("compensator must be none, paper or exact, not '" + s + "'");
}

/// The true state at the first frame of the buffer (identity attitude, at the origin, at rest
/// in velocity, rotating at ω(0)).
template <typename T>
nav::NavState<T> initial_state() {
  nav::NavState<T> init;
  init.w_b = motion_at(0.0).w_b.cast<T>();
  return init;
}

/// A configured pipeline already navigating (alignment skipped: start_at the true initial state
/// with the first frame).
template <typename T>
nav::NavPipeline<T> make_pipeline(nav::CompensatorKind kind, const Counts& first) {
  nav::NavPipeline<T> p;
  const Status st = p.configure(make_config<T>(kind));
  if (!st.is_ok()) throw std::runtime_error(st.message());
  p.start_at(initial_state<T>(), first);
  return p;
}

/// Replays the buffer cyclically through a pipeline. At each wrap the pipeline restarts at the
/// true initial state (start_at, about the cost of one step), so that the integrated state, and
/// with it the work per step, stays that of the 1 s trajectory: without it the uncompensated
/// pipeline's angular rate drifts over minutes until the rotation-vector step leaves its Taylor
/// branch, which would measure a different code path.
template <typename T>
class Replay {
 public:
  Replay(nav::CompensatorKind kind, const std::vector<Counts>& buffer)
      : buf_(buffer), pipe_(make_pipeline<T>(kind, buffer[0])) {}

  /// One sample: the per-sample step (or the restart at a wrap of the buffer).
  void step() {
    ++seq_;
    t_ns_ += 1000000;
    if (i_ == 0) {
      nav::NavState<T> init = initial_state<T>();
      init.seq = seq_;
      init.t_ns = t_ns_;
      pipe_.start_at(init, buf_[0]);
    } else {
      RawSample s = buf_[i_];
      s.t_ns = t_ns_;
      s.seq = seq_;
      pipe_.process(s);
    }
    i_ = (i_ + 1 == buf_.size()) ? 0 : i_ + 1;
  }

  const nav::NavPipeline<T>& pipeline() const { return pipe_; }

 private:
  const std::vector<Counts>& buf_;
  nav::NavPipeline<T> pipe_;
  std::size_t i_ = 1;
  std::uint32_t seq_ = 0;
  std::int64_t t_ns_ = 0;
};

}  // namespace gfins::bench
