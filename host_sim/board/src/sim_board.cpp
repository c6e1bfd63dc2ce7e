#include "gfins/host_sim/board/sim_board.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <thread>

#include "gfins/host_sim/chip/simulated_adc.hpp"
#include "gfins/host_sim/sample_generator.hpp"
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

SimSampleSource::SimSampleSource(SensorStream& stream, ChipAdc& adc, hal::Clock& clock,
                                 app::SampleClock* sample_clock, Pacing pacing,
                                 double sample_rate_hz, std::uint32_t samples)
    : stream_(stream),
      adc_(adc),
      clock_(clock),
      sample_clock_(sample_clock),
      pacing_(pacing),
      period_ns_(static_cast<std::int64_t>(std::llround(1e9 / sample_rate_hz))),
      remaining_(samples) {
  // Real time: the first edge one period from now, so the loop starts on a fresh period.
  if (pacing_ == Pacing::kRealTime) t0_ns_ = clock_.now_ns() + period_ns_;
}

SimSampleSource::SimSampleSource(SensorStream& stream, ChipAdc& adc, hal::Clock& clock,
                                 hal::DataReadyLine& drdy, std::uint32_t samples)
    : stream_(stream),
      adc_(adc),
      clock_(clock),
      sample_clock_(nullptr),
      pacing_(Pacing::kGpio),
      period_ns_(0),
      remaining_(samples),
      drdy_(&drdy) {}

bool SimSampleSource::contains(const std::vector<std::uint32_t>& v, std::uint32_t x) {
  return std::find(v.begin(), v.end(), x) != v.end();
}

std::int64_t SimSampleSource::edge_time(std::uint32_t seq) const {
  // Fast: scenario time of the conversion (the same instant AdcModel stamps); real time: the
  // monotonic time the edge is due.
  return t0_ns_ + static_cast<std::int64_t>(seq) * period_ns_;
}

Result<RawSample> SimSampleSource::read_gpio_paced(std::int64_t timeout_ns) {
  // The edge first: no edge, no conversion (a silent line times out here as on the board).
  const Result<hal::DataReadyEdge> edge = drdy_->wait_edge(timeout_ns);
  if (!edge.is_ok()) return edge.status();
  if (!have_first_edge_) {
    have_first_edge_ = true;
    first_edge_seq_ = edge.value().seq;
  }
  // Conversion index since the first edge (modulo 2^32, as the line's sequence).
  const std::uint32_t seq = edge.value().seq - first_edge_seq_;
  if (seq < next_seq_) {
    return Status(ErrorCode::kOutOfRange, "sim: data-ready sequence went back");
  }
  // Conversions whose edges were missed happened all the same: their voltages are skipped.
  while (next_seq_ < seq && remaining_ > 0) {
    (void)stream_.volts(next_seq_++);
    --remaining_;
  }
  if (remaining_ == 0) return Status(ErrorCode::kUnavailable, "sim: scenario finished");
  ++next_seq_;
  --remaining_;
  // The conversion is stamped with the kernel's timestamp of its edge; the driver sees the
  // edge's sequence, so a gap counts as missed edges exactly as on the Linux board.
  return adc_.convert(stream_.volts(seq), seq, edge.value().t_ns);
}

