// What the firmware hands the CAN publisher once per sample: the navigation state, the six
// compensated accelerometer outputs, the mode, the validity/health bits, the calibration identity
// and the health counters (docs/can-interface.md describes how each reaches the bus).
#pragma once

#include <array>
#include <cstdint>
#include <limits>

#include "gfins/nav_core/nav_state.hpp"

namespace gfins::can {

/// Operating mode carried by GfinsEpoch.Mode (4 bits on the bus; VAL_ table in the DBC).
enum class Mode : std::uint8_t {
  kStartup = 0,      // configuring the ADC, loading calibration
  kAligning = 1,     // static leveling in progress: attitude not yet valid
  kNavigating = 2,   // navigation outputs valid
  kCalibrating = 3,  // a calibration capture is running (navigation continues)
  kFault = 4,        // a fault stopped navigation; health frames say which
  kReplay = 5,       // fed from a recorded or synthetic stream (hardware-in-the-loop)
};

/// Bits of Epoch::status_bits and of GfinsStatus.StatusFlags (20 bits on the bus). Bits 0..3 are
/// the navigation core's nav_status bits, at the same positions (checked below).
namespace status_bits {
inline constexpr std::uint32_t kAligned = 1u << 0;       // initial attitude set
inline constexpr std::uint32_t kSampleGap = 1u << 1;     // sample counter jumped before this step
inline constexpr std::uint32_t kInputInvalid = 1u << 2;  // a sample was rejected (flags, NaN)
inline constexpr std::uint32_t kCompensated = 1u << 3;   // misalignment compensation active
inline constexpr std::uint32_t kCanSaturated = 1u << 4;  // a value of this epoch was clipped to
                                                         // its signal's documented limit
inline constexpr std::uint32_t kCanNotAvailable = 1u << 5;  // a value was NaN/inf: sent as N/A
inline constexpr std::uint32_t kAdcCrcError = 1u << 6;      // ADC frame CRC error since last epoch
inline constexpr std::uint32_t kAdcSaturated = 1u << 7;     // an ADC channel at full scale
inline constexpr std::uint32_t kAdcChannelStuck = 1u << 8;  // a channel judged stuck
inline constexpr std::uint32_t kNominalCalibration = 1u << 9;  // no calibration file: nominal
inline constexpr std::uint32_t kLoopOverrun = 1u << 10;        // the sample loop missed a deadline
inline constexpr std::uint32_t kCanTxDropped = 1u << 11;       // CAN frames were dropped
inline constexpr std::uint32_t kCaptureActive = 1u << 12;      // calibration capture running
inline constexpr std::uint32_t kHealthDegraded = 1u << 13;     // any health counter grew recently
inline constexpr std::uint32_t kAdcRecovered = 1u << 14;       // the ADC was reset and reconfigured
inline constexpr std::uint32_t kDataReadyLost = 1u << 15;      // no data-ready edge in time
inline constexpr std::uint32_t kBusOff = 1u << 16;             // the CAN controller went bus-off
inline constexpr std::uint32_t kExtraEdge = 1u << 17;  // a data-ready edge without a conversion
inline constexpr std::uint32_t kCanRxDropped = 1u
                                               << 18;  // received CAN frames were lost (the
                                                       // kernel's socket queue or the controller)
inline constexpr std::uint32_t kAdcReadError = 1u << 19;   // the ADC delivered no sample (SPI or
                                                           // driver failure, a dead chip)
inline constexpr std::uint32_t kAllBits = (1u << 20) - 1;  // width of the bus field
static_assert(kAligned == nav::nav_status::kAligned && kSampleGap == nav::nav_status::kSampleGap &&
                  kInputInvalid == nav::nav_status::kInputInvalid &&
                  kCompensated == nav::nav_status::kCompensated,
              "bits 0..3 mirror nav_status so the publisher can OR NavState::status in");
inline constexpr std::uint32_t kNavStatusMask = 0xFu;
}  // namespace status_bits

/// Counters carried by GfinsHealthAdc / GfinsHealthSystem. Each only grows; on the bus it is
/// sent modulo 2^(signal length) (a rolling count: receivers look at differences).
struct Health {
  std::uint32_t missed_drdy_edges = 0;  // data-ready edges the loop did not service
  std::uint32_t adc_crc_errors = 0;     // ADC frames with a CRC mismatch
  std::uint32_t adc_resets = 0;         // chip resets detected / recoveries
  std::uint32_t saturated_samples = 0;  // samples with a channel at full scale
  std::uint8_t stuck_channel_mask = 0;  // bit c = channel c judged stuck (6 bits)
  std::uint32_t can_tx_dropped = 0;     // frames the CAN backend dropped
  std::uint32_t bus_off_events = 0;     // transitions into bus-off
  std::uint32_t loop_overruns = 0;      // sample-loop deadline misses
  std::uint32_t log_dropped = 0;        // log records lost to a full log queue
};

/// Which navigation groups of an epoch hold a value the board stands behind. A group that is not
/// valid goes on the bus as the not-available raw code of each of its signals (never a made-up
/// zero or identity): while aligning, after a reset, or when the filter's 1σ of the group exceeds
/// its configured horizon. The app sets these from the filter; every group starts valid so that a
/// caller that does not know about validity publishes what it always did.
struct Validity {
  bool attitude = true;       // GfinsQuaternion, GfinsEuler
  bool rate = true;           // GfinsAngularRate
  bool angular_accel = true;  // GfinsAngularAccel
  bool accel = true;          // GfinsAccel
  bool velocity = true;       // GfinsVelocity (VelN/E/D)
  bool position = true;       // GfinsPositionNE, GfinsPositionD (PosN/E/D)

