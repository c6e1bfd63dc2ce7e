// The simulated board (docs/firmware.md, "The simulated board"): the same firmware loop as on the
// board, fed through the same seams by simulation backends:
//
//   scenario → trajectory → QA-1100 sensor model → volts ─┐
//   sample clock → data-ready edge (seq, t_ns) ───────────┴→ ADC (chain) → RawSample → SampleLoop
//   SampleLoop → Publisher → hal::CanBus (MemoryCanBus here, or SocketCAN / a candump log file)
//
// Pacing: kFast takes the next edge at once, stamped with its scenario time (driven by the
// sample index, bit-exact run to run); kRealTime sleeps until each edge's time on the monotonic
// clock and stamps it with that time (for latency figures); kGpio waits for each conversion's
// data-ready edge on a real line (hal::DataReadyLine: lnx::GpiodDataReady on the virtual board's
// gpio-sim line) and carries the edge's kernel timestamp and sequence into the conversion.
//
// Fault injection (tests, docs/faults.md) sits at the places the faults happen: the ADC chain
// (CRC error, stuck or saturated channel, chip reset), the data-ready line (missing, extra and
// absent edges) and the CAN bus (MemoryCanBus: refusing frames, bus-off).
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "gfins/app/board.hpp"
#include "gfins/app/config.hpp"
#include "gfins/app/ports.hpp"
#include "gfins/app/sample_clock.hpp"
#include "gfins/calib_file/calibration_data.hpp"
#include "gfins/can/aiding_input.hpp"
#include "gfins/hal/can_bus.hpp"
#include "gfins/hal/clock.hpp"
#include "gfins/hal/data_ready.hpp"
#include "gfins/host_sim/gnss_model.hpp"
#include "gfins/host_sim/scenario.hpp"

namespace gfins::sim_board {

/// The monotonic clock through std::chrono::steady_clock (CLOCK_MONOTONIC on Linux).
class SteadyClock final : public hal::Clock {
 private:
  std::int64_t do_now_ns() override;
  Status do_sleep_until_ns(std::int64_t t_ns) override;
};

/// Scenario → six sensor voltages per sample (the analog side of the board).
class SensorStream {
 public:
  virtual ~SensorStream() = default;
  /// Volts at the six sensor outputs for conversion `seq` (called once per conversion, in order).
  virtual std::array<double, 6> volts(std::uint32_t seq) = 0;
};

/// The ADC between the sensor voltages and the RawSample: the register-level ADS131M06 model
/// behind the simulated SPI and data-ready line, read by the real driver (sim::SimulatedAdc).
/// Faults are injected into the chip and the line, where they happen on the board.
class ChipAdc {
 public:
  explicit ChipAdc(double sample_rate_hz);
  ~ChipAdc();
  ChipAdc(const ChipAdc&) = delete;
  ChipAdc& operator=(const ChipAdc&) = delete;

  Status start();
  /// Conversion `seq` of the sensor voltages at edge time t_ns, read through the driver.
  /// kUnavailable for a conversion whose data-ready edge was lost (drop_edge()).
  Result<RawSample> convert(const std::array<double, 6>& volts, std::uint32_t seq,
                            std::int64_t t_ns);
  /// Volts at the sensor per count (divider and ADC LSB).
  double volts_per_count() const;
  app::AdcCounters counters() const;

