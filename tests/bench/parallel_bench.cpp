// Google Benchmark: Monte-Carlo runs and the covariance report on 1 and 2 threads.
// Wall time (UseRealTime) is what a user waits for; the CPU column is the whole
// process's (MeasureProcessCPUTime), so CPU / wall tells how many cores the run really had. The
// speed-up is wall(jobs 1) / wall(jobs 2); on a shared machine it is bounded by the cores the
// other processes leave free, so read it with the load average. Nothing asserts a time; that the
// results are the same for every thread count is a unit test (montecarlo_test, covariance_test).
//
//   build/<dir>/tests/bench/gfins_parallel_bench --benchmark_repetitions=5
//       --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <cstddef>
#include <cstdint>
#include <vector>

#include "gfins/host_sim/covariance.hpp"
#include "gfins/host_sim/montecarlo.hpp"
#include "gfins/host_sim/scenario.hpp"
#include "gfins/host_sim/trajectory.hpp"
#include "support/covariance_spec.hpp"

namespace gfins::sim {
namespace {

// The manoeuvre with the Table 6 misalignment compensated from a simulated calibration: each run
// makes its own sensor stream (sensor model + ADC model, 2000 samples) and its own calibration,
// then navigates in double. About 3 ms of one core per run on the development host.
constexpr const char* kMonteCarloScenario = R"([scenario]
description = "Monte-Carlo benchmark: manoeuvre, calibrated compensator"
duration_s = 2.0
rate_hz = 1000.0
[trajectory]
kind = "maneuver"
[sensors]
orientation = "paper_table6"
noise_mg = 0.1
[compensator]
kind = "exact"
misalignment = "calibrated"
)";
constexpr std::size_t kRuns = 16;

void BM_MonteCarlo(benchmark::State& state) {
  const auto jobs = static_cast<std::size_t>(state.range(0));
  const HostResult<Scenario> s = parse_scenario(kMonteCarloScenario, "parallel_bench");
  if (!s.is_ok()) {
    state.SkipWithError(s.error().message.c_str());
    return;
  }
  for (auto _ : state) {
    const auto r = run_montecarlo(s.value(), kRuns, 1, {}, NavScalar::kDouble, jobs);
    if (!r.is_ok()) {
      state.SkipWithError(r.error().message.c_str());
      break;
    }
    benchmark::DoNotOptimize(r.value().rms_norm[0].back());
  }
  state.counters["runs_per_s"] = benchmark::Counter(static_cast<double>(state.iterations()) * kRuns,
                                                    benchmark::Counter::kIsRate);
}

// gfins-sim covariance on the manoeuvre with every error source: 2 s at 1 kHz, seven
// propagations (the whole spec and six source groups) of 2000 steps.
void BM_CovarianceReport(benchmark::State& state) {
  const auto jobs = static_cast<std::size_t>(state.range(0));
  const auto traj = make_maneuver(1.0);
  test::EverySourceSigmas sigmas;
  sigmas.white_mps2 = 1e-3;
  sigmas.bias_rw_mps2_sqrt_s = 1e-5;
  sigmas.orientation_rad = 1e-4;
  const CovarianceSpec spec = test::every_source_spec(*traj, 2.0, 1e-3, sigmas);
  const std::vector<double> times = {1.0, 2.0};
  for (auto _ : state) {
    const CovarianceReport r = covariance_report(spec, times, jobs);
    benchmark::DoNotOptimize(r.envelopes.sigma[0].back());
  }
}

BENCHMARK(BM_MonteCarlo)
    ->ArgName("jobs")
    ->Arg(1)
    ->Arg(2)
    ->UseRealTime()
    ->MeasureProcessCPUTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_CovarianceReport)
    ->ArgName("jobs")
    ->Arg(1)
    ->Arg(2)
    ->UseRealTime()
    ->MeasureProcessCPUTime()
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace gfins::sim

BENCHMARK_MAIN();
