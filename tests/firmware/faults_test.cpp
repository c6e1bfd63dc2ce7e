// Fault injection on the simulated board, one test per row of docs/faults.md: each fault is
// detected, counted (the loop's health counters), published (the frames actually sent on the
// in-memory bus, decoded here from the byte layout of docs/can-interface.md written out below, not
// through the firmware's message table), logged (the lines the logger thread would print, rate
// limited per kind), the loop keeps its rate (status frames per unit of sample time while the
// fault lasts), and navigation resumes or degrades as the table says.
//
// The oracle for "resumes" is the same scenario run without the fault, with a bound derived from
// the samples the fault removed (Resume below), and each test checks that a navigation frozen at
// the fault would violate that bound by a wide margin.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <optional>
#include <set>

#include "gfins/calib_file/calibration_file.hpp"
#include "gfins/can/aiding_input.hpp"
#include "gfins/can/command.hpp"
#include "gfins/nav_core/math.hpp"
#include "sim_rig.hpp"

namespace gfins::app {
namespace {

using testing::SimRig;

// ---- The bus, as a receiver reads it (docs/can-interface.md, "Messages"), node id 1 ---------
// Classic CAN, 8 bytes, little-endian signals: payload bit b is bit b%8 of byte b/8.
constexpr std::uint32_t kNodeId = 1;
constexpr std::uint32_t kEpochId = 0x100 + kNodeId;     // TimeUs 0|32, SampleCount 32|16, Mode 48|4
constexpr std::uint32_t kStatusId = 0x110 + kNodeId;    // StatusFlags 0|20, CalId 20|32
constexpr std::uint32_t kVelocityId = 0x170 + kNodeId;  // VelN 0|16 signed x0.01 m/s, NA = -32768
constexpr std::uint32_t kHealthAdcId = 0x1A0 + kNodeId;     // MissedEdges 0|16, AdcCrcErrors 16|16,
                                                            // AdcResets 32|8, StuckMask 40|6,
                                                            // LogDropped 46|6
constexpr std::uint32_t kHealthSystemId = 0x1B0 + kNodeId;  // SaturatedSamples 0|16,
                                                            // CanTxDropped 16|16, BusOffEvents
                                                            // 32|8, LoopOverruns 40|12
constexpr std::uint32_t kResponseId = 0x680 + kNodeId;      // Opcode 0|8, Token 8|8, Part 16|8,
                                                            // Result 24|8 (part 0)
constexpr std::int64_t kNotAvailable16 = -32768;
// StatusFlags bits (docs/can-interface.md, GfinsStatus.StatusFlags)
constexpr std::uint32_t kBitSampleGap = 1u << 1;
constexpr std::uint32_t kBitInputInvalid = 1u << 2;
constexpr std::uint32_t kBitNotAvailable = 1u << 5;
constexpr std::uint32_t kBitCrc = 1u << 6;
constexpr std::uint32_t kBitSaturated = 1u << 7;
constexpr std::uint32_t kBitStuck = 1u << 8;
constexpr std::uint32_t kBitNominalCal = 1u << 9;
constexpr std::uint32_t kBitOverrun = 1u << 10;
constexpr std::uint32_t kBitTxDropped = 1u << 11;
constexpr std::uint32_t kBitDegraded = 1u << 13;
constexpr std::uint32_t kBitAdcRecovered = 1u << 14;
constexpr std::uint32_t kBitDataReadyLost = 1u << 15;
constexpr std::uint32_t kBitBusOff = 1u << 16;
constexpr std::uint32_t kBitExtraEdge = 1u << 17;
constexpr std::uint32_t kBitRxLost = 1u << 18;
constexpr std::uint32_t kBitAdcReadError = 1u << 19;
constexpr std::uint32_t kModeNavigating = 2;

std::uint64_t payload(const hal::CanFrame& f) {
  std::uint64_t p = 0;
  for (int i = 7; i >= 0; --i) p = (p << 8) | f.data[static_cast<std::size_t>(i)];
  return p;
}
std::uint64_t bits(std::uint64_t p, unsigned start, unsigned len) {
  return (p >> start) & ((std::uint64_t{1} << len) - 1);
}
std::int64_t signed_bits(std::uint64_t p, unsigned start, unsigned len) {
  const auto v = static_cast<std::int64_t>(bits(p, start, len));
  return v >= (std::int64_t{1} << (len - 1)) ? v - (std::int64_t{1} << len) : v;
}

/// One epoch on the bus: a GfinsEpoch frame and the frames after it up to the next one.
struct BusEpoch {
  std::uint32_t time_us = 0;
  std::uint32_t count = 0;  // SampleCount (16 bits)
  std::uint32_t mode = 0;
  std::uint32_t flags = 0;
  std::uint32_t cal_id = 0;
  bool has_status = false;
  bool has_velocity = false;
  std::int64_t vel_n_raw = 0;
  bool has_health = false;  // both health frames
  std::uint32_t missed = 0, crc = 0, resets = 0, stuck = 0, log_dropped = 0;
  std::uint32_t saturated = 0, tx_dropped = 0, bus_off = 0, overruns = 0;
};

struct Bus {
  std::vector<BusEpoch> epochs;
  std::vector<std::uint32_t> response_results;  // Result of each status response (part 0)
};

Bus decode(const std::vector<hal::CanFrame>& frames) {
  Bus bus;
  for (const hal::CanFrame& f : frames) {
    const std::uint64_t p = payload(f);
    if (f.id == kEpochId) {
      BusEpoch e;
      e.time_us = static_cast<std::uint32_t>(bits(p, 0, 32));
      e.count = static_cast<std::uint32_t>(bits(p, 32, 16));
      e.mode = static_cast<std::uint32_t>(bits(p, 48, 4));
      bus.epochs.push_back(e);
      continue;
    }
    if (f.id == kResponseId && bits(p, 16, 8) == 0) {
      bus.response_results.push_back(static_cast<std::uint32_t>(bits(p, 24, 8)));
      continue;
    }
    if (bus.epochs.empty()) continue;
    BusEpoch& e = bus.epochs.back();
    if (f.id == kStatusId) {
      e.has_status = true;
      e.flags = static_cast<std::uint32_t>(bits(p, 0, 20));
      e.cal_id = static_cast<std::uint32_t>(bits(p, 20, 32));
    } else if (f.id == kVelocityId) {
      e.has_velocity = true;
      e.vel_n_raw = signed_bits(p, 0, 16);
    } else if (f.id == kHealthAdcId) {
      e.has_health = true;
      e.missed = static_cast<std::uint32_t>(bits(p, 0, 16));
      e.crc = static_cast<std::uint32_t>(bits(p, 16, 16));
      e.resets = static_cast<std::uint32_t>(bits(p, 32, 8));
      e.stuck = static_cast<std::uint32_t>(bits(p, 40, 6));
      e.log_dropped = static_cast<std::uint32_t>(bits(p, 46, 6));
    } else if (f.id == kHealthSystemId) {
      e.saturated = static_cast<std::uint32_t>(bits(p, 0, 16));
      e.tx_dropped = static_cast<std::uint32_t>(bits(p, 16, 16));
      e.bus_off = static_cast<std::uint32_t>(bits(p, 32, 8));
      e.overruns = static_cast<std::uint32_t>(bits(p, 40, 12));
    }
  }
  return bus;
}

Bus decode(const SimRig& rig) { return decode(rig.bus->sent()); }

// The rig's board started afresh on `cal` (what gfins-fw does after load_calibration), run to
// its end, its bus decoded.
Bus run_from_start(SimRig& rig, const StartupCalibration& cal, const FwConfig& c) {
  rig.loop = std::make_unique<SampleLoop>(*rig.tap, *rig.bus, *rig.recording, rig.clock, *rig.log);
  EXPECT_TRUE(rig.loop->configure(cal.set, loop_options(c)).is_ok());
  rig.run();
  return decode(rig);
}

/// The bus epoch whose SampleCount is `seq` (mod 2^16); fails the test when there is none.
const BusEpoch& on_bus(const Bus& bus, std::uint32_t seq) {
  for (const BusEpoch& e : bus.epochs) {
    if (e.count == (seq & 0xFFFFu)) return e;
  }
  ADD_FAILURE() << "no epoch with sample count " << seq << " on the bus";
  static const BusEpoch kNone{};
  return kNone;
}
/// The first bus epoch carrying the health frames at or after sample `seq`.
const BusEpoch& health_after(const Bus& bus, std::uint32_t seq) {
  for (const BusEpoch& e : bus.epochs) {
    if (e.has_health && e.count >= seq) return e;
  }
  ADD_FAILURE() << "no health frames on the bus at or after sample " << seq;
  static const BusEpoch kNone{};
  return kNone;
}

// ---- The loop's rate on the bus -------------------------------------------------------------
// Status frames go out with every Epoch frame, on the sample counters divisible by the Epoch
// divider (docs/can-interface.md, default 10 at 1 kHz: 100 Hz). The loop keeps its rate when
// the bus carries exactly one status frame for every such counter in a window, except for the
// samples that no longer exist (edges lost on the line: `lost`). A loop that stops publishing
// while the ADC is silent, or spins and publishes the same counter again, fails this.
constexpr std::uint32_t kEpochDivider = 10;
void expect_status_rate(const Bus& bus, std::uint32_t from, std::uint32_t to,
                        const std::set<std::uint32_t>& lost = {}) {
  std::vector<std::uint32_t> expected;
  for (std::uint32_t k = from; k < to; ++k) {
    if (k % kEpochDivider == 0 && lost.count(k) == 0) expected.push_back(k);
  }
  std::vector<std::uint32_t> seen;
  std::uint32_t previous_time = 0;
  for (const BusEpoch& e : bus.epochs) {
    if (e.count < from || e.count >= to) continue;
    EXPECT_TRUE(e.has_status) << "epoch " << e.count << " without its status frame";
    // TimeUs follows the sample counter: 1 ms per sample at 1 kHz.
    if (!seen.empty()) {
      EXPECT_EQ(e.time_us - previous_time, (e.count - seen.back()) * 1000u) << e.count;
    }
    previous_time = e.time_us;
    seen.push_back(e.count);
  }
  EXPECT_EQ(seen, expected) << "status frames in samples [" << from << ", " << to << ")";
}
/// Every status frame of samples [from, to) has all of `set_bits`.
void expect_flags(const Bus& bus, std::uint32_t from, std::uint32_t to, std::uint32_t set_bits) {
  std::uint32_t n = 0;
  for (const BusEpoch& e : bus.epochs) {
    if (e.count < from || e.count >= to) continue;
    ++n;
    EXPECT_EQ(e.flags & set_bits, set_bits)
        << "sample " << e.count << " flags " << std::hex << e.flags;
  }
  EXPECT_GT(n, 0u) << "no status frame in [" << from << ", " << to << ")";
}

// ---- The log, rate-limited per kind (docs/faults.md: one line per second per kind) ----------
std::vector<std::string> lines_with(const std::vector<std::string>& lines, const std::string& key) {
  std::vector<std::string> out;
  for (const auto& l : lines) {
    if (l.find(key) != std::string::npos) out.push_back(l);
  }
  return out;
}

// ---- "Navigation resumes" ------------------------------------------------------------------
// A rejected or lost sample j is not integrated: the next good sample g is integrated over the
// periods since the last integrated one instead. In the strapdown (docs/navigation.md) the body
// rate is ω_k = ω_{k-1} + ω̇_k·dt, so the run with the hole ends with
//     δω = dt · Σ_j (ω̇_g − ω̇_j)
// against the fault-free run, and δf = dt · Σ_j (f_g − f_j) of velocity directly. The rate error
// tilts the attitude by δω·t after t seconds and leaks gravity into the horizontal velocity,
// δv(T) = g·|δω|·T²/2 at the end of the run, T after the fault. The values ω̇_j, f_j are the
// fault-free run's own (its recorded epochs), so the bound is computed from this realisation
// rather than from a noise figure. The model overstates the leak already (a rate error about the
// vertical does not tilt, yet |δω| counts it); kResumeSafety covers what it leaves out (the
// second-order terms: |ω| < 0.02 rad/s here, the cross terms ω×δω are < 1e-3 relative; float32
// rounding, 1e-7 relative). Measured: the differences are 0.35..0.75 of the unscaled bound.
constexpr double kResumeSafety = 1.5;
// A navigation frozen at the fault (or restarted from rest) would end |v_base(end) − v_base(fault)|
// away from the fault-free run; each test checks that this is at least kFrozenMargin times the
// bound, so the bound cannot be passed by a loop that stopped navigating. Faults remove at most
// three samples in the tests that check the bound: the bound grows with the hole (√k for noise),
// the frozen gap does not.
constexpr double kFrozenMargin = 3.0;

constexpr double kRunSeconds = 6.0;
constexpr std::uint32_t kFaultSeq = 4000;  // faults at 4 s: aligned at 1 s, 2 s left to grow

struct Resume {
  double bound = 0;       // m/s
  double frozen_gap = 0;  // m/s, what a frozen navigation would be off by
  double difference = 0;  // m/s, |v_fault(end) − v_base(end)|
};

Resume resume(const SimRig& base, const SimRig& faulty, const std::set<std::uint32_t>& skipped) {
  const auto& epochs = base.recording->epochs();
  const auto by_seq = [&](std::uint32_t seq) -> const can::Epoch& {
    const auto it = std::find_if(epochs.begin(), epochs.end(),
                                 [&](const can::Epoch& e) { return e.nav.seq == seq; });
    if (it == epochs.end()) throw std::runtime_error("baseline has no epoch for that sample");
    return *it;
  };
  constexpr double kDt = 1e-3;  // rest.toml: 1 kHz
  Eigen::Vector3d dw = Eigen::Vector3d::Zero();
  Eigen::Vector3d df = Eigen::Vector3d::Zero();
  for (std::uint32_t j : skipped) {
    std::uint32_t g = j + 1;
    while (skipped.count(g) != 0) ++g;
    dw += kDt * (by_seq(g).nav.wdot_b - by_seq(j).nav.wdot_b).cast<double>();
    df += kDt * (by_seq(g).nav.f_b - by_seq(j).nav.f_b).cast<double>();
  }
  const double first = skipped.empty() ? 0.0 : static_cast<double>(*skipped.begin()) * kDt;
  const double t_left = kRunSeconds - first;
  Resume r;
  r.bound = kResumeSafety * (nav::kStandardGravity * dw.norm() * t_left * t_left / 2 + df.norm());
  const auto& v_end = base.loop->pipeline().state().v_n;
  const auto& v_fault = skipped.empty() ? v_end : by_seq(*skipped.begin() - 1).nav.v_n;
  r.frozen_gap = static_cast<double>((v_end - v_fault).norm());
  r.difference = static_cast<double>((faulty.loop->pipeline().state().v_n - v_end).norm());
  return r;
}

void expect_resumes(const Resume& r) {
  std::printf(
      "[ resume   ] |v - v_fault-free| %.4f m/s, bound %.4f m/s, frozen would be %.4f m/s\n",
      r.difference, r.bound, r.frozen_gap);
  EXPECT_LT(r.difference, r.bound) << "frozen would be " << r.frozen_gap;
  EXPECT_GT(r.frozen_gap, kFrozenMargin * r.bound)
      << "the bound " << r.bound << " m/s would not tell a frozen navigation from a resumed one";
}

class CountingWatchdog final : public hal::Watchdog {
 public:
  std::uint64_t kicks = 0;

