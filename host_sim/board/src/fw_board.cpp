// gfins-fw on the simulated board (board.kind = "sim"): the scenario through the sensor model
// and the register-level chip model, paced fast, in real time or by a real data-ready line, with
// the firmware's CAN output and watchdog (docs/firmware.md, "The simulated board").
#include <cmath>
#include <memory>
#include <string>

#include "gfins/app/board.hpp"
#include "gfins/app/publisher_sink.hpp"
#include "gfins/app/sample_clock.hpp"
#include "gfins/host_sim/board/sim_board.hpp"
#include "gfins/host_sim/progress_interval.hpp"
#include "gfins/host_sim/scenario.hpp"

namespace gfins::sim_board {
namespace {

struct SimParts {
  std::unique_ptr<SensorStream> stream;
  std::unique_ptr<ChipAdc> adc;
  std::unique_ptr<SimSampleSource> sim_source;  // behind a ScheduledFaultSource ([[board.faults]])
  std::unique_ptr<hal::DataReadyLine> drdy;     // pacing "gpio" only
};

}  // namespace

app::BoardResult make_board(const app::FwConfig& c) {
  if (!c.sim_recording.empty()) return make_replay_board(c);
  app::BoardResult out;
  // Named scenarios: sim.scenario_dir when set, else found relative to this program
  // ($GFINS_SCENARIO_DIR, PREFIX/share/gfins/scenarios, PREFIX/share/gfins-fw/scenarios: the
  // gfins-fw package carries its own copy; gfins/host_sim/data_paths.hpp).
  const auto parsed = c.sim_scenario_dir.empty()
                          ? sim::load_scenario(c.sim_scenario)
                          : sim::load_scenario(c.sim_scenario, c.sim_scenario_dir);
  if (!parsed.is_ok()) {
    out.error = parsed.error().message;
    return out;
  }
  const sim::Scenario& s = parsed.value();
  if (s.rate_hz != c.sample_rate_hz) {
    out.error = "scenario " + s.name + " runs at " + std::to_string(s.rate_hz) +
                " Hz but adc.sample_rate_hz is " + std::to_string(c.sample_rate_hz);
    return out;
  }
  const double duration = c.sim_duration_s > 0 ? c.sim_duration_s : s.duration_s;
  auto parts = std::make_shared<SimParts>();
  auto stream = make_scenario_stream(s);
  if (!stream.is_ok()) {
    out.error = stream.error().message;
    return out;
  }
  parts->stream = std::move(stream).value();
  parts->adc = std::make_unique<ChipAdc>(s.rate_hz);
  if (const Status st = parts->adc->start(); !st.is_ok()) {
    out.error = std::string("simulated ADC start: ") + st.message();
    return out;
  }
  auto b = std::make_unique<app::Board>();
  const bool fast = c.pacing == app::Pacing::kFast;
  app::SampleClock* sample_clock = nullptr;
  if (fast) {
    auto clock = std::make_unique<app::SampleClock>();
    sample_clock = clock.get();
    b->clock = std::move(clock);
  } else {
    // CLOCK_MONOTONIC: the clock of the kernel's GPIO edge timestamps too.
    b->clock = std::make_unique<SteadyClock>();
  }
  const auto samples = static_cast<std::uint32_t>(std::llround(duration * s.rate_hz)) + 1;
  std::unique_ptr<SimSampleSource> source;
  if (c.pacing == app::Pacing::kGpio) {
    app::DataReadyResult drdy = app::open_data_ready(c);
    if (!drdy.line) {
      out.error = drdy.error;
      return out;
    }
    parts->drdy = std::move(drdy.line);
    source = std::make_unique<SimSampleSource>(*parts->stream, *parts->adc, *b->clock, *parts->drdy,
                                               samples);
  } else {
    source = std::make_unique<SimSampleSource>(*parts->stream, *parts->adc, *b->clock, sample_clock,
                                               fast ? Pacing::kFast : Pacing::kRealTime, s.rate_hz,
                                               samples);
  }
  const SimSampleSource* src = source.get();
  b->finished = [src] { return src->finished(); };
  const double rate = s.rate_hz;
  // The scenario's time of the last sample read (-1 before the first).
  const auto now_s = [src, rate] {
    return src->next_seq() == 0 ? -1.0 : static_cast<double>(src->next_seq() - 1) / rate;
  };
  if (fast) {
    // Faster than real time, a long scenario runs for minutes: gfins-fw reports how far it got.
    b->progress = [src, samples, duration] {
      return app::BoardProgress{1.0 - static_cast<double>(src->remaining()) / samples, duration};
    };
    b->progress_interval_s = paths::progress_interval_s();
  }
  if (!s.board_faults.empty() && c.pacing == app::Pacing::kGpio) {
    out.error = "scenario " + s.name +
                ": [[board.faults]] are made by the simulated ADC and need sim.pacing \"fast\" or "
                "\"realtime\" (with \"gpio\" the faults are made on the line and the bus)";
    return out;
  }
  if (!s.board_faults.empty()) {
    // The scenario's board faults ([[board.faults]]): the sample source's before the loop reads,
    // the CAN output's below.
    parts->sim_source = std::move(source);
    b->source = std::make_unique<ScheduledFaultSource>(*parts->sim_source, *b->clock,
                                                       s.board_faults, s.rate_hz);
  } else {
    b->source = std::move(source);
  }
  if (std::string e = app::open_can_output(c, *b->clock, *b); !e.empty()) {
    out.error = e;
    return out;
  }
  if (!s.board_faults.empty()) {
    b->bus = std::make_unique<FaultyCanBus>(std::move(b->bus), s.board_faults, now_s);
  }
  app::add_can_protocol(c, *b);
  // The scenario's GNSS receiver ([gnss]) sends its fixes on the board's bus, as a receiver
  // wired to the board would; gfins-fw uses them when aiding is on (aiding.inputs).
  if (s.gnss) {
    auto traj = sim::make_trajectory(s.trajectory);
    if (!traj.is_ok()) {
      out.error = traj.error().message;
      return out;
    }
    std::vector<sim::GnssSample> fixes = sim::GnssModel(*s.gnss, *traj.value()).fixes(duration);
    b->bus = std::make_unique<GnssReceiverBus>(std::move(b->bus), std::move(fixes), *s.gnss,
                                               static_cast<std::uint8_t>(c.node_id),
                                               app::id_bases(c), now_s);
  }
  // Uncalibrated defaults: the nominal chain (no misalignment, nominal scale factors, no bias).
  // The factory calibration: the scenario's true parameters.
  b->factory = scenario_calibration(s, parts->adc->volts_per_count());
  b->defaults = *b->factory;
  for (auto& sensor : b->defaults.sensors) {
    sensor.bias_g = 0.0;
    sensor.location_error_m = {0.0, 0.0, 0.0};
  }
  b->defaults.beta = {};
  b->defaults.alpha = {};
  b->defaults.compensator = nav::CompensatorKind::kNone;
  // Real-time and GPIO pacing run against the wall clock: give them the board's real-time
  // set-up and its watchdog too (the service unit's WatchdogSec on the virtual board).
  if (!fast) {
    b->enter_realtime = app::enter_realtime;
    if (std::string e = app::open_watchdog(c, *b->clock, *b); !e.empty()) {
      out.error = e;
      return out;
    }
  }
  b->close = [bus = b->bus.get()] { bus->service(); };
  b->keep_alive = parts;
  out.board = std::move(b);
  return out;
}

std::string check_config(const app::FwConfig& c, const std::string& origin) {
  if (!c.sim_recording.empty()) return check_recording(c, origin);
  const auto bad = [&](const std::string& why) {
    return origin + ": sim.scenario = " + app::quote_text(c.sim_scenario) + ": " + why;
  };
  const auto s = c.sim_scenario_dir.empty()
                     ? sim::load_scenario(c.sim_scenario)
                     : sim::load_scenario(c.sim_scenario, c.sim_scenario_dir);
  if (!s.is_ok()) return bad(s.error().message);
  // The simulated ADC runs at the scenario's rate; the loop and the front end at the configured
  // one: they must agree (make_board refuses the mismatch too).
  if (s.value().rate_hz != c.sample_rate_hz) {
    std::string rates = std::to_string(s.value().rate_hz);
    rates.erase(rates.find_last_not_of('0') + 1);
    if (!rates.empty() && rates.back() == '.') rates.pop_back();
    return bad("runs at " + rates + " Hz: adc.sample_rate_hz must be the same");
  }
  return "";
}

void add_to(app::BoardTable& t) {
  t.add(app::BoardEntry{app::BoardKind::kSim, check_config, make_board});
}

}  // namespace gfins::sim_board
