// The 6-channel, 24-bit simultaneous-sampling delta-sigma ADC (TI ADS131M06 class,
// docs/architecture.md) as a behavioural model: volts at the sensor outputs → one RawSample per
// data-ready edge.
//
// Signal chain per channel (all channels sampled at the same instant):
//
//   v_adc = v_sensor · input_divider          resistive divider in front of the ADC pins
//   code  = round(v_adc · gain / vref · 2^23)  round to nearest, ties away from zero
//   code  clipped to [−2^23, 2^23 − 1]         kAdcCodeMin / kAdcCodeMax
//
// so one count is vref / (gain · input_divider · 2^23) volts at the sensor (volts_per_count()).
// Default: vref 1.2 V (ADS131M06 internal reference), gain 1, divider 1/8.33 → ±9.996 V full
// scale at the sensor, 1.19 µV per count (docs/sensor-model.md).
//
// A code that reaches a rail (clipped, or exactly at full scale) sets sample_flags::kSaturated,
// matching nav::FrontEnd::convert, which treats a code at either rail as saturated. A non-finite
// input voltage gives code 0 and kSaturated (the value is not a measurement). Every sample also
// carries sample_flags::kSynthetic.
//
// Timing: the data-ready edge of sample seq is at t_ns = round(seq · 1e9 / sample_rate_hz)
// + group_delay_ns + jitter, jitter ~ N(0, jitter_ns_rms²) rounded to whole ns (seeded, so
// reproducible). The model is driven by sample index, never by a clock.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <random>

#include "gfins/sample/raw_sample.hpp"

namespace gfins::sim {

struct AdcConfig {
  double vref_v = 1.2;                // ADS131M06 internal reference, V
  double gain = 1.0;                  // PGA gain (1..128 on the ADS131M06)
  double input_divider = 1.0 / 8.33;  // v_adc / v_sensor: ±10 V sensor swing → ±1.2 V
  double sample_rate_hz = 1000.0;     // output data rate, Hz
  std::int64_t group_delay_ns = 0;    // constant delay of the data-ready edge, ns
  double jitter_ns_rms = 0.0;         // white jitter of the data-ready edge, ns (σ)
  std::uint64_t jitter_seed = 1;      // seed of the jitter stream
};

class AdcModel {
 public:
  /// Throws std::invalid_argument when vref, gain, divider or rate is not positive and finite,
  /// or the jitter is negative.
  explicit AdcModel(const AdcConfig& c);

  /// One simultaneous conversion of the six channels at data-ready edge `seq`. Advances the
  /// jitter stream when jitter is enabled.
  RawSample sample(const Eigen::Matrix<double, 6, 1>& volts, std::uint32_t seq);

  /// Volts at the sensor per count: vref / (gain · input_divider · 2^23). What
  /// nav::FrontEndParams::volts_per_count needs.
  double volts_per_count() const;

  /// The code of one channel and whether it sits at a rail (no timing, no random state).
  std::int32_t code_for(double volts, bool& saturated) const;

  /// Data-ready time of `seq` without jitter, ns.
  std::int64_t nominal_time_ns(std::uint32_t seq) const;

  const AdcConfig& config() const { return config_; }

 private:
  AdcConfig config_;
  double counts_per_volt_;
  std::mt19937_64 jitter_rng_;
  std::normal_distribution<double> jitter_normal_{};
};

}  // namespace gfins::sim
