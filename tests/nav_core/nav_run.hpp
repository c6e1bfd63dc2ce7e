// Test support: runs a truth trajectory through the strapdown integrator with an ideal array
// (optionally with white noise) and reports the navigation errors against the truth.
//
// Below the sample seam on purpose: these helpers test the integrator as a unit (convergence
// order, stability, float vs double), whose truncation errors ADC quantisation would mask (one
// count is 0.9 µg, a random walk in ω). Everything that tests a sample's path goes through
// host_sim's SampleGenerator and NavLoop (docs/architecture.md, "One path for a sample").
#pragma once

#include <cmath>
#include <random>

#include "gfins/host_sim/array_model.hpp"
#include "gfins/host_sim/trajectory.hpp"
#include "gfins/nav_core/integrator.hpp"
#include "gfins/nav_core/misalignment.hpp"
#include "gfins/nav_core/paper_table6.hpp"

namespace gfins::nav::testing {

struct NavErrors {
  double attitude_rad = 0;  // angle of q_truth⁻¹ ⊗ q_nav
  double velocity_mps = 0;
  double position_m = 0;
  double rate_rps = 0;
  bool finite = true;
  double max_quat_norm_error = 0;
};

struct RunOptions {
  double rho_m = 0.1;
  double duration_s = 5.0;
  double dt_s = 1e-3;
  double noise_mps2 = 0.0;  // white noise σ per sensor sample
  unsigned seed = 1;
  // Run on the geometry the exact compensator inverts (Table 6 orientation errors plus ~1 mm
  // location errors): K then has non-zero ω̇ rows and the integrator takes its general branch.
  bool misaligned = false;
};

/// Table 1, or its misaligned version (RunOptions::misaligned).
inline ArrayGeometry<double, 6> run_geometry(const RunOptions& opts) {
  const auto nominal = table1_geometry<double>(opts.rho_m);
  if (!opts.misaligned) return nominal;
  Misalignment<double> m = paper_table6::misalignment<double>();
  for (std::size_t j = 0; j < 6; ++j) {
    const double s = (j % 2 == 0) ? 1.0 : -1.0;
    m.drho_b[j] = Vec3<double>(0.001 * s, -0.0007, 0.0005 * s);
  }
  return misaligned_geometry(nominal, m);
}

inline NavErrors errors_against(const NavState<double>& nav, const sim::TruthState& truth) {
  NavErrors e;
  e.attitude_rad = truth.q_nb.angularDistance(nav.q_nb);
  e.velocity_mps = (nav.v_n - truth.v_n).norm();
  e.position_m = (nav.r_n - truth.r_n).norm();
  e.rate_rps = (nav.w_b - truth.w_b).norm();
  e.finite = nav.q_nb.coeffs().allFinite() && nav.v_n.allFinite() && nav.r_n.allFinite() &&
             nav.w_b.allFinite();
  return e;
}

/// Integrates `traj` from t = 0 for opts.duration_s with scalar T (the ideal outputs are computed
/// in double, then rounded to T as a float32 front end would deliver them).
template <typename T>
NavErrors run_trajectory(const sim::Trajectory& traj, const RunOptions& opts) {
  const auto geometry = run_geometry(opts);
  const auto gravity = GravityModel<double>::constant(kStandardGravity);
  const sim::IdealArrayModel<6> model(geometry, gravity);
  const auto solver = ArraySolver<T>::create(geometry.template cast<T>());
  Strapdown<T> nav(solver.value(), GravityModel<T>::constant(static_cast<T>(kStandardGravity)));
  std::mt19937_64 rng(opts.seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  const auto outputs_at = [&](double t) {
    Vec6<double> s = model.outputs(traj.at(t));
    if (opts.noise_mps2 > 0) {
      for (int j = 0; j < 6; ++j) s(j) += opts.noise_mps2 * noise(rng);
    }
    return Vec6<T>(s.template cast<T>());
  };
  nav.initialize(sim::to_nav_state<T>(traj.at(0.0)), outputs_at(0.0));
  const auto steps = static_cast<long>(std::llround(opts.duration_s / opts.dt_s));
  double max_norm_err = 0;
  for (long k = 1; k <= steps; ++k) {
    const double t = static_cast<double>(k) * opts.dt_s;
    nav.step(outputs_at(t), static_cast<T>(opts.dt_s), static_cast<std::int64_t>(t * 1e9),
             static_cast<std::uint32_t>(k));
    max_norm_err =
        std::max(max_norm_err, std::abs(static_cast<double>(nav.state().q_nb.norm()) - 1));
  }
  NavErrors e = errors_against(nav.state().template cast<double>(),
                               traj.at(static_cast<double>(steps) * opts.dt_s));
  e.max_quat_norm_error = max_norm_err;
  return e;
}

}  // namespace gfins::nav::testing
