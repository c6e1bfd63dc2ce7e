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
#include <csignal>
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
///
/// `stop` (may be null), polled between runs: once non-zero (a SIGINT/SIGTERM handler sets it)
/// no further run starts, and the result holds the runs finished in order so far (runs = their
/// count; kFailedPrecondition with fewer than 2).
HostResult<MonteCarloResult> run_montecarlo(const Scenario& base, std::size_t runs,
                                            std::uint64_t seed0, const ProgressFn& progress = {},
                                            NavScalar scalar = NavScalar::kDouble,
                                            std::size_t jobs = 0,
                                            const volatile std::sig_atomic_t* stop = nullptr);

/// Peak memory of run_montecarlo (bytes), an upper bound: per sample, every run in flight
/// (run_memory_bytes without the uncompensated run, plus its error rows), the 2 × jobs finished
/// runs that may wait for their turn (parallel.hpp), the running sums, and at the end the result;
/// plus kProcessBaseBytes. `jobs` as run_montecarlo's (0: the hardware's), capped at `runs`.
/// Checked against a measured peak (getrusage ru_maxrss of a child run) in
/// tests/host_sim/estimate_cli.cpp.
std::uint64_t montecarlo_memory_bytes(const Scenario& s, std::size_t runs, std::size_t jobs);

/// Before any work: at least two samples and montecarlo_memory_bytes within
/// max_run_memory_bytes(); the message gives samples, runs, threads, the estimate and the limit,
/// and says that fewer threads (-j) or a shorter run fit.
HostStatus check_montecarlo_size(const Scenario& s, std::size_t runs, std::size_t jobs);

/// Wall-clock time a Monte-Carlo of `runs` runs is expected to take on `jobs` threads, s, from
/// kMcSecondsPerSampleRun.
double montecarlo_seconds_estimate(const Scenario& s, std::size_t runs, std::size_t jobs);
/// Measured cost of one sample of one Monte-Carlo run (simulation, ADC model, float32 core,
/// statistics; Release build, -j 1, 100 runs, the 2-core development machine otherwise idle):
/// `rest` 1.40 s for 10,001 × 100 samples (1.40 µs), `drive` 3.38 s for 20,001 × 100 (1.69 µs),
/// `spin` 0.71 s for 5,001 × 100 (1.42 µs): 2 µs, the slowest rounded up.
inline constexpr double kMcSecondsPerSampleRun = 2e-6;

/// Least-squares slope of log y against log t over the samples with t in [t_lo, t_hi] and y > 0.
/// Returns NaN with fewer than two such samples.
double loglog_slope(const std::vector<double>& t, const std::vector<double>& y, double t_lo,
                    double t_hi);

/// Writes t, mean and σ of every quantity and axis, and the RMS norms, as CSV. Throws
/// std::runtime_error on I/O errors.
HostStatus write_montecarlo_csv(const MonteCarloResult& r, const std::string& path);

}  // namespace gfins::sim
