// Monte-Carlo runs of one scenario: N seeds of sensor noise and of the simulated calibration,
// statistics of the navigation errors over time (mean, 1σ, RMS of the norm), and log-log slopes
// compared with the growth kinematics predicts (docs/simulation.md, "Monte-Carlo").
//
// Why slopes 1 and 2. ω is integrated from ω̇; a residual of the compensation that is constant
// over a run (a calibration error of the angles, a bias) gives a constant ω̇ error c, hence
// δω = c t and δθ ≈ c t²/2: log-log slopes 1 and 2 (docs/math.md, "Error growth without a
// gyroscope"). White sensor noise alone gives a random walk: δω ∝ √t and δθ ∝ t^1.5 (slopes 0.5
// and 1.5).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "gfins/host_sim/scenario.hpp"

namespace gfins::sim {

/// The error quantities tracked, each a 3-vector per sample.
enum class McQuantity : std::size_t { kRate = 0, kAttitude, kVelocity, kPosition };
inline constexpr std::size_t kMcQuantities = 4;
inline constexpr std::array<const char*, kMcQuantities> kMcQuantityNames = {
    "w_err_b_rps", "att_err_b_rad", "v_err_n_mps", "r_err_n_m"};

struct MonteCarloResult {
  std::size_t runs = 0;
  std::vector<double> t_s;
  // [quantity][axis][sample]: mean and sample standard deviation (N − 1) over the runs.
  std::array<std::array<std::vector<double>, 3>, kMcQuantities> mean;
  std::array<std::array<std::vector<double>, 3>, kMcQuantities> std;
  // [quantity][sample]: RMS over the runs of the error norm.
  std::array<std::vector<double>, kMcQuantities> rms_norm;
  // RMS over the runs of the calibration's angle error (rad), 0 with the true misalignment.
  double rms_calibration_angle_error_rad = 0;
};

/// Runs the scenario `runs` times (compensated run only): run k uses noise seed seed0 + k and
/// calibration seed seed0 + 100003 k. `progress` gets the fraction of runs done (called on the
/// calling thread). `scalar` is the navigation core's (gfins-sim: float, the board's, unless
/// --scalar double). The runs go to `jobs` threads (0: one per hardware thread, parallel.hpp); the
/// result is bit for bit the same for every `jobs`: each run's random streams come from (seed0, k)
/// only and the statistics add the runs in the order k = 0, 1, 2, ...
HostResult<MonteCarloResult> run_montecarlo(const Scenario& base, std::size_t runs,
                                            std::uint64_t seed0, const ProgressFn& progress = {},
                                            NavScalar scalar = NavScalar::kDouble,
                                            std::size_t jobs = 0);

/// Least-squares slope of log y against log t over the samples with t in [t_lo, t_hi] and y > 0.
/// Returns NaN with fewer than two such samples.
double loglog_slope(const std::vector<double>& t, const std::vector<double>& y, double t_lo,
                    double t_hi);

/// Writes t, mean and σ of every quantity and axis, and the RMS norms, as CSV. Throws
/// std::runtime_error on I/O errors.
HostStatus write_montecarlo_csv(const MonteCarloResult& r, const std::string& path);

}  // namespace gfins::sim
