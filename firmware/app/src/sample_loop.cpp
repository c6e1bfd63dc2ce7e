#include "gfins/app/sample_loop.hpp"

#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <thread>

#include "gfins/app/config.hpp"
#include "gfins/app/nav_accuracy.hpp"
#include "gfins/app/vehicle_frame.hpp"
#include "gfins/can/aiding_offer.hpp"

namespace gfins::app {

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
  settings_ = options.stored;
  inputs_ = can::InputDecoder(options.node_id, options.ids);
  period_ns_ = static_cast<std::int64_t>(std::llround(1e9 / options.sample_rate_hz));
  adc_seen_ = adc_.counters();
  can_seen_ = bus_.counters();
  can_state_ = bus_.state();
  ref_t_ns_ = clock_.now_ns();
  mode_ = can::Mode::kAligning;
  return Status::ok();
}

void SampleLoop::log(LogLevel level, std::int64_t t_ns, const char* fmt, std::int64_t a0,
                     std::int64_t a1, std::int64_t a2, std::int64_t a3) {
  if (!log_.push(level, t_ns, fmt, a0, a1, a2, a3)) health_.log_dropped = log_.dropped();
}

SampleLoop::Cycle SampleLoop::step() {
  const Result<RawSample> r = adc_.read_sample(kReadTimeoutPeriods * period_ns_);
  Cycle cycle = Cycle::kSample;
  if (r.is_ok()) {
    t_cycle_ = r.value().t_ns;
    wait_for_recorder();
    if (recorder_ != nullptr && !record_sample(*recorder_, r.value())) note_record_dropped();
    on_sample(r.value());
  } else {
    t_cycle_ = clock_.now_ns();
    if (r.status().code() == ErrorCode::kTimeout) {
      ++health_.drdy_timeouts;
      events_.set(status_bits::kDataReadyLost, sample_index_);
      limited_log(LogKind::kDataReadyTimeout, LogLevel::kError, t_cycle_,
                  "no data-ready edge for {} periods (timeouts: {}; {} more since the last line)",
                  kReadTimeoutPeriods, health_.drdy_timeouts);
      cycle = Cycle::kTimeout;
    } else {
      on_read_error(t_cycle_, r.status());
      cycle = Cycle::kReadError;
    }
    update_adc_counters(sample_index_);
  }

  // Latency: edge → the epoch's frames handed to the bus backend (cycles that sent frames).
  if (r.is_ok()) {
    const std::uint32_t frames = out_.publish(epoch_);
    published_seq_ = r.value().seq;
    have_published_ = true;
    if (frames > 0) latency_.add(clock_.now_ns() - t_cycle_);
  } else {
    // No sample: the periods the ADC should have filled still get their status and health
    // frames (the fault bits set, navigation values not available).
    publish_gap(t_cycle_, cycle == Cycle::kTimeout ? status_bits::kDataReadyLost
                                                   : status_bits::kAdcReadError);
  }
  bus_.service();
  update_can_counters(sample_index_, t_cycle_);

  handle_commands(t_cycle_);
  poll_reload(t_cycle_);
  offer_settings();

  // Overrun: this cycle's work ended after the next edge was due (that sample waits, and a
  // second overrun in a row loses it: the ADC overwrites its output buffer).
  if (r.is_ok() && clock_.now_ns() > t_cycle_ + period_ns_) {
    ++health_.loop_overruns;
    events_.set(status_bits::kLoopOverrun, sample_index_);
    limited_log(LogKind::kOverrun, LogLevel::kWarn, t_cycle_,
                "loop overrun: cycle took {} ns of a {} ns period (overruns: {}; {} more since the "
                "last line)",
                clock_.now_ns() - t_cycle_, period_ns_, health_.loop_overruns);
  }
  // The loop is alive whatever the ADC does: a hung loop stops kicking, a dead ADC shows in the
  // status instead, until it has delivered nothing for kDeadAdcWatchdogNs (docs/faults.md).
  if (adc_failing_ && !watchdog_held_ && t_cycle_ - failing_since_ns_ >= kDeadAdcWatchdogNs) {
    watchdog_held_ = true;
    limited_log(LogKind::kAdcDead, LogLevel::kError, t_cycle_,
                "ADC delivered no sample for {} ms: watchdog kicks stop so the service manager "
                "restarts the firmware (read errors: {}; {} more since the last line)",
                kDeadAdcWatchdogNs / 1000000, health_.adc_read_errors);
  }
  if (status_board_ != nullptr)
    status_board_->publish(mode_, (epoch_.status_bits & status_bits::kHealthDegraded) != 0,
                           cal_.calibrated, cal_.cal_id, health_);
  if (watchdog_ != nullptr && !watchdog_held_) (void)watchdog_->kick();
  if (cycle == Cycle::kReadError) {
    // A read that failed at once (a dead chip, an SPI error) must not make the loop spin: wait
    // for the next sample period on the grid of the last edge, as a data-ready wait would.
    const std::int64_t since = t_cycle_ - ref_t_ns_;
    const std::int64_t next =
        ref_t_ns_ + (since < 0 ? period_ns_ : (since / period_ns_ + 1) * period_ns_);
    (void)clock_.sleep_until_ns(next);
  }
  return cycle;
}

