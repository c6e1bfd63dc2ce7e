#include "gfins/host_sim/sample_generator.hpp"

#include "gfins/host_sim/chip/simulated_adc.hpp"

#include <cmath>
#include <cstddef>
#include <stdexcept>
#include <utility>

namespace gfins::sim {

Result<RawSample> BehaviouralAdc::convert(const std::array<double, 6>& sensor_volts,
                                          std::uint32_t seq, std::int64_t t_ns) {
  Eigen::Matrix<double, 6, 1> v;
  for (std::size_t j = 0; j < 6; ++j) v(static_cast<Eigen::Index>(j)) = sensor_volts[j];
  RawSample s = model_.sample(v, seq);
  s.t_ns = t_ns;  // the source's edge time (SimulatedAdc takes it as an input too)
  return s;
}

namespace {

/// The register-level converter: the ADS131M06 chip model, a simulated data-ready line and the
/// real driver (host_sim/chip, SimulatedAdc), configured to match `config` (reference, PGA gain,
/// divider, rate) so its codes equal the behavioural model's within 1 LSB
/// (tests/host_sim/simulated_adc_test.cpp). Its driver checks CRCs, the status word and the
/// edge sequence of every frame exactly as on the board.
class RegisterLevelAdc final : public SourceAdc {
 public:
  explicit RegisterLevelAdc(const SimulatedAdcConfig& c) : adc_(c) {}
  Status start() { return adc_.start(); }
  Result<RawSample> convert(const std::array<double, 6>& sensor_volts, std::uint32_t seq,
                            std::int64_t t_ns) override {
    return adc_.convert(sensor_volts, seq, t_ns);
  }
  double volts_per_count() const override { return adc_.volts_per_count(0); }

 private:
  SimulatedAdc adc_;
};

}  // namespace

std::unique_ptr<SourceAdc> make_source_adc(const AdcConfig& config) {
  // The one place that picks the host's converter: the register-level SimulatedAdc, so every
  // host run goes trajectory → sensor model → ADS131M06 registers and frames → the board's
  // driver → RawSample. AdcConfig's group delay and jitter do not apply: the source gives the
  // edge time. A configuration the chip cannot do is a set-up error (host code: it throws, like
  // AdcModel's constructor).
  const Result<SimulatedAdcConfig> c = SimulatedAdc::config_for(
      config.vref_v, config.gain, config.input_divider, config.sample_rate_hz);
  if (!c.is_ok()) throw std::invalid_argument(c.status().message());
  auto adc = std::make_unique<RegisterLevelAdc>(c.value());
  const Status st = adc->start();
  if (!st.is_ok()) throw std::invalid_argument(st.message());
  return adc;
}

SampleGenerator::SampleGenerator(const Trajectory& trajectory, SensorArrayModel sensors,
                                 std::unique_ptr<SourceAdc> adc, double sample_rate_hz)
    : trajectory_(trajectory),
      sensors_(std::move(sensors)),
      adc_(std::move(adc)),
      rate_hz_(sample_rate_hz) {}

void SampleGenerator::set_uniform_noise_mps2(double sigma_mps2, std::uint64_t seed) {
  uniform_sigma_mps2_ = sigma_mps2;
  uniform_rng_.seed(seed);
}

Result<GeneratedSample> SampleGenerator::next() {
  const std::uint32_t k = k_++;
  GeneratedSample out;
  out.truth = trajectory_.at(static_cast<double>(k) / rate_hz_);
  out.volts = sensors_.volts(out.truth);
  if (uniform_sigma_mps2_ > 0.0) {
    for (std::size_t j = 0; j < 6; ++j) {
      const double n_mps2 = std::sqrt(3.0) * uniform_sigma_mps2_ * (2.0 * u01_(uniform_rng_) - 1.0);
      out.volts(static_cast<Eigen::Index>(j)) +=
          n_mps2 / nav::kStandardGravity * sensors_.errors().sensors[j].scale_v_per_g;
    }
  }
  out.raw.seq = k;
  out.raw.t_ns = std::llround(static_cast<double>(k) * 1e9 / rate_hz_);
  if (!adc_) return out;
  std::array<double, 6> v{};
  for (std::size_t j = 0; j < 6; ++j) v[j] = out.volts(static_cast<Eigen::Index>(j));
  const Result<RawSample> raw = adc_->convert(v, k, out.raw.t_ns);
  if (!raw.is_ok()) return raw.status();
  out.raw = raw.value();
  return out;
}

}  // namespace gfins::sim
