// The simulated board's sample chain for the firmware tests: a scenario's sensor stream → the
// ADS131M06 chip model behind the real driver → the fast-paced sample source on a test clock.
// Throws with the reason (tests only: a failure here is a broken fixture, not a finding).
#pragma once

#include <cstdint>
#include <memory>
#include <stdexcept>

#include "gfins/host_sim/board/sim_board.hpp"
#include "gfins/host_sim/scenario.hpp"

namespace gfins::test {

struct SimChain {
  std::unique_ptr<sim_board::SensorStream> stream;
  std::unique_ptr<sim_board::ChipAdc> adc;
  std::unique_ptr<sim_board::SimSampleSource> source;
};

/// `samples` conversions of scenario `s`, paced by `clock` (kFast), with `faults` injected.
inline SimChain make_sim_chain(const sim::Scenario& s, app::SampleClock& clock,
                               std::uint32_t samples, const sim_board::FaultPlan& faults) {
  SimChain c;
  auto made = sim_board::make_scenario_stream(s);
  if (!made.is_ok()) throw std::runtime_error(made.error().message);
  c.stream = std::move(made).value();
  c.adc = std::make_unique<sim_board::ChipAdc>(s.rate_hz);
  if (const Status st = c.adc->start(); !st.is_ok()) throw std::runtime_error(st.message());
  c.source = std::make_unique<sim_board::SimSampleSource>(
      *c.stream, *c.adc, clock, &clock, sim_board::Pacing::kFast, s.rate_hz, samples);
  c.source->set_faults(faults);
  return c;
}

}  // namespace gfins::test
