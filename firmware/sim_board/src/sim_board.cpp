#include "gfins/sim_board/sim_board.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <thread>

#include "gfins/host_sim/adc_model.hpp"
#include "gfins/host_sim/sensor_model.hpp"

namespace gfins::sim_board {

// ---- Clocks ---------------------------------------------------------------------------------

std::int64_t SteadyClock::do_now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

Status SteadyClock::do_sleep_until_ns(std::int64_t t_ns) {
  std::this_thread::sleep_until(
      std::chrono::steady_clock::time_point(std::chrono::nanoseconds(t_ns)));
  return Status::ok();
}

// ---- Sample source ----------------------------------------------------------------------------

SimSampleSource::SimSampleSource(SensorStream& stream, AdcChain& adc, hal::Clock& clock,
                                 SampleClock* sample_clock, Pacing pacing, double sample_rate_hz,
                                 std::uint32_t samples)
    : stream_(stream),
      adc_(adc),
      clock_(clock),
      sample_clock_(sample_clock),
      pacing_(pacing),
      period_ns_(static_cast<std::int64_t>(std::llround(1e9 / sample_rate_hz))),
      period_s_(1.0 / sample_rate_hz),
      remaining_(samples) {
  // Real time: the first edge one period from now, so the loop starts on a fresh period.
  if (pacing_ == Pacing::kRealTime) t0_ns_ = clock_.now_ns() + period_ns_;
}

bool SimSampleSource::contains(const std::vector<std::uint32_t>& v, std::uint32_t x) {
  return std::find(v.begin(), v.end(), x) != v.end();
}

std::int64_t SimSampleSource::edge_time(std::uint32_t seq) const {
  // Fast: scenario time of the conversion (the same instant AdcModel stamps); real time: the
  // monotonic time the edge is due.
  return t0_ns_ + static_cast<std::int64_t>(seq) * period_ns_;
}

Result<RawSample> SimSampleSource::do_read_sample(std::int64_t timeout_ns) {
  if (remaining_ == 0) return Status(ErrorCode::kUnavailable, "sim: scenario finished");
  // A silent data-ready line: no edge for the timeout; the conversions still happen (the sensor
  // stream advances) and are lost.
  if (faults_.silent_from != 0 && next_seq_ == faults_.silent_from && silent_left_ == 0) {
    silent_left_ = faults_.silent_edges;
  }
  if (silent_left_ > 0) {
    const auto periods = static_cast<std::uint32_t>(std::max<std::int64_t>(1, timeout_ns / period_ns_));
    const std::uint32_t n = std::min({periods, silent_left_, remaining_});
    for (std::uint32_t i = 0; i < n; ++i) (void)stream_.volts(next_seq_++);
    silent_left_ -= n;
    remaining_ -= n;
    const std::int64_t t = edge_time(next_seq_ - 1) + period_ns_ / 2;
    if (pacing_ == Pacing::kRealTime) (void)clock_.sleep_until_ns(t);
    if (sample_clock_ != nullptr) sample_clock_->set(t);
    if (remaining_ == 0) return Status(ErrorCode::kUnavailable, "sim: scenario finished");
    return Status(ErrorCode::kTimeout, "sim: no data-ready edge");
  }
  // A spurious edge: the driver finds no new conversion behind it and counts it; the loop only
  // sees the next real one.
  if (extra_pending_) {
    extra_pending_ = false;
    ++extra_.extra_edges;
  }
  // Lost edges: those conversions are never read.
  while (remaining_ > 1 && contains(faults_.missing_edges, next_seq_)) {
    (void)stream_.volts(next_seq_++);
    --remaining_;
  }
  const std::uint32_t seq = next_seq_++;
  --remaining_;
  std::array<double, 6> v = stream_.volts(seq);
  const std::int64_t t = edge_time(seq);
  if (pacing_ == Pacing::kRealTime) (void)clock_.sleep_until_ns(t);
  if (sample_clock_ != nullptr) sample_clock_->set(t);
  if (faults_.reset_at != 0 && seq == faults_.reset_at) {
    // The chip reset itself (brown-out, ESD): the driver sees the reset status, reconfigures and
    // loses the conversions of the recovery (two periods).
    ++extra_.chip_resets;
    for (int i = 0; i < 2 && remaining_ > 1; ++i) {
      (void)stream_.volts(next_seq_++);
      --remaining_;
    }
  }
  Result<RawSample> r = adc_.convert(v, seq, t);
  if (!r.is_ok()) return r;
  RawSample s = r.value();
  const auto in = [seq](std::uint32_t from, std::uint32_t until) {
    return seq >= from && (until == 0 || seq < until);
  };
  if (faults_.stuck_channel >= 0 && in(faults_.stuck_from, faults_.stuck_until)) {
    const auto j = static_cast<std::size_t>(faults_.stuck_channel);
    if (seq == faults_.stuck_from) frozen_[j] = s.counts[j];
    s.counts[j] = frozen_[j];
  }
  if (faults_.saturated_channel >= 0 && in(faults_.saturated_from, faults_.saturated_until)) {
    s.counts[static_cast<std::size_t>(faults_.saturated_channel)] = kAdcCodeMax;
    s.flags |= sample_flags::kSaturated;
  }
  if (contains(faults_.crc_error_at, seq)) {
    s.flags |= sample_flags::kCrcError;
    ++extra_.crc_errors;
  }
  if (contains(faults_.extra_edge_after, seq)) extra_pending_ = true;
  return s;
}

app::AdcCounters SimSampleSource::do_counters() const {
  app::AdcCounters c = adc_.counters();
  c.crc_errors += extra_.crc_errors;
  c.extra_edges += extra_.extra_edges;
  c.chip_resets += extra_.chip_resets;
  c.missed_edges += extra_.missed_edges;
  return c;
}

// ---- CAN bus in memory ----------------------------------------------------------------------

MemoryCanBus::MemoryCanBus(std::size_t capacity, std::size_t rx_capacity)
    : ring_(std::max<std::size_t>(capacity, 1)), rx_(std::max<std::size_t>(rx_capacity, 1)) {}

void MemoryCanBus::bus_off(bool on) {
  if (on && state_ != hal::CanBusState::kBusOff) {
    state_ = hal::CanBusState::kBusOff;
    ++counters_.bus_off_events;
  } else if (!on && state_ == hal::CanBusState::kBusOff) {
    state_ = hal::CanBusState::kErrorActive;
    ++counters_.restarts;
  }
}

bool MemoryCanBus::inject_rx(const hal::CanFrame& f) {
  if (rx_count_ == rx_.size()) return false;
  rx_[(rx_head_ + rx_count_) % rx_.size()] = f;
  ++rx_count_;
  return true;
}

std::vector<hal::CanFrame> MemoryCanBus::sent() const {
  std::vector<hal::CanFrame> out;
  const std::size_t n = std::min<std::uint64_t>(total_, ring_.size());
  out.reserve(n);
  const std::size_t start = total_ > ring_.size() ? head_ : 0;
  for (std::size_t i = 0; i < n; ++i) out.push_back(ring_[(start + i) % ring_.size()]);
  return out;
}

Status MemoryCanBus::do_send(const hal::CanFrame& f) {
  if (state_ == hal::CanBusState::kBusOff) {
    ++counters_.tx_dropped;
    return Status(ErrorCode::kUnavailable, "memory can: bus-off");
  }
  if (refuse_) {
    ++counters_.tx_dropped;
    return Status(ErrorCode::kResourceExhausted, "memory can: queue full");
  }
  ring_[head_] = f;
  head_ = (head_ + 1) % ring_.size();
  ++total_;
  ++counters_.tx_frames;
  return Status::ok();
}

Result<hal::CanFrame> MemoryCanBus::do_receive(std::int64_t /*timeout_ns*/) {
  if (rx_count_ == 0) return Status(ErrorCode::kTimeout, "memory can: no frame");
  const hal::CanFrame f = rx_[rx_head_];
  rx_head_ = (rx_head_ + 1) % rx_.size();
  --rx_count_;
  ++counters_.rx_frames;
  return f;
}

// ---- Scenario stream, ADC stand-in, calibration ------------------------------------------------

namespace {

class ScenarioStream final : public SensorStream {
 public:
  explicit ScenarioStream(const sim::Scenario& s)
      : traj_(sim::make_trajectory(s.trajectory)),
        model_(nav::table1_geometry<double>(s.rho_m), errors(s), sim::gravity_model(s), s.rate_hz,
               s.seed),
        rate_hz_(s.rate_hz) {}

