// Google Benchmark, part of gfins_parity_bench (parity_bench.cpp has its main): one estimate of the
// angular rate from the centripetal terms (redundancy/centripetal_rate.hpp) on the nine- and
// twelve-sensor triad layouts, float and double. Figures go to docs/performance.md; nothing here
// asserts a time.
#include <benchmark/benchmark.h>

#include "gfins/nav_core/redundancy/centripetal_rate.hpp"
#include "parity_bench_data.hpp"

namespace gfins::bench {
namespace {

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

BENCHMARK_TEMPLATE(BM_CentripetalRate, float, 9);
BENCHMARK_TEMPLATE(BM_CentripetalRate, float, 12);
BENCHMARK_TEMPLATE(BM_CentripetalRate, double, 12);

}  // namespace
}  // namespace gfins::bench
