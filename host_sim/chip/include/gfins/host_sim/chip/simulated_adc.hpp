// The simulated board's ADC: the register-level ADS131M06 model, a data-ready line driven by the
// sample clock, and the REAL driver (gfins::drivers::Ads131m06) reading frames from the model.
// What the host sample source and the simulated board use to turn sensor volts into RawSample
// through exactly the code the board runs.
//
//   sensor volts (V across each QA-1100 load resistor)
//     → × divider_j (Qa1100Channel)                        V at the ADC pins
//     → Ads131m06Model: code = round(v · gain / vref · 2^23), STATUS, CRC   (register level)
//     → SimDataReadyLine edge (seq, t_ns) → Ads131m06::read_sample → RawSample (+ kSynthetic)
//
// Per sample nothing is allocated: the model, the line's ring and the driver's frame buffers
// are members.
#pragma once

#include <array>
#include <cstdint>

#include "gfins/drivers/ads131m06.hpp"
#include "gfins/drivers/qa1100_front_end.hpp"
#include "gfins/host_sim/chip/ads131m06_model.hpp"
#include "gfins/host_sim/chip/sim_data_ready.hpp"
#include "gfins/sample/raw_sample.hpp"
#include "gfins/status/status.hpp"

namespace gfins::sim {

struct SimulatedAdcConfig {
  drivers::Ads131m06Config adc{};               // what the driver programs (rate, gains, ...)
  drivers::Qa1100FrontEnd::Channels sensors{};  // K1, load, divider, range per channel
  std::int64_t read_timeout_ns = 2'000'000;     // passed to read_sample (sim time does not pass)
};

class SimulatedAdc : private SimDataReadyLine::Listener {
 public:
  explicit SimulatedAdc(const SimulatedAdcConfig& c = {});
  SimulatedAdc(const SimulatedAdc&) = delete;  // the driver holds references to members
  SimulatedAdc& operator=(const SimulatedAdc&) = delete;

  /// The configuration matching the behavioural AdcModel's parameters (reference, PGA gain,
  /// divider in front of the pins, rate), so the two converters give the same codes. The PGA
  /// gain must be one of 1, 2, 4, ..., 128. CLKIN stays 8.192 MHz when an OSR reaches the rate
  /// from it (§8.3.7: 250 Hz ... 32 kHz in powers of two); otherwise the simulated board gets
  /// the largest CLKIN ≤ 8.192 MHz that makes the rate exact (100 Hz: OSR 16384, CLKIN
  /// 3.2768 MHz) — a real board at such a rate needs that oscillator. kInvalidArgument when
  /// nothing fits.
  static Result<SimulatedAdcConfig> config_for(double vref_v, double gain, double input_divider,
                                               double sample_rate_hz);
  /// The fastest rate config_for accepts: CLKIN 8.192 MHz / (2 × the smallest OSR, 128) (§8.3.6,
  /// §8.3.7) = 32 kHz.
  static constexpr double kMaxSampleRateHz = 8.192e6 / (2.0 * 128.0);

  /// Starts the driver against the model (reset, identity, configuration with read-back) and
  /// checks that the model now converts at the configured rate. kInvalidArgument for a front
  /// end or ADC configuration that cannot be built.
  Status start();

  /// Presents the six sensor voltages of conversion `seq` at edge time t_ns, raises DRDY and
  /// reads the frame through the real driver: the RawSample the board would produce (flags also
  /// carry kSynthetic). Errors are the driver's (kTimeout when the chip produced no conversion,
  /// kDataLoss after a detected chip reset, ...) or kUnavailable for an injected lost edge.
  Result<RawSample> convert(const std::array<double, 6>& sensor_volts, std::uint32_t seq,
                            std::int64_t t_ns);

  /// The chip, for fault injection (CRC errors, stuck/saturated channel, reset, halts, ...).
  Ads131m06Model& chip() { return chip_; }
  SimDataReadyLine& line() { return line_; }
  const drivers::Ads131m06& driver() const { return driver_; }
  const drivers::Qa1100FrontEnd& front_end() const { return front_end_; }

  /// The next `n` conversions happen but their data-ready edges are lost (kernel overflow): the
  /// driver is not woken for them and counts the gap on the next edge.
  void drop_edges(std::uint32_t n) { drop_pending_ = n; }
  /// A spurious data-ready edge (no conversion behind it) before each of the next `n` conversions.
  void inject_extra_edges(std::uint32_t n) { extra_pending_ = n; }

  /// One count in volts at the sensor output (load resistor) of channel j: what
  /// nav::FrontEndParams::volts_per_count needs.
  double volts_per_count(int j) const { return front_end_.volts_per_count(j); }

 private:
  void on_conversion_edge(const hal::DataReadyEdge& e) override;
  Result<RawSample> read();

  SimulatedAdcConfig config_;
  Ads131m06Model chip_;
  SimDataReadyLine line_;
  drivers::Ads131m06 driver_;
  drivers::Qa1100FrontEnd front_end_;
  Ads131m06Model::PinVolts pending_pins_{};
  bool started_ = false;
  std::uint32_t drop_pending_ = 0;
  std::uint32_t extra_pending_ = 0;
  std::uint32_t glitches_ = 0;  // spurious edges so far: they shift the line's numbering
};

}  // namespace gfins::sim