 private:
  Status do_kick() override {
    ++kicks;
    return Status::ok();
  }
};

class Faults : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    baseline_ = new SimRig("rest", kRunSeconds);
    baseline_->configure();
    baseline_->run();
    ASSERT_EQ(baseline_->loop->mode(), can::Mode::kNavigating);
  }
  static void TearDownTestSuite() {
    delete baseline_;
    baseline_ = nullptr;
  }
  SimRig& make(const sim_board::FaultPlan& f = {}, double seconds = kRunSeconds) {
    rig_ = std::make_unique<SimRig>("rest", seconds, f);
    rig_->configure();
    rig_->loop->set_watchdog(&watchdog_);
    return *rig_;
  }
  SimRig& run(const sim_board::FaultPlan& f) {
    make(f);
    rig_->run();
    lines_ = rig_->drain_log();
    return *rig_;
  }
  static SimRig* baseline_;
  std::unique_ptr<SimRig> rig_;
  std::vector<std::string> lines_;
  CountingWatchdog watchdog_;
};
SimRig* Faults::baseline_ = nullptr;

TEST_F(Faults, CrcErrorIsCountedRejectedPublishedLoggedAndNavigationResumes) {
  sim_board::FaultPlan f;
  f.crc_error_at = {kFaultSeq, kFaultSeq + 1, kFaultSeq + 500};
  SimRig& rig = run(f);
  EXPECT_EQ(rig.loop->health().crc_errors, 3u);
  EXPECT_EQ(rig.loop->health().rejected_samples, 3u);
  EXPECT_EQ(rig.loop->health().samples, rig.samples);  // every edge read
  const Bus bus = decode(rig);
  EXPECT_EQ(health_after(bus, kFaultSeq + 501).crc, 3u);
  EXPECT_EQ(on_bus(bus, kFaultSeq).flags & kBitInputInvalid, kBitInputInvalid);  // that sample
  expect_flags(bus, kFaultSeq, kFaultSeq + 1000, kBitCrc);  // held 1 s after each
  EXPECT_EQ(on_bus(bus, kFaultSeq + 10).mode, kModeNavigating);
  EXPECT_EQ(on_bus(bus, kFaultSeq + 10).flags & kBitDegraded, 0u);  // a CRC error alone
  EXPECT_EQ(on_bus(bus, kFaultSeq + 1600).flags & kBitCrc, 0u);     // expired
  expect_status_rate(bus, 1000, rig.samples);
  // Three occurrences within 1 s: one line (the rate limit), carrying the counter.
  const auto crc = lines_with(lines_, "CRC error");
  ASSERT_EQ(crc.size(), 1u);
  EXPECT_NE(crc[0].find("(CRC errors: 1;"), std::string::npos) << crc[0];
  expect_resumes(resume(*baseline_, rig, {kFaultSeq, kFaultSeq + 1, kFaultSeq + 500}));
}