  std::array<double, 6> volts(std::uint32_t seq) override {
    const sim::TruthState x = traj_->at(static_cast<double>(seq) / rate_hz_);
    const sim::SensorArrayModel::Volts v = model_.volts(x);
    return {v(0), v(1), v(2), v(3), v(4), v(5)};
  }

  static sim::ArrayErrors errors(const sim::Scenario& s) {
    sim::ArrayErrors e;
    e.misalignment = s.misalignment;
    e.temperature_c = s.temperature_c;
    for (std::size_t j = 0; j < 6; ++j) {
      sim::AccelErrors& a = e.sensors[j];
      if (s.qa1100) a = sim::AccelErrors::qa1100_typical();
      a.bias_g += s.bias_mps2[j] / nav::kStandardGravity;
      if (s.noise_mps2 > 0 || !s.qa1100) a.noise_g = s.noise_mps2 / nav::kStandardGravity;
    }
    return e;
  }

 private:
  std::unique_ptr<sim::Trajectory> traj_;
  sim::SensorArrayModel model_;
  double rate_hz_;
};

class BehaviouralAdc final : public AdcChain {
 public:
  explicit BehaviouralAdc(const sim::Scenario& s) : model_(config(s)) {}
  Status start() override { return Status::ok(); }
  Result<RawSample> convert(const std::array<double, 6>& volts, std::uint32_t seq,
                            std::int64_t t_ns) override {
    Eigen::Matrix<double, 6, 1> v;
    for (int j = 0; j < 6; ++j) v(j) = volts[static_cast<std::size_t>(j)];
    RawSample r = model_.sample(v, seq);
    r.t_ns = t_ns;
    return r;
  }
  double volts_per_count() const override { return model_.volts_per_count(); }
  app::AdcCounters counters() const override { return {}; }

