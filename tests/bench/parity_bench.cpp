// Google Benchmark: the parity monitor's cost per sample (redundancy/parity_monitor.hpp) for the
// layouts of docs/redundancy.md, float (the board's) and double, and what an exclusion costs
// (solver_without + the monitor's set_solver). Figures go to docs/performance.md; nothing here
// asserts a time.
//
//   build/<dir>/tests/bench/gfins_parity_bench --benchmark_repetitions=5
#include <benchmark/benchmark.h>

#include <random>
#include <vector>

#include "gfins/nav_core/redundancy/centripetal_rate.hpp"
#include "gfins/nav_core/redundancy/layouts.hpp"
#include "gfins/nav_core/redundancy/parity_monitor.hpp"

namespace gfins::bench {
namespace {

template <typename T, int N>
nav::ArrayGeometry<T, N> layout() {
  if constexpr (N == 12) {
    return nav::four_triads<T>(T(0.1));
  } else {
    return nav::table1_with_corners<T, N>(T(0.1));
  }
}

/// 1000 noisy samples of a spinning array (so the centripetal term is not zero), made before the
/// timed loop and cycled through.
template <typename T, int N>
std::vector<Eigen::Matrix<T, N, 1>> samples(const nav::ArraySolver<T, N>& solver,
                                            const nav::Vec3<T>& w) {
  std::mt19937_64 rng(1);
  std::normal_distribution<double> noise(0.0, 5e-4);
  const auto clean =
      solver.predict(nav::Vec3<T>::Zero(), nav::Vec3<T>(T(0.3), T(-0.2), T(-9.8)), w);
  std::vector<Eigen::Matrix<T, N, 1>> out(1000, clean);
  for (auto& s : out) {
    for (int j = 0; j < N; ++j) s(j) += static_cast<T>(noise(rng));
  }
  return out;
}

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

/// One centripetal-rate estimate (Gauss–Newton from the true rate plus 0.05 rad/s, to
/// convergence), on the nine- and twelve-sensor triad layouts.
template <typename T, int N>
void BM_CentripetalRate(benchmark::State& state) {
  static_assert(N == 9 || N == 12, "the triad layouts");
  nav::ArrayGeometry<T, N> geometry;
  if constexpr (N == 12) {
    geometry = nav::four_triads<T>(T(0.1));
  } else {
    geometry = nav::three_triads<T>(T(0.1));
  }
  const auto solver = nav::ArraySolver<T, N>::create(geometry).value();
  nav::CentripetalRateEstimator<T, N> est;
  if (!est.configure(solver, T(5e-4)).is_ok()) {
    state.SkipWithError("bench: estimator configuration rejected");
    return;
  }
  const nav::Vec3<T> w(T(1.5), T(-2.0), T(1.0));
  const auto in = samples<T, N>(solver, w);
  const nav::Vec3<T> seed = w + nav::Vec3<T>::Constant(T(0.05));
  std::size_t k = 0;
  int iterations = 0;
  for (auto _ : state) {
    const auto r = est.estimate(in[k], seed);
    iterations += r.iterations;
    benchmark::DoNotOptimize(r.w_b.data());
    k = k + 1 == in.size() ? 0 : k + 1;
  }
  state.counters["iterations"] =
      static_cast<double>(iterations) / static_cast<double>(state.iterations());
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
BENCHMARK_TEMPLATE(BM_CentripetalRate, float, 9);
BENCHMARK_TEMPLATE(BM_CentripetalRate, float, 12);
BENCHMARK_TEMPLATE(BM_CentripetalRate, double, 12);

}  // namespace
}  // namespace gfins::bench

BENCHMARK_MAIN();