  void corrupt_next_frame();  // output CRC error on the next frame
  void stick_channel(int ch, std::int32_t code);
  void saturate_channel(int ch);
  void clear_channel_faults();
  void power_on_reset();  // the chip resets before the next conversion
  void drop_edge();       // the next conversion's data-ready edge is lost
  void extra_edge();      // a spurious edge before the next conversion

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Faults injected per conversion index (seq) or on the data-ready line.
struct FaultPlan {
  std::vector<std::uint32_t> crc_error_at;      // frame of this seq arrives with a bad CRC
  std::vector<std::uint32_t> missing_edges;     // the edge of this seq is lost (conversion unseen)
  std::vector<std::uint32_t> extra_edge_after;  // a spurious edge after this seq's edge
  std::uint32_t reset_at = 0;                   // the chip resets before this seq (0 = never)
  std::uint32_t silent_from = 0;                // no edges from this seq on ... (0 = never)
  std::uint32_t silent_edges = 0;               // ... for this many periods
  int stuck_channel = -1;                       // this channel's code freezes from stuck_from
  std::uint32_t stuck_from = 0;
  std::uint32_t stuck_until = 0;  // 0 = for ever
  int saturated_channel = -1;     // this channel sits at full scale ...
  std::uint32_t saturated_from = 0;
  std::uint32_t saturated_until = 0;  // ... until here (0 = for ever)
};

/// How the simulated board paces its samples: the firmware configuration's `sim.pacing`.
using Pacing = app::Pacing;

/// The data-ready line and the ADC of the simulated board, as the loop sees them.
class SimSampleSource final : public app::SampleSource {
 public:
  SimSampleSource(SensorStream& stream, ChipAdc& adc, hal::Clock& clock,
                  app::SampleClock* sample_clock, Pacing pacing, double sample_rate_hz,
                  std::uint32_t samples);
  /// kGpio pacing: conversion k happens at the edge whose sequence is the first edge's + k, at
  /// that edge's timestamp. Edges the line reports missing (a sequence step > 1) cost their
  /// conversions, as on the board: the sensor stream advances over them and the ADC driver
  /// counts them from the sequence gap (Ads131m06Counters::missed_edges, the Linux board's
  /// counter). `clock` must be the line's time base (CLOCK_MONOTONIC for libgpiod). The fault
  /// plan does not apply: the faults are made on the line and the bus.
  SimSampleSource(SensorStream& stream, ChipAdc& adc, hal::Clock& clock, hal::DataReadyLine& drdy,
                  std::uint32_t samples);

  void set_faults(const FaultPlan& f) { faults_ = f; }
  /// True once every sample of the run was delivered.
  bool finished() const { return remaining_ == 0; }
  /// Samples of the run not delivered yet.
  std::uint32_t remaining() const { return remaining_; }
  std::uint32_t next_seq() const { return next_seq_; }

 private:
  Result<RawSample> do_read_sample(std::int64_t timeout_ns) override;
  Result<RawSample> read_gpio_paced(std::int64_t timeout_ns);
  app::AdcCounters do_counters() const override;
  double do_volts_per_count() const override { return adc_.volts_per_count(); }
  std::int64_t edge_time(std::uint32_t seq) const;
  static bool contains(const std::vector<std::uint32_t>& v, std::uint32_t x);

  SensorStream& stream_;
  ChipAdc& adc_;
  hal::Clock& clock_;
  app::SampleClock* sample_clock_;
  Pacing pacing_;
  std::int64_t period_ns_;
  std::int64_t t0_ns_ = 0;
  std::uint32_t next_seq_ = 0;
  std::uint32_t remaining_;
  FaultPlan faults_{};
  std::uint32_t silent_left_ = 0;
  hal::DataReadyLine* drdy_ = nullptr;  // kGpio only
  bool have_first_edge_ = false;
  std::uint32_t first_edge_seq_ = 0;
};

/// ADC read failures the chip model cannot make (docs/faults.md, "ADC read error", "ADC dead"),
/// in front of a sample source (tests/firmware/faults_test.cpp; [[board.faults]] read_error and
/// adc_dead through ScheduledFaultSource):
///  - fail_reads(n): the next n reads take their conversion and then fail as an SPI transfer
///    error does (kIoError): that conversion is lost;
///  - set_dead(true): every read fails at once without waiting for an edge, as the ADS131M06
///    driver does in its kFailed state (kFailedPrecondition). When the ADC comes back, the
///    conversions made meanwhile are lost (read and dropped until one is not older than the
///    clock), so the sample clock never runs backwards;
///  - add_flags(n, flags): the next n samples carry `flags` besides their own (a producer that
///    flags a frame the chip model would not: a recording's saturated frames, counts off the
///    rails).
class FaultySource final : public app::SampleSource {
 public:
  FaultySource(app::SampleSource& inner, hal::Clock& clock) : inner_(inner), clock_(clock) {}
  void fail_reads(std::uint32_t n) { fail_ = n; }
  void add_flags(std::uint32_t n, std::uint32_t flags) {
    flag_n_ = n;
    flags_ = flags;
  }
  void set_dead(bool dead) {
    if (dead_ && !dead) revive_ = true;
    dead_ = dead;
  }
  bool dead() const { return dead_; }