  /// Nothing valid (aligning, no filter yet).
  static constexpr Validity none() { return {false, false, false, false, false, false}; }
};

/// Bits of Accuracy::filter_mode (GfinsVelocity.FilterMode): which aiding the filter used within
/// its aiding window. 0 = no filter running (aligning, stopped).
namespace filter_mode {
inline constexpr std::uint8_t kUnaided = 1u << 0;     // propagating on the inertial data only
inline constexpr std::uint8_t kStandstill = 1u << 1;  // zero-velocity / zero-rate updates
inline constexpr std::uint8_t kGnss = 1u << 2;        // GNSS position and/or velocity
inline constexpr std::uint8_t kHeading = 1u << 3;     // external heading
}  // namespace filter_mode

/// Kinds of aiding update: GfinsAidingCounters.AidKind and the index of Accuracy::aiding.
enum class AidKind : std::uint8_t { kZupt, kZaru, kGnssPosition, kGnssVelocity, kHeading };
inline constexpr std::size_t kAidKindCount = 5;

inline constexpr float kNoValue = std::numeric_limits<float>::quiet_NaN();

/// Updates of one kind. The counts only grow (sent modulo 2^16).
struct AidCounter {
  std::uint32_t accepted = 0;
  std::uint32_t rejected = 0;         // by the filter's innovation test or the input checks
  float since_accepted_s = kNoValue;  // time since the last accepted one; NaN = none yet
};

/// The filter's 1σ (square roots of its covariance's diagonal, combined as the signals say) and
/// its aiding. NaN = not available (no filter running): sent as the signal's not-available code.
/// A σ beyond its signal's range goes out as the range's maximum, flagged as saturated.
struct Accuracy {
  float sigma_roll_rad = kNoValue;
  float sigma_pitch_rad = kNoValue;
  float sigma_heading_rad = kNoValue;
  float sigma_vel_h_mps = kNoValue;                // sqrt(σ_vN² + σ_vE²)
  float sigma_vel_v_mps = kNoValue;                // σ_vD
  float sigma_pos_h_m = kNoValue;                  // sqrt(σ_N² + σ_E²)
  float sigma_pos_v_m = kNoValue;                  // σ_D
  std::uint8_t filter_mode = 0;                    // filter_mode bits
  std::array<AidCounter, kAidKindCount> aiding{};  // index = AidKind
};

/// GfinsCommandCounters: what became of the commands received and where the CAN settings came
/// from. The counts only grow (sent modulo 2^16, 2^8).
struct CommandCounters {
  std::uint32_t done = 0;            // commands carried out
  std::uint32_t refused = 0;         // commands refused, each answered with its Result
  std::uint32_t replayed = 0;        // of which refused as Replayed
  std::uint8_t last_refusal = 0;     // ResultCode of the last refusal; 0 = none yet
  std::uint8_t settings_source = 0;  // kSettingsSourceValues of message_table.hpp
};

/// One sample's worth of what may be published. Every value refers to nav.t_ns, the sampling
/// instant (data-ready edge) of sample nav.seq.
struct Epoch {
  nav::NavState<float> nav;           // q_nb, ω_b, ω̇_b, f_b, v_n, r_n (frames: b FRD, n NED)
  std::array<float, 6> accel_mps2{};  // compensated outputs of the six sensors, m/s²
  Mode mode = Mode::kStartup;         // GfinsEpoch.Mode
  std::uint32_t status_bits = 0;      // status_bits (nav.status bits 0..3 are ORed in)
  std::uint32_t cal_id = 0;           // identity of the calibration in use (0 = nominal)
  Health health;
  Validity valid;  // per navigation group; an invalid group is sent as not available
  Accuracy accuracy;
  CommandCounters commands;
};

}  // namespace gfins::can