void SampleLoop::on_read_error(std::int64_t t_ns, const Status& st) {
  ++health_.adc_read_errors;
  events_.set(status_bits::kAdcReadError, sample_index_);
  if (!adc_failing_) {
    adc_failing_ = true;
    failing_since_ns_ = t_ns;
  }
  limited_log(LogKind::kAdcReadError, LogLevel::kError, t_ns,
              "ADC read failed: error code {} (read errors: {}; {} more since the last line)",
              static_cast<std::int64_t>(st.code()), health_.adc_read_errors);
}

void SampleLoop::publish_gap(std::int64_t t_ns, std::uint32_t cause) {
  // The conversions the ADC should have delivered since the last sample: the periods that ended
  // at least half a period before now (the half period keeps a late edge that is still coming
  // from being published twice).
  const std::int64_t elapsed = t_ns - ref_t_ns_ - period_ns_ / 2;
  if (elapsed < period_ns_) return;
  const auto periods = static_cast<std::uint32_t>(elapsed / period_ns_);
  const std::uint32_t last = ref_seq_ + periods;
  std::uint32_t k = have_published_ ? published_seq_ + 1u : ref_seq_ + 1u;
  if (static_cast<std::int32_t>(last - k) < 0) return;  // already published up to `last`
  if (last - k >= kMaxGapEpochsPerCycle) k = last - kMaxGapEpochsPerCycle + 1u;
  for (;; ++k) {
    build_gap_epoch(k, ref_t_ns_ + static_cast<std::int64_t>(k - ref_seq_) * period_ns_, cause);
    (void)out_.publish(epoch_);
    if (k == last) break;
  }
  published_seq_ = last;
  have_published_ = true;
}

void SampleLoop::build_gap_epoch(std::uint32_t seq, std::int64_t t_ns, std::uint32_t cause) {
  // No sample behind this epoch: time and counter are the period's nominal ones, the navigation
  // values are not available (NaN: the encoder sends each signal's not-available code and the
  // status frame's "a value was not available" bit), the state itself is kept for when samples
  // return (NavPipeline integrates across the gap).
  constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
  const bool aligned = pipeline_.phase() == nav::PipelinePhase::kNavigating;
  epoch_.nav = pipeline_.state();
  epoch_.nav.t_ns = t_ns;
  epoch_.nav.seq = seq;
  epoch_.nav.q_nb = nav::Quat<float>(kNaN, kNaN, kNaN, kNaN);
  epoch_.nav.w_b.setConstant(kNaN);
  epoch_.nav.wdot_b.setConstant(kNaN);
  epoch_.nav.f_b.setConstant(kNaN);
  epoch_.nav.v_n.setConstant(kNaN);
  epoch_.nav.r_n.setConstant(kNaN);
  epoch_.nav.status = nav::nav_status::kInputInvalid | (aligned ? nav::nav_status::kAligned : 0u);
  epoch_.accel_mps2.fill(kNaN);
  std::uint32_t bits = events_.get(sample_index_) | cause | status_bits::kInputInvalid;
  if (!cal_.calibrated) bits |= status_bits::kNominalCalibration;
  if (aligned) bits |= status_bits::kAligned;
  if (health_.stuck_mask != 0) bits |= status_bits::kAdcChannelStuck;
  if (capture_.active) bits |= status_bits::kCaptureActive;
  // Nothing is being measured: the output is degraded whatever the cause.
  bits |= status_bits::kHealthDegraded;
  set_mode(aligned, bits);
  epoch_.status_bits = bits;
  epoch_.cal_id = cal_.cal_id;
  health_.log_dropped = log_.dropped();
  epoch_.health = bus_health(health_);
  epoch_.commands = bus_command_counters(health_, settings_source());
  epoch_.valid = can::Validity::none();  // no sample behind this epoch
  // The σ are the held state's (the values above are not available, the filter's knowledge
  // is), in the frame the epochs publish.
  nav::NavState<float> held = pipeline_.state();
  if (mounted(options_.q_vb)) to_vehicle_frame(held, options_.q_vb);
  epoch_.accuracy = epoch_accuracy(pipeline_, t_ns, held);
}

