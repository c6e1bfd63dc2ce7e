#include "board.hpp"

#include <filesystem>

#include "gfins/app/epoch_sinks.hpp"
#include "gfins/app/startup.hpp"
#include "gfins/host_sim/scenario.hpp"
#include "gfins/sim_board/sim_board.hpp"

namespace gfins::app {
namespace {

// Named scenarios: next to the installed program (../share/gfins/scenarios), else the source
// tree's (a build that was not installed).
std::string scenario_dir(const FwConfig& c) {
  if (!c.sim_scenario_dir.empty()) return c.sim_scenario_dir;
  std::error_code ec;
  const auto exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    const auto installed = exe.parent_path().parent_path() / "share" / "gfins" / "scenarios";
    if (std::filesystem::is_directory(installed, ec)) return installed.string();
  }
  return GFINS_SCENARIO_DIR;
}

struct SimParts {
  std::unique_ptr<sim_board::SensorStream> stream;
  std::unique_ptr<sim_board::AdcChain> adc;
  sim_board::SampleClock sample_clock;
};

BoardResult make_sim_board(const FwConfig& c) {
  BoardResult out;
  const sim::ParsedScenario parsed = sim::load_scenario(c.sim_scenario, scenario_dir(c));
  if (!parsed.ok()) {
    out.error = parsed.error;
    return out;
  }
  sim::Scenario s = *parsed.scenario;
  if (s.rate_hz != c.sample_rate_hz) {
    out.error = "scenario " + s.name + " runs at " + std::to_string(s.rate_hz) +
                " Hz but adc.sample_rate_hz is " + std::to_string(c.sample_rate_hz);
    return out;
  }
  const double duration = c.sim_duration_s > 0 ? c.sim_duration_s : s.duration_s;
  auto parts = std::make_shared<SimParts>();
  parts->stream = sim_board::make_scenario_stream(s);
  parts->adc = sim_board::make_adc_chain(s);
  if (const Status st = parts->adc->start(); !st.is_ok()) {
    out.error = std::string("simulated ADC start: ") + st.message();
    return out;
  }
  auto b = std::make_unique<Board>();
  const bool fast = c.pacing == Pacing::kFast;
  if (fast) {
    b->clock = std::make_unique<sim_board::SampleClock>();
  } else {
    b->clock = std::make_unique<sim_board::SteadyClock>();
  }
  const auto samples = static_cast<std::uint32_t>(std::llround(duration * s.rate_hz)) + 1;
  auto source = std::make_unique<sim_board::SimSampleSource>(
      *parts->stream, *parts->adc, *b->clock,
      fast ? static_cast<sim_board::SampleClock*>(b->clock.get()) : nullptr,
      fast ? sim_board::Pacing::kFast : sim_board::Pacing::kRealTime, s.rate_hz, samples);
  const sim_board::SimSampleSource* src = source.get();
  b->finished = [src] { return src->finished(); };
  b->source = std::move(source);
  b->bus = std::make_unique<sim_board::MemoryCanBus>(1024);
  b->sink = std::make_unique<CountingSink>();
  // Uncalibrated defaults: the nominal chain (no misalignment, nominal scale factors). The
  // factory calibration: the scenario's true parameters.
  b->defaults = sim_board::scenario_calibration(s, parts->adc->volts_per_count());
  b->factory = b->defaults;
  for (auto& sensor : b->defaults.sensors) {
    sensor.bias_g = 0.0;
    sensor.location_error_m = {0.0, 0.0, 0.0};
  }
  b->defaults.beta = {};
  b->defaults.alpha = {};
  b->defaults.compensator = nav::CompensatorKind::kNone;
  b->keep_alive = parts;
  out.board = std::move(b);
  return out;
}

}  // namespace

BoardResult make_board(const FwConfig& c) {
  if (c.board == BoardKind::kSim) return make_sim_board(c);
  BoardResult out;
  out.error = "the Linux board backends (drivers/linux, drivers/ads131m06) are not in this build";
  return out;
}

}  // namespace gfins::app