 private:
  Result<RawSample> do_read_sample(std::int64_t timeout_ns) override;
  app::AdcCounters do_counters() const override { return inner_.counters(); }
  double do_volts_per_count() const override { return inner_.volts_per_count(); }

  app::SampleSource& inner_;
  hal::Clock& clock_;
  std::uint32_t fail_ = 0;
  std::uint32_t flag_n_ = 0;
  std::uint32_t flags_ = 0;
  bool dead_ = false;
  bool revive_ = false;
};

/// The scenario's [[board.faults]] on the simulated board (docs/simulation.md, "Board faults"):
/// the ADC and data-ready faults through the sample source's FaultPlan (each set before its
/// conversion comes), read errors and a dead ADC through a FaultySource in front of it, both by
/// the conversion's index (sample k of the run at k / rate).
class ScheduledFaultSource final : public app::SampleSource {
 public:
  ScheduledFaultSource(SimSampleSource& source, hal::Clock& clock,
                       const std::vector<sim::BoardFault>& faults, double rate_hz);

 private:
  Result<RawSample> do_read_sample(std::int64_t timeout_ns) override;
  app::AdcCounters do_counters() const override { return faulty_.counters(); }
  double do_volts_per_count() const override { return faulty_.volts_per_count(); }
  /// The FaultPlan's single-valued faults (reset, silence, stuck, saturated): each kind's first
  /// fault that has not ended by conversion `seq`.
  void refresh(std::uint32_t seq);

  struct Timed {
    sim::BoardFault fault;
    std::uint32_t from = 0;   // first conversion
    std::uint32_t until = 0;  // first conversion after it (from + 1 for an instant)
    bool applied = false;     // read_error: handed to the FaultySource
  };
  SimSampleSource& source_;
  hal::Clock& clock_;
  FaultySource faulty_;
  std::vector<Timed> faults_;
  FaultPlan plan_{};
  std::int64_t period_ns_;
  std::int64_t t0_ns_ = 0;
  bool have_t0_ = false;
};

/// The scenario's CAN faults (can_refuse, bus_off) on the board's output, by scenario time
/// (`now_s`: the time of the last sample read, as GnssReceiverBus takes it): a refusing sink drops
/// and counts every frame (kResourceExhausted), a bus-off controller drops and counts them too
/// (kUnavailable) and reports kBusOff; leaving bus-off counts a restart, as SocketCAN's automatic
/// restart does.
class FaultyCanBus final : public hal::CanBus {
 public:
  FaultyCanBus(std::unique_ptr<hal::CanBus> inner, const std::vector<sim::BoardFault>& faults,
               std::function<double()> now_s);

 private:
  Status do_send(const hal::CanFrame& f) override;
  Result<hal::CanFrame> do_receive(std::int64_t timeout_ns) override {
    return inner_->receive(timeout_ns);
  }
  void do_service() override {
    update();
    inner_->service();
  }
  hal::CanBusState do_state() const override;
  hal::CanCounters do_counters() const override;
  void update();
  bool within(sim::BoardFaultKind kind) const;

  std::unique_ptr<hal::CanBus> inner_;
  std::function<double()> now_s_;
  std::vector<sim::BoardFault> faults_;  // can_refuse and bus_off only
  hal::CanCounters own_{};               // what this layer dropped and its state changes
  bool bus_off_ = false;
};

/// An in-memory CAN bus: frames sent are kept (fixed capacity, the oldest overwritten), frames
/// queued with inject_rx() are received. Faults: refuse(true) makes every send fail as a full
/// queue does (kResourceExhausted, counted as dropped); bus_off(true) enters bus-off (sends fail
/// with kUnavailable, counted) until bus_off(false) (counted as a restart).
class MemoryCanBus final : public hal::CanBus {
 public:
  explicit MemoryCanBus(std::size_t capacity = 1u << 16, std::size_t rx_capacity = 64);

  void refuse(bool on) { refuse_ = on; }
  void bus_off(bool on);
  /// `n` received frames lost before the board read them, as SocketCAN reports a full socket
  /// receive queue (SO_RXQ_OVFL: hal::CanCounters::rx_kernel_dropped).
  void lose_received(std::uint32_t n) { counters_.rx_kernel_dropped += n; }
  /// Host → board frame (commands); false when the receive queue is full.
  bool inject_rx(const hal::CanFrame& f);
  /// Frames sent, oldest first (at most `capacity`); total() counts all ever sent.
  std::vector<hal::CanFrame> sent() const;
  std::uint64_t total() const { return total_; }
  void clear_sent() { head_ = 0, total_ = 0; }

