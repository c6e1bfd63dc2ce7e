// Covariance analysis of the navigation errors along a trajectory's truth, with the linear
// error-state model of nav_core/error_model.hpp (paper §3), and the error budget: the share of
// each error source in each state's σ, found by propagating that source alone.
//
// Sources. Stochastic ones go through P ← Φ P Φᵀ + Q_d: random-constant bias (initial P), bias
// random walk and white noise (Q_d). Deterministic random constants that multiply the motion
// (scale factor, residual orientation and location errors after compensation) have no state:
// each parameter p of 1σ σ_p is propagated as a deterministic error x_p(t) for δs = σ_p ∂s/∂p,
// and adds x_p x_pᵀ to P (independent parameters). The model is linear, so the budget's
// variances add up to the total.
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "gfins/host_sim/error.hpp"
#include "gfins/host_sim/trajectory.hpp"
#include "gfins/nav_core/error_model.hpp"
#include "gfins/nav_core/geometry.hpp"
#include "gfins/nav_core/gravity.hpp"

namespace gfins::sim {

/// Names of the twelve navigation error states (CSV columns), in err_idx order.
inline constexpr std::array<const char*, 12> kErrorStateNames = {
    "phi_n_x_rad", "phi_n_y_rad", "phi_n_z_rad", "dr_n_x_m",   "dr_n_y_m",   "dr_n_z_m",
    "dv_n_x_mps",  "dv_n_y_mps",  "dv_n_z_mps",  "dw_b_x_rps", "dw_b_y_rps", "dw_b_z_rps"};

/// The truth at one instant as the point the error model is evaluated at (f_b from gravity).
nav::NavState<double> truth_nav_state(const TruthState& x, const nav::GravityModel<double>& g);

/// Random constants per sensor (1σ), each an independent parameter.
struct ConstantErrorSpec {
  std::array<double, 6> scale_factor_sigma{};     // relative (1e-4 = 100 ppm)
  std::array<double, 6> orientation_sigma_rad{};  // each of the two axes ⊥ θ_j
  std::array<double, 6> location_sigma_m{};       // each of the three axes of Δρ_j
};

struct CovarianceSpec {
  const Trajectory* trajectory = nullptr;  // not owned
  nav::ArrayGeometry<double, 6> geometry = nav::table1_geometry<double>(0.1);
  nav::GravityModel<double> gravity = nav::GravityModel<double>::constant(nav::kStandardGravity);
  double duration_s = 10.0;
  double dt_s = 1e-3;           // sample interval of the array (white noise is per sample)
  std::size_t decimation = 10;  // keep every decimation-th sample in the result
  nav::SensorNoiseSpec<double> noise{};
  ConstantErrorSpec constants{};
};

struct CovarianceResult {
  std::vector<double> t_s;
  std::array<std::vector<double>, 12> sigma;  // [state][sample], predicted 1σ
};

/// Propagates from t = 0 (zero initial navigation error) to duration_s. Throws
/// std::invalid_argument when the trajectory is missing, dt_s is not positive or the geometry is
/// refused by the array solver.
CovarianceResult propagate_covariance(const CovarianceSpec& spec);

/// The six source groups of the budget.
inline constexpr std::array<const char*, 6> kBudgetSources = {
    "bias", "bias_random_walk", "white_noise", "scale_factor", "orientation", "location"};

struct ErrorBudget {
  std::vector<double> t_s;  // the chosen times (the nearest kept sample)
  // [source (kBudgetSources, then "total")][time][state] 1σ
  std::vector<std::vector<std::array<double, 12>>> sigma;
};

/// Propagates each source group alone and all together; σ at the samples nearest `times_s`.
/// The seven propagations run on `jobs` threads (0: one per hardware thread, parallel.hpp), with
/// the same result for every `jobs`.
ErrorBudget error_budget(const CovarianceSpec& spec, const std::vector<double>& times_s,
                         std::size_t jobs = 0);

/// What gfins-sim covariance writes: the envelopes of the whole spec and the budget, whose
/// "total" is the same propagation (done once). Same threads and guarantee as error_budget.
struct CovarianceReport {
  CovarianceResult envelopes;
  ErrorBudget budget;
};
CovarianceReport covariance_report(const CovarianceSpec& spec, const std::vector<double>& times_s,
                                   std::size_t jobs = 0);

/// CSV writers.
HostStatus write_covariance_csv(const CovarianceResult& r, const std::string& path);
HostStatus write_budget_csv(const ErrorBudget& b, const std::string& path);

}  // namespace gfins::sim