TEST_F(Faults, MissingEdgesAreCountedAsGapsAndNavigationIntegratesAcross) {
  sim_board::FaultPlan f;
  f.missing_edges = {kFaultSeq, kFaultSeq + 1, kFaultSeq + 2, kFaultSeq + 1500};
  SimRig& rig = run(f);
  EXPECT_EQ(rig.loop->health().missed_edges, 4u);
  EXPECT_EQ(rig.loop->health().samples, rig.samples - 4);
  EXPECT_EQ(rig.loop->pipeline().counters().missed_samples, 4u);
  const Bus bus = decode(rig);
  EXPECT_EQ(health_after(bus, kFaultSeq + 3).missed, 3u);
  EXPECT_EQ(health_after(bus, kFaultSeq + 1501).missed, 4u);
  expect_flags(bus, kFaultSeq + 10, kFaultSeq + 1000, kBitSampleGap);
  EXPECT_EQ(on_bus(bus, kFaultSeq + 10).flags & kBitDegraded, 0u);
  // The lost samples have no epoch: the edge never came, the loop never saw them.
  expect_status_rate(bus, 1000, rig.samples, {kFaultSeq, kFaultSeq + 1500});
  // Two occurrences 1.5 s apart: two lines.
  EXPECT_EQ(lines_with(lines_, "missed before").size(), 2u);
  expect_resumes(resume(*baseline_, rig, {kFaultSeq, kFaultSeq + 1, kFaultSeq + 2}));
}

TEST_F(Faults, ExtraEdgeIsCountedAndChangesNothingElse) {
  sim_board::FaultPlan f;
  f.extra_edge_after = {kFaultSeq};
  SimRig& rig = run(f);
  EXPECT_EQ(rig.loop->health().extra_edges, 1u);
  EXPECT_EQ(rig.loop->health().missed_edges, 0u);
  const Bus bus = decode(rig);
  expect_flags(bus, kFaultSeq + 10, kFaultSeq + 1000, kBitExtraEdge);
  expect_status_rate(bus, 1000, rig.samples);
  EXPECT_EQ(lines_with(lines_, "without a new conversion").size(), 1u);
  // The same samples reached the core: the navigation frames are the fault-free run's.
  const Bus base = decode(*baseline_);
  EXPECT_EQ(on_bus(bus, 5990).vel_n_raw, on_bus(base, 5990).vel_n_raw);
  EXPECT_EQ(rig.loop->pipeline().state().v_n, baseline_->loop->pipeline().state().v_n);
}

TEST_F(Faults, ShortSilenceOnDataReadyTimesOutDegradesThenResumes) {
  sim_board::FaultPlan f;
  f.silent_from = kFaultSeq;
  f.silent_edges = 3;  // one read timeout of 3 periods
  SimRig& rig = run(f);
  EXPECT_EQ(rig.loop->health().drdy_timeouts, 1u);
  EXPECT_EQ(rig.loop->health().missed_edges, 3u);
  const Bus bus = decode(rig);
  // The silent samples' epochs are on the bus all the same: no navigation, the fault bits.
  const BusEpoch& silent = on_bus(bus, kFaultSeq);
  EXPECT_EQ(silent.flags & (kBitDataReadyLost | kBitDegraded | kBitInputInvalid | kBitNotAvailable),
            kBitDataReadyLost | kBitDegraded | kBitInputInvalid | kBitNotAvailable);
  EXPECT_EQ(silent.vel_n_raw, kNotAvailable16);
  expect_flags(bus, kFaultSeq + 10, kFaultSeq + 1000, kBitDataReadyLost | kBitDegraded);
  EXPECT_EQ(on_bus(bus, kFaultSeq + 1100).flags & kBitDegraded, 0u);  // 1 s after the last
  EXPECT_EQ(health_after(bus, kFaultSeq + 3).missed, 3u);
  expect_status_rate(bus, 1000, rig.samples);
  EXPECT_EQ(lines_with(lines_, "no data-ready edge").size(), 1u);
  EXPECT_EQ(rig.loop->mode(), can::Mode::kNavigating);
  std::set<std::uint32_t> lost;
  for (std::uint32_t k = 0; k < 3; ++k) lost.insert(kFaultSeq + k);
  expect_resumes(resume(*baseline_, rig, lost));
}

