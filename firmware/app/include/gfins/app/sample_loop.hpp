// The real-time sample loop (docs/firmware.md, "The sample loop"): one cycle per data-ready edge
//
//   read frame → NavPipeline::process → health → Publisher (dividers) → CAN service →
//   commands (receive with timeout 0, at most kMaxCommandsPerCycle) → watchdog kick
//
// A cycle without a sample (data-ready timeout, ADC read error, a dead ADC) still publishes: one
// "no-sample" epoch per sample period the ADC would have delivered (navigation values not
// available, the fault bits set), so the status and health frames keep their rates while the
// ADC is silent. A read error that returns at once is paced to the sample period (the loop never
// spins) and the watchdog stops being kicked after kDeadAdcWatchdogNs without a sample
// (docs/faults.md, "Watchdog").
//
// After configure() nothing here allocates, blocks (except the data-ready wait inside
// read_sample and the pause after a read error) or formats text: events go to the log queue as
// fixed-size records, at most one per kind per kLogIntervalNs (LogLimiter).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "gfins/app/health.hpp"
#include "gfins/app/log_queue.hpp"
#include "gfins/app/ports.hpp"
#include "gfins/app/record_queue.hpp"
#include "gfins/app/reload_worker.hpp"
#include "gfins/app/status_board.hpp"
#include "gfins/can/aiding_input.hpp"
#include "gfins/can/command.hpp"
#include "gfins/can/epoch.hpp"
#include "gfins/hal/can_bus.hpp"
#include "gfins/hal/clock.hpp"
#include "gfins/hal/watchdog.hpp"
#include "gfins/nav_core/pipeline.hpp"

namespace gfins::app {

/// Commands handled per cycle: a burst of commands cannot stretch one cycle past its period
/// (each is a few µs; two keep the worst case far below 1 ms).
inline constexpr int kMaxCommandsPerCycle = 2;
/// read_sample waits this many sample periods before reporting a lost data-ready line.
inline constexpr std::int64_t kReadTimeoutPeriods = 3;
/// Log rate limit per kind: one record per second of loop time (the sample clock), docs/faults.md.
inline constexpr std::int64_t kLogIntervalNs = 1000000000;
/// Consecutive time without a sample, with the ADC failing to answer (read errors, not mere
/// data-ready timeouts), after which the loop stops kicking the watchdog so the service manager
/// restarts the firmware and with it the ADC start-up (reset, identity check, configuration).
/// 10 s: long against a transient (the driver's own recovery takes a few ms), short against an
/// operator's patience with a board that publishes only "ADC read failed".
inline constexpr std::int64_t kDeadAdcWatchdogNs = 10000000000;
/// No-sample epochs published per cycle at most: a cycle that was stalled for longer (the loop
/// was descheduled) publishes only the most recent periods instead of a burst on the bus.
inline constexpr auto kMaxGapEpochsPerCycle = static_cast<std::uint32_t>(2 * kReadTimeoutPeriods);
/// A calibration capture averages at most this many samples (65 s at 1 kHz).
inline constexpr std::uint32_t kMaxCaptureSamples = 65535;
/// Capture motion threshold: a channel whose standard deviation exceeds 2 mg of its scale factor
/// was not static (QA-1100 noise is 70 µg rms per sample, docs/sensor-model.md: ~30x that).
inline constexpr double kCaptureMotionStdG = 2e-3;

/// Latency of the loop: data-ready edge → the cycle's frames handed to the CAN backend. A fixed
/// histogram of 1 µs bins (no allocation); values beyond the last bin land in it.
class LatencyHistogram {
 public:
  static constexpr std::size_t kBins = 20000;  // 0..20 ms
  void add(std::int64_t ns) {
    constexpr auto kLast = static_cast<std::int64_t>(kBins) - 1;
    const std::int64_t us = ns < 0 ? 0 : ns / 1000;
    ++bins_[static_cast<std::size_t>(us < kLast ? us : kLast)];
    ++count_;
    if (ns > max_ns_) max_ns_ = ns;
  }
  std::uint64_t count() const { return count_; }
  std::int64_t max_ns() const { return max_ns_; }
  /// Upper edge of the bin holding quantile q (0..1), µs.
  double quantile_us(double q) const;
  /// Count of bin b ([b, b+1) µs; the last bin holds everything beyond).
  std::uint32_t bin(std::size_t b) const { return bins_[b]; }

