// The six QA-1100 channels of the array as analog sources: truth → volts per sensor, with every
// error of the standard pendulous (force-rebalance) accelerometer model.
//
// Per sensor j, with a_j the specific force sensed along the real axis θ*_j at the real
// position ρ*_j, in g (the rigid-body terms of IdealArrayModel over nav::misaligned_geometry,
// i.e. paper eqs. (14)/(15) for the axes and (19) for the positions):
//
//   a_in  = clamp(a_j, ±saturation_g)                                  rebalance loop range
//   ΔT    = temperature_c − reference_temperature_c                    °C
//   b(t)  = bias_g + bias_tc_g_per_c·ΔT + w_j(t)                       g, w_j the random walk
//   SF'   = scale_v_per_g · (1 + scale_tc_ppm_per_c·1e-6·ΔT)           V/g
//   P_j   = SF' · (a_in + k2_g_per_g2·a_in² + b(t) + n_j)              V   (paper eq. (21) + K2)
//
// n_j is white, N(0, noise_g²) per sample; w_j(t) advances by N(0, bias_rw²·dt) each sample
// (dt = 1/sample_rate_hz), so its standard deviation grows as bias_rw·√t. Cross-axis,
// pendulous-axis (Kip) and higher-order terms are not modelled: the paper's calibration has no
// place for them and orientation errors already cover the first-order cross-axis sensitivity.
//
// Channel failures (ChannelFailure, from a time on; docs/simulation.md, "Channel failures"):
// a bias step or a ramp added to b(t), the white noise n_j multiplied by a factor (the same draws,
// so the run is identical up to the onset), the rebalance range cut to a lower limit, the output
// held at its last value before the onset (stuck), or 0 V (dead: zero counts through the
// converter).
//
// The noise streams are per sensor (seeded from `seed` and the sensor index), so changing one
// sensor's errors never changes the random numbers another sensor draws, and a given seed
// reproduces the same volts on the same standard library.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <random>
#include <vector>

#include "gfins/host_sim/array_model.hpp"
#include "gfins/host_sim/error.hpp"
#include "gfins/host_sim/trajectory.hpp"
#include "gfins/nav_core/geometry.hpp"
#include "gfins/nav_core/gravity.hpp"
#include "gfins/nav_core/misalignment.hpp"

namespace gfins::sim {

/// One QA-1100 channel. The member defaults are an error-free unit-gain sensor; qa1100_typical()
/// and SensorArrayModel::paper_table6() give documented values (docs/sensor-model.md).
struct AccelErrors {
  double scale_v_per_g = 1.0;  // SF, V/g (current output through the load resistor)
  double bias_g = 0.0;
  double k2_g_per_g2 = 0.0;                                // second-order nonlinearity
  double noise_g = 0.0;                                    // white noise σ per sample, g
  double bias_rw_g_per_sqrt_s = 0.0;                       // bias random walk
  double bias_tc_g_per_c = 0.0, scale_tc_ppm_per_c = 0.0;  // temperature coefficients
  double saturation_g = 60.0;                              // QA-1100 range

  /// Datasheet-class QA-1100 magnitudes (docs/sensor-model.md gives each figure and its source):
  /// SF 1.33 mA/g through a 1 kΩ load, bias 0, K2 20 µg/g², noise 70 µg rms per sample (the
  /// 10-500 Hz band, i.e. a 1 kHz sampled channel), bias random walk 10 µg/√s, bias TC 30 µg/°C,
  /// scale TC 180 ppm/°C, ±60 g.
  static AccelErrors qa1100_typical();
};

/// How a channel fails (ChannelFailure::value's unit in brackets).
enum class ChannelFailureKind : std::uint8_t {
  kBias,        // bias step [g]
  kRamp,        // bias growing linearly from the onset [g/s]
  kNoise,       // white noise multiplied by a factor [1]
  kSaturation,  // rebalance range cut to ±value [g]
  kStuck,       // output held at its last value before the onset
  kDead,        // output 0 V
};

/// One channel's failure from start_s on (scenario time, s).
struct ChannelFailure {
  ChannelFailureKind kind = ChannelFailureKind::kBias;
  std::size_t sensor = 0;  // 0..5
  double start_s = 0.0;
  double value = 0.0;
};

struct ArrayErrors {
  std::array<AccelErrors, 6> sensors{};
  std::vector<ChannelFailure> failures{};
  nav::Misalignment<double> misalignment{};  // orientation (eqs. 14/15) and location (eq. 19)
  double temperature_c = 25.0, reference_temperature_c = 25.0;
};

/// Truth → volts per sensor, with every error of AccelErrors and the array's misalignment.
class SensorArrayModel {
 public:
  using Volts = Eigen::Matrix<double, 6, 1>;