TEST_F(Faults, LongSilenceKeepsStatusAndHealthFramesAtTheirRatesAndLogsOncePerSecond) {
  // 1.5 s without a data-ready edge: 500 timeouts of 3 periods.
  constexpr std::uint32_t kFrom = 3000, kEdges = 1500;
  constexpr std::uint32_t kTimeoutPeriods = 3;  // docs/faults.md
  sim_board::FaultPlan f;
  f.silent_from = kFrom;
  f.silent_edges = kEdges;
  SimRig& rig = make(f);
  rig.run_cycles(kFrom);  // samples 0..2999
  std::uint32_t timeouts = 0, cycles = 0;
  while (rig.source->next_seq() < kFrom + kEdges && cycles < 10 * kEdges) {
    timeouts += rig.loop->step() == SampleLoop::Cycle::kTimeout ? 1 : 0;
    ++cycles;
  }
  // The loop waited for each timeout: one cycle per 3 periods, not a spin.
  EXPECT_EQ(cycles, kEdges / kTimeoutPeriods);
  EXPECT_EQ(timeouts, kEdges / kTimeoutPeriods);
  rig.run();
  lines_ = rig.drain_log();
  EXPECT_EQ(rig.loop->health().drdy_timeouts, kEdges / kTimeoutPeriods);
  const Bus bus = decode(rig);
  // Status frames at 100 Hz of sample time through the silence, each with the fault bits, the
  // navigation values not available; the health frames at their 1 Hz (samples 3000 and 4000).
  expect_status_rate(bus, 1000, rig.samples);
  expect_flags(bus, kFrom, kFrom + kEdges,
               kBitDataReadyLost | kBitDegraded | kBitInputInvalid | kBitNotAvailable);
  for (std::uint32_t k = kFrom; k < kFrom + kEdges; k += kEpochDivider) {
    EXPECT_EQ(on_bus(bus, k).vel_n_raw, kNotAvailable16) << k;
  }
  EXPECT_TRUE(on_bus(bus, kFrom).has_health);
  EXPECT_TRUE(on_bus(bus, kFrom + 1000).has_health);
  EXPECT_EQ(health_after(bus, kFrom + kEdges).missed, kEdges);
  // One line per second per kind: timeouts every 3 ms from t0 give lines at t0 and at the first
  // timeout >= 1 s later, the 334th (334 · 3 ms = 1.002 s): 333 held back in between.
  const auto lines = lines_with(lines_, "no data-ready edge");
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_NE(lines[1].find("(timeouts: 335; 333 more since the last line)"), std::string::npos)
      << lines[1];
  EXPECT_EQ(rig.loop->health().log_dropped, 0u);
}

TEST_F(Faults, AdcResetMidRunIsCountedAndNavigationContinues) {
  sim_board::FaultPlan f;
  f.reset_at = kFaultSeq;
  SimRig& rig = run(f);
  EXPECT_EQ(rig.loop->health().adc_resets, 1u);
  // The conversion the reset hit is lost: the driver reconfigures the chip in that read.
  EXPECT_EQ(rig.loop->health().missed_edges, 1u);
  const Bus bus = decode(rig);
  EXPECT_EQ(health_after(bus, kFaultSeq + 1).resets, 1u);
  expect_flags(bus, kFaultSeq + 10, kFaultSeq + 1000, kBitAdcRecovered);
  expect_status_rate(bus, 1000, rig.samples, {kFaultSeq});
  EXPECT_EQ(lines_with(lines_, "ADC reset").size(), 1u);
  EXPECT_EQ(rig.loop->mode(), can::Mode::kNavigating);
  expect_resumes(resume(*baseline_, rig, {kFaultSeq}));
}

TEST_F(Faults, StuckChannelIsDetectedAfterKSamplesDegradesAndClears) {
  sim_board::FaultPlan f;
  f.stuck_channel = 2;
  f.stuck_from = kFaultSeq;
  f.stuck_until = kFaultSeq + 500;
  SimRig& rig = make(f);
  // Health frames every 10 ms so the stuck mask is seen while it lasts.
  ASSERT_TRUE(rig.publisher->set_divider(10, 10).is_ok());
  rig.run();
  lines_ = rig.drain_log();
  EXPECT_EQ(rig.loop->health().stuck_events, 1u);
  const Bus bus = decode(rig);
  // K = 50 repeats (docs/faults.md): not at sample 4040, at 4050.
  EXPECT_EQ(on_bus(bus, kFaultSeq + 40).stuck, 0u);
  EXPECT_EQ(on_bus(bus, kFaultSeq + 50).stuck, 1u << 2);
  expect_flags(bus, kFaultSeq + 50, kFaultSeq + 500, kBitStuck | kBitDegraded);
  EXPECT_EQ(on_bus(bus, kFaultSeq + 510).stuck, 0u);  // moves again: cleared
  EXPECT_EQ(on_bus(bus, kFaultSeq + 510).flags & (kBitStuck | kBitDegraded), 0u);
  expect_status_rate(bus, 1000, rig.samples);
  EXPECT_EQ(lines_with(lines_, "stuck: code unchanged").size(), 1u);
  EXPECT_EQ(lines_with(lines_, "stuck channel mask now 0").size(), 1u);
  EXPECT_EQ(rig.loop->mode(), can::Mode::kNavigating);
}

TEST_F(Faults, SaturatedChannelIsRejectedDegradesAndNavigationResumes) {
  sim_board::FaultPlan f;
  f.saturated_channel = 0;
  f.saturated_from = kFaultSeq;
  f.saturated_until = kFaultSeq + 3;
  SimRig& rig = run(f);
  EXPECT_EQ(rig.loop->health().saturated_samples, 3u);
  EXPECT_EQ(rig.loop->health().rejected_samples, 3u);
  EXPECT_EQ(rig.loop->pipeline().counters().rejected, 3u);
  const Bus bus = decode(rig);
  EXPECT_EQ(on_bus(bus, kFaultSeq).flags & (kBitSaturated | kBitInputInvalid | kBitDegraded),
            kBitSaturated | kBitInputInvalid | kBitDegraded);
  expect_flags(bus, kFaultSeq + 10, kFaultSeq + 1000, kBitSaturated | kBitDegraded);
  EXPECT_EQ(on_bus(bus, kFaultSeq + 10).flags & kBitInputInvalid, 0u);  // the next one is good
  EXPECT_EQ(health_after(bus, kFaultSeq + 10).saturated, 3u);
  expect_status_rate(bus, 1000, rig.samples);
  const auto sat = lines_with(lines_, "full scale");
  ASSERT_EQ(sat.size(), 1u);  // three in 3 ms: one line
  EXPECT_NE(sat[0].find("mask 0x1"), std::string::npos) << sat[0];
  EXPECT_EQ(rig.loop->mode(), can::Mode::kNavigating);
  std::set<std::uint32_t> lost;
  for (std::uint32_t k = 0; k < 3; ++k) lost.insert(kFaultSeq + k);
  expect_resumes(resume(*baseline_, rig, lost));
}

TEST_F(Faults, LoopOverrunIsCountedPublishedLoggedAndNavigationIsUntouched) {
  SimRig& rig = make();
  rig.run_cycles(kFaultSeq);
  // Five cycles in a row finish 1.5 periods after their edge.
  rig.stalling->stall(5, 1500000);
  rig.run();
  lines_ = rig.drain_log();
  EXPECT_EQ(rig.loop->health().loop_overruns, 5u);
  EXPECT_EQ(rig.loop->health().samples, rig.samples);
  const Bus bus = decode(rig);
  EXPECT_EQ(health_after(bus, kFaultSeq + 5).overruns, 5u);
  expect_flags(bus, kFaultSeq + 10, kFaultSeq + 1000, kBitOverrun);
  expect_status_rate(bus, 1000, rig.samples);
  const auto o = lines_with(lines_, "loop overrun");
  ASSERT_EQ(o.size(), 1u);
  EXPECT_NE(o[0].find("cycle took 1500000 ns of a 1000000 ns period"), std::string::npos) << o[0];
  EXPECT_EQ(rig.loop->pipeline().state().v_n, baseline_->loop->pipeline().state().v_n);
}

