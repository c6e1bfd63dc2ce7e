// A covariance specification with every error source of sim::CovarianceSpec switched on at once,
// the same σ for all six sensors: what the error-budget tests and the parallel benchmark
// propagate (every source moves P, so every job of covariance_report has work).
#pragma once

#include "gfins/host_sim/covariance.hpp"
#include "gfins/host_sim/trajectory.hpp"

namespace gfins::test {

/// 1σ of each source, the same for the six sensors.
struct EverySourceSigmas {
  double white_mps2 = 1e-2;           // white noise per sample
  double bias_mps2 = 1e-4;            // random-constant bias (≈ 10 µg)
  double bias_rw_mps2_sqrt_s = 1e-4;  // bias random walk
  double scale_factor = 1e-4;         // relative (100 ppm)
  double orientation_rad = 1e-3;      // each of the two axes ⊥ θ_j
  double location_m = 1e-4;           // each axis of Δρ_j
};

/// Along `trajectory` (not owned), the default geometry (Table 1, ρ = 0.1 m) and gravity, for
/// duration_s at dt_s per sample.
inline sim::CovarianceSpec every_source_spec(const sim::Trajectory& trajectory, double duration_s,
                                             double dt_s, const EverySourceSigmas& s = {}) {
  sim::CovarianceSpec spec;
  spec.trajectory = &trajectory;
  spec.duration_s = duration_s;
  spec.dt_s = dt_s;
  spec.noise.white_sigma_mps2.fill(s.white_mps2);
  spec.noise.bias_sigma_mps2.fill(s.bias_mps2);
  spec.noise.bias_rw_mps2_sqrt_s.fill(s.bias_rw_mps2_sqrt_s);
  spec.constants.scale_factor_sigma.fill(s.scale_factor);
  spec.constants.orientation_sigma_rad.fill(s.orientation_rad);
  spec.constants.location_sigma_m.fill(s.location_m);
  return spec;
}

}  // namespace gfins::test