 private:
  static sim::AdcConfig config(const sim::Scenario& s) {
    sim::AdcConfig c;
    c.sample_rate_hz = s.rate_hz;
    return c;
  }
  sim::AdcModel model_;
};

std::string device_id_for(const std::string& name) {
  std::string id = "sim-";
  for (char ch : name) {
    const bool ok = (ch >= 'A' && ch <= 'Z') || (ch >= 'a' && ch <= 'z') ||
                    (ch >= '0' && ch <= '9') || ch == '.' || ch == '_' || ch == '-';
    id += ok ? ch : '_';
  }
  return id.substr(0, calib_file::kMaxDeviceIdLength);
}

}  // namespace

std::unique_ptr<SensorStream> make_scenario_stream(const sim::Scenario& s) {
  return std::make_unique<ScenarioStream>(s);
}

std::unique_ptr<AdcChain> make_adc_chain(const sim::Scenario& s) {
  return std::make_unique<BehaviouralAdc>(s);
}

calib_file::CalibrationData scenario_calibration(const sim::Scenario& s, double volts_per_count) {
  calib_file::CalibrationData d;
  d.device_id = device_id_for(s.name);
  d.created_utc = "1970-01-01T00:00:00Z";
  d.source = "simulated board: the scenario's true sensor parameters";
  d.geometry.kind = calib_file::GeometryKind::kTable1;
  d.geometry.rho_m = s.rho_m;
  const sim::ArrayErrors e = ScenarioStream::errors(s);
  for (std::size_t j = 0; j < 6; ++j) {
    d.sensors[j].adc_lsb_v_per_count = volts_per_count;
    d.sensors[j].scale_v_per_g = e.sensors[j].scale_v_per_g;
    d.sensors[j].bias_g = e.sensors[j].bias_g;
    const nav::Vec3<double>& dr = s.misalignment.drho_b[j];
    d.sensors[j].location_error_m = {dr.x(), dr.y(), dr.z()};
  }
  for (std::size_t i = 0; i < 6; ++i) {
    d.beta.angle_deg[i] = s.misalignment.orientation.beta[i] / calib_file::kRadPerDeg;
    d.alpha.angle_deg[i] = s.misalignment.orientation.alpha[i] / calib_file::kRadPerDeg;
  }
  d.compensator = s.compensator;
  return d;
}

}  // namespace gfins::sim_board
