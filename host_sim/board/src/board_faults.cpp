// Faults of the simulated board itself: read failures the chip model cannot make (FaultySource),
// the scenario's [[board.faults]] through the sample source (ScheduledFaultSource) and the CAN
// output (FaultyCanBus). docs/simulation.md, "Board faults"; docs/faults.md has the rows.
#include <algorithm>
#include <cmath>
#include <functional>
#include <utility>

#include "gfins/host_sim/board/sim_board.hpp"

namespace gfins::sim_board {

using sim::BoardFaultKind;

Result<RawSample> FaultySource::do_read_sample(std::int64_t timeout_ns) {
  if (dead_) {
    return Status(ErrorCode::kFailedPrecondition,
                  "adc: not running (start() failed or not called)");
  }
  if (revive_) {
    revive_ = false;
    const std::int64_t t = clock_.now_ns();
    for (;;) {
      Result<RawSample> r = inner_.read_sample(timeout_ns);
      if (!r.is_ok() || r.value().t_ns >= t) return r;
    }
  }
  Result<RawSample> r = inner_.read_sample(timeout_ns);
  if (fail_ > 0 && r.is_ok()) {
    --fail_;
    return Status(ErrorCode::kIoError, "spidev: SPI_IOC_MESSAGE failed");
  }
  if (flag_n_ > 0 && r.is_ok()) {
    --flag_n_;
    RawSample s = r.value();
    s.flags |= flags_;
    return s;
  }
  return r;
}

// ---- [[board.faults]] through the sample source ----------------------------------------------

ScheduledFaultSource::ScheduledFaultSource(SimSampleSource& source, hal::Clock& clock,
                                           const std::vector<sim::BoardFault>& faults,
                                           double rate_hz)
    : source_(source),
      clock_(clock),
      faulty_(source, clock),
      period_ns_(static_cast<std::int64_t>(std::llround(1e9 / rate_hz))) {
  const auto at = [rate_hz](double t_s) {
    return static_cast<std::uint32_t>(std::max<long long>(1, std::llround(t_s * rate_hz)));
  };
  for (const sim::BoardFault& f : faults) {
    Timed t;
    t.fault = f;
    t.from = at(f.at_s);
    t.until = f.duration_s > 0.0 ? at(f.at_s + f.duration_s) : t.from + f.count;
    switch (f.kind) {
      case BoardFaultKind::kCrcError:
        plan_.crc_error_at.push_back(t.from);
        break;
      case BoardFaultKind::kMissedEdges:
        for (std::uint32_t k = 0; k < f.count; ++k) plan_.missing_edges.push_back(t.from + k);
        break;
      case BoardFaultKind::kExtraEdge:
        plan_.extra_edge_after.push_back(t.from);
        break;
      case BoardFaultKind::kCanRefuse:
      case BoardFaultKind::kBusOff:
        continue;  // FaultyCanBus
      default:
        faults_.push_back(t);
        break;
    }
  }
  source_.set_faults(plan_);
  refresh(0);
}

void ScheduledFaultSource::refresh(std::uint32_t seq) {
  // Each single-valued fault of the plan: the first of its kind not over by conversion `seq`
  // (a fault that ends at `until` is still in the plan at `until`, where the source clears it).
  const auto current = [&](BoardFaultKind kind) -> const Timed* {
    for (const Timed& t : faults_) {
      if (t.fault.kind == kind && t.until >= seq) return &t;
    }
    return nullptr;
  };
  // Called before every read: only the single-valued fields are compared and set (no copy of
  // the plan's lists), and the source gets the plan again only when one of them changed.
  const Timed* reset = current(BoardFaultKind::kAdcReset);
  const Timed* silent = current(BoardFaultKind::kSilentLine);
  const Timed* stuck = current(BoardFaultKind::kStuck);
  const Timed* sat = current(BoardFaultKind::kSaturated);
  const std::uint32_t reset_at = reset != nullptr ? reset->from : 0;
  const std::uint32_t silent_from = silent != nullptr ? silent->from : 0;
  const int stuck_channel = stuck != nullptr ? static_cast<int>(stuck->fault.channel) : -1;
  const std::uint32_t stuck_from = stuck != nullptr ? stuck->from : 0;
  const int sat_channel = sat != nullptr ? static_cast<int>(sat->fault.channel) : -1;
  const std::uint32_t sat_from = sat != nullptr ? sat->from : 0;
  if (reset_at == plan_.reset_at && silent_from == plan_.silent_from &&
      stuck_channel == plan_.stuck_channel && stuck_from == plan_.stuck_from &&
      sat_channel == plan_.saturated_channel && sat_from == plan_.saturated_from) {
    return;
  }
  plan_.reset_at = reset_at;
  plan_.silent_from = silent_from;
  plan_.silent_edges = silent != nullptr ? silent->fault.count : 0;
  plan_.stuck_channel = stuck_channel;
  plan_.stuck_from = stuck_from;
  plan_.stuck_until = stuck != nullptr ? stuck->until : 0;
  plan_.saturated_channel = sat_channel;
  plan_.saturated_from = sat_from;
  plan_.saturated_until = sat != nullptr ? sat->until : 0;
  source_.set_faults(plan_);
}

Result<RawSample> ScheduledFaultSource::do_read_sample(std::int64_t timeout_ns) {
  const std::uint32_t seq = source_.next_seq();
  refresh(seq);
  // A dead ADC delivers nothing, so its window is on the loop's clock (which runs on, one period
  // per failed read), from the first sample's time.
  const std::int64_t now = clock_.now_ns();
  bool dead = false;
  for (Timed& t : faults_) {
    if (t.fault.kind == BoardFaultKind::kReadError && !t.applied && seq >= t.from) {
      faulty_.fail_reads(t.fault.count);
      t.applied = true;
    }
    if (t.fault.kind == BoardFaultKind::kAdcDead && have_t0_) {
      dead = dead || (now >= t0_ns_ + static_cast<std::int64_t>(t.from) * period_ns_ &&
                      now < t0_ns_ + static_cast<std::int64_t>(t.until) * period_ns_);
    }
  }
  if (dead != faulty_.dead()) faulty_.set_dead(dead);
  Result<RawSample> r = faulty_.read_sample(timeout_ns);
  if (r.is_ok() && !have_t0_) {
    t0_ns_ = r.value().t_ns - static_cast<std::int64_t>(r.value().seq) * period_ns_;
    have_t0_ = true;
  }
  return r;
}

// ---- [[board.faults]] on the CAN output --------------------------------------------------------

FaultyCanBus::FaultyCanBus(std::unique_ptr<hal::CanBus> inner,
                           const std::vector<sim::BoardFault>& faults,
                           std::function<double()> now_s)
    : inner_(std::move(inner)), now_s_(std::move(now_s)) {
  for (const sim::BoardFault& f : faults) {
    if (f.kind == BoardFaultKind::kCanRefuse || f.kind == BoardFaultKind::kBusOff) {
      faults_.push_back(f);
    }
  }
}

bool FaultyCanBus::within(BoardFaultKind kind) const {
  const double t = now_s_();
  return std::any_of(faults_.begin(), faults_.end(), [&](const sim::BoardFault& f) {
    return f.kind == kind && t >= f.at_s && t < f.at_s + f.duration_s;
  });
}

void FaultyCanBus::update() {
  const bool off = within(BoardFaultKind::kBusOff);
  if (off && !bus_off_) ++own_.bus_off_events;
  if (!off && bus_off_) ++own_.restarts;
  bus_off_ = off;
}

Status FaultyCanBus::do_send(const hal::CanFrame& f) {
  update();
  if (bus_off_) {
    ++own_.tx_dropped;
    return Status(ErrorCode::kUnavailable, "can: bus-off");
  }
  if (within(BoardFaultKind::kCanRefuse)) {
    ++own_.tx_dropped;
    return Status(ErrorCode::kResourceExhausted, "can: transmit queue full");
  }
  return inner_->send(f);
}

hal::CanBusState FaultyCanBus::do_state() const {
  return bus_off_ ? hal::CanBusState::kBusOff : inner_->state();
}

hal::CanCounters FaultyCanBus::do_counters() const {
  hal::CanCounters c = inner_->counters();
  c.tx_dropped += own_.tx_dropped;
  c.bus_off_events += own_.bus_off_events;
  c.restarts += own_.restarts;
  return c;
}

}  // namespace gfins::sim_board
