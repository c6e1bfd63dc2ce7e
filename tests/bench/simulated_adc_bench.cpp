// Cost of one sample through the register-level ADC path (SimulatedAdc: chip model frame with
// CRC, simulated data-ready edge, the real driver's decode and CRC check): what each Monte-Carlo
// sample pays on top of the behavioural AdcModel it replaces.
#include <benchmark/benchmark.h>

#include <array>
#include <cmath>

#include "gfins/host_sim/adc_model.hpp"
#include "gfins/host_sim/chip/simulated_adc.hpp"

namespace {

void BM_SimulatedAdcConvert(benchmark::State& state) {
  gfins::sim::SimulatedAdc adc{gfins::sim::SimulatedAdcConfig{}};
  if (!adc.start().is_ok()) {
    state.SkipWithError("start failed");
    return;
  }
  std::uint32_t k = 0;
  std::array<double, 6> v{};
  for (auto _ : state) {
    for (int j = 0; j < 6; ++j) v[static_cast<std::size_t>(j)] = 5.0 * std::sin(1e-3 * k + j);
    auto s = adc.convert(v, k, static_cast<std::int64_t>(k) * 1'000'000);
    benchmark::DoNotOptimize(s);
    ++k;
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_SimulatedAdcConvert);

void BM_BehaviouralAdcSample(benchmark::State& state) {
  gfins::sim::AdcModel adc{gfins::sim::AdcConfig{}};
  std::uint32_t k = 0;
  Eigen::Matrix<double, 6, 1> v;
  for (auto _ : state) {
    for (int j = 0; j < 6; ++j) v(j) = 5.0 * std::sin(1e-3 * k + j);
    auto s = adc.sample(v, k);
    benchmark::DoNotOptimize(s);
    ++k;
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_BehaviouralAdcSample);

}  // namespace

BENCHMARK_MAIN();
