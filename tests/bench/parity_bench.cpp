// Google Benchmark: the parity monitor's cost per sample (redundancy/parity_monitor.hpp) for the
// layouts of docs/redundancy.md, float (the board's) and double, and what an exclusion costs
// (solver_without + the monitor's set_solver); the centripetal rate's estimate is in
// centripetal_rate_bench.cpp, linked into the same program. Figures go to docs/performance.md;
// nothing here asserts a time.
//
//   build/<dir>/tests/bench/gfins_parity_bench --benchmark_repetitions=5
#include <benchmark/benchmark.h>

#include "gfins/nav_core/redundancy/parity_monitor.hpp"
#include "parity_bench_data.hpp"

namespace gfins::bench {
namespace {

template <typename T, int N>
void BM_ParityAdd(benchmark::State& state) {
  const auto solver = nav::ArraySolver<T, N>::create(layout<T, N>()).value();
  nav::ParityMonitor<T, N> mon;
  if (!mon.configure(solver, nav::ParityConfig<T>{}).is_ok()) {
    state.SkipWithError("bench: parity configuration rejected");
    return;
  }
  const nav::Vec3<T> w(T(0.3), T(-0.2), T(0.5));
  const auto in = samples<T, N>(solver, w);
  std::size_t k = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(mon.add(in[k], w));
    k = k + 1 == in.size() ? 0 : k + 1;
  }
  benchmark::DoNotOptimize(mon.mean_statistic());
  state.SetItemsProcessed(state.iterations());
}

template <typename T, int N>
void BM_Exclusion(benchmark::State& state) {
  const auto solver = nav::ArraySolver<T, N>::create(layout<T, N>()).value();
  nav::ParityMonitor<T, N> mon;
  if (!mon.configure(solver, nav::ParityConfig<T>{}).is_ok()) {
    state.SkipWithError("bench: parity configuration rejected");
    return;
  }
  for (auto _ : state) {
    const auto reduced = nav::solver_without(solver, 3);
    benchmark::DoNotOptimize(mon.set_solver(reduced.value()).is_ok());
  }
  state.SetItemsProcessed(state.iterations());
}

BENCHMARK_TEMPLATE(BM_ParityAdd, float, 7);
BENCHMARK_TEMPLATE(BM_ParityAdd, float, 8);
BENCHMARK_TEMPLATE(BM_ParityAdd, float, 9);
BENCHMARK_TEMPLATE(BM_ParityAdd, float, 12);
BENCHMARK_TEMPLATE(BM_ParityAdd, double, 8);
BENCHMARK_TEMPLATE(BM_ParityAdd, double, 12);
BENCHMARK_TEMPLATE(BM_Exclusion, float, 8);
BENCHMARK_TEMPLATE(BM_Exclusion, float, 12);

}  // namespace
}  // namespace gfins::bench

BENCHMARK_MAIN();
