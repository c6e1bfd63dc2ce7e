// A simulated board wired to the firmware's sample loop for tests: the same parts gfins-fw --sim
// builds (scenario stream, ADC chain, fast pacing, in-memory CAN bus), plus taps that record the
// samples the loop read and the epochs it handed to the publisher.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "gfins/app/config.hpp"
#include "gfins/app/epoch_sinks.hpp"
#include "gfins/app/logger.hpp"
#include "gfins/app/publisher_sink.hpp"
#include "gfins/app/sample_loop.hpp"
#include "gfins/app/startup.hpp"
#include "gfins/can/aiding_input.hpp"
#include "gfins/host_sim/board/sim_board.hpp"
#include "gfins/host_sim/scenario.hpp"
#include "gfins/recording/codec.hpp"
#include "support/sim_chain.hpp"

namespace gfins::testing {

/// Records every sample read through it (reserved up front: no allocation while recording).
class TapSource final : public app::SampleSource {
 public:
  TapSource(app::SampleSource& inner, std::size_t reserve) : inner_(inner) {
    samples_.reserve(reserve);
  }
  const std::vector<RawSample>& samples() const { return samples_; }

 private:
  Result<RawSample> do_read_sample(std::int64_t timeout_ns) override {
    Result<RawSample> r = inner_.read_sample(timeout_ns);
    if (r.is_ok() && samples_.size() < samples_.capacity()) samples_.push_back(r.value());
    return r;
  }
  app::AdcCounters do_counters() const override { return inner_.counters(); }
  double do_volts_per_count() const override { return inner_.volts_per_count(); }

  app::SampleSource& inner_;
  std::vector<RawSample> samples_;
};

/// ADC read failures on the simulated board: the board's own (sim_board.hpp).
using FaultySource = sim_board::FaultySource;

/// A publisher that takes too long: while stalls are pending, each epoch handed over moves the
/// (sample) clock to `stall_ns` after the epoch's edge, as a cycle that overran would.
class StallingSink final : public app::EpochSink {
 public:
  StallingSink(app::EpochSink& next, app::SampleClock& clock) : next_(next), clock_(clock) {}
  void stall(std::uint32_t epochs, std::int64_t stall_ns) { left_ = epochs, stall_ns_ = stall_ns; }
  std::uint32_t publish(const can::Epoch& e) override {
    const std::uint32_t n = next_.publish(e);
    if (left_ > 0) {
      --left_;
      clock_.set(e.nav.t_ns + stall_ns_);
    }
    return n;
  }
  Status set_divider(std::size_t m, std::uint16_t d) override { return next_.set_divider(m, d); }
  Status set_dividers(const std::array<std::uint16_t, app::kNumMessages>& d) override {
    return next_.set_dividers(d);
  }

 private:
  app::EpochSink& next_;
  app::SampleClock& clock_;
  std::uint32_t left_ = 0;
  std::int64_t stall_ns_ = 0;
};

struct SimRig {
  /// `scenario`: a name in host_sim/scenarios; `seconds`: run length (samples = seconds·rate+1).
  SimRig(const std::string& scenario, double seconds, const sim_board::FaultPlan& faults = {},
         std::size_t can_capacity = 1u << 16) {
    const auto p = sim::load_scenario(scenario, GFINS_SCENARIO_DIR);
    if (!p.is_ok()) throw std::runtime_error(p.error().message);
    s = p.value();
    config.board = app::BoardKind::kSim;
    config.calibration_file.clear();
    config.node_id = kNode;  // the node whose commands the loop answers
    samples = static_cast<std::uint32_t>(seconds * s.rate_hz) + 1;
    test::SimChain chain = test::make_sim_chain(s, clock, samples, faults);
    stream = std::move(chain.stream);
    adc = std::move(chain.adc);
    source = std::move(chain.source);
    faulty = std::make_unique<FaultySource>(*source, clock);
    tap = std::make_unique<TapSource>(*faulty, samples);
    bus = std::make_unique<sim_board::MemoryCanBus>(can_capacity);
    publisher = std::make_unique<app::PublisherSink>(*bus, kNode, app::bus_dividers(config),
                                                     app::bus_budget(config));
    stalling = std::make_unique<StallingSink>(*publisher, clock);
    // Twice the samples: cycles without a sample publish epochs too (one per period).
    recording = std::make_unique<app::RecordingSink>(stalling.get(), 2 * std::size_t{samples});
    log = std::make_unique<app::FwLogQueue>();
    factory = sim_board::scenario_calibration(s, adc->volts_per_count());
    cal = app::load_calibration(config, factory, &factory).set;
    loop = std::make_unique<app::SampleLoop>(*tap, *bus, *recording, clock, *log);
    loop->set_commands(true);
  }