  /// The checked way to build one, for code the firmware runs (the simulated board): a rate that
  /// is not positive and finite is a HostError naming it, never an exception.
  static HostResult<SensorArrayModel> make(const nav::ArrayGeometry<double, 6>& nominal,
                                           const ArrayErrors& errors,
                                           const nav::GravityModel<double>& gravity,
                                           double sample_rate_hz, std::uint64_t seed);

  /// `nominal` is the design geometry (e.g. nav::table1_geometry); the sensors sense along
  /// nav::misaligned_geometry(nominal, errors.misalignment). `sample_rate_hz` sets the random-walk
  /// step. Throws std::invalid_argument when it is not positive and finite: host tools and tests
  /// only (their main() catches it); the firmware's simulated board uses make().
  SensorArrayModel(const nav::ArrayGeometry<double, 6>& nominal, const ArrayErrors& errors,
                   const nav::GravityModel<double>& gravity, double sample_rate_hz,
                   std::uint64_t seed);

  /// P_j of the file comment (V) for the truth x. Advances the noise and random-walk state by one
  /// sample, so call it once per ADC sample, in time order.
  Volts volts(const TruthState& x);

  /// s_j = θ_j·(f_b + ω̇×ρ_j + ω×(ω×ρ_j)) (m/s²) of the nominal geometry: what an error-free
  /// array would sense. Does not touch the random state.
  Volts ideal_specific_force(const TruthState& x) const;

  /// a_j·g (m/s²): specific force along the real (misaligned) axes at the real positions, before
  /// any sensor error. Does not touch the random state.
  Volts sensed_specific_force(const TruthState& x) const;

  /// Table 6 of the paper: SF, bias and the twelve orientation angles (degrees → rad), zero
  /// location error, every other error zero.
  static ArrayErrors paper_table6();

  /// Changes the array temperature (°C) from the next sample on.
  void set_temperature_c(double temperature_c) { errors_.temperature_c = temperature_c; }

  /// The random-walk part w_j of each bias, g.
  const std::array<double, 6>& bias_walk_g() const { return walk_g_; }
  const ArrayErrors& errors() const { return errors_; }
  const nav::ArrayGeometry<double, 6>& real_geometry() const { return real_.geometry(); }
  double sample_rate_hz() const { return sample_rate_hz_; }

 private:
  ArrayErrors errors_;
  IdealArrayModel<6> nominal_;
  IdealArrayModel<6> real_;
  double sample_rate_hz_;
  double sqrt_dt_s_;
  std::array<std::mt19937_64, 6> noise_rng_;
  std::array<std::mt19937_64, 6> walk_rng_;
  std::array<std::normal_distribution<double>, 6> noise_normal_{};  // N(0, 1)
  std::array<std::normal_distribution<double>, 6> walk_normal_{};   // N(0, 1)
  std::array<double, 6> walk_g_{};
  std::uint64_t k_ = 0;         // samples produced so far (the time of the failures)
  Volts last_ = Volts::Zero();  // the previous sample's volts (stuck channels hold them)
};

}  // namespace gfins::sim
