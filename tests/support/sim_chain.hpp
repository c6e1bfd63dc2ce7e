// The simulated board's sample chain for the firmware tests: a scenario's sensor stream → the
// ADS131M06 chip model behind the real driver → the fast-paced sample source on a test clock.
// Throws with the reason (tests only: a failure here is a broken fixture, not a finding).
#pragma once

#include <cstdint>
#include <memory>
#include <stdexcept>

#include "gfins/calib_file/calibration_file.hpp"
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

/// The true calibration of scenario `name` (found in `dir`) through the simulated board's chain,
/// saved as a calibration file at `path`: the file a recording board is given so that its
/// recording replays with the same calibration.
inline void save_scenario_calibration(const std::string& name, const std::string& dir,
                                      const std::string& path) {
  const auto s = sim::load_scenario(name, dir);
  if (!s.is_ok()) throw std::runtime_error(s.error().message);
  sim_board::ChipAdc adc(s.value().rate_hz);
  if (const Status st = adc.start(); !st.is_ok()) throw std::runtime_error(st.message());
  const auto saved = calib_file::save_calibration_file(
      path, sim_board::scenario_calibration(s.value(), adc.volts_per_count()));
  if (!saved.is_ok()) throw std::runtime_error(saved.message());
}

}  // namespace gfins::test