TEST_F(Faults, AdcReadErrorLosesThatSampleIsPublishedAndNavigationResumes) {
  SimRig& rig = make();
  rig.run_cycles(kFaultSeq);  // samples 0..3999
  rig.faulty->fail_reads(3);  // the reads of 4000..4002 fail after the edge
  rig.run();
  lines_ = rig.drain_log();
  EXPECT_EQ(rig.loop->health().adc_read_errors, 3u);
  EXPECT_EQ(rig.loop->health().missed_edges, 3u);
  const Bus bus = decode(rig);
  // Sample 4000 has an epoch all the same (no navigation, the read-error bit)...
  const BusEpoch& e = on_bus(bus, kFaultSeq);
  EXPECT_EQ(e.flags & (kBitAdcReadError | kBitInputInvalid | kBitNotAvailable),
            kBitAdcReadError | kBitInputInvalid | kBitNotAvailable);
  EXPECT_EQ(e.vel_n_raw, kNotAvailable16);
  // ... and the bit is held for 1 s, degraded (the ADC did not deliver).
  expect_flags(bus, kFaultSeq + 10, kFaultSeq + 1000, kBitAdcReadError | kBitDegraded);
  expect_status_rate(bus, 1000, rig.samples);
  EXPECT_EQ(lines_with(lines_, "ADC read failed").size(), 1u);
  EXPECT_EQ(watchdog_.kicks, rig.loop->health().samples + 3u);  // every cycle
  expect_resumes(resume(*baseline_, rig, {kFaultSeq, kFaultSeq + 1, kFaultSeq + 2}));
}

TEST_F(Faults, DeadAdcKeepsTheLoopAtItsPeriodPublishingTheFault) {
  SimRig& rig = make();
  rig.run_cycles(kFaultSeq);  // samples 0..3999
  // The driver gives up (kFailed): every read returns at once, for 1.5 s of sample time.
  constexpr std::int64_t kDeadNs = 1500000000;
  constexpr std::uint32_t kDeadPeriods = 1500;
  const std::int64_t t0 = rig.clock.now_ns();
  rig.faulty->set_dead(true);
  std::uint32_t cycles = 0;
  while (rig.clock.now_ns() < t0 + kDeadNs && cycles < 100 * kDeadPeriods) {
    EXPECT_EQ(rig.loop->step(), SampleLoop::Cycle::kReadError);
    ++cycles;
  }
  // One cycle per sample period: the loop waited each time (a spinning loop would run
  // 150,000 cycles here without the sample clock moving).
  EXPECT_EQ(cycles, kDeadPeriods);
  EXPECT_EQ(watchdog_.kicks, rig.loop->health().samples + kDeadPeriods);  // < 10 s: kicked
  EXPECT_TRUE(rig.loop->kicking_watchdog());
  rig.faulty->set_dead(false);
  rig.run();
  lines_ = rig.drain_log();
  EXPECT_EQ(rig.loop->health().adc_read_errors, kDeadPeriods);
  const Bus bus = decode(rig);
  // Status frames at 100 Hz through the outage (samples 4000..5499), health frames at 1 Hz.
  expect_status_rate(bus, 1000, kFaultSeq + kDeadPeriods);
  expect_flags(bus, kFaultSeq, kFaultSeq + kDeadPeriods,
               kBitAdcReadError | kBitDegraded | kBitInputInvalid | kBitNotAvailable);
  EXPECT_TRUE(on_bus(bus, kFaultSeq).has_health);
  EXPECT_TRUE(on_bus(bus, kFaultSeq + 1000).has_health);
  // Reads failing every 1 ms for 1.5 s: lines at 0 and 1 s, 999 held back in between.
  const auto lines = lines_with(lines_, "ADC read failed");
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_NE(lines[1].find("(read errors: 1001; 999 more since the last line)"), std::string::npos)
      << lines[1];
}

TEST_F(Faults, AdcDeadForTenSecondsStopsTheWatchdogKicks) {
  SimRig& rig = make({}, 16.0);  // samples left for when the ADC comes back at 14 s
  rig.run_cycles(2000);
  rig.faulty->set_dead(true);
  const std::int64_t t0 = rig.clock.now_ns();
  std::uint64_t kicks_at_10s = 0;
  // docs/faults.md: kicks stop once the ADC has delivered nothing for 10 s.
  constexpr std::int64_t kDeadLimitNs = 10000000000;
  std::uint32_t cycles = 0;  // bounded: a loop that spins would never move the sample clock
  while (rig.clock.now_ns() < t0 + kDeadLimitNs + 2000000000 && ++cycles < 100000) {
    rig.loop->step();
    if (rig.clock.now_ns() <= t0 + kDeadLimitNs - 2000000) kicks_at_10s = watchdog_.kicks;
  }
  const std::uint64_t kicks_dead = watchdog_.kicks;
  EXPECT_EQ(cycles, 12000u);  // one per period
  EXPECT_FALSE(rig.loop->kicking_watchdog());
  // Kicked for 10 s at 1 kHz (±2 cycles at the ends of the window), then not at all.
  EXPECT_NEAR(static_cast<double>(kicks_dead - 2000), 10000.0, 2.0);
  EXPECT_LE(kicks_dead - kicks_at_10s, 2u);
  lines_ = rig.drain_log();
  EXPECT_EQ(lines_with(lines_, "watchdog kicks stop").size(), 1u);
  // The ADC comes back: kicks resume.
  rig.faulty->set_dead(false);
  rig.run_cycles(10);
  EXPECT_TRUE(rig.loop->kicking_watchdog());
  EXPECT_GT(watchdog_.kicks, kicks_dead);
}

TEST_F(Faults, FullLogQueueCountsTheLostRecordAndPublishesTheCount) {
  sim_board::FaultPlan f;
  f.crc_error_at = {kFaultSeq};
  SimRig& rig = make(f);
  rig.run_cycles(kFaultSeq - 10);
  (void)rig.drain_log();
  // The logger thread stalls: the queue fills up (the test is the only other producer and the
  // loop is not running meanwhile).
  while (rig.log->push(LogLevel::kInfo, 0, "filler")) {
  }
  const std::uint32_t lost_before = rig.log->dropped();  // the push that found it full
  rig.run();
  EXPECT_EQ(rig.loop->health().crc_errors, 1u);
  EXPECT_EQ(rig.log->dropped(), lost_before + 1);  // the CRC error's record
  EXPECT_EQ(rig.loop->health().log_dropped, lost_before + 1);
  const Bus bus = decode(rig);
  EXPECT_EQ(health_after(bus, kFaultSeq).log_dropped, (lost_before + 1) % 64);
  EXPECT_EQ(health_after(bus, kFaultSeq).crc, 1u);  // counters keep what the log lost
  expect_status_rate(bus, 1000, rig.samples);
  EXPECT_TRUE(lines_with(rig.drain_log(), "CRC error").empty());
}