  /// Moves the board's identifier groups (config.id_bases, can::IdGroup order) before
  /// configure(): the publisher and the loop are made again with them.
  void move_ids(const std::array<int, 4>& bases) {
    config.id_bases = bases;
    loop.reset();
    recording.reset();
    stalling.reset();
    publisher = std::make_unique<app::PublisherSink>(
        *bus, kNode, app::bus_dividers(config), app::bus_budget(config), app::id_bases(config));
    stalling = std::make_unique<StallingSink>(*publisher, clock);
    recording = std::make_unique<app::RecordingSink>(stalling.get(), 2 * std::size_t{samples});
    loop = std::make_unique<app::SampleLoop>(*tap, *bus, *recording, clock, *log);
    loop->set_commands(true);
  }

  void configure() {
    const Status st = loop->configure(cal, app::loop_options(config));
    if (!st.is_ok()) throw std::runtime_error(st.message());
  }

  /// Runs until the scenario's samples are all delivered.
  void run() {
    while (!source->finished()) loop->step();
  }

  /// Runs `n` cycles at most.
  void run_cycles(std::uint32_t n) {
    for (std::uint32_t i = 0; i < n && !source->finished(); ++i) loop->step();
  }

  /// Log lines the loop queued so far (formatted as the logger thread would).
  std::vector<std::string> drain_log() {
    std::vector<std::string> lines;
    app::LogRecord r;
    while (log->pop(r)) lines.push_back(app::format_record(r));
    return lines;
  }

  sim::Scenario s;
  app::FwConfig config;
  std::uint32_t samples = 0;
  std::unique_ptr<sim_board::SensorStream> stream;
  static constexpr std::uint8_t kNode = 1;
  std::unique_ptr<sim_board::ChipAdc> adc;
  app::SampleClock clock;
  std::unique_ptr<sim_board::SimSampleSource> source;
  std::unique_ptr<FaultySource> faulty;
  std::unique_ptr<TapSource> tap;
  std::unique_ptr<sim_board::MemoryCanBus> bus;
  std::unique_ptr<app::PublisherSink> publisher;
  std::unique_ptr<StallingSink> stalling;
  std::unique_ptr<app::RecordingSink> recording;
  std::unique_ptr<app::FwLogQueue> log;
  calib_file::CalibrationData factory;
  app::CalibrationSet cal;
  std::unique_ptr<app::SampleLoop> loop;
};

/// The recording header gfins-fw writes for this rig's board (rate, the chain's LSB, the
/// configured nominal geometry): for tests that attach a recorder to the loop.
inline recording::Header recording_header(const SimRig& rig) {
  recording::Header h;
  h.sample_rate_hz = rig.s.rate_hz;
  h.volts_per_count.fill(rig.adc->volts_per_count());
  h.geometry = rig.cal.config.nominal.cast<double>();
  return h;
}

/// The fix a receiver (1.5 m horizontal, 3 m vertical, 0.1 m/s) sends 50 ms after its time of
/// validity for a board at rest at the origin: position and velocity zero.
inline can::GnssFix gnss_fix_at_rest(std::uint8_t fix_id) {
  can::GnssFix fix;
  fix.fix_id = fix_id;
  fix.has_position = true;
  fix.has_velocity = true;
  fix.sigma_pos_h_m = 1.5;
  fix.sigma_pos_v_m = 3.0;
  fix.sigma_vel_mps = 0.1;
  fix.age_s = 0.05;
  return fix;
}

}  // namespace gfins::testing