void SampleLoop::update_adc_counters(std::uint32_t sample) {
  const AdcCounters c = adc_.counters();
  if (c.crc_errors != adc_seen_.crc_errors) {
    health_.crc_errors += c.crc_errors - adc_seen_.crc_errors;
    events_.set(status_bits::kAdcCrcError, sample);
    limited_log(LogKind::kCrcError, LogLevel::kWarn, t_cycle_,
                "ADC frame CRC error: sample skipped (CRC errors: {}; {} more since the last line)",
                health_.crc_errors);
  }
  if (c.chip_resets != adc_seen_.chip_resets) {
    health_.adc_resets += c.chip_resets - adc_seen_.chip_resets;
    events_.set(status_bits::kAdcRecovered, sample);
    limited_log(LogKind::kAdcReset, LogLevel::kError, t_cycle_,
                "ADC reset detected and reconfigured (resets: {}; {} more since the last line)",
                health_.adc_resets);
  }
  if (c.extra_edges != adc_seen_.extra_edges) {
    health_.extra_edges += c.extra_edges - adc_seen_.extra_edges;
    events_.set(status_bits::kExtraEdge, sample);
    limited_log(LogKind::kExtraEdge, LogLevel::kWarn, t_cycle_,
                "data-ready edge without a new conversion (extra edges: {}; {} more since the "
                "last line)",
                health_.extra_edges);
  }
  adc_seen_ = c;
}