Result<RawSample> SimSampleSource::do_read_sample(std::int64_t timeout_ns) {
  if (remaining_ == 0) return Status(ErrorCode::kUnavailable, "sim: scenario finished");
  if (pacing_ == Pacing::kGpio) return read_gpio_paced(timeout_ns);
  // A silent data-ready line: no edge for the timeout; the conversions still happen (the sensor
  // stream advances) and are lost.
  if (faults_.silent_from != 0 && next_seq_ == faults_.silent_from && silent_left_ == 0) {
    silent_left_ = faults_.silent_edges;
  }
  if (silent_left_ > 0) {
    const auto periods =
        static_cast<std::uint32_t>(std::max<std::int64_t>(1, timeout_ns / period_ns_));
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
  // Conversions until one is read: a lost edge or a chip reset costs the conversion it hits.
  for (;;) {
    const std::uint32_t seq = next_seq_++;
    --remaining_;
    const std::array<double, 6> v = stream_.volts(seq);
    const std::int64_t t = edge_time(seq);
    if (pacing_ == Pacing::kRealTime) (void)clock_.sleep_until_ns(t);
    if (sample_clock_ != nullptr) sample_clock_->set(t);
    const auto in = [seq](std::uint32_t from, std::uint32_t until) {
      return seq >= from && (until == 0 || seq < until);
    };
    if (faults_.reset_at != 0 && seq == faults_.reset_at) adc_.power_on_reset();
    if (contains(faults_.missing_edges, seq)) adc_.drop_edge();
    if (contains(faults_.extra_edge_after, seq - 1)) adc_.extra_edge();
    if (contains(faults_.crc_error_at, seq)) adc_.corrupt_next_frame();
    if (faults_.saturated_channel >= 0) {
      if (seq == faults_.saturated_from) adc_.saturate_channel(faults_.saturated_channel);
      if (seq == faults_.saturated_until) adc_.clear_channel_faults();
    }
    if (faults_.stuck_channel >= 0 && seq == faults_.stuck_until && faults_.stuck_until != 0) {
      adc_.clear_channel_faults();
    }
    Result<RawSample> r = adc_.convert(v, seq, t);
    if (r.is_ok() && faults_.stuck_channel >= 0 && seq == faults_.stuck_from &&
        in(faults_.stuck_from, faults_.stuck_until)) {
      // From the next conversion on the channel repeats this one's code.
      const auto j = static_cast<std::size_t>(faults_.stuck_channel);
      adc_.stick_channel(faults_.stuck_channel, r.value().counts[j]);
    }
    if (r.is_ok() || remaining_ == 0) return r;
    if (r.status().code() != ErrorCode::kUnavailable && r.status().code() != ErrorCode::kDataLoss) {
      return r;
    }
    // kUnavailable: the edge was lost; kDataLoss: the driver found the chip reset and has
    // reconfigured it. Either way no sample for this conversion: the loop sees the next one.
  }
}

app::AdcCounters SimSampleSource::do_counters() const { return adc_.counters(); }

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

can::GnssFix to_gnss_fix(const sim::GnssSample& s, const sim::GnssSpec& spec) {
  can::GnssFix f;
  f.fix_id = static_cast<std::uint8_t>(s.index & 0x0Fu);
  f.has_position = true;
  f.has_velocity = true;
  for (int i = 0; i < 3; ++i) {
    f.r_n_m[static_cast<std::size_t>(i)] = s.r_n_m[i];
    f.v_n_mps[static_cast<std::size_t>(i)] = s.v_n_mps[i];
  }
  f.sigma_pos_h_m = spec.sigma_pos_h_m;
  f.sigma_pos_v_m = spec.sigma_pos_v_m;
  f.sigma_vel_mps = spec.sigma_vel_mps;
  f.age_s = s.t_send_s - s.t_valid_s;
  return f;
}

GnssReceiverBus::GnssReceiverBus(std::unique_ptr<hal::CanBus> inner,
                                 std::vector<sim::GnssSample> fixes, const sim::GnssSpec& spec,
                                 std::uint8_t node_id, const can::IdBases& ids,
                                 std::function<double()> now_s)
    : inner_(std::move(inner)),
      fixes_(std::move(fixes)),
      spec_(spec),
      node_id_(node_id),
      ids_(ids),
      now_s_(std::move(now_s)) {}

Result<hal::CanFrame> GnssReceiverBus::do_receive(std::int64_t timeout_ns) {
  if (pending_next_ >= pending_.size() && next_ < fixes_.size()) {
    const double now = now_s_();
    const sim::GnssSample& g = fixes_[next_];
    if (g.t_send_s <= now) {
      // Handed over after the sample at `now`: the age is counted from that sample, so the
      // board's time of validity (that sample's time - age) is the fix's own.
      can::GnssFix fix = to_gnss_fix(g, spec_);
      fix.age_s = now - g.t_valid_s;
      pending_ = can::encode_gnss_fix(fix, node_id_, ids_);
      pending_next_ = 0;
      ++next_;
    }
  }
  if (pending_next_ < pending_.size()) return pending_[pending_next_++];
  return inner_->receive(timeout_ns);
}

bool MemoryCanBus::inject_rx(const hal::CanFrame& f) {
  if (rx_count_ == rx_.size()) return false;
  rx_[(rx_head_ + rx_count_) % rx_.size()] = f;
  ++rx_count_;
  return true;
}

std::vector<hal::CanFrame> MemoryCanBus::sent() const {
  std::vector<hal::CanFrame> out;
  const auto n = static_cast<std::size_t>(std::min<std::uint64_t>(total_, ring_.size()));
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

// The host's one sample source (host_sim/sample_generator.hpp) up to the sensor voltages: the
// simulated board puts its own converter (the chip model, with its data-ready line and fault
// injection) behind them, so the source runs without one.
class ScenarioStream final : public SensorStream {
 public:
  ScenarioStream(const sim::Scenario& s, std::unique_ptr<sim::Trajectory> traj,
                 sim::SensorArrayModel sensors)
      : traj_(std::move(traj)), source_(*traj_, std::move(sensors), nullptr, s.rate_hz) {
    if (s.noise_uniform) source_.set_uniform_noise_mps2(s.noise_mps2, s.seed);
  }

  std::array<double, 6> volts(std::uint32_t /*seq*/) override {
    // Index-driven: conversion k is the source's k-th sample (the caller asks in order).
    const Result<sim::GeneratedSample> x = source_.next();
    const sim::SensorArrayModel::Volts& v = x.value().volts;
    return {v(0), v(1), v(2), v(3), v(4), v(5)};
  }

  /// The scenario's sensors as the host's scenario runner builds them (sim::array_errors). The
  /// simulated board always has its converter, so a scenario written without one (the paper's
  /// §6.3) still gets the QA-1100 scale factor here.
  static sim::ArrayErrors errors(const sim::Scenario& s) {
    sim::ArrayErrors e = sim::array_errors(s);
    if (!s.adc) {
      for (auto& a : e.sensors) a.scale_v_per_g = sim::AccelErrors::qa1100_typical().scale_v_per_g;
    }
    return e;
  }

 private:
  std::unique_ptr<sim::Trajectory> traj_;
  sim::SampleGenerator source_;
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

sim::HostResult<std::unique_ptr<SensorStream>> make_scenario_stream(const sim::Scenario& s) {
  // Values, not exceptions: this runs inside gfins-fw (docs/architecture.md, errors).
  auto traj = sim::make_trajectory(s.trajectory);
  if (!traj.is_ok()) {
    return sim::HostError{traj.error().code, "scenario " + s.name + ": " + traj.error().message};
  }
  auto sensors =
      sim::SensorArrayModel::make(nav::table1_geometry<double>(s.rho_m), ScenarioStream::errors(s),
                                  sim::gravity_model(s), s.rate_hz, s.seed);
  if (!sensors.is_ok()) {
    return sim::HostError{sensors.error().code,
                          "scenario " + s.name + ": " + sensors.error().message};
  }
  return std::unique_ptr<SensorStream>(
      std::make_unique<ScenarioStream>(s, std::move(traj).value(), std::move(sensors).value()));
}

// ---- The chip -----------------------------------------------------------------------------

struct ChipAdc::Impl {
  explicit Impl(const sim::SimulatedAdcConfig& c) : adc(c) {}
  sim::SimulatedAdc adc;
};

namespace {
sim::SimulatedAdcConfig chip_config(double sample_rate_hz) {
  sim::SimulatedAdcConfig c;
  c.adc.sample_rate_hz = sample_rate_hz;
  return c;
}
}  // namespace

ChipAdc::ChipAdc(double sample_rate_hz)
    : impl_(std::make_unique<Impl>(chip_config(sample_rate_hz))) {}
ChipAdc::~ChipAdc() = default;
Status ChipAdc::start() { return impl_->adc.start(); }
Result<RawSample> ChipAdc::convert(const std::array<double, 6>& volts, std::uint32_t seq,
                                   std::int64_t t_ns) {
  return impl_->adc.convert(volts, seq, t_ns);
}
double ChipAdc::volts_per_count() const { return impl_->adc.volts_per_count(0); }
app::AdcCounters ChipAdc::counters() const {
  const drivers::Ads131m06Counters& d = impl_->adc.driver().counters();
  app::AdcCounters c;
  c.crc_errors = d.crc_errors;
  c.missed_edges = d.missed_edges;
  c.extra_edges = d.extra_edges;
  // A reset the driver meets as a re-verification mismatch (its RREG answer replaced the STATUS
  // word that would have shown RESET) is recovered the same way: both count (docs/faults.md).
  c.chip_resets = d.chip_resets + d.register_mismatches;
  return c;
}
void ChipAdc::corrupt_next_frame() { impl_->adc.chip().corrupt_output_crc(1); }
void ChipAdc::stick_channel(int ch, std::int32_t code) {
  impl_->adc.chip().stick_channel(ch, code);
}
void ChipAdc::saturate_channel(int ch) { impl_->adc.chip().saturate_channel(ch, true); }
void ChipAdc::clear_channel_faults() { impl_->adc.chip().clear_channel_faults(); }
void ChipAdc::power_on_reset() { impl_->adc.chip().power_on_reset(); }
void ChipAdc::drop_edge() { impl_->adc.drop_edges(1); }
void ChipAdc::extra_edge() { impl_->adc.inject_extra_edges(1); }

calib_file::CalibrationData scenario_calibration(const sim::Scenario& s, double volts_per_count) {
  calib_file::CalibrationData d;
  d.device_id = device_id_for(s.name);
  d.created_utc = "1970-01-01T00:00:00Z";
  d.source = "simulated board: the scenario's true sensor parameters";
  d.geometry.kind = calib_file::GeometryKind::kTable1;
  d.geometry.rho_m = s.rho_m;
  const sim::ArrayErrors e = ScenarioStream::errors(s);
  // A board calibrated where the scenario is: its g (the g of V/g) is the scenario's gravity at
  // the origin. The sensor model's parameters are per standard g, so they are restated per local
  // g; the conversion to m/s² is unchanged (scale·g and bias·g are the same products).
  const double g_local = std::abs(sim::gravity_model(s).magnitude_at_origin());
  const double per_local = nav::kStandardGravity / g_local;
  d.gravity_mps2 = g_local;
  d.gravity_source = "simulated board: the scenario's gravity model at the origin";
  for (std::size_t j = 0; j < 6; ++j) {
    d.sensors[j].adc_lsb_v_per_count = volts_per_count;
    d.sensors[j].scale_v_per_g = e.sensors[j].scale_v_per_g / per_local;
    d.sensors[j].bias_g = e.sensors[j].bias_g * per_local;
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
