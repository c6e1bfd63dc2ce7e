// The QA-1100 analog front end as data: what lies between a sensor's proof mass and the ADC code.
//
// A QA-1100 (Honeywell Q-Flex) is a servo accelerometer with a CURRENT output: the rebalance
// current is proportional to the specific force along its input axis, K1 ≈ 1.33 mA/g (catalogue
// range 1.20-1.46 mA/g; docs/sensor-model.md gives the figures and their status), up to ±60 g.
// Per channel j:
//
//   i_j   = K1_j · a_j                      A, a_j in g (bias and errors: host_sim sensor model)
//   v_j   = i_j · R_L,j                     V across the load resistor (the "sensor voltage")
//   v_pin = v_j · divider_j                 V at the ADC input pins (resistive divider)
//   code  = round(v_pin · gain_j / vref · 2^23), clipped to [−2^23, 2^23 − 1]   (ADS131M06
//                                           §8.5.1.9; gain and vref from Ads131m06Config)
//
// so SF_j = K1_j · R_L,j (V/g) is the scale factor nav::FrontEndParams::scale_v_per_g and the
// paper's eq. (21) use, and volts_per_count(j) = vref / (gain_j · 2^23 · divider_j) is the LSB
// at the sensor, nav::FrontEndParams::volts_per_count. The nav core's FrontEnd does the
// counts → m/s² arithmetic with the calibrated SF and bias; this type only holds the hardware
// values, gives the nominal ones, and says when a code cannot be a measurement (saturated).
#pragma once

#include <array>
#include <cmath>
#include <cstdint>

#include "gfins/drivers/ads131m06.hpp"
#include "gfins/sample/raw_sample.hpp"
#include "gfins/status/status.hpp"

namespace gfins::drivers {

struct Qa1100Channel {
  double scale_a_per_g = 1.33e-3;  // K1, A/g (QA-1100 catalogue: 1.20-1.46 mA/g)
  double load_ohm = 1000.0;        // R_L, Ω: current → volts
  double divider = 1.0 / 8.33;     // v_pin / v_load: ±9.996 V at the load → ±1.2 V at the pins
  double range_g = 60.0;           // sensor input range ±range_g (rebalance loop limit)

  double scale_v_per_g() const { return scale_a_per_g * load_ohm; }
};

class Qa1100FrontEnd {
 public:
  using Channels = std::array<Qa1100Channel, ads131m06::kChannels>;

  Qa1100FrontEnd() = default;

  /// kInvalidArgument when a scale factor, load, divider or range is not positive and finite, or
  /// the ADC configuration has an impossible gain or reference.
  static Result<Qa1100FrontEnd> create(const Channels& ch, const Ads131m06Config& adc) {
    for (std::size_t j = 0; j < ch.size(); ++j) {
      const Qa1100Channel& c = ch[j];
      if (!(c.scale_a_per_g > 0) || !(c.load_ohm > 0) || !(c.divider > 0) || !(c.range_g > 0) ||
          !std::isfinite(c.scale_a_per_g) || !std::isfinite(c.load_ohm) ||
          !std::isfinite(c.divider) || !std::isfinite(c.range_g)) {
        return Status(ErrorCode::kInvalidArgument,
                      "front end: K1, load, divider and range must be positive and finite");
      }
      const unsigned g = adc.pga_gain[j];
      if (g == 0 || g > 128 || (g & (g - 1)) != 0) {
        return Status(ErrorCode::kInvalidArgument, "front end: PGA gain must be 1, 2, 4..128");
      }
    }
    if (!(adc.vref_v > 0) || !std::isfinite(adc.vref_v)) {
      return Status(ErrorCode::kInvalidArgument, "front end: vref must be positive");
    }
    Qa1100FrontEnd fe;
    fe.channels_ = ch;
    for (std::size_t j = 0; j < ch.size(); ++j) {
      fe.pin_volts_per_count_[j] = adc.vref_v / (static_cast<double>(adc.pga_gain[j]) * kCodeScale);
    }
    return fe;
  }

  const Channels& channels() const { return channels_; }
  /// One count in volts across the load resistor (the sensor output), V.
  double volts_per_count(int j) const {
    return pin_volts_per_count_[idx(j)] / channels_[idx(j)].divider;
  }
  /// SF_j = K1 · R_L, V/g (nominal; calibration replaces it).
  double scale_v_per_g(int j) const { return channels_[idx(j)].scale_v_per_g(); }
  /// Counts per g of specific force (nominal SF, zero bias).
  double counts_per_g(int j) const { return scale_v_per_g(j) / volts_per_count(j); }
  /// Specific force at the ADC's positive full scale, g: the measurable range of the channel is
  /// ±min(full_scale_g, range_g).
  double full_scale_g(int j) const { return static_cast<double>(kAdcCodeMax) / counts_per_g(j); }
  /// Nominal specific force of a code, g (no bias: the calibrated bias is the nav core's job).
  double specific_force_g(int j, std::int32_t code) const {
    return static_cast<double>(code) / counts_per_g(j);
  }
  /// Largest |code| that is still inside the sensor's range: beyond it the QA-1100's rebalance
  /// loop is at its limit even though the ADC is not.
  std::int32_t sensor_limit_code(int j) const {
    const double c = std::floor(channels_[idx(j)].range_g * counts_per_g(j));
    return c >= static_cast<double>(kAdcCodeMax) ? kAdcCodeMax : static_cast<std::int32_t>(c);
  }

  /// Bit j set when channel j is not a measurement: the code sits at an ADC rail (the same rule
  /// as nav::FrontEnd::convert) or beyond the sensor's range.
  std::uint32_t saturated_mask(const std::array<std::int32_t, kAdcChannels>& counts) const {
    std::uint32_t m = 0;
    for (int j = 0; j < kAdcChannels; ++j) {
      const std::int32_t c = counts[idx(j)];
      const std::int32_t lim = sensor_limit_code(j);
      if (c >= kAdcCodeMax || c <= kAdcCodeMin || c > lim || c < -lim) m |= 1u << j;
    }
    return m;
  }

 private:
  static constexpr double kCodeScale = 8388608.0;  // 2^23
  static std::size_t idx(int j) { return static_cast<std::size_t>(j); }

  Channels channels_{};
  std::array<double, ads131m06::kChannels> pin_volts_per_count_{};
};

}  // namespace gfins::drivers