TEST_F(Faults, MissingCalibrationIsFlaggedOnTheBus) {
  SimRig& rig = make();
  FwConfig c = rig.config;
  c.calibration_file = "/nonexistent/gfins-calibration.toml";
  const StartupCalibration cal = load_calibration(c, rig.factory, &rig.factory);
  EXPECT_FALSE(cal.from_file);
  EXPECT_NE(cal.message.find("UNCALIBRATED"), std::string::npos) << cal.message;
  EXPECT_NE(cal.message.find("/nonexistent/gfins-calibration.toml"), std::string::npos);
  const Bus bus = run_from_start(rig, cal, c);
  const BusEpoch& e = on_bus(bus, 3000);
  EXPECT_EQ(e.flags & kBitNominalCal, kBitNominalCal);
  EXPECT_EQ(e.cal_id, 0u);
  EXPECT_EQ(e.mode, kModeNavigating);
  expect_status_rate(bus, 1000, rig.samples);
}

// A calibration made for another converter setting (the README's paper calibration, 1.192e-6
// V/count, against the simulated board's ADS131M06 LSB) scales every count by their ratio: |f|
// reads 2.8 g at rest and navigation runs away. It is refused at start-up like any bad file
// (nominal defaults, flagged on the bus) and by the reload command (the calibration in use stays).
// Oracle: the factory calibration's own LSB, changed by the test.
TEST_F(Faults, ACalibrationOfAnotherConverterIsRefusedAtStartAndOnReload) {
  SimRig& rig = make();
  calib_file::CalibrationData other = rig.factory;
  for (auto& sensor : other.sensors) sensor.adc_lsb_v_per_count = 1.192e-6;
  const std::string good = ::testing::TempDir() + "gfins_factory_cal.toml";
  const std::string bad = ::testing::TempDir() + "gfins_other_converter_cal.toml";
  ASSERT_TRUE(calib_file::save_calibration_file(good, rig.factory).is_ok());
  ASSERT_TRUE(calib_file::save_calibration_file(bad, other).is_ok());
  FwConfig c = rig.config;
  c.calibration_file = bad;
  const StartupCalibration cal = load_calibration(c, rig.factory, &rig.factory);
  EXPECT_FALSE(cal.from_file);
  EXPECT_FALSE(cal.set.calibrated);
  EXPECT_NE(cal.message.find("UNCALIBRATED: " + bad +
                             ": sensor a1 has an ADC LSB of 1.192e-06 "
                             "V/count, the board's converter "),
            std::string::npos)
      << cal.message;
  EXPECT_NE(cal.message.find("another converter setting"), std::string::npos) << cal.message;
  // The same file of this converter is taken.
  c.calibration_file = good;
  EXPECT_TRUE(load_calibration(c, rig.factory, &rig.factory).from_file);
  // Reload: the other converter's file is refused, this converter's file is taken.
  c.calibration_file = bad;
  EXPECT_FALSE(calibration_reloader(c, converter_lsb(rig.factory))(ReloadRequest{rig.cal.config})
                   .set.has_value());
  c.calibration_file = good;
  EXPECT_TRUE(calibration_reloader(c, converter_lsb(rig.factory))(ReloadRequest{rig.cal.config})
                  .set.has_value());
  static_cast<void>(std::remove(good.c_str()));
  static_cast<void>(std::remove(bad.c_str()));
}

// The reload's device rule: a board on its nominal defaults takes the first file whatever its
// device id; from then on (and from a start with a file) only files of that device. Oracle: the
// ids the test writes.
TEST_F(Faults, AReloadKeepsToTheDeviceOfTheCalibrationInUse) {
  SimRig& rig = make();
  const std::string path = ::testing::TempDir() + "gfins_device_rule_cal.toml";
  FwConfig c = rig.config;
  c.calibration_file = path;
  const auto save_as = [&](const std::string& id, double bias) {
    calib_file::CalibrationData d = rig.factory;
    d.device_id = id;
    d.sensors[2].bias_g = bias;
    return calib_file::save_calibration_file(path, d).is_ok();
  };
  auto from_defaults = calibration_reloader(c, converter_lsb(rig.factory), "");
  ASSERT_TRUE(save_as("board-a", 1e-4));
  EXPECT_TRUE(from_defaults(ReloadRequest{rig.cal.config}).set.has_value())
      << "the first file of a nominal board";
  ASSERT_TRUE(save_as("board-b", 1e-4));
  EXPECT_FALSE(from_defaults(ReloadRequest{rig.cal.config}).set.has_value())
      << "board-a's calibration is in use";
  ASSERT_TRUE(save_as("board-a", 2e-4));
  EXPECT_TRUE(from_defaults(ReloadRequest{rig.cal.config}).set.has_value())
      << "board-a recalibrated";
  auto from_file = calibration_reloader(c, converter_lsb(rig.factory), "board-b");
  const ReloadOutcome refused = from_file(ReloadRequest{rig.cal.config});
  EXPECT_FALSE(refused.set.has_value()) << "started on board-b's file";
  EXPECT_TRUE(refused.other_device) << "refused for the device, not as a failure";
  // Forced, the other board's file is taken, and its device is the one in use from then on.
  EXPECT_TRUE(from_file(ReloadRequest{rig.cal.config, true}).set.has_value());
  EXPECT_TRUE(from_file(ReloadRequest{rig.cal.config}).set.has_value()) << "board-a now in use";
  static_cast<void>(std::remove(path.c_str()));
}

// A calibration that loads (every value in range) but that the navigation core refuses: a custom
// geometry whose six axes are all x sees no rotation about x and no y/z specific force, so the
// array's solve is singular. Like any bad file it leaves the board on its flagged defaults
// (start-up), keeps the calibration in use (reload) and is named by --check-config's note; before,
// the run stopped with exit 1 and --check-config said nothing. Oracle: the geometry, by
// construction (rank 1 at most in the three force columns).
TEST_F(Faults, ACalibrationTheCoreRefusesLeavesTheBoardOnItsDefaults) {
  SimRig& rig = make();
  calib_file::CalibrationData singular = rig.factory;
  singular.geometry.kind = calib_file::GeometryKind::kCustom;
  for (std::size_t j = 0; j < singular.geometry.axes.size(); ++j) {
    singular.geometry.axes[j] = {1.0, 0.0, 0.0};
    singular.geometry.positions_m[j] = {0.0, 0.1 * static_cast<double>(j) - 0.25, 0.05};
  }
  const std::string bad = ::testing::TempDir() + "gfins_singular_cal.toml";
  ASSERT_TRUE(calib_file::save_calibration_file(bad, singular).is_ok());
  ASSERT_TRUE(calib_file::load_calibration_file(bad).is_ok()) << "the file itself is valid";
  FwConfig c = rig.config;
  c.calibration_file = bad;
  const StartupCalibration cal = load_calibration(c, rig.factory, &rig.factory);
  EXPECT_FALSE(cal.from_file);
  EXPECT_FALSE(cal.set.calibrated);
  EXPECT_EQ(cal.set.cal_id, 0u);
  EXPECT_NE(cal.message.find("UNCALIBRATED: " + bad + ": the navigation core refuses it: "),
            std::string::npos)
      << cal.message;
  // The defaults it falls back to are the ones the core takes: the run goes on.
  const Bus bus = run_from_start(rig, cal, c);
  const BusEpoch& e = on_bus(bus, 3000);
  EXPECT_EQ(e.flags & kBitNominalCal, kBitNominalCal);
  EXPECT_EQ(e.mode, kModeNavigating);
  // Reload refuses it; --check-config's note names it.
  EXPECT_FALSE(calibration_reloader(c, converter_lsb(rig.factory))(ReloadRequest{rig.cal.config})
                   .set.has_value());
  const std::string note = calibration_note(c);
  EXPECT_NE(note.find("the navigation core refuses it"), std::string::npos) << note;
  EXPECT_NE(note.find("UNCALIBRATED"), std::string::npos) << note;
  // The factory calibration itself passes the same rule (the check is not a blanket refusal).
  const std::array<double, 6> lsb = converter_lsb(rig.factory);
  EXPECT_FALSE(calibration_refusal(c, rig.factory, &lsb).has_value());
  static_cast<void>(std::remove(bad.c_str()));
}

