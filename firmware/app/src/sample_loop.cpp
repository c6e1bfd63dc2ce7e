#include "gfins/app/sample_loop.hpp"

#include <cmath>
#include <numbers>

#include "gfins/app/config.hpp"

namespace gfins::app {
namespace {

// Rate limit of repeated log records of one loop: one per second of samples at 1 kHz, carrying
// the counter so nothing is lost from the record, only from the log.
constexpr std::uint32_t kLogEverySamples = 1000;

}  // namespace

double LatencyHistogram::quantile_us(double q) const {
  if (count_ == 0) return 0.0;
  const auto want = static_cast<std::uint64_t>(std::ceil(q * static_cast<double>(count_)));
  std::uint64_t seen = 0;
  for (std::size_t b = 0; b < kBins; ++b) {
    seen += bins_[b];
    if (seen >= want && seen > 0) return static_cast<double>(b + 1);
  }
  return static_cast<double>(kBins);
}

SampleLoop::SampleLoop(SampleSource& adc, hal::CanBus& bus, EpochSink& out, hal::Clock& clock,
                       FwLogQueue& log)
    : adc_(adc), bus_(bus), out_(out), clock_(clock), log_(log) {}

Status SampleLoop::configure(const CalibrationSet& cal, const LoopOptions& options) {
  if (!(options.sample_rate_hz > 0.0)) {
    return Status(ErrorCode::kInvalidArgument, "sample loop: sample rate must be positive");
  }
  nav::PipelineConfig<float> cfg = cal.config;
  cfg.sample_rate_hz = static_cast<float>(options.sample_rate_hz);
  cfg.heading_rad = options.initial_heading_rad;
  cfg.r0_n = options.initial_position_n;
  if (const Status s = pipeline_.configure(cfg); !s.is_ok()) return s;
  cal_ = cal;
  cal_.config = cfg;
  options_ = options;
  period_ns_ = static_cast<std::int64_t>(std::llround(1e9 / options.sample_rate_hz));
  adc_seen_ = adc_.counters();
  can_seen_ = bus_.counters();
  can_state_ = bus_.state();
  mode_ = Mode::kAligning;
  return Status::ok();
}

void SampleLoop::log(LogLevel level, std::int64_t t_ns, const char* fmt, std::int64_t a0,
                     std::int64_t a1, std::int64_t a2, std::int64_t a3) {
  if (!log_.push(level, t_ns, fmt, a0, a1, a2, a3)) health_.log_dropped = log_.dropped();
}

SampleLoop::Cycle SampleLoop::step() {
  const Result<RawSample> r = adc_.read_sample(kReadTimeoutPeriods * period_ns_);
  Cycle cycle = Cycle::kSample;
  std::int64_t t_edge = 0;
  if (r.is_ok()) {
    t_edge = r.value().t_ns;
    on_sample(r.value());
  } else {
    t_edge = clock_.now_ns();
    if (r.status().code() == ErrorCode::kTimeout) {
      ++health_.drdy_timeouts;
      events_.set(status_bits::kDataReadyLost, sample_index_);
      log(LogLevel::kError, t_edge, "no data-ready edge for {} periods (timeouts: {})",
          kReadTimeoutPeriods, health_.drdy_timeouts);
      cycle = Cycle::kTimeout;
    } else {
      ++health_.adc_read_errors;
      log(LogLevel::kError, t_edge, "ADC read failed: error code {} (read errors: {})",
          static_cast<std::int64_t>(r.status().code()), health_.adc_read_errors);
      cycle = Cycle::kReadError;
    }
    update_adc_counters(sample_index_);
  }

  // Latency: edge → the epoch's frames handed to the bus backend (cycles that sent frames).
  const std::uint32_t frames = r.is_ok() ? out_.publish(epoch_) : 0;
  if (frames > 0) latency_.add(clock_.now_ns() - t_edge);
  bus_.service();
  update_can_counters(sample_index_, t_edge);

  handle_commands(t_edge);
  poll_reload(t_edge);

  // Overrun: this cycle's work ended after the next edge was due (that sample waits, and a
  // second overrun in a row loses it: the ADC overwrites its output buffer).
  if (r.is_ok() && clock_.now_ns() > t_edge + period_ns_) {
    ++health_.loop_overruns;
    events_.set(status_bits::kLoopOverrun, sample_index_);
    if (sample_index_ - last_log_ >= kLogEverySamples || health_.loop_overruns == 1) {
      last_log_ = sample_index_;
      log(LogLevel::kWarn, t_edge,
          "loop overrun: cycle took {} ns of a {} ns period (overruns: {})",
          clock_.now_ns() - t_edge, period_ns_, health_.loop_overruns);
    }
  }
  // The loop is alive whatever the ADC does: a hung loop stops kicking, a dead ADC shows in the
  // status instead (docs/faults.md).
  if (status_board_ != nullptr)
    status_board_->publish(mode_, cal_.calibrated, cal_.cal_id, health_);
  if (watchdog_ != nullptr) (void)watchdog_->kick();
  return cycle;
}

void SampleLoop::update_adc_counters(std::uint32_t sample) {
  const AdcCounters c = adc_.counters();
  if (c.crc_errors != adc_seen_.crc_errors) {
    const std::uint32_t before = health_.crc_errors;
    health_.crc_errors += c.crc_errors - adc_seen_.crc_errors;
    events_.set(status_bits::kCrcError, sample);
    if (before == 0 || sample - last_log_ >= kLogEverySamples) {
      last_log_ = sample;
      log(LogLevel::kWarn, 0, "ADC frame CRC error: sample skipped (CRC errors: {})",
          health_.crc_errors);
    }
  }
  if (c.chip_resets != adc_seen_.chip_resets) {
    health_.adc_resets += c.chip_resets - adc_seen_.chip_resets;
    events_.set(status_bits::kAdcRecovered, sample);
    log(LogLevel::kError, 0, "ADC reset detected and reconfigured (resets: {})",
        health_.adc_resets);
  }
  if (c.extra_edges != adc_seen_.extra_edges) {
    health_.extra_edges += c.extra_edges - adc_seen_.extra_edges;
    events_.set(status_bits::kExtraEdge, sample);
    log(LogLevel::kWarn, 0, "data-ready edge without a new conversion (extra edges: {})",
        health_.extra_edges);
  }
  adc_seen_ = c;
}

void SampleLoop::update_can_counters(std::uint32_t sample, std::int64_t t_ns) {
  const hal::CanCounters c = bus_.counters();
  if (c.tx_dropped != can_seen_.tx_dropped) {
    const std::uint32_t before = health_.can_tx_dropped;
    health_.can_tx_dropped += c.tx_dropped - can_seen_.tx_dropped;
    events_.set(status_bits::kCanTxDrop, sample);
    if (before == 0 || sample - last_log_ >= kLogEverySamples) {
      last_log_ = sample;
      log(LogLevel::kWarn, t_ns, "CAN frames dropped by the bus backend (dropped: {})",
          health_.can_tx_dropped);
    }
  }
  // Commands arrive on the receive side: a lost frame may be a lost command (the host's cmd
  // times out and says so), so the loss is flagged and counted, never silent.
  const std::uint32_t rx_lost =
      (c.rx_kernel_dropped - can_seen_.rx_kernel_dropped) + (c.rx_dropped - can_seen_.rx_dropped);
  if (rx_lost != 0) {
    health_.can_rx_dropped += rx_lost;
    events_.set(status_bits::kCanRxDrop, sample);
    log(LogLevel::kWarn, t_ns, "{} received CAN frame(s) lost before the loop read them (lost: {})",
        rx_lost, health_.can_rx_dropped);
  }
  if (c.bus_off_events != can_seen_.bus_off_events) {
    health_.bus_off_events += c.bus_off_events - can_seen_.bus_off_events;
    events_.set(status_bits::kBusOff, sample);
    log(LogLevel::kError, t_ns, "CAN bus-off (events: {}); frames are dropped until it recovers",
        health_.bus_off_events);
  }
  const hal::CanBusState state = bus_.state();
  if (state == hal::CanBusState::kBusOff) events_.set(status_bits::kBusOff, sample);
  if (state != can_state_) {
    log(LogLevel::kInfo, t_ns, "CAN state {} -> {} (0 active, 1 warning, 2 passive, 3 off, 4 down)",
        static_cast<std::int64_t>(can_state_), static_cast<std::int64_t>(state));
    can_state_ = state;
  }
  can_seen_ = c;
}

void SampleLoop::on_sample(const RawSample& s) {
  const std::uint32_t k = ++sample_index_;
  ++health_.samples;
  // Missed edges: the sample counter comes from the data-ready edge sequence.
  if (have_seq_ && s.seq - last_seq_ != 1u) {
    const std::uint32_t lost = s.seq - last_seq_ - 1u;
    health_.missed_edges += lost;
    events_.set(status_bits::kSampleGap, k);
    log(LogLevel::kWarn, s.t_ns, "{} data-ready edge(s) missed before sample {} (missed: {})", lost,
        s.seq, health_.missed_edges);
  }
  last_seq_ = s.seq;
  have_seq_ = true;
  update_adc_counters(k);

  const bool crc_ok = (s.flags & sample_flags::kCrcError) == 0;
  std::uint8_t saturated = 0;
  for (std::size_t j = 0; j < kAdcChannels; ++j) {
    if (s.counts[j] >= kAdcCodeMax || s.counts[j] <= kAdcCodeMin) {
      saturated = static_cast<std::uint8_t>(saturated | (1u << j));
    }
  }
  if (crc_ok) {
    health_.saturated_mask = saturated;
    if (saturated != 0) {
      if (health_.saturated_samples++ == 0 || k - last_log_ >= kLogEverySamples) {
        last_log_ = k;
        log(LogLevel::kWarn, s.t_ns, "channel mask {:#x} at full scale (saturated samples: {})",
            saturated, health_.saturated_samples);
      }
      events_.set(status_bits::kSaturated, k);
    }
    const std::uint8_t stuck = stuck_.update(s.counts);
    if (stuck != health_.stuck_mask) {
      const auto fresh = static_cast<std::uint8_t>(stuck & ~health_.stuck_mask);
      if (fresh != 0) {
        for (std::size_t j = 0; j < kAdcChannels; ++j) health_.stuck_events += (fresh >> j) & 1u;
        log(LogLevel::kError, s.t_ns,
            "channel mask {} stuck: code unchanged for {} samples (stuck events: {})", stuck,
            kStuckSamples, health_.stuck_events);
      } else {
        log(LogLevel::kInfo, s.t_ns, "stuck channel mask now {}", stuck);
      }
      health_.stuck_mask = stuck;
    }
    last_counts_ = s.counts;
  }
  if (!crc_ok || saturated != 0) ++health_.rejected_samples;

  // A CRC error means the counts are not a measurement: the pipeline skips the sample (and a
  // saturated one) and integrates across the hole with the next good one.
  if (crc_ok && saturated == 0) last_good_ = s;
  pipeline_.process(s);
  if (capture_.active && crc_ok) capture_add(s);
  build_epoch(s);
}

void SampleLoop::build_epoch(const RawSample& s) {
  const std::uint32_t k = sample_index_;
  epoch_.nav = pipeline_.state();
  // Every epoch refers to the sample just read (its edge time and counter). When the core did
  // not step on it (aligning, or the sample was rejected) the values are the last state held,
  // and a rejected sample is flagged as such.
  epoch_.nav.t_ns = s.t_ns;
  epoch_.nav.seq = s.seq;
  if ((s.flags & sample_flags::kCrcError) != 0 || health_.saturated_mask != 0) {
    epoch_.nav.status |= nav::nav_status::kInputInvalid;
  }
  nav::Vec6<float> f;
  pipeline_.front_end().convert(last_counts_, f);
  for (std::size_t j = 0; j < kAdcChannels; ++j) epoch_.accel_mps2[j] = f(static_cast<int>(j));
  const bool aligned = pipeline_.phase() == nav::PipelinePhase::kNavigating;
  std::uint32_t bits = events_.get(k);
  if (!cal_.calibrated) bits |= status_bits::kUncalibrated;
  if (aligned) bits |= status_bits::kAligned;
  if ((epoch_.nav.status & nav::nav_status::kInputInvalid) != 0) bits |= status_bits::kInputInvalid;
  if ((epoch_.nav.status & nav::nav_status::kCompensated) != 0) bits |= status_bits::kCompensated;
  if (health_.stuck_mask != 0) bits |= status_bits::kStuckChannel;
  if (capture_.active) bits |= status_bits::kCaptureActive;
  // Degraded: the solution integrates inputs known to be wrong (a stuck or saturated channel) or
  // the ADC stopped delivering; a CRC error or a missed edge alone costs one step across a gap.
  const bool degraded = (bits & (status_bits::kStuckChannel | status_bits::kSaturated |
                                 status_bits::kDataReadyLost)) != 0;
  if (degraded) bits |= status_bits::kDegraded;
  mode_ = !aligned ? Mode::kAligning : (degraded ? Mode::kDegraded : Mode::kNavigating);
  epoch_.mode = mode_;
  epoch_.status_bits = bits;
  epoch_.cal_id = cal_.cal_id;
  health_.log_dropped = log_.dropped();
  epoch_.health = health_;
}

// ---- Commands -------------------------------------------------------------------------------

void SampleLoop::handle_commands(std::int64_t t_ns) {
  if (codec_ == nullptr) return;
  for (int i = 0; i < kMaxCommandsPerCycle; ++i) {
    const Result<hal::CanFrame> f = bus_.receive(0);
    if (!f.is_ok()) return;  // kTimeout: nothing waiting
    const DecodedFrame d = codec_->decode(f.value());
    if (!d.addressed) continue;
    Response r;
    if (!d.ok) {
      r.raw_opcode = d.raw_opcode;
      r.token = d.token;
      r.result = d.error;
      ++health_.command_errors;
      log(LogLevel::kWarn, t_ns, "command frame id {:#x} rejected: result {}", f.value().id,
          static_cast<std::int64_t>(d.error));
    } else {
      execute(d.command, r);
      log(LogLevel::kInfo, t_ns, "command {} token {} -> result {}",
          static_cast<std::int64_t>(d.command.kind), d.command.token,
          static_cast<std::int64_t>(r.result));
    }
    if (!r.deferred) send_response(r);
  }
}

void SampleLoop::send_response(const Response& r) {
  if (codec_ == nullptr) return;
  std::array<hal::CanFrame, 24> frames{};
  const std::size_t n = codec_->encode(r, frames);
  for (std::size_t i = 0; i < n && i < frames.size(); ++i) (void)bus_.send(frames[i]);
}

Status SampleLoop::reconfigure_keep_navigation(const nav::PipelineConfig<float>& cfg) {
  const bool navigating = pipeline_.phase() == nav::PipelinePhase::kNavigating;
  const nav::NavState<float> state = pipeline_.state();
  if (const Status s = pipeline_.configure(cfg); !s.is_ok()) return s;
  // configure() restarts alignment; a running navigation continues from its current state
  // with the new compensation instead.
  if (navigating) pipeline_.start_at(state, last_good_);
  return Status::ok();
}

void SampleLoop::execute(const Command& c, Response& r) {
  r = Response{};
  r.kind = c.kind;
  r.raw_opcode = static_cast<std::uint8_t>(c.kind);
  r.token = c.token;
  r.cal_id = cal_.cal_id;
  r.calibrated = cal_.calibrated;
  const auto reject = [&](CommandResult why) {
    r.result = why;
    ++health_.command_errors;
  };
  switch (c.kind) {
    case CommandKind::kRealign:
    case CommandKind::kResetNavigation: {
      const bool realign = c.kind == CommandKind::kRealign;
      if (realign && !(std::abs(c.heading_rad) <= 2.0f * std::numbers::pi_v<float>)) {
        return reject(CommandResult::kOutOfRange);
      }
      nav::PipelineConfig<float> cfg = cal_.config;
      cfg.heading_rad = realign ? c.heading_rad : options_.initial_heading_rad;
      cfg.r0_n = options_.initial_position_n;
      if (!pipeline_.configure(cfg).is_ok()) return reject(CommandResult::kFailed);
      cal_.config = cfg;
      stuck_.reset();
      break;
    }
    case CommandKind::kSetCompensator: {
      if (c.compensator != nav::CompensatorKind::kNone &&
          c.compensator != nav::CompensatorKind::kPaper &&
          c.compensator != nav::CompensatorKind::kExact) {
        return reject(CommandResult::kOutOfRange);
      }
      nav::PipelineConfig<float> cfg = cal_.config;
      cfg.compensator = c.compensator;
      if (!reconfigure_keep_navigation(cfg).is_ok()) return reject(CommandResult::kFailed);
      cal_.config = cfg;
      break;
    }
    case CommandKind::kSetDivider:
      if (c.message >= kNumMessages || c.divider > kMaxDivider) {
        return reject(CommandResult::kOutOfRange);
      }
      if (!out_.set_divider(c.message, c.divider).is_ok())
        return reject(CommandResult::kOutOfRange);
      r.value = c.divider;
      break;
    case CommandKind::kReportCalibration:
      break;
    case CommandKind::kCaptureCalibration:
      if (c.samples == 0 || c.samples > kMaxCaptureSamples || c.pose > kMaxPose) {
        return reject(CommandResult::kOutOfRange);
      }
      if (capture_.active) return reject(CommandResult::kBusy);
      capture_ = Capture{};
      capture_.active = true;
      capture_.command = c;
      capture_.target = c.samples;
      r.value = c.samples;
      break;
    case CommandKind::kReloadCalibration:
      if (reload_ == nullptr) return reject(CommandResult::kFailed);
      if (reload_pending_ || !reload_->request(cal_.config)) return reject(CommandResult::kBusy);
      reload_pending_ = true;
      reload_token_ = c.token;
      r.deferred = true;  // answered when the worker is done (poll_reload)
      break;
    default:
      return reject(CommandResult::kUnknownOpcode);
  }
  ++health_.commands;
}

void SampleLoop::capture_add(const RawSample& s) {
  for (std::size_t j = 0; j < kAdcChannels; ++j) {
    if (s.counts[j] >= kAdcCodeMax || s.counts[j] <= kAdcCodeMin) capture_.saturated[j] = true;
    // Welford's running mean and sum of squares (numerically stable for long captures).
    const auto v = static_cast<double>(s.counts[j]);
    const double n = static_cast<double>(++capture_.n[j]);
    const double d = v - capture_.mean[j];
    capture_.mean[j] += d / n;
    capture_.m2[j] += d * (v - capture_.mean[j]);
  }
  if (capture_.n[0] >= capture_.target) capture_finish();
}

void SampleLoop::capture_finish() {
  const auto& fe = pipeline_.front_end().params();
  Response r;
  r.kind = CommandKind::kCaptureCalibration;
  r.raw_opcode = static_cast<std::uint8_t>(r.kind);
  r.token = capture_.command.token;
  r.result = CommandResult::kOk;
  r.cal_id = cal_.cal_id;
  r.calibrated = cal_.calibrated;
  r.has_capture = true;
  r.capture.pose = capture_.command.pose;
  r.capture.samples = capture_.command.samples;
  for (std::size_t j = 0; j < kAdcChannels; ++j) {
    CaptureChannel& ch = r.capture.channels[j];
    const std::uint32_t n = capture_.n[j];
    ch.count = n;
    ch.mean_counts = static_cast<float>(capture_.mean[j]);
    const double sd = n > 1 ? std::sqrt(capture_.m2[j] / static_cast<double>(n - 1)) : 0.0;
    ch.std_counts = static_cast<float>(sd);
    ch.saturated = capture_.saturated[j];
    // counts → g through the channel's LSB (V/count) and scale factor (V/g)
    const double g_per_count =
        static_cast<double>(fe.volts_per_count[j]) / static_cast<double>(fe.scale_v_per_g[j]);
    ch.motion = sd * g_per_count > kCaptureMotionStdG;
  }
  capture_.active = false;
  last_capture_ = r.capture;
  log(LogLevel::kInfo, 0, "calibration capture pose {} done: {} samples, motion {}", r.capture.pose,
      r.capture.channels[0].count, r.capture.motion() ? 1 : 0);
  send_response(r);
}

void SampleLoop::poll_reload(std::int64_t t_ns) {
  if (!reload_pending_ || reload_ == nullptr) return;
  CalibrationSet fresh;
  const ReloadWorker::Poll p = reload_->poll(fresh);
  if (p == ReloadWorker::Poll::kNothing) return;
  reload_pending_ = false;
  Response r;
  r.kind = CommandKind::kReloadCalibration;
  r.raw_opcode = static_cast<std::uint8_t>(r.kind);
  r.token = reload_token_;
  r.result = CommandResult::kFailed;
  if (p == ReloadWorker::Poll::kReady) {
    nav::PipelineConfig<float> cfg = fresh.config;
    cfg.sample_rate_hz = cal_.config.sample_rate_hz;
    cfg.heading_rad = cal_.config.heading_rad;
    cfg.r0_n = cal_.config.r0_n;
    cfg.gravity = cal_.config.gravity;
    cfg.alignment_samples = cal_.config.alignment_samples;
    if (reconfigure_keep_navigation(cfg).is_ok()) {
      cal_.config = cfg;
      cal_.cal_id = fresh.cal_id;
      cal_.calibrated = fresh.calibrated;
      r.result = CommandResult::kOk;
      log(LogLevel::kInfo, t_ns, "calibration reloaded: id {:#x}", cal_.cal_id);
    }
  }
  if (r.result != CommandResult::kOk) {
    ++health_.command_errors;
    log(LogLevel::kError, t_ns, "calibration reload failed; the previous calibration (id {}) stays",
        cal_.cal_id);
  }
  r.cal_id = cal_.cal_id;
  r.calibrated = cal_.calibrated;
  send_response(r);
}

}  // namespace gfins::app
