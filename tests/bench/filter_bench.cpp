// Google Benchmark: the aided filter's operations one at a time (propagation over 10 ms, ZUPT,
// ZARU, GNSS position and velocity, heading), float (the board's) and double (tests/bench/
// filter_ops.hpp). Figures go to docs/performance.md; nothing here asserts a time.
//
//   build/<dir>/tests/bench/gfins_filter_bench --benchmark_repetitions=5
#include <benchmark/benchmark.h>

#include "filter_ops.hpp"

namespace gfins::bench {
namespace {

template <typename T>
void BM_FilterOp(benchmark::State& state) {
  const auto op = static_cast<FilterOp>(state.range(0));
  FilterRig<T> rig;
  if (!rig.ok()) {
    state.SkipWithError("bench: filter configuration rejected");
    return;
  }
  for (auto _ : state) {
    if (!rig.run(op)) {
      state.SkipWithError("bench: the filter refused the operation");
      return;
    }
  }
  benchmark::DoNotOptimize(rig.checksum());
  state.SetLabel(to_string(op));
  state.SetItemsProcessed(state.iterations());
}

void all_ops(benchmark::internal::Benchmark* b) {
  for (FilterOp op : {FilterOp::kPropagate, FilterOp::kZupt, FilterOp::kZaru,
                      FilterOp::kGnssPosition, FilterOp::kGnssVelocity, FilterOp::kHeading}) {
    b->Arg(static_cast<int>(op));
  }
}

BENCHMARK_TEMPLATE(BM_FilterOp, float)->Apply(all_ops);
BENCHMARK_TEMPLATE(BM_FilterOp, double)->Apply(all_ops);

}  // namespace
}  // namespace gfins::bench

BENCHMARK_MAIN();
