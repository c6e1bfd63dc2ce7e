#include "gfins/host_sim/adc_model.hpp"

#include <cmath>
#include <cstddef>
#include <stdexcept>

#include "gfins/nav_core/front_end.hpp"

namespace gfins::sim {
namespace {
constexpr double kTwoPow23 = 8388608.0;  // 2^23: codes per vref at gain 1
}  // namespace

AdcModel::AdcModel(const AdcConfig& c)
    : config_(c),
      counts_per_volt_(c.gain * c.input_divider / c.vref_v * kTwoPow23),
      jitter_rng_(c.jitter_seed) {
  const auto positive = [](double v) { return v > 0.0 && std::isfinite(v); };
  if (!positive(c.vref_v) || !positive(c.gain) || !positive(c.input_divider) ||
      !positive(c.sample_rate_hz) || !(c.jitter_ns_rms >= 0.0)) {
    throw std::invalid_argument(
        "AdcModel: vref, gain, input divider and sample rate must be positive, jitter ≥ 0");
  }
}

double AdcModel::volts_per_count() const { return 1.0 / counts_per_volt_; }

std::int32_t AdcModel::code_for(double volts, bool& saturated) const {
  const double x = volts * counts_per_volt_;
  if (!std::isfinite(x)) {
    saturated = true;
    return 0;
  }
  // Clip in double before converting, so that no out-of-range conversion ever happens.
  const double r = std::round(x);  // nearest, ties away from zero
  const double hi = static_cast<double>(kAdcCodeMax);
  const double lo = static_cast<double>(kAdcCodeMin);
  if (r >= hi) {
    saturated = true;
    return kAdcCodeMax;
  }
  if (r <= lo) {
    saturated = true;
    return kAdcCodeMin;
  }
  saturated = false;
  return static_cast<std::int32_t>(r);
}

std::int64_t AdcModel::nominal_time_ns(std::uint32_t seq) const {
  // seq < 2^32 and 1e9/rate ≤ 1e6 ns at ≥ 1 kHz keep the product below 2^53: exact in double
  // to well under 1 ns for any realistic rate.
  return std::llround(static_cast<double>(seq) * 1e9 / config_.sample_rate_hz) +
         config_.group_delay_ns;
}

RawSample AdcModel::sample(const Eigen::Matrix<double, 6, 1>& volts, std::uint32_t seq) {
  RawSample s;
  s.seq = seq;
  s.t_ns = nominal_time_ns(seq);
  if (config_.jitter_ns_rms > 0.0) {
    s.t_ns += std::llround(config_.jitter_ns_rms * jitter_normal_(jitter_rng_));
  }
  s.flags = sample_flags::kSynthetic;
  for (std::size_t j = 0; j < 6; ++j) {
    bool saturated = false;
    s.counts[j] = code_for(volts(static_cast<Eigen::Index>(j)), saturated);
    if (saturated) s.flags |= sample_flags::kSaturated;
  }
  return s;
}

}  // namespace gfins::sim