void SampleLoop::update_can_counters(std::uint32_t sample, std::int64_t t_ns) {
  const hal::CanCounters c = bus_.counters();
  if (c.tx_dropped != can_seen_.tx_dropped) {
    health_.can_tx_dropped += c.tx_dropped - can_seen_.tx_dropped;
    events_.set(status_bits::kCanTxDropped, sample);
    limited_log(LogKind::kCanTxDrop, LogLevel::kWarn, t_ns,
                "CAN frames dropped by the bus backend (dropped: {}; {} more since the last line)",
                health_.can_tx_dropped);
  }
  // Commands arrive on the receive side: a lost frame may be a lost command (the host's cmd
  // times out and says so), so the loss is flagged and counted, never silent.
  const std::uint32_t rx_lost =
      (c.rx_kernel_dropped - can_seen_.rx_kernel_dropped) + (c.rx_dropped - can_seen_.rx_dropped);
  if (rx_lost != 0) {
    health_.can_rx_dropped += rx_lost;
    events_.set(status_bits::kCanRxDropped, sample);
    limited_log(LogKind::kCanRxDrop, LogLevel::kWarn, t_ns,
                "{} received CAN frame(s) lost before the loop read them (lost: {}; {} more "
                "since the last line)",
                rx_lost, health_.can_rx_dropped);
  }
  if (c.bus_off_events != can_seen_.bus_off_events) {
    health_.bus_off_events += c.bus_off_events - can_seen_.bus_off_events;
    events_.set(status_bits::kBusOff, sample);
    limited_log(LogKind::kBusOff, LogLevel::kError, t_ns,
                "CAN bus-off (events: {}); frames are dropped until it recovers ({} more since "
                "the last line)",
                health_.bus_off_events);
  }
  const hal::CanBusState state = bus_.state();
  if (state == hal::CanBusState::kBusOff) events_.set(status_bits::kBusOff, sample);
  if (state != can_state_) {
    const bool worse = state == hal::CanBusState::kErrorPassive ||
                       state == hal::CanBusState::kBusOff || state == hal::CanBusState::kDown;
    limited_log(worse ? LogKind::kCanStateWorse : LogKind::kCanStateBetter, LogLevel::kInfo, t_ns,
                "CAN state {} -> {} (0 active, 1 warning, 2 passive, 3 off, 4 down; {} more "
                "changes since the last line)",
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
    limited_log(LogKind::kMissedEdges, LogLevel::kWarn, s.t_ns,
                "{} data-ready edge(s) missed before sample {} (missed: {}; {} more since the "
                "last line)",
                lost, s.seq, health_.missed_edges);
  }
  last_seq_ = s.seq;
  have_seq_ = true;
  // The time base of no-sample epochs, and the end of any ADC failure.
  ref_seq_ = s.seq;
  ref_t_ns_ = s.t_ns;
  adc_failing_ = false;
  watchdog_held_ = false;
  update_adc_counters(k);

  const bool crc_ok = (s.flags & sample_flags::kCrcError) == 0;
  const std::uint8_t saturated = rail_mask(s.counts);
  const bool flagged_saturated = (s.flags & sample_flags::kSaturated) != 0;
  if (crc_ok) {
    health_.saturated_mask = saturated;
    if (saturated != 0 || flagged_saturated) {
      ++health_.saturated_samples;
      limited_log(LogKind::kSaturated, LogLevel::kWarn, s.t_ns,
                  "channel mask {:#x} at full scale (saturated samples: {}; {} more since the "
                  "last line)",
                  saturated, health_.saturated_samples);
      events_.set(status_bits::kAdcSaturated, k);
    }
    const std::uint8_t stuck = stuck_.update(s.counts);
    if (stuck != health_.stuck_mask) {
      const auto fresh = static_cast<std::uint8_t>(stuck & ~health_.stuck_mask);
      if (fresh != 0) {
        for (std::size_t j = 0; j < kAdcChannels; ++j) health_.stuck_events += (fresh >> j) & 1u;
        limited_log(LogKind::kStuck, LogLevel::kError, s.t_ns,
                    "channel mask {} stuck: code unchanged for {} samples (stuck events: {}; {} "
                    "more since the last line)",
                    stuck, kStuckSamples, health_.stuck_events);
      } else {
        limited_log(LogKind::kStuckCleared, LogLevel::kInfo, s.t_ns,
                    "stuck channel mask now {} ({} more since the last line)", stuck);
      }
      health_.stuck_mask = stuck;
    }
    last_counts_ = s.counts;
  }
  // A CRC error or a saturated channel means the counts are not a measurement: the pipeline
  // skips the sample and integrates across the hole with the next good one (is_measurement,
  // the core's rule, here with the rails already scanned).
  const bool measured = (s.flags & sample_flags::kNotMeasured) == 0 && saturated == 0;
  if (!measured) ++health_.rejected_samples;
  if (measured) last_good_ = s;
  pipeline_.process(s);
  note_alignment_refusal(s.t_ns);
  if (pipeline_.phase() == nav::PipelinePhase::kAligning) {
    gravity_checked_ = false;
  } else if (!gravity_checked_) {
    gravity_checked_ = true;
    check_gravity(s.t_ns);
  }
  if (capture_.active && crc_ok) capture_add(s, saturated);
  build_epoch(s, measured);
}

void SampleLoop::set_mode(bool aligned, std::uint32_t bits) {
  // GfinsEpoch.Mode: a navigation on faulty inputs is still navigating (the HealthDegraded bit
  // says so); a calibration capture while navigating is reported as calibrating.
  if (!aligned) {
    mode_ = can::Mode::kAligning;
  } else if ((bits & status_bits::kCaptureActive) != 0) {
    mode_ = can::Mode::kCalibrating;
  } else {
    mode_ = can::Mode::kNavigating;
  }
  epoch_.mode = mode_;
}

void SampleLoop::build_epoch(const RawSample& s, bool measured) {
  const std::uint32_t k = sample_index_;
  epoch_.nav = pipeline_.state();
  // Every epoch refers to the sample just read (its edge time and counter). When the core did
  // not step on it (aligning, or the sample was rejected) the values are the last state held,
  // and a rejected sample is flagged as such.
  epoch_.nav.t_ns = s.t_ns;
  epoch_.nav.seq = s.seq;
  if (mounted(options_.q_vb)) to_vehicle_frame(epoch_.nav, options_.q_vb);
  if (!measured) {
    epoch_.nav.status |= nav::nav_status::kInputInvalid;
  }
  nav::Vec6<float> f;
  pipeline_.front_end().convert(last_counts_, f);
  for (std::size_t j = 0; j < kAdcChannels; ++j) epoch_.accel_mps2[j] = f(static_cast<int>(j));
  const bool aligned = pipeline_.phase() == nav::PipelinePhase::kNavigating;
  std::uint32_t bits = events_.get(k);
  if (!cal_.calibrated) bits |= status_bits::kNominalCalibration;
  if (aligned) bits |= status_bits::kAligned;
  if ((epoch_.nav.status & nav::nav_status::kInputInvalid) != 0) bits |= status_bits::kInputInvalid;
  if ((epoch_.nav.status & nav::nav_status::kCompensated) != 0) bits |= status_bits::kCompensated;
  if (health_.stuck_mask != 0) bits |= status_bits::kAdcChannelStuck;
  if (capture_.active) bits |= status_bits::kCaptureActive;
  // Degraded: the solution integrates inputs known to be wrong (a stuck or saturated channel) or
  // the ADC stopped delivering (no edge, or a read that failed); a CRC error or a missed edge
  // alone costs one step across a gap.
  const bool degraded = (bits & (status_bits::kAdcChannelStuck | status_bits::kAdcSaturated |
                                 status_bits::kDataReadyLost | status_bits::kAdcReadError)) != 0;
  if (degraded) bits |= status_bits::kHealthDegraded;
  set_mode(aligned, bits);
  epoch_.status_bits = bits;
  epoch_.cal_id = cal_.cal_id;
  health_.log_dropped = log_.dropped();
  epoch_.health = bus_health(health_);
  epoch_.commands = bus_command_counters(health_, settings_source());
  epoch_.valid = epoch_validity(pipeline_, epoch_.nav);
  epoch_.accuracy = epoch_accuracy(pipeline_, s.t_ns, epoch_.nav);
}

// ---- Commands -------------------------------------------------------------------------------

void SampleLoop::wait_for_recorder() const {
  if (recorder_ == nullptr || !recorder_waits_) return;
  while (!recorder_->has_room()) std::this_thread::yield();
}

void SampleLoop::note_record_dropped() {
  ++health_.record_dropped;
  limited_log(LogKind::kRecordDropped, LogLevel::kError, t_cycle_,
              "recorder queue full: record lost, the recording has a hole (lost: {}; {} more "
              "since the last line)",
              health_.record_dropped);
}

void SampleLoop::handle_commands(std::int64_t t_ns) {
  if (!commands_ && !options_.aiding_inputs) return;
  for (int i = 0; i < kMaxCommandsPerCycle; ++i) {
    const Result<hal::CanFrame> f = bus_.receive(0);
    if (!f.is_ok()) return;  // kTimeout: nothing waiting
    wait_for_recorder();
    if (recorder_ != nullptr && !record_frame(*recorder_, f.value(), t_ns)) note_record_dropped();
    if (options_.aiding_inputs && handle_input(f.value(), t_ns)) continue;
    if (!commands_) continue;
    const can::DecodedCommand d = can::decode_command(f.value(), options_.node_id, options_.ids);
    if (!d.addressed) continue;
    CommandReply r;
    if (!d.ok()) {
      r.response = can::error_response(d.error);
      note_refusal(d.error.code);
      limited_log(LogKind::kCommandRejected, LogLevel::kWarn, t_ns,
                  "command frame id {:#x} rejected: result {} ({} more since the last line)",
                  f.value().id, static_cast<std::int64_t>(d.error.code));
    } else if (!take_sequence(d.command, r)) {
      limited_log(LogKind::kCommandRejected, LogLevel::kWarn, t_ns,
                  "command {} refused as replayed: sequence {} is not above {} ({} more since "
                  "the last line)",
                  static_cast<std::int64_t>(d.command.opcode), d.command.sequence, last_sequence_);
    } else {
      execute(d.command, r);
      log(LogLevel::kInfo, t_ns, "command {} token {} -> result {}",
          static_cast<std::int64_t>(d.command.opcode), d.command.token,
          static_cast<std::int64_t>(r.response.result));
    }
    if (!r.deferred) send_response(r.response);
  }
}

bool SampleLoop::take_sequence(const can::Command& c, CommandReply& r) {
  if (!can::carries_sequence(c.opcode)) return true;
  if (c.sequence > last_sequence_) {
    last_sequence_ = c.sequence;
    return true;
  }
  r = CommandReply{};
  r.response = can::Response{static_cast<std::uint8_t>(c.opcode), c.token,
                             can::ResultCode::kReplayed, last_sequence_};
  note_refusal(can::ResultCode::kReplayed);
  return false;
}

void SampleLoop::note_refusal(can::ResultCode why) {
  ++health_.command_errors;
  health_.last_refusal = static_cast<std::uint8_t>(why);
  if (why == can::ResultCode::kReplayed) ++health_.commands_replayed;
}

std::uint8_t SampleLoop::settings_source() const {
  return settings_port_ != nullptr ? settings_port_->source() : 0;
}

void SampleLoop::offer_settings() {
  if (!settings_dirty_ || settings_port_ == nullptr) return;
  if (settings_port_->post(settings_)) settings_dirty_ = false;
}

void SampleLoop::flush_settings() {
  while (settings_dirty_ && settings_port_ != nullptr) {
    offer_settings();
    if (settings_dirty_) std::this_thread::yield();
  }
}

void SampleLoop::execute_settings(const can::Command& c, CommandReply& r) {
  if (c.opcode == can::Opcode::kSetNodeId) {
    // Without a store a node id would be forgotten before it takes effect: refused.
    const can::ResultCode why = settings_port_ == nullptr     ? can::ResultCode::kFailed
                                : c.node_id > can::kMaxNodeId ? can::ResultCode::kOutOfRange
                                                              : can::ResultCode::kOk;
    if (why != can::ResultCode::kOk) {
      r.response.result = why;
      return note_refusal(why);
    }
    settings_.node_id = c.node_id;
    r.response.value = c.node_id;
  } else if (c.opcode == can::Opcode::kSetIdBase) {
    // Stored for the next start, as the node id; refused without a store, and when the groups of
    // the next start (the configuration's, the ones stored before, this one) would leave 11 bits,
    // overlap each other or a reserved range: the board would come up deaf or on others' IDs.
    const auto g = static_cast<std::size_t>(c.id_group);
    can::IdBases next = options_.config_ids;
    for (std::size_t h = 0; h < can::kIdGroupCount; ++h) {
      if (settings_.id_bases[h]) next.base[h] = *settings_.id_bases[h];
    }
    next.base[g] = c.id_base;
    bool fits = can::id_bases_valid(next);
    for (std::size_t h = 0; h < can::kIdGroupCount; ++h) {
      for (const std::array<std::uint32_t, 2>& res : options_.reserved_ids) {
        fits = fits && !can::id_group_overlaps(next, h, res[0], res[1]);
      }
    }
    const can::ResultCode why = settings_port_ == nullptr ? can::ResultCode::kFailed
                                : !fits                   ? can::ResultCode::kOutOfRange
                                                          : can::ResultCode::kOk;
    if (why != can::ResultCode::kOk) {
      r.response.result = why;
      return note_refusal(why);
    }
    settings_.id_bases[g] = c.id_base;
    r.response.value = c.id_base;
  } else {
    // The configuration's dividers at once; its node id from the next start.
    if (!out_.set_dividers(options_.config_dividers).is_ok()) {
      r.response.result = can::ResultCode::kFailed;
      return note_refusal(can::ResultCode::kFailed);
    }
    settings_ = CanSettings{};
    r.response.value = options_.config_node_id;
  }
  settings_dirty_ = true;
  offer_settings();
  ++health_.commands;
}

void SampleLoop::note_alignment_refusal(std::int64_t t_ns) {
  const nav::PipelineCounters& c = pipeline_.counters();
  if (c.alignment_restarts == alignment_refusals_seen_) return;
  // configure() (a re-align, a reload) starts the core's counters again from 0.
  const bool refused = c.alignment_restarts > alignment_refusals_seen_;
  alignment_refusals_seen_ = c.alignment_restarts;
  if (!refused) return;
  // One literal per reason (AlignmentRefusal order): a log record carries numbers only.
  static constexpr std::array<const char*, 6> kWhy = {
      "",
      "alignment window refused: |f| is no gravity vector (board not at rest or no sensor "
      "signal); {} refused, {} more since the last line",
      "alignment window refused: the specific force scattered beyond the limit (the board "
      "moved); {} refused, {} more since the last line",
      "alignment window refused: angular acceleration beyond the limit (the board turned); {} "
      "refused, {} more since the last line",
      "alignment window refused: |f| differs from the navigation gravity (the board "
      "accelerates, or a wrong calibration); {} refused, {} more since the last line",
      "alignment window refused: a GNSS velocity fix says the board moves; {} refused, {} more "
      "since the last line",
  };
  static_assert(static_cast<std::size_t>(nav::AlignmentRefusal::kGnssMotion) + 1 == kWhy.size());
  const auto why = static_cast<std::size_t>(c.last_refusal);
  if (why == 0 || why >= kWhy.size()) return;
  limited_log(LogKind::kAlignmentRefused, LogLevel::kInfo, t_ns, kWhy[why],
              static_cast<std::int64_t>(c.alignment_restarts));
}

void SampleLoop::check_gravity(std::int64_t t_ns) {
  // At rest the array measures gravity: |mean f| of the alignment window against the model the
  // core navigates with. Allowed: 5σ of that mean (the window's own scatter) plus 1 mg for what
  // a calibrated array's residual bias puts into |f|. Standard gravity on a board calibrated at
  // 24.8° (1.7 mg off) or a calibration for another converter is beyond it.
  const nav::AlignmentResult<float>& a = pipeline_.alignment();
  if (a.samples == 0) return;
  const double g_model = static_cast<double>(pipeline_.config().gravity.magnitude_at_origin());
  const double f = static_cast<double>(a.gravity_mps2);
  const double sigma_mean =
      static_cast<double>(a.f_noise_mps2) / std::sqrt(static_cast<double>(a.samples));
  constexpr double kResidualBiasMps2 = 1e-3 * nav::kStandardGravity;
  const double allowed = 5.0 * sigma_mean + kResidualBiasMps2;
  if (std::abs(f - g_model) <= allowed) return;
  ++health_.gravity_mismatches;
  limited_log(LogKind::kGravityMismatch, LogLevel::kWarn, t_ns,
              "aligned at rest, |f| = {} um/s^2 but the navigation gravity is {} um/s^2 (allowed "
              "difference {} um/s^2): check navigation.gravity and the calibration file ({} more "
              "since the last line)",
              std::llround(f * 1e6), std::llround(g_model * 1e6), std::llround(allowed * 1e6));
}

bool SampleLoop::handle_input(const hal::CanFrame& f, std::int64_t t_ns) {
  const Result<can::InputEvent> ev = inputs_.add(f);
  if (!ev.is_ok()) {
    ++health_.aiding_input_errors;
    limited_log(LogKind::kInputRejected, LogLevel::kWarn, t_ns,
                "aiding input frame id {:#x} rejected: reason {} (refused: {}; {} more since the "
                "last line)",
                f.id, static_cast<std::int64_t>(inputs_.last_reject()),
                health_.aiding_input_errors);
    return true;
  }
  const can::InputEvent& e = ev.value();
  if (e.kind == can::InputEventKind::kIgnored) return false;
  if (e.kind == can::InputEventKind::kPending) return true;
  ++health_.aiding_inputs;
  // The filter counts what it accepts and rejects (published in GfinsAidingCounters); the log
  // says when a fix was not applied.
  const nav::UpdateStatus worst = can::offer_input(pipeline_, e, t_ns);
  if (worst != nav::UpdateStatus::kAccepted) {
    limited_log(LogKind::kAidingRejected, LogLevel::kInfo, t_ns,
                "aiding input not applied: outcome {} ({} more since the last line)",
                static_cast<std::int64_t>(worst));
  }
  return true;
}

void SampleLoop::send_response(const can::Response& r) {
  if (!commands_) return;
  (void)bus_.send(can::encode_response(r, options_.node_id, options_.ids));
  // The calibration identity follows the response of a report or a reload that succeeded.
  const auto op = static_cast<can::Opcode>(r.opcode);
  if (r.result == can::ResultCode::kOk &&
      (op == can::Opcode::kReportCalibrationId || op == can::Opcode::kReloadCalibration)) {
    (void)bus_.send(
        can::encode_calibration_id_response(r.token, cal_.cal_id, options_.node_id, options_.ids));
  }
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

void SampleLoop::execute(const can::Command& c, CommandReply& r) {
  using can::ResultCode;
  r = CommandReply{};
  r.response.opcode = static_cast<std::uint8_t>(c.opcode);
  r.response.token = c.token;
  const auto reject = [&](ResultCode why) {
    r.response.result = why;
    note_refusal(why);
  };
  switch (c.opcode) {
    case can::Opcode::kRealign:
    case can::Opcode::kResetNavigation: {
      const bool realign = c.opcode == can::Opcode::kRealign;
      // The command's Heading signal range (±3.1416 rad: ±π to its resolution); the codec
      // refuses a frame beyond it, a caller of execute() is held to the same.
      if (realign && !(std::abs(static_cast<double>(c.heading_rad)) <= can::kHeadingLimitRad)) {
        return reject(ResultCode::kOutOfRange);
      }
      // A new alignment while the vehicle moves would navigate from a wrong attitude: with the
      // aiding's standstill detector running, only a board it judges at rest (or a forced
      // command) starts over.
      if (!c.forced && pipeline_.aiding().started() && !pipeline_.aiding().at_rest()) {
        return reject(ResultCode::kMoving);
      }
      nav::PipelineConfig<float> cfg = cal_.config;
      cfg.heading_rad = realign ? c.heading_rad : options_.initial_heading_rad;
      cfg.r0_n = options_.initial_position_n;
      if (!pipeline_.configure(cfg).is_ok()) return reject(ResultCode::kFailed);
      cal_.config = cfg;
      stuck_.reset();
      break;
    }
    case can::Opcode::kSetCompensator: {
      if (c.compensator != nav::CompensatorKind::kNone &&
          c.compensator != nav::CompensatorKind::kPaper &&
          c.compensator != nav::CompensatorKind::kExact) {
        return reject(ResultCode::kOutOfRange);
      }
      nav::PipelineConfig<float> cfg = cal_.config;
      cfg.compensator = c.compensator;
      if (!reconfigure_keep_navigation(cfg).is_ok()) return reject(ResultCode::kFailed);
      cal_.config = cfg;
      break;
    }
    case can::Opcode::kSetDivider:
      if (static_cast<std::size_t>(c.message) >= kNumMessages || c.divider > kMaxDivider) {
        return reject(ResultCode::kOutOfRange);
      }
      if (const Status s = out_.set_divider(static_cast<std::size_t>(c.message), c.divider);
          !s.is_ok()) {
        return reject(s.code() == ErrorCode::kResourceExhausted ? ResultCode::kBusLoad
                                                                : ResultCode::kOutOfRange);
      }
      r.response.value = c.divider;
      if (static_cast<std::size_t>(c.message) < kNumMessages) {
        settings_.dividers[static_cast<std::size_t>(c.message)] = c.divider;
        // The epoch divider moves the status divider with it (Publisher::set_divider).
        if (c.message == can::MessageId::kEpoch) {
          settings_.dividers[static_cast<std::size_t>(can::MessageId::kStatus)] = c.divider;
        }
        settings_dirty_ = true;
        offer_settings();
      }
      break;
    case can::Opcode::kReportCalibrationId:
      // The status part's Value: the last sequence number taken, so that a host that does not
      // track the board's numbers can send the next one (docs/can-interface.md).
      r.response.value = last_sequence_;
      break;
    case can::Opcode::kStartCapture:
      if (c.samples == 0 || c.samples > kMaxCaptureSamples || c.pose > can::kMaxCapturePose) {
        return reject(ResultCode::kOutOfRange);
      }
      if (capture_.active) return reject(ResultCode::kBusy);
      capture_ = Capture{};
      capture_.active = true;
      capture_.command = c;
      capture_.target = c.samples;
      r.response.value = c.samples;
      break;
    case can::Opcode::kReloadCalibration:
      if (reload_ == nullptr) return reject(ResultCode::kFailed);
      if (reload_pending_ || !reload_->request(ReloadRequest{cal_.config, c.forced})) {
        return reject(ResultCode::kBusy);
      }
      reload_pending_ = true;
      reload_token_ = c.token;
      r.deferred = true;  // answered when the worker is done (poll_reload), counted there
      return;
    case can::Opcode::kSetNodeId:
    case can::Opcode::kSetIdBase:
    case can::Opcode::kRestoreDefaults:
      return execute_settings(c, r);
    default:
      return reject(ResultCode::kUnknownOpcode);
  }
  ++health_.commands;
}

void SampleLoop::capture_add(const RawSample& s, std::uint8_t rails) {
  for (std::size_t j = 0; j < kAdcChannels; ++j) {
    if (((rails >> j) & 1u) != 0) capture_.saturated[j] = true;
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
  can::CaptureResult& cap = last_capture_;
  cap = can::CaptureResult{};
  cap.pose = capture_.command.pose;
  cap.samples = capture_.command.samples;
  for (std::size_t j = 0; j < kAdcChannels; ++j) {
    can::ChannelCapture& ch = cap.channels[j];
    const std::uint32_t n = capture_.n[j];
    ch.count = static_cast<std::uint16_t>(std::min<std::uint32_t>(n, kMaxCaptureSamples));
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
  log(LogLevel::kInfo, 0, "calibration capture pose {} done: {} samples, motion {}", cap.pose,
      cap.channels[0].count, cap.motion() ? 1 : 0);
  if (!commands_) return;
  for (const hal::CanFrame& f :
       can::encode_capture_result(cap, capture_.command.token, options_.node_id, options_.ids)) {
    (void)bus_.send(f);
  }
}

void SampleLoop::poll_reload(std::int64_t t_ns) {
  if (!reload_pending_ || reload_ == nullptr) return;
  CalibrationSet fresh;
  const ReloadWorker::Poll p = reload_->poll(fresh);
  if (p == ReloadWorker::Poll::kNothing) return;
  reload_pending_ = false;
  can::Response r;
  r.opcode = static_cast<std::uint8_t>(can::Opcode::kReloadCalibration);
  r.token = reload_token_;
  r.result = can::ResultCode::kFailed;
  if (p == ReloadWorker::Poll::kReady) {
    nav::PipelineConfig<float> cfg = fresh.config;
    cfg.sample_rate_hz = cal_.config.sample_rate_hz;
    cfg.heading_rad = cal_.config.heading_rad;
    cfg.r0_n = cal_.config.r0_n;
    cfg.gravity = cal_.config.gravity;
    cfg.alignment_samples = cal_.config.alignment_samples;
    cfg.aiding = cal_.config.aiding;  // the filter restarts from its initial covariance
    if (reconfigure_keep_navigation(cfg).is_ok()) {
      cal_.config = cfg;
      cal_.cal_id = fresh.cal_id;
      cal_.calibrated = fresh.calibrated;
      r.result = can::ResultCode::kOk;
      ++health_.commands;
      log(LogLevel::kInfo, t_ns, "calibration reloaded: id {:#x}", cal_.cal_id);
    }
  }
  if (p == ReloadWorker::Poll::kOtherDevice) r.result = can::ResultCode::kOtherDevice;
  if (r.result != can::ResultCode::kOk) {
    note_refusal(r.result);
    log(LogLevel::kError, t_ns, "calibration reload failed; the previous calibration (id {}) stays",
        cal_.cal_id);
  }
  send_response(r);
}

}  // namespace gfins::app