 private:
  Status do_send(const hal::CanFrame& f) override;
  Result<hal::CanFrame> do_receive(std::int64_t timeout_ns) override;
  hal::CanBusState do_state() const override { return state_; }
  hal::CanCounters do_counters() const override { return counters_; }

  std::vector<hal::CanFrame> ring_;
  std::size_t head_ = 0;
  std::uint64_t total_ = 0;
  std::vector<hal::CanFrame> rx_;
  std::size_t rx_head_ = 0, rx_count_ = 0;
  bool refuse_ = false;
  hal::CanBusState state_ = hal::CanBusState::kErrorActive;
  hal::CanCounters counters_{};
};

/// The fix a sample becomes on the bus: position and velocity, the spec's σ, age = the latency,
/// fix id = index mod 16 (what `gfins-can gnss` sends and the simulated board's receiver too).
can::GnssFix to_gnss_fix(const sim::GnssSample& s, const sim::GnssSpec& spec);

/// The scenario's GNSS receiver on the simulated board's bus: a CanBus in front of the board's
/// own that, on each receive, first hands over the frames of the fixes sent by now (t_send ≤ the
/// scenario time of the last sample read), each fix's age stating how long before that sample
/// it was valid; everything else goes to and comes from `inner`.
class GnssReceiverBus final : public hal::CanBus {
 public:
  /// `now_s`: the scenario time of the last sample the loop read; `ids`: the board's identifier
  /// groups (can.*_id_base), at which the receiver sends.
  GnssReceiverBus(std::unique_ptr<hal::CanBus> inner, std::vector<sim::GnssSample> fixes,
                  const sim::GnssSpec& spec, std::uint8_t node_id, const can::IdBases& ids,
                  std::function<double()> now_s);
  std::size_t fixes_sent() const { return next_; }

 private:
  Status do_send(const hal::CanFrame& f) override { return inner_->send(f); }
  Result<hal::CanFrame> do_receive(std::int64_t timeout_ns) override;
  void do_service() override { inner_->service(); }
  hal::CanBusState do_state() const override { return inner_->state(); }
  hal::CanCounters do_counters() const override { return inner_->counters(); }

  std::unique_ptr<hal::CanBus> inner_;
  std::vector<sim::GnssSample> fixes_;
  sim::GnssSpec spec_;
  std::uint8_t node_id_;
  can::IdBases ids_;
  std::function<double()> now_s_;
  std::size_t next_ = 0;
  std::array<hal::CanFrame, 4> pending_{};
  std::size_t pending_next_ = 4;  // pending_[pending_next_..3] still to hand over
};

/// Stream of a host_sim scenario: trajectory and QA-1100 array model, computed sample by sample;
/// a HostError naming what cannot be built (trajectory, sensor model). Never throws.
sim::HostResult<std::unique_ptr<SensorStream>> make_scenario_stream(const sim::Scenario& s);

/// The factory calibration of the simulated array: its true scale factors, biases and
/// misalignment (the scenario's), the ADC chain's LSB, the scenario's compensator.
calib_file::CalibrationData scenario_calibration(const sim::Scenario& s, double volts_per_count);

// ---- gfins-fw on the simulated board (fw_board.cpp) -----------------------------------------

/// The simulated board of `c` (sim.scenario, sim.pacing, sim.duration_s; the CAN output and the
/// watchdog as the firmware opens them for every board).
app::BoardResult make_board(const app::FwConfig& c);

/// preflight()'s checks for this board: the scenario loads and runs at adc.sample_rate_hz.
std::string check_config(const app::FwConfig& c, const std::string& origin);

/// gfins-fw --replay (sim.recording set): the recording's samples and received frames through the
/// loop (replay_board.cpp; docs/replay.md, "Replay through the firmware").
app::BoardResult make_replay_board(const app::FwConfig& c);
/// preflight()'s checks for a replay: the recording opens, its rate and LSB fit the configuration.
std::string check_recording(const app::FwConfig& c, const std::string& origin);
/// Registers the simulated board (board.kind = "sim") in the firmware's board table.
void add_to(app::BoardTable& t);

}  // namespace gfins::sim_board
