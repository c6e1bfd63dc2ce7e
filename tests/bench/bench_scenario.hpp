// The workload of the per-sample benchmarks (gfins_nav_bench, gfins_pipeline_ir,
// gfins_baseline_bench) and of two tests that reuse it: a pipeline configuration with the paper's
// calibration (Table 6) and kSamples ADC samples from host_sim's one sample source
// (sample_generator.hpp): trajectory → sensor model → ADC → RawSample, the path every gfins-sim
// command and test helper takes (docs/architecture.md, "One path for a sample").
//
//   trajectory   make_maneuver(1.0), the first second: |ω| up to about 1 rad/s, attitude,
//                velocity and position all changing (trajectory.hpp)
//   sensors      SensorArrayModel with Table 6's scale factors, biases and orientation errors,
//                location errors of about 1 mm (array_errors()), no noise: the buffer is the same
//                in every run
//   converter    make_source_adc(), the register-level ADS131M06 model behind the real driver:
//                24-bit codes with the converter's LSB
//
// The samples are made once, before any timed loop, by code out of line in bench_scenario.cpp
// (library gfins::bench_workload); the benchmarks replay the buffer cyclically
// (Replay), so every step sees new, realistic inputs the compiler cannot fold. Its size is fixed,
// so its one-time cost cancels in callgrind's per-sample difference.
#pragma once

#include <array>
#include <cstdint>
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

/// Location error Δρ of sensor j (m, body): about 1 mm, signs alternating, so that the exact
/// compensator's solver has dense ω̇ rows.
template <typename T>
nav::Vec3<T> location_error_m(std::size_t j) {
  const double sgn = (j % 2 == 0) ? 1.0 : -1.0;
  return nav::Vec3<T>(static_cast<T>(0.001 * sgn), static_cast<T>(-0.0005),
                      static_cast<T>(0.0008 * sgn));
}

/// The converter's LSB, volts at the sensor per count (what the front end is told).
/// bench_scenario.cpp, as make_workload(): out of line, so that the set-up code of the sample
/// source is never inlined into a benchmark's timed function and changes its code generation.
double volts_per_count();

/// Pipeline configuration in T for a compensator: the front end of the source's converter and
/// sensors (LSB, Table 6 scale factors and biases) and the array's true misalignment (Table 6
/// orientation errors, location_error_m()).
template <typename T>
nav::PipelineConfig<T> make_config(nav::CompensatorKind kind) {
  nav::PipelineConfig<T> c;
  c.nominal = nav::table1_geometry(static_cast<T>(kRhoM));
  namespace t6 = nav::paper_table6;
  for (std::size_t j = 0; j < 6; ++j) {
    c.front_end.scale_v_per_g[j] = static_cast<T>(t6::kScaleVPerG[j]);
    c.front_end.bias_g[j] = static_cast<T>(t6::kBiasG[j]);
    c.front_end.volts_per_count[j] = static_cast<T>(volts_per_count());
  }
  c.misalignment = t6::misalignment<T>();
  for (std::size_t j = 0; j < 6; ++j) c.misalignment.drho_b[j] = location_error_m<T>(j);
  c.compensator = kind;
  c.sample_rate_hz = kRateHz;
  return c;
}

/// The samples and what was true at each.
struct Workload {
  std::vector<RawSample> samples;            // seq k, t_ns k·1 ms, as the source numbers them
  std::vector<nav::NavState<double>> truth;  // at t_k = k / kRateHz (sim::to_nav_state)
};

/// kSamples samples from the sample source (file comment): the array make_config() describes
/// (Table 6, location_error_m()), no noise. Throws if the converter fails.
Workload make_workload();

inline nav::CompensatorKind parse_kind(const std::string& s) {
  if (s == "none") return nav::CompensatorKind::kNone;
  if (s == "paper") return nav::CompensatorKind::kPaper;
  if (s == "exact") return nav::CompensatorKind::kExact;
  throw std::invalid_argument("compensator must be none, paper or exact, not '" + s + "'");
}

/// The true state at the first sample of the buffer.
template <typename T>
nav::NavState<T> initial_state(const Workload& w) {
  return w.truth.front().template cast<T>();
}

/// A configured pipeline already navigating (alignment skipped: start_at the true initial state
/// with the first sample).
template <typename T>
nav::NavPipeline<T> make_pipeline(nav::CompensatorKind kind, const Workload& w) {
  nav::NavPipeline<T> p;
  const Status st = p.configure(make_config<T>(kind));
  if (!st.is_ok()) throw std::runtime_error(st.message());
  p.start_at(initial_state<T>(w), w.samples.front());
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
  Replay(nav::CompensatorKind kind, const Workload& w)
      : buf_(w.samples), init_(initial_state<T>(w)), pipe_(make_pipeline<T>(kind, w)) {}

  /// One sample: the per-sample step (or the restart at a wrap of the buffer).
  void step() {
    ++seq_;
    t_ns_ += 1000000;
    if (i_ == 0) {
      nav::NavState<T> init = init_;
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
  const std::vector<RawSample>& buf_;
  nav::NavState<T> init_;
  nav::NavPipeline<T> pipe_;
  std::size_t i_ = 1;
  std::uint32_t seq_ = 0;
  std::int64_t t_ns_ = 0;
};

}  // namespace gfins::bench
