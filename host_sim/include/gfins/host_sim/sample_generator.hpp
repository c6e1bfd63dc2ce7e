// The one sample generator of the host: trajectory → sensor model → ADC → RawSample, the frames
// the board's ADC driver would hand to the pipeline (docs/architecture.md, "one path for a
// sample"). A generator, not a source in the firmware's sense (app::SampleSource, the port a
// board's sample loop reads): the simulated board wraps it in one (SimSampleSource).
//
//   Trajectory::at(t_k)            truth at t_k = k / rate (analytic, trajectory.hpp)
//   SensorArrayModel::volts(x)     six QA-1100 output voltages, with every sensor error
//                                  (sensor_model.hpp; V at the sensor terminals)
//   + uniform noise (optional)     what the sensor model does not draw (scenario files)
//   SourceAdc::convert(v, k, t_ns) the converter: 24-bit codes, flags (sample_flags)
//
// The converter is the seam: SourceAdc has the signature of the register-level SimulatedAdc
// (host_sim/chip: chip model + data-ready line + the real ADS131M06 driver). make_source_adc()
// is the one place that chooses it: the register-level SimulatedAdc; BehaviouralAdc
// (AdcModel, adc_model.hpp) remains for tests and benchmarks that want the fast model.
//
// Sample k has seq = k and t_ns = round(k · 1e9 / rate): driven by index, never by a clock.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <random>

#include "gfins/host_sim/adc_model.hpp"
#include "gfins/host_sim/sensor_model.hpp"
#include "gfins/host_sim/trajectory.hpp"
#include "gfins/sample/raw_sample.hpp"
#include "gfins/status/status.hpp"

namespace gfins::sim {

/// The converter behind the sample source: six sensor voltages of conversion `seq`, presented
/// at data-ready edge time t_ns → the RawSample the board would read.
class SourceAdc {
 public:
  virtual ~SourceAdc() = default;
  virtual Result<RawSample> convert(const std::array<double, 6>& sensor_volts, std::uint32_t seq,
                                    std::int64_t t_ns) = 0;
  /// Volts at the sensor terminals per count (what nav::FrontEndParams::volts_per_count needs).
  virtual double volts_per_count() const = 0;
};

/// The behavioural converter (AdcModel): quantisation, clipping, kSaturated and kSynthetic; the
/// edge time is the one given (the source's, not AdcModel's own timing).
class BehaviouralAdc final : public SourceAdc {
 public:
  explicit BehaviouralAdc(const AdcConfig& c) : model_(c) {}
  Result<RawSample> convert(const std::array<double, 6>& sensor_volts, std::uint32_t seq,
                            std::int64_t t_ns) override;
  double volts_per_count() const override { return model_.volts_per_count(); }

 private:
  AdcModel model_;
};

/// The converter every host sample source uses (one place to switch to the register-level
/// SimulatedAdc). `config` gives reference, gain, input divider and rate.
std::unique_ptr<SourceAdc> make_source_adc(const AdcConfig& config);

/// One sample of the source: what the board would read, and what was true.
struct GeneratedSample {
  RawSample raw;
  TruthState truth;
  SensorArrayModel::Volts volts = SensorArrayModel::Volts::Zero();  // at the sensor terminals
};

/// Makes sample k = 0, 1, 2, ... of a trajectory on demand (no pacing, no clock).
class SampleGenerator {
 public:
  /// `trajectory` must outlive the source. `adc` may be null only for the paper's §6.3
  /// experiment, which has no converter (then raw is left empty and only volts are produced).
  SampleGenerator(const Trajectory& trajectory, SensorArrayModel sensors,
                  std::unique_ptr<SourceAdc> adc, double sample_rate_hz);

  /// Uniform white noise per channel of σ in m/s² of specific force (half-width √3·σ), added in
  /// volts through each sensor's scale factor: scenario files ask for it (noise_uniform); the
  /// sensor model draws only Gaussian noise.
  void set_uniform_noise_mps2(double sigma_mps2, std::uint64_t seed);

  /// The next sample (k = 0, 1, 2, ...). Fails only if the converter fails.
  Result<GeneratedSample> next();

  /// Volts per count of the converter (0 without one).
  double volts_per_count() const { return adc_ ? adc_->volts_per_count() : 0.0; }
  double sample_rate_hz() const { return rate_hz_; }
  const SensorArrayModel& sensors() const { return sensors_; }
  SensorArrayModel& sensors() { return sensors_; }
  bool has_adc() const { return adc_ != nullptr; }

 private:
  const Trajectory& trajectory_;
  SensorArrayModel sensors_;
  std::unique_ptr<SourceAdc> adc_;
  double rate_hz_;
  std::uint32_t k_ = 0;
  double uniform_sigma_mps2_ = 0.0;
  // Seeded from the scenario's seed when the noise is switched on (set_uniform_noise): a run
  // must be reproducible.
  std::mt19937_64 uniform_rng_{1};  // NOLINT(bugprone-random-generator-seed)
  std::uniform_real_distribution<double> u01_{0.0, 1.0};
};

}  // namespace gfins::sim