TEST_F(Faults, MalformedCommandIsAnsweredCountedAndLoggedOncePerSecond) {
  SimRig& rig = make();
  rig.run_cycles(2000);
  // A command frame for this node with a bad CRC (byte 7), five times in 50 ms.
  hal::CanFrame bad;
  bad.id = 0x600 + kNodeId;
  bad.len = 8;
  bad.data = {5, 42, 0, 0, 0, 0, 0, 0x00};
  for (int i = 0; i < 5; ++i) {
    ASSERT_TRUE(rig.bus->inject_rx(bad));
    rig.run_cycles(10);
  }
  rig.run();
  lines_ = rig.drain_log();
  EXPECT_EQ(rig.loop->health().command_errors, 5u);
  const Bus bus = decode(rig);
  ASSERT_EQ(bus.response_results.size(), 5u);
  for (std::uint32_t r : bus.response_results) EXPECT_EQ(r, 3u);  // Result 3 = BadCrc
  EXPECT_EQ(lines_with(lines_, "rejected").size(), 1u);
  expect_status_rate(bus, 1000, rig.samples);
}

// With aiding on, the epochs published for a data-ready silence carry no navigation values but
// keep the filter's σ: nothing was measured, but the filter's knowledge of the held state is what
// it was one sample before. Oracle: the epoch of the last sample before the silence; the σ grow
// only by the process noise of the propagations in between (at rest, none of the 3 ms would move
// roll's σ by 1 %). A σ computed from the gap epoch's own not-available state reads NaN.
TEST_F(Faults, AnAidedBoardKeepsItsSigmaInTheEpochsOfASilence) {
  sim_board::FaultPlan f;
  f.silent_from = 2500;  // after the 1 s alignment and the filter's start
  f.silent_edges = 3;
  SimRig rig("rest", 3.0, f);
  rig.config.aiding = true;
  rig.cal = app::load_calibration(rig.config, rig.factory, &rig.factory).set;
  rig.configure();
  rig.run();
  ASSERT_EQ(rig.loop->health().drdy_timeouts, 1u);
  const std::vector<can::Epoch>& epochs = rig.recording->epochs();
  const can::Epoch* before = nullptr;
  const can::Epoch* gap = nullptr;
  for (const can::Epoch& e : epochs) {
    if ((e.status_bits & app::status_bits::kDataReadyLost) != 0 && std::isnan(e.nav.v_n.x())) {
      gap = &e;
      break;
    }
    before = &e;
  }
  ASSERT_NE(gap, nullptr) << "no epoch of the silence";
  ASSERT_NE(before, nullptr);
  ASSERT_TRUE(std::isfinite(before->accuracy.sigma_roll_rad));
  EXPECT_TRUE(std::isfinite(gap->accuracy.sigma_roll_rad));
  EXPECT_NEAR(gap->accuracy.sigma_roll_rad, before->accuracy.sigma_roll_rad,
              0.01F * before->accuracy.sigma_roll_rad);
  EXPECT_NEAR(gap->accuracy.sigma_pitch_rad, before->accuracy.sigma_pitch_rad,
              0.01F * before->accuracy.sigma_pitch_rad);
  EXPECT_TRUE(std::isfinite(gap->accuracy.sigma_vel_h_mps));
}

// GNSS and heading input frames with aiding on: a corrupted frame is refused, counted and logged;
// a whole fix (the board's true position and velocity at rest, zero) reaches the filter, which
// accepts both of its updates, and so does an external heading equal to the board's. The oracle is
// the scenario: the board is at rest at the origin.
TEST_F(Faults, GnssInputFramesReachTheFilterAndACorruptedOneIsCountedAndLogged) {
  SimRig rig("rest", 3.0);
  rig.config.aiding = true;
  rig.cal = app::load_calibration(rig.config, rig.factory, &rig.factory).set;
  rig.configure();
  rig.run_cycles(2000);  // aligned after 1 s
  const auto frames = can::encode_gnss_fix(testing::gnss_fix_at_rest(3), SimRig::kNode);
  hal::CanFrame bad = frames[0];
  bad.data[7] ^= 0x5A;  // CRC byte
  ASSERT_TRUE(rig.bus->inject_rx(bad));
  rig.run_cycles(1);
  for (const hal::CanFrame& f : frames) ASSERT_TRUE(rig.bus->inject_rx(f));
  rig.run_cycles(1);
  // An external heading equal to the one the board was given (navigation.heading_deg = 0).
  can::HeadingFix h;
  h.sequence = 1;
  h.heading_rad = 0.0;
  h.sigma_rad = 0.01;
  h.age_s = 0.01;
  ASSERT_TRUE(rig.bus->inject_rx(can::encode_heading_fix(h, SimRig::kNode)));
  rig.run_cycles(1);
  // The same heading 5 s old (ExtHeadingAge reaches 8.19 s): the loop dates it by its age, which
  // lies before the filter's history (320 ms at the default rates), so it is refused, not taken
  // as a heading of now.
  h.sequence = 2;
  h.age_s = 5.0;
  ASSERT_TRUE(rig.bus->inject_rx(can::encode_heading_fix(h, SimRig::kNode)));
  rig.run_cycles(1);
  rig.run();
  lines_ = rig.drain_log();
  EXPECT_EQ(rig.loop->health().aiding_input_errors, 1u);
  EXPECT_EQ(rig.loop->health().aiding_inputs, 3u);   // the fix and the two headings
  EXPECT_EQ(rig.loop->health().command_errors, 0u);  // input frames are not commands
  const auto& c = rig.loop->pipeline().aiding().filter().counters();
  EXPECT_EQ(c.accepted[static_cast<std::size_t>(nav::AidingKind::kGnssPosition)], 1u);
  EXPECT_EQ(c.accepted[static_cast<std::size_t>(nav::AidingKind::kGnssVelocity)], 1u);
  EXPECT_EQ(c.accepted[static_cast<std::size_t>(nav::AidingKind::kHeading)], 1u);
  EXPECT_EQ(c.invalid[static_cast<std::size_t>(nav::AidingKind::kHeading)], 1u);
  EXPECT_EQ(lines_with(lines_, "aiding input frame").size(), 1u);
  EXPECT_EQ(lines_with(lines_, "aiding input not applied").size(), 1u);
}

