// The seams of the sample loop, each with one implementation per board: where samples come from
// (the ADS131M06 driver on the board and on the simulated board), where epochs go (the CAN
// publisher), how command frames are decoded and responses encoded (the CAN command codec).
// Everything the loop calls through these is allocation-free and non-blocking (read_sample waits
// for data-ready with a timeout: that wait, and the loop's pause of one period after a read that
// failed at once, are its only sleeps).
#pragma once

#include <array>
#include <cstdint>

#include "gfins/app/health.hpp"
#include "gfins/can/epoch.hpp"
#include "gfins/hal/can_bus.hpp"
#include "gfins/nav_core/compensator.hpp"
#include "gfins/nav_core/nav_state.hpp"
#include "gfins/sample/raw_sample.hpp"
#include "gfins/status/status.hpp"

namespace gfins::app {

/// Navigation mode published with every epoch.
enum class Mode : std::uint8_t {
  kStartup = 0,     // before the first sample
  kAligning = 1,    // static alignment: averaging gravity, the board must be at rest
  kNavigating = 2,  // navigation valid
  kDegraded = 3,    // navigating, but an input fault makes the output untrustworthy
};

/// One sample's worth of what may be published (the CAN protocol's Epoch carries the same).
struct Epoch {
  nav::NavState<float> nav;
  std::array<float, kAdcChannels> accel_mps2{};  // front-end outputs (calibrated SF and bias)
  Mode mode = Mode::kStartup;
  std::uint32_t status_bits = 0;  // status_bits::
  std::uint32_t cal_id = 0;       // calibration identity (0 = uncalibrated defaults)
  HealthCounters health{};
  can::Validity valid = can::Validity::none();  // per navigation group (nav_accuracy.hpp)
  can::Accuracy accuracy{};                     // the filter's 1σ, mode, aiding counters
};

/// What the ADC driver counts (cumulative).
struct AdcCounters {
  std::uint32_t crc_errors = 0;
  std::uint32_t missed_edges = 0;
  std::uint32_t extra_edges = 0;
  std::uint32_t chip_resets = 0;
};

class SampleSource {
 public:
  virtual ~SampleSource() = default;
  /// Waits for the next data-ready edge (at most timeout_ns) and reads that conversion.
  /// kTimeout when no edge came; other errors when the frame could not be read.
  [[nodiscard]] Result<RawSample> read_sample(std::int64_t timeout_ns) {
    if (timeout_ns < 0) return Status(ErrorCode::kInvalidArgument, "adc: negative timeout");
    return do_read_sample(timeout_ns);
  }
  AdcCounters counters() const { return do_counters(); }
  /// Volts at the sensor per count (the front end's LSB) of the configured chain.
  double volts_per_count() const { return do_volts_per_count(); }

 private:
  virtual Result<RawSample> do_read_sample(std::int64_t timeout_ns) = 0;
  virtual AdcCounters do_counters() const = 0;
  virtual double do_volts_per_count() const = 0;
};

class EpochSink {
 public:
  virtual ~EpochSink() = default;
  /// Once per sample; sends what the message dividers select. Never blocks. Returns how many
  /// frames it handed to the bus (accepted or refused).
  virtual std::uint32_t publish(const Epoch& e) = 0;
  /// Divider of message `message` (index in kMessageNames); 0 = off.
  [[nodiscard]] virtual Status set_divider(std::size_t message, std::uint16_t divider) = 0;
};

// ---- Commands ------------------------------------------------------------------------------

enum class CommandKind : std::uint8_t {
  kRealign = 1,             // re-align with the given heading (board at rest)
  kResetNavigation = 2,     // re-align with the configured heading and position
  kSetCompensator = 3,      // none / paper / exact, navigation continues
  kSetDivider = 4,          // output divider of one message
  kReportCalibration = 5,   // calibration identity
  kCaptureCalibration = 6,  // average N samples per channel for pose k
  kReloadCalibration = 7,   // re-read the calibration file (the last good one stays on error)
};

struct Command {
  CommandKind kind = CommandKind::kReportCalibration;
  std::uint8_t token = 0;  // echoed in the response so the host matches it
  float heading_rad = 0;   // kRealign
  bool forced = false;     // kRealign, kResetNavigation: even while the board moves
  nav::CompensatorKind compensator = nav::CompensatorKind::kNone;  // kSetCompensator
  std::uint8_t message = 0;                                        // kSetDivider
  std::uint16_t divider = 0;                                       // kSetDivider
  std::uint8_t pose = 0;                                           // kCaptureCalibration
  std::uint16_t samples = 0;                                       // kCaptureCalibration
};

/// Result of a command; the values are the CAN response's Result codes (docs/can-interface.md).
enum class CommandResult : std::uint8_t {
  kOk = 0,
  kUnknownOpcode = 1,
  kBadLength = 2,
  kBadCrc = 3,
  kOutOfRange = 4,  // a parameter outside its domain
  kMalformed = 5,   // frame could not be decoded
  kBusy = 6,        // a capture or reload is already running
  kFailed = 7,      // executed but failed (reload: bad file; the previous calibration stays)
  kMoving = 9,      // re-align or reset refused while the board moves (not forced)
};

/// Calibration capture statistics of one channel, in ADC codes.
struct CaptureChannel {
  float mean_counts = 0;
  float std_counts = 0;
  std::uint32_t count = 0;  // samples averaged (CRC-error samples are skipped)
  bool saturated = false;   // a sample at full scale was seen
  bool motion = false;      // the spread says the board moved (the pose was not static)
};

struct CaptureResult {
  std::uint8_t pose = 0;
  std::uint16_t samples = 0;
  std::array<CaptureChannel, kAdcChannels> channels{};
  bool motion() const {
    for (const auto& c : channels) {
      if (c.motion) return true;
    }
    return false;
  }
};

struct Response {
  CommandKind kind = CommandKind::kReportCalibration;
  std::uint8_t raw_opcode = 0;  // of a frame that did not decode (kind is then meaningless)
  std::uint8_t token = 0;
  CommandResult result = CommandResult::kOk;
  std::uint32_t value = 0;   // accepted divider / capture N
  std::uint32_t cal_id = 0;  // kReportCalibration / kReloadCalibration
  bool calibrated = false;   // kReportCalibration
  bool deferred = false;     // no response now: it follows when the work is done (reload)
  bool has_capture = false;
  CaptureResult capture{};  // kCaptureCalibration, final response
};

/// Command frames in, response frames out (the CAN protocol's codec behind it).
struct DecodedFrame {
  bool addressed = false;  // a command frame for this node (others are ignored, not answered)
  bool ok = false;
  Command command{};
  CommandResult error = CommandResult::kOk;  // why not ok
  std::uint8_t raw_opcode = 0;
  std::uint8_t token = 0;
};

class CommandCodec {
 public:
  virtual ~CommandCodec() = default;
  virtual DecodedFrame decode(const hal::CanFrame& f) const = 0;
  /// The response frames (a capture result takes 20); returns how many were written.
  virtual std::size_t encode(const Response& r, std::array<hal::CanFrame, 24>& frames) const = 0;
};

}  // namespace gfins::app
