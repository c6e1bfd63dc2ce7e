// Google Benchmark: one full per-sample step of nav::NavPipeline<T> (front end, compensator,
// Chen mechanization, strapdown integration) for each compensator, in float and double, and the
// array solver alone. Inputs are realistic, changing ADC samples from host_sim's sample source
// replayed from a 1 s buffer (bench_scenario.hpp), with a restart at the true state once per 1000
// samples. Figures go to docs/performance.md; nothing here asserts a time.
//
//   build/<dir>/tests/bench/gfins_nav_bench --benchmark_repetitions=5
#include <benchmark/benchmark.h>

#include <cstddef>
#include <cstdint>
#include <vector>

#include "bench_scenario.hpp"

namespace gfins::bench {
namespace {

const Workload& workload() {
  static const Workload w = make_workload();
  return w;
}

template <typename T>
void BM_PipelineStep(benchmark::State& state) {
  const auto kind = static_cast<nav::CompensatorKind>(state.range(0));
  Replay<T> replay(kind, workload());
  for (auto _ : state) {
    replay.step();
    benchmark::DoNotOptimize(replay.pipeline().state());
  }
  state.SetLabel(nav::to_string(kind));
  state.SetItemsProcessed(state.iterations());
}

template <typename T>
void BM_SolverAlone(benchmark::State& state) {
  const auto& buf = workload().samples;
  const auto cfg = make_config<T>(nav::CompensatorKind::kNone);
  const auto fe = nav::FrontEnd<T, 6>::create(cfg.front_end);
  const auto solver = nav::ArraySolver<T, 6>::create(cfg.nominal);
  if (!fe.is_ok() || !solver.is_ok()) {
    state.SkipWithError("bench: configuration rejected");
    return;
  }
  std::vector<nav::Vec6<T>> outputs(buf.size());
  std::vector<nav::Vec3<T>> rates(buf.size());
  for (std::size_t k = 0; k < buf.size(); ++k) {
    fe->convert(buf[k].counts, outputs[k]);
    rates[k] = workload().truth[k].w_b.cast<T>();
  }
  std::size_t i = 0;
  nav::Vec3<T> wdot_b;
  nav::Vec3<T> f_b;
  for (auto _ : state) {
    solver->solve(outputs[i], rates[i], wdot_b, f_b);
    benchmark::DoNotOptimize(wdot_b);
    benchmark::DoNotOptimize(f_b);
    i = (i + 1 == buf.size()) ? 0 : i + 1;
  }
  state.SetItemsProcessed(state.iterations());
}

void compensators(benchmark::internal::Benchmark* b) {
  b->ArgName("comp");
  for (auto k :
       {nav::CompensatorKind::kNone, nav::CompensatorKind::kPaper, nav::CompensatorKind::kExact}) {
    b->Arg(static_cast<std::int64_t>(k));
  }
}

BENCHMARK(BM_PipelineStep<float>)->Apply(compensators);
BENCHMARK(BM_PipelineStep<double>)->Apply(compensators);
BENCHMARK(BM_SolverAlone<float>);
BENCHMARK(BM_SolverAlone<double>);

}  // namespace
}  // namespace gfins::bench

BENCHMARK_MAIN();
