// SimulatedAdc: chip model + simulated data-ready line + the real driver (see the header).
#include "gfins/host_sim/chip/simulated_adc.hpp"

#include <cmath>

namespace gfins::sim {

static_assert(SimulatedAdc::kMaxSampleRateHz == 8.192e6 / (2.0 * drivers::ads131m06::kOsrValues[0]),
              "the smallest OSR sets the fastest rate");

SimulatedAdc::SimulatedAdc(const SimulatedAdcConfig& c)
    : config_(c), chip_(c.adc.vref_v), driver_(chip_, line_, c.adc) {
  line_.set_listener(this);
}

Result<SimulatedAdcConfig> SimulatedAdc::config_for(double vref_v, double gain,
                                                    double input_divider, double sample_rate_hz) {
  constexpr double kNominalClkinHz = 8.192e6;  // high-resolution mode (§6.3)
  if (!(vref_v > 0) || !(input_divider > 0) || !(sample_rate_hz > 0) || !std::isfinite(vref_v) ||
      !std::isfinite(input_divider) || !std::isfinite(sample_rate_hz)) {
    return Status(ErrorCode::kInvalidArgument,
                  "sim adc: vref, divider and rate must be positive and finite");
  }
  int g = -1;
  for (int code = 0; code < 8; ++code) {
    if (gain == static_cast<double>(1 << code)) g = 1 << code;
  }
  if (g < 0) return Status(ErrorCode::kInvalidArgument, "sim adc: PGA gain must be 1, 2, ..., 128");
  SimulatedAdcConfig c;
  c.adc.vref_v = vref_v;
  c.adc.sample_rate_hz = sample_rate_hz;
  c.adc.pga_gain.fill(static_cast<std::uint8_t>(g));
  for (auto& ch : c.sensors) ch.divider = input_divider;
  c.adc.clkin_hz = kNominalClkinHz;
  if (!drivers::Ads131m06::osr_code_for(sample_rate_hz, kNominalClkinHz).is_ok()) {
    double best = 0.0;
    for (const std::uint32_t osr : drivers::ads131m06::kOsrValues) {
      const double clkin = 2.0 * sample_rate_hz * static_cast<double>(osr);  // §8.3.6/§8.3.7
      if (clkin <= kNominalClkinHz && clkin > best) best = clkin;
    }
    if (best == 0.0) {
      return Status(ErrorCode::kInvalidArgument,
                    "sim adc: no OSR gives this rate with CLKIN <= 8.192 MHz");
    }
    c.adc.clkin_hz = best;
  }
  c.read_timeout_ns = static_cast<std::int64_t>(2e9 / sample_rate_hz);
  return c;
}

Status SimulatedAdc::start() {
  const Result<drivers::Qa1100FrontEnd> fe =
      drivers::Qa1100FrontEnd::create(config_.sensors, config_.adc);
  if (!fe.is_ok()) return fe.status();
  front_end_ = fe.value();
  const Status st = driver_.start();
  if (!st.is_ok()) return st;
  // The model must now convert at the rate the driver was asked for: a cross-check of the OSR
  // arithmetic through the register the driver actually wrote.
  const double rate = chip_.data_rate_hz(config_.adc.clkin_hz);
  if (std::fabs(rate - config_.adc.sample_rate_hz) > 1e-9 * config_.adc.sample_rate_hz) {
    return Status(ErrorCode::kFailedPrecondition,
                  "sim adc: the chip's OSR does not give the configured sample rate");
  }
  line_.clear();
  started_ = true;
  return Status::ok();
}

void SimulatedAdc::on_conversion_edge(const hal::DataReadyEdge& /*e*/) {
  // The conversion completes at its data-ready edge; if the chip is halted or in standby it
  // produces nothing (and convert() raised no edge for it).
  (void)chip_.convert(pending_pins_);
}

Result<RawSample> SimulatedAdc::convert(const std::array<double, 6>& sensor_volts,
                                        std::uint32_t seq, std::int64_t t_ns) {
  if (!started_) return Status(ErrorCode::kFailedPrecondition, "sim adc: start() first");
  for (std::size_t j = 0; j < pending_pins_.size(); ++j) {
    pending_pins_[j] = sensor_volts[j] * config_.sensors[j].divider;
  }
  if (extra_pending_ > 0) {
    // A glitch half a period before the conversion; the kernel numbers it like any edge.
    --extra_pending_;
    line_.set_next_seq(seq + glitches_);
    ++glitches_;
    const auto half_period_ns = static_cast<std::int64_t>(5e8 / config_.adc.sample_rate_hz);
    (void)line_.raise_glitch(t_ns - half_period_ns);
  }
  line_.set_next_seq(seq + glitches_);
  if (!chip_.will_convert()) {
    // Standby or a halted clock: no conversion, no edge; the driver waits in vain (kTimeout).
    (void)chip_.convert(pending_pins_);
    return read();
  }
  if (drop_pending_ > 0) {
    --drop_pending_;
    (void)chip_.convert(pending_pins_);  // the data are there, the wake-up is not
    line_.raise_lost();
    return Status(ErrorCode::kUnavailable,
                  "sim adc: data-ready edge lost (injected); no sample for this conversion");
  }
  (void)line_.raise(t_ns);
  return read();
}

Result<RawSample> SimulatedAdc::read() {
  Result<RawSample> r = driver_.read_sample(config_.read_timeout_ns);
  if (r.is_ok()) r.value().flags |= sample_flags::kSynthetic;
  return r;
}

}  // namespace gfins::sim