 private:
  std::array<std::uint32_t, kBins> bins_{};
  std::uint64_t count_ = 0;
  std::int64_t max_ns_ = 0;
};

/// What the loop logs, each kind rate-limited on its own (a storm of one kind never hides another).
enum class LogKind : std::uint8_t {
  kDataReadyTimeout,
  kAdcReadError,
  kAdcDead,
  kCrcError,
  kAdcReset,
  kExtraEdge,
  kMissedEdges,
  kSaturated,
  kStuck,
  kStuckCleared,
  kCanTxDrop,
  kCanRxDrop,
  kBusOff,
  kCanStateWorse,   // into error-passive, bus-off or down
  kCanStateBetter,  // back to error-active or warning
  kOverrun,
  kCommandRejected,
  kInputRejected,     // a GNSS / heading input frame refused by its decoder
  kAidingRejected,    // a decoded fix refused by the filter (χ² gate, before alignment)
  kGravityMismatch,   // the aligned |f| and the navigation gravity disagree
  kRecordDropped,     // a record lost to the recorder's full queue
  kAlignmentRefused,  // an alignment window refused: the board was not at rest (says why)
  kCount,
};

/// Per-kind rate limit: the first record of a kind goes out, then at most one per
/// kLogIntervalNs; the occurrences in between are counted and the next record of that kind says
/// how many were not logged. Times are the loop's clock (sample time on the simulated board).
class LogLimiter {
 public:
  /// True when a record of `kind` may be queued at t_ns; then `suppressed` is the number of
  /// occurrences of that kind not logged since its previous record.
  bool allow(LogKind kind, std::int64_t t_ns, std::int64_t& suppressed) {
    Entry& e = entries_[static_cast<std::size_t>(kind)];
    if (e.logged && t_ns - e.last_t_ns < kLogIntervalNs) {
      ++e.suppressed;
      return false;
    }
    suppressed = e.suppressed;
    e = Entry{true, t_ns, 0};
    return true;
  }

 private:
  struct Entry {
    bool logged = false;
    std::int64_t last_t_ns = 0;
    std::int64_t suppressed = 0;
  };
  std::array<Entry, static_cast<std::size_t>(LogKind::kCount)> entries_{};
};

struct LoopOptions {
  double sample_rate_hz = 1000.0;
  float initial_heading_rad = 0;
  nav::Vec3<float> initial_position_n = nav::Vec3<float>::Zero();
  // Board -> vehicle rotation (navigation.mounting_rpy_deg); identity: publish the board's frame.
  nav::Quat<float> q_vb = nav::Quat<float>::Identity();
  std::uint8_t node_id =
      can::kDefaultNodeId;     // the input frames (GNSS, heading) addressed to this node
  bool aiding_inputs = false;  // decode them and offer them to the filter
  can::IdBases ids{};          // the identifier groups (can.*_id_base)
  /// What the settings store held at start (commands add to it), and the configuration's
  /// dividers and node id, to which RestoreDefaults returns.
  CanSettings stored{};
  std::array<std::uint16_t, kNumMessages> config_dividers = kDefaultDividers;
  std::uint8_t config_node_id = can::kDefaultNodeId;
  /// The configuration's identifier groups and the ranges other equipment uses
  /// (can.reserved_ids, [first, last]): what SetIdBase checks a new base against, with the bases
  /// stored before it.
  can::IdBases config_ids{};
  std::vector<std::array<std::uint32_t, 2>> reserved_ids;
};

class SampleLoop {
 public:
  SampleLoop(SampleSource& adc, hal::CanBus& bus, EpochSink& out, hal::Clock& clock,
             FwLogQueue& log);

  /// Optional collaborators (set before configure): command handling (the CAN command frames of
  /// options.node_id, decoded and answered by the CAN protocol's codec), watchdog, reload worker.
  void set_commands(bool on) { commands_ = on; }
  void set_watchdog(hal::Watchdog* wd) { watchdog_ = wd; }
  void set_reload_worker(ReloadWorker* w) { reload_ = w; }
  /// Where settings changed by SetDivider, SetNodeId and RestoreDefaults are kept across
  /// restarts. Null: they last until the board stops, and SetNodeId is refused (a node id that
  /// would be forgotten before it takes effect).
  void set_settings_port(SettingsPort* p) { settings_port_ = p; }
  /// Where each cycle leaves the mode and health for the service status line (read by another
  /// thread: service_status.hpp).
  void set_status_board(StatusBoard* b) { status_board_ = b; }
  /// The raw-sample recorder's queue (record_queue.hpp): every sample read and every CAN frame
  /// received go into it, in the order the loop handles them. Null: no recording.
  /// With `wait_for_room` (the simulated board in fast pacing, which keeps no real time) the loop
  /// waits for the writer when the queue is full instead of losing the record.
  void set_recorder(RecordQueue* q, bool wait_for_room = false) {
    recorder_ = q;
    recorder_waits_ = wait_for_room;
  }

