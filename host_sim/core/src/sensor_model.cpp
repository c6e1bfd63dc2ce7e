#include "gfins/host_sim/sensor_model.hpp"
#include "gfins/nav_core/paper_table6.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <numbers>
#include <stdexcept>
#include <string>

namespace gfins::sim {
namespace {

// Distinct, fixed stream ids so that the noise and the walk of each sensor come from separate
// engines (splitmix64 constants: any odd 64-bit mixers would do).
constexpr std::uint64_t kNoiseStream = 0x9E3779B97F4A7C15ull;
constexpr std::uint64_t kWalkStream = 0xBF58476D1CE4E5B9ull;

std::uint64_t mix_seed(std::uint64_t seed, std::uint64_t stream, std::size_t sensor) {
  // splitmix64 finaliser: neighbouring seeds give unrelated engine states.
  std::uint64_t z = seed + stream * (static_cast<std::uint64_t>(sensor) + 1u);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

}  // namespace

AccelErrors AccelErrors::qa1100_typical() {
  AccelErrors e;
  e.scale_v_per_g = 1.33;          // 1.33 mA/g (datasheet 1.20-1.46 mA/g) × 1 kΩ load
  e.bias_g = 0.0;                  // datasheet < 4 mg: calibrated per unit, so 0 by default
  e.k2_g_per_g2 = 20e-6;           // datasheet < 20 µg/g²
  e.noise_g = 70e-6;               // datasheet 70 µg rms in 10-500 Hz
  e.bias_rw_g_per_sqrt_s = 10e-6;  // assumption (no datasheet figure), see docs
  e.bias_tc_g_per_c = 30e-6;       // datasheet < 30 µg/°C
  e.scale_tc_ppm_per_c = 180.0;    // datasheet < 180 ppm/°C
  e.saturation_g = 60.0;           // datasheet ±60 g input range
  return e;
}

namespace {
bool valid_rate(double sample_rate_hz) {
  return sample_rate_hz > 0.0 && std::isfinite(sample_rate_hz);
}
}  // namespace

HostResult<SensorArrayModel> SensorArrayModel::make(const nav::ArrayGeometry<double, 6>& nominal,
                                                    const ArrayErrors& errors,
                                                    const nav::GravityModel<double>& gravity,
                                                    double sample_rate_hz, std::uint64_t seed) {
  if (!valid_rate(sample_rate_hz)) {
    return HostError{ErrorCode::kInvalidArgument, "sensor model: sample rate " +
                                                      std::to_string(sample_rate_hz) +
                                                      " Hz must be positive and finite"};
  }
  return SensorArrayModel(nominal, errors, gravity, sample_rate_hz, seed);  // cannot throw now
}

SensorArrayModel::SensorArrayModel(const nav::ArrayGeometry<double, 6>& nominal,
                                   const ArrayErrors& errors,
                                   const nav::GravityModel<double>& gravity, double sample_rate_hz,
                                   std::uint64_t seed)
    : errors_(errors),
      nominal_(nominal, gravity),
      real_(nav::misaligned_geometry(nominal, errors.misalignment), gravity),
      sample_rate_hz_(sample_rate_hz),
      sqrt_dt_s_(std::sqrt(1.0 / sample_rate_hz)) {
  if (!valid_rate(sample_rate_hz)) {
    throw std::invalid_argument("SensorArrayModel: sample rate must be positive and finite");
  }
  for (std::size_t j = 0; j < 6; ++j) {
    noise_rng_[j].seed(mix_seed(seed, kNoiseStream, j));
    walk_rng_[j].seed(mix_seed(seed, kWalkStream, j));
  }
}

SensorArrayModel::Volts SensorArrayModel::ideal_specific_force(const TruthState& x) const {
  return nominal_.outputs(x);
}

SensorArrayModel::Volts SensorArrayModel::sensed_specific_force(const TruthState& x) const {
  return real_.outputs(x);
}

SensorArrayModel::Volts SensorArrayModel::volts(const TruthState& x) {
  const Volts s_mps2 = real_.outputs(x);
  const double dtemp_c = errors_.temperature_c - errors_.reference_temperature_c;
  const double t_s = static_cast<double>(k_) / sample_rate_hz_;
  Volts p;
  for (std::size_t j = 0; j < 6; ++j) {
    const AccelErrors& e = errors_.sensors[j];
    // Both draws happen every sample, whatever the σ, so the streams stay aligned in time.
    double n_g = e.noise_g * noise_normal_[j](noise_rng_[j]);
    walk_g_[j] += e.bias_rw_g_per_sqrt_s * sqrt_dt_s_ * walk_normal_[j](walk_rng_[j]);
    double saturation_g = e.saturation_g;
    double failure_bias_g = 0.0;
    bool stuck = false;
    bool dead = false;
    for (const ChannelFailure& f : errors_.failures) {
      if (f.sensor != j || t_s < f.start_s) continue;
      switch (f.kind) {
        case ChannelFailureKind::kBias:
          failure_bias_g += f.value;
          break;
        case ChannelFailureKind::kRamp:
          failure_bias_g += f.value * (t_s - f.start_s);
          break;
        case ChannelFailureKind::kNoise:
          n_g *= f.value;
          break;
        case ChannelFailureKind::kSaturation:
          saturation_g = std::min(saturation_g, f.value);
          break;
        case ChannelFailureKind::kStuck:
          stuck = true;
          break;
        case ChannelFailureKind::kDead:
          dead = true;
          break;
      }
    }
    const auto jj = static_cast<Eigen::Index>(j);
    const double a_g = s_mps2(jj) / nav::kStandardGravity;
    const double a_in_g = std::clamp(a_g, -saturation_g, saturation_g);
    const double bias_g = e.bias_g + e.bias_tc_g_per_c * dtemp_c + walk_g_[j] + failure_bias_g;
    const double sf_v_per_g = e.scale_v_per_g * (1.0 + e.scale_tc_ppm_per_c * 1e-6 * dtemp_c);
    // paper eq. (21), P = SF (f·θ + b), plus the second-order term and the noise.
    p(jj) = sf_v_per_g * (a_in_g + e.k2_g_per_g2 * a_in_g * a_in_g + bias_g + n_g);
    if (stuck && k_ > 0) p(jj) = last_(jj);
    if (dead) p(jj) = 0.0;
  }
  ++k_;
  last_ = p;
  return p;
}

ArrayErrors SensorArrayModel::paper_table6() {
  ArrayErrors e;
  for (std::size_t j = 0; j < 6; ++j) {
    e.sensors[j].scale_v_per_g = nav::paper_table6::kScaleVPerG[j];
    e.sensors[j].bias_g = nav::paper_table6::kBiasG[j];
  }
  e.misalignment = nav::paper_table6::misalignment<double>();
  return e;
}

}  // namespace gfins::sim