// Gravity the board has: a board at rest at 24.8° and 50 m, where WGS-84 normal gravity is
// 9.789262 m/s² (Somigliana with the free-air term; the figure is computed outside the project),
// with the QA-1100 model at its calibration temperature (at 40 °C its 0.27 % scale-factor drift
// alone moves |f| by 2 mg, which the check rightly reports). The simulated board's factory
// calibration states that g, and the default navigation gravity ("calibration") takes it: the
// alignment's |f| agrees and nothing is flagged. Standard gravity (1.77 mg more) is flagged once
// per alignment: counted and logged.
TEST_F(Faults, TheAlignmentChecksTheMeasuredGravityAgainstTheNavigationGravity) {
  const std::string scenario = ::testing::TempDir() + "gfins_rest_24_8_deg.toml";
  {
    std::FILE* f = std::fopen(scenario.c_str(), "w");
    ASSERT_NE(f, nullptr);
    std::fputs(
        "[scenario]\nduration_s = 2.0\nrate_hz = 1000.0\nrho_m = 0.1\n"
        "[gravity]\nmodel = \"normal\"\nlatitude_deg = 24.8\nheight_m = 50.0\n"
        "[trajectory]\nkind = \"rest\"\neuler_deg = [3.0, -2.0, 45.0]\n"
        "[sensors]\norientation = \"paper_table6\"\nmodel = \"qa1100\"\ntemperature_c = 25.0\n"
        "[compensator]\nkind = \"exact\"\n",
        f);
    ASSERT_EQ(std::fclose(f), 0);
  }
  for (const bool standard : {false, true}) {
    SimRig rig(scenario, 2.0);
    if (standard) {
      rig.config.gravity = app::GravityChoice::kStandard;
      rig.cal = app::load_calibration(rig.config, rig.factory, &rig.factory).set;
    }
    rig.configure();
    rig.run();
    const auto lines = rig.drain_log();
    const auto g = static_cast<double>(rig.loop->pipeline().config().gravity.magnitude_at_origin());
    std::printf("navigation gravity %.6f m/s^2, aligned |f| %.6f m/s^2\n", g,
                static_cast<double>(rig.loop->pipeline().alignment().gravity_mps2));
    if (standard) {
      EXPECT_NEAR(g, nav::kStandardGravity, 1e-5);
      EXPECT_EQ(rig.loop->health().gravity_mismatches, 1u);
      EXPECT_EQ(lines_with(lines, "navigation gravity").size(), 1u);
    } else {
      EXPECT_NEAR(g, 9.789262, 2e-6);  // float32 of the file's value
      EXPECT_EQ(rig.loop->health().gravity_mismatches, 0u);
      EXPECT_EQ(lines_with(lines, "navigation gravity").size(), 0u);
    }
  }
  std::remove(scenario.c_str());
}

TEST_F(Faults, FailedCalibrationReloadKeepsTheCalibrationAnswersFailedAndLogs) {
  SimRig& rig = make();
  ReloadWorker reload([](const ReloadRequest&) -> ReloadOutcome { return {}; });
  rig.loop->set_reload_worker(&reload);
  rig.run_cycles(2000);
  const std::uint32_t cal_before = rig.loop->cal_id();
  can::Command c;
  c.opcode = can::Opcode::kReloadCalibration;
  c.token = 9;
  c.sequence = 1;
  ASSERT_TRUE(rig.bus->inject_rx(can::encode_command(c, SimRig::kNode)));
  rig.run_cycles(1);
  reload.wait_settled();  // the worker's outcome is seen by the next cycle's poll
  rig.run();
  lines_ = rig.drain_log();
  EXPECT_EQ(rig.loop->health().command_errors, 1u);
  EXPECT_EQ(rig.loop->cal_id(), cal_before);
  const Bus bus = decode(rig);
  ASSERT_EQ(bus.response_results.size(), 1u);
  EXPECT_EQ(bus.response_results[0], 7u);  // Result 7 = Failed
  EXPECT_EQ(lines_with(lines_, "calibration reload failed").size(), 1u);
  EXPECT_EQ(on_bus(bus, 3000).cal_id, cal_before);
  expect_status_rate(bus, 1000, rig.samples);
  EXPECT_EQ(rig.loop->pipeline().state().v_n, baseline_->loop->pipeline().state().v_n);
}

// Frames the publisher sends for the samples read in [first, last): its documented rule, every
// data message whose divider divides the sample counter (docs/can-interface.md).
std::uint32_t frames_for(const SimRig& rig, std::size_t first, std::size_t last) {
  std::uint32_t n = 0;
  for (std::size_t i = first; i < last; ++i) {
    for (std::uint16_t d : rig.config.dividers) {
      if (d != 0 && rig.tap->samples()[i].seq % d == 0) ++n;
    }
    // GfinsCommandCounters, on every board at the table's 1000 samples.
    if (rig.tap->samples()[i].seq % 1000 == 0) ++n;
  }
  return n;
}

TEST(CanFaults, RefusingSinkAndBusOffAreCountedPublishedLoggedAndTheLoopKeepsReading) {
  SimRig rig("rest", 5.0);
  rig.configure();
  rig.run_cycles(2000);
  const std::size_t refuse_from = rig.tap->samples().size();
  rig.bus->refuse(true);
  rig.run_cycles(100);
  rig.bus->refuse(false);
  const std::size_t refuse_to = rig.tap->samples().size();
  rig.run_cycles(400);
  const std::size_t off_from = rig.tap->samples().size();
  rig.bus->bus_off(true);
  rig.run_cycles(200);
  rig.bus->bus_off(false);
  const std::size_t off_to = rig.tap->samples().size();
  rig.run();
  const auto lines = rig.drain_log();
  const HealthCounters& h = rig.loop->health();
  // The loop's rate while the bus refuses: it offered every frame its dividers select.
  const std::uint32_t expected =
      frames_for(rig, refuse_from, refuse_to) + frames_for(rig, off_from, off_to);
  EXPECT_GT(expected, 100u);
  EXPECT_EQ(h.can_tx_dropped, expected);
  EXPECT_EQ(h.can_tx_dropped, rig.bus->counters().tx_dropped);
  EXPECT_EQ(h.bus_off_events, 1u);
  EXPECT_EQ(h.samples, rig.samples);
  // On the bus once it carries frames again: the counters and the held bits.
  const Bus bus = decode(rig);
  const BusEpoch& health = health_after(bus, 3000);
  EXPECT_EQ(health.tx_dropped, expected);
  EXPECT_EQ(health.bus_off, 1u);
  expect_flags(bus, 2100, 3000, kBitTxDropped);
  expect_flags(bus, 2710, 3600, kBitBusOff);
  EXPECT_EQ(on_bus(bus, 2710).mode, kModeNavigating);  // CAN faults do not touch navigation
  EXPECT_EQ(on_bus(bus, 2710).flags & kBitDegraded, 0u);
  EXPECT_EQ(lines_with(lines, "bus-off (events: 1)").size(), 1u);
  EXPECT_EQ(lines_with(lines, "dropped by the bus backend").size(), 1u);
  // The state line on the way into bus-off and on the way back (docs: A -> B).
  EXPECT_EQ(lines_with(lines, "CAN state 0 -> 3").size(), 1u);
  EXPECT_EQ(lines_with(lines, "CAN state 3 -> 0").size(), 1u);
}

TEST(CanFaults, ReceivedFramesLostInTheKernelAreCountedFlaggedAndLogged) {
  // Given a navigating board
  SimRig rig("rest", 5.0);
  rig.configure();
  rig.run_cycles(2000);
  // When the kernel reports 3 received frames dropped, 4 more 10 ms later, and 1 more 1.5 s on
  rig.bus->lose_received(3);
  rig.run_cycles(10);
  rig.bus->lose_received(4);
  rig.run_cycles(1500);
  rig.bus->lose_received(1);
  rig.run();
  // Then the health counter has all 8, the status bit is set after the loss, one log line per
  // second (the second report held back and counted in the third's line)
  const auto lines = rig.drain_log();
  EXPECT_EQ(rig.loop->health().can_rx_dropped, 8u);
  const Bus bus = decode(rig);
  EXPECT_EQ(on_bus(bus, 1990).flags & kBitRxLost, 0u);
  expect_flags(bus, 2010, 3000, kBitRxLost);
  EXPECT_EQ(on_bus(bus, 2100).mode, kModeNavigating);
  const auto rx = lines_with(lines, "received CAN frame(s) lost");
  ASSERT_EQ(rx.size(), 2u);
  EXPECT_NE(rx[1].find("(lost: 8; 1 more since the last line)"), std::string::npos) << rx[1];
}

}  // namespace
}  // namespace gfins::app