  /// Start-up: configures the pipeline (alignment starts with the first sample).
  [[nodiscard]] Status configure(const CalibrationSet& cal, const LoopOptions& options);

  enum class Cycle : std::uint8_t { kSample, kTimeout, kReadError };
  /// One cycle: waits for the next edge, processes it.
  Cycle step();

  const HealthCounters& health() const { return health_; }
  /// At the end of a run (not from the loop): hands a change the store has not taken yet to
  /// it, waiting for the store as long as it takes.
  void flush_settings();
  /// False once the ADC has delivered nothing for kDeadAdcWatchdogNs with read errors: the loop
  /// no longer kicks the watchdog.
  bool kicking_watchdog() const { return !watchdog_held_; }
  const LatencyHistogram& latency() const { return latency_; }
  const nav::NavPipeline<float>& pipeline() const { return pipeline_; }
  /// GfinsEpoch.Mode of the last epoch (navigating on faulty inputs is kNavigating with the
  /// HealthDegraded status bit).
  can::Mode mode() const { return mode_; }
  std::uint32_t cal_id() const { return cal_.cal_id; }
  bool calibrated() const { return cal_.calibrated; }
  bool capture_active() const { return capture_.active; }
  /// The result of the last finished calibration capture (also sent as response frames).
  const can::CaptureResult& last_capture() const { return last_capture_; }

  /// What execute() decided: the response frame's fields, and whether it goes out now or when
  /// the work is done (a reload answers once the worker has read the file; a capture's result
  /// frames follow its last sample).
  struct CommandReply {
    can::Response response{};
    bool deferred = false;
  };
  /// Executes one decoded command (the CAN path calls it; tests may too). Fills `r` with the
  /// immediate response; nothing changes when the command is rejected.
  void execute(const can::Command& c, CommandReply& r);

 private:
  struct Capture {
    bool active = false;
    can::Command command{};
    std::uint32_t target = 0;
    std::array<double, kAdcChannels> mean{}, m2{};
    std::array<std::uint32_t, kAdcChannels> n{};
    std::array<bool, kAdcChannels> saturated{};
  };

  void on_sample(const RawSample& s);
  void update_adc_counters(std::uint32_t sample);
  void update_can_counters(std::uint32_t sample, std::int64_t t_ns);
  /// `rails`: rail_mask of the sample's counts (on_sample has it already).
  void capture_add(const RawSample& s, std::uint8_t rails);
  void capture_finish();
  void handle_commands(std::int64_t t_ns);
  /// A configuration-changing command's sequence number against the last one taken: true (and
  /// taken) when above it, else `r` is the Replayed refusal.
  bool take_sequence(const can::Command& c, CommandReply& r);
  /// Counts a refused command (the response carries `why`).
  void note_refusal(can::ResultCode why);
  /// SetNodeId / RestoreDefaults (execute's settings part).
  void execute_settings(const can::Command& c, CommandReply& r);
  /// Hands the settings to the store; retried each cycle until the store takes them.
  void offer_settings();
  std::uint8_t settings_source() const;
  void poll_reload(std::int64_t t_ns);
  /// The response frame, and the calibration identity after a report or reload that succeeded.
  void send_response(const can::Response& r);
  /// GfinsEpoch.Mode from the alignment and this epoch's status bits.
  void set_mode(bool aligned, std::uint32_t bits);
  /// `measured`: the sample is one the core integrates (is_measurement).
  void build_epoch(const RawSample& s, bool measured);
  void publish_gap(std::int64_t t_ns, std::uint32_t cause);
  void build_gap_epoch(std::uint32_t seq, std::int64_t t_ns, std::uint32_t cause);
  void on_read_error(std::int64_t t_ns, const Status& st);
  /// A record of `kind` through the rate limit; the count of records it held back since the
  /// previous one is the argument after `args`.
  template <typename... Args>
  void limited_log(LogKind kind, LogLevel level, std::int64_t t_ns, const char* fmt, Args... args) {
    static_assert(sizeof...(Args) < LogRecord::kMaxArgs, "one argument is the suppressed count");
    std::int64_t suppressed = 0;
    if (!limiter_.allow(kind, t_ns, suppressed)) return;
    const std::array<std::int64_t, LogRecord::kMaxArgs> a{static_cast<std::int64_t>(args)...,
                                                          suppressed};
    log(level, t_ns, fmt, a[0], a[1], a[2], a[3]);
  }
  Status reconfigure_keep_navigation(const nav::PipelineConfig<float>& cfg);
  /// A received frame that is a GNSS or heading input of this node: decoded, offered to the
  /// filter, counted. False when it is not one (a command frame, another node's input).
  bool handle_input(const hal::CanFrame& f, std::int64_t t_ns);
  /// A record the recorder's queue refused: counted and logged (rate-limited).
  void note_record_dropped();
  /// In fast pacing: waits until the recorder's queue has room (see set_recorder).
  void wait_for_recorder() const;
  /// Once per alignment: the mean |f| at rest against the navigation gravity.
  void check_gravity(std::int64_t t_ns);
  /// Logs why the core refused an alignment window (PipelineCounters::last_refusal), once per
  /// refusal the counter shows, rate-limited.
  void note_alignment_refusal(std::int64_t t_ns);
  void log(LogLevel level, std::int64_t t_ns, const char* fmt, std::int64_t a0 = 0,
           std::int64_t a1 = 0, std::int64_t a2 = 0, std::int64_t a3 = 0);

  SampleSource& adc_;
  hal::CanBus& bus_;
  EpochSink& out_;
  hal::Clock& clock_;
  FwLogQueue& log_;
  bool commands_ = false;
  can::InputDecoder inputs_{1};                // GNSS / heading frames of options_.node_id
  bool gravity_checked_ = false;               // check_gravity() done for the current alignment
  std::uint32_t alignment_refusals_seen_ = 0;  // PipelineCounters::alignment_restarts logged
  hal::Watchdog* watchdog_ = nullptr;
  ReloadWorker* reload_ = nullptr;
  StatusBoard* status_board_ = nullptr;
  RecordQueue* recorder_ = nullptr;
  bool recorder_waits_ = false;
  SettingsPort* settings_port_ = nullptr;
  CanSettings settings_{};           // what the store is to keep: what commands set
  bool settings_dirty_ = false;      // settings_ not yet taken by the store
  std::uint16_t last_sequence_ = 0;  // the last sequence number taken this session

  nav::NavPipeline<float> pipeline_{};
  CalibrationSet cal_{};
  LoopOptions options_{};
  std::int64_t period_ns_ = 1000000;
  HealthCounters health_{};
  AdcCounters adc_seen_{};
  hal::CanCounters can_seen_{};
  hal::CanBusState can_state_ = hal::CanBusState::kErrorActive;
  StuckDetector stuck_{};
  LatchedBits events_{};
  Capture capture_{};
  can::CaptureResult last_capture_{};
  can::Epoch epoch_{};
  LatencyHistogram latency_{};
  std::array<std::int32_t, kAdcChannels> last_counts_{};
  RawSample last_good_{};  // the last sample the core could integrate (warm restarts)
  std::uint32_t last_seq_ = 0;
  bool have_seq_ = false;
  std::uint8_t reload_token_ = 0;
  bool reload_pending_ = false;
  can::Mode mode_ = can::Mode::kStartup;
  std::uint32_t sample_index_ = 0;
  LogLimiter limiter_{};
  std::int64_t t_cycle_ = 0;  // time of this cycle's edge (or of the failed read)
  // The time base of no-sample epochs: the last sample read (or configure()'s time before any).
  std::uint32_t ref_seq_ = 0;
  std::int64_t ref_t_ns_ = 0;
  std::uint32_t published_seq_ = 0;  // the last sample counter handed to the publisher
  bool have_published_ = false;
  bool adc_failing_ = false;  // a read error since the last sample
  std::int64_t failing_since_ns_ = 0;
  bool watchdog_held_ = false;
};

}  // namespace gfins::app
