// The one message table of the gfins CAN interface. The firmware encoder (Publisher, responses),
// the host decoder (gfins-can), the command codec and the DBC generator all read it; nothing about
// the bus layout is written anywhere else (docs/can-interface.md is generated from the same facts
// and checked against it).
//
// Conventions (docs/can-interface.md): classic CAN 2.0, 11-bit identifiers = base + node id
// (node id 0..15), 8 data bytes, signals little-endian (Intel, DBC "@1"), bit 0 = LSB of byte 0.
// Data frames: payload bits 0..51, rolling epoch counter bits 52..55, CRC-8/SAE-J1850 bits 56..63
// over the two identifier bytes (little-endian) and data bytes 0..6. Aiding input frames (GNSS,
// heading; aiding_input.hpp) are framed the same way, their counter being the fix sequence id.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

namespace gfins::can {

inline constexpr std::uint8_t kMaxNodeId = 15;
/// The node id of a board out of the box (can.node_id's default): the node the committed DBC and
/// the tools' defaults are for, so that they decode a stock board.
inline constexpr std::uint8_t kDefaultNodeId = 1;
inline constexpr std::uint32_t kNodeIdSpan = 16;  // base IDs are 16 apart
inline constexpr std::uint32_t kDefaultBitRate = 500000;
inline constexpr double kDefaultSampleRateHz = 1000.0;  // the dividers' defaults assume 1 kHz
inline constexpr std::uint8_t kFrameLength = 8;
inline constexpr std::uint8_t kCounterStartBit = 52;
inline constexpr std::uint8_t kCounterLength = 4;
inline constexpr std::uint8_t kCrcStartBit = 56;
inline constexpr std::uint8_t kCrcByte = 7;

/// What a signal carries, so the encoder knows where to read it and the decoder where to put it.
enum class Field : std::uint8_t {
  kNone,
  kCounter,
  kCrc,
  // GfinsEpoch / GfinsStatus
  kTimeUs,
  kSampleCount,
  kMode,
  kStatusFlags,
  kCalId,
  // navigation (index = axis or component)
  kQuaternion,  // index 0 = w, 1..3 = x, y, z
  kEuler,       // 0 roll, 1 pitch, 2 yaw
  kRate,
  kAngularAccel,
  kAccel,
  kVelocity,
  kPosition,
  kSensorAccel,  // index = sensor 0..5
  // accuracy (filter covariance, 1σ) and aiding
  kSigmaAttitude,  // index 0 roll, 1 pitch, 2 heading
  kSigmaVelocity,  // 0 horizontal, 1 vertical
  kSigmaPosition,  // 0 horizontal, 1 vertical
  kFilterMode,
  kAidKind,      // the multiplexor of GfinsAidingCounters
  kAidAccepted,  // index = AidKind
  kAidRejected,
  kAidSinceAccepted,
  // health
  kMissedEdges,
  kAdcCrcErrors,
  kAdcResets,
  kStuckMask,
  kSaturatedSamples,
  kCanTxDropped,
  kBusOffEvents,
  kLoopOverruns,
  kLogDropped,
  // command
  kCmdOpcode,
  kCmdToken,
  kCmdHeading,
  kCmdCompensator,
  kCmdMessage,
  kCmdDivider,
  kCmdPose,
  kCmdSamples,
  kCmdForced,
  kCmdSequence,  // configuration-changing commands: must exceed the last one of the session
  kCmdNodeId,
  kCmdIdGroup,
  kCmdIdBase,
  // command counters and settings (GfinsCommandCounters)
  kCmdAccepted,
  kCmdRefused,
  kCmdReplayed,
  kCmdLastRefusal,
  kSettingsSource,
  // aiding inputs (GNSS receiver / heading source -> board)
  kInGnssPos,  // index 0 N, 1 E, 2 D
  kInGnssVel,
  kInGnssSigmaPosH,
  kInGnssSigmaPosV,
  kInGnssSigmaVel,
  kInGnssAge,
  kInGnssContent,
  kInHeading,
  kInHeadingSigma,
  kInHeadingAge,
  // response
  kRspOpcode,
  kRspToken,
  kRspPart,
  kRspResult,
  kRspValue,
  kRspCalId,
  kRspMean,  // index = channel
  kRspStd,
  kRspCount,
  kRspSaturated,
  kRspMotion,
  kRspPose,
  kRspSamples,
};

/// What happens to a value beyond the signal's range: navigation values are clipped to the
/// documented limit (and the epoch flagged), counters and times wrap modulo 2^length.
enum class Overflow : std::uint8_t { kSaturate, kWrap };

inline constexpr std::int16_t kNotMultiplexed = -1;
inline constexpr std::int16_t kMultiplexor = -2;

struct ValueName {
  std::int64_t raw;
  std::string_view name{};
};

struct SignalDef {
  std::string_view name{};
  Field field = Field::kNone;
  std::uint8_t index = 0;  // axis / component / channel for array fields
  std::uint8_t start_bit = 0;
  std::uint8_t length = 0;
  bool is_signed = false;
  double factor = 1.0;
  double offset = 0.0;
  std::string_view unit{};
  double min = 0.0;  // physical limits: encoder saturates here, DBC [min|max]
  double max = 0.0;
  bool has_na = false;      // a raw value reserved for "not available"
  std::int64_t na_raw = 0;  // that raw value (most negative for signed, all ones for unsigned)
  Overflow overflow = Overflow::kSaturate;
  std::int16_t mux = kNotMultiplexed;   // kMultiplexor, or the selector value this signal needs
  std::span<const ValueName> values{};  // enumeration (DBC VAL_)
  std::string_view instant{};           // which instant the value refers to
  std::string_view comment{};
  bool round_up = false;  // quantise upwards (σ: never shown smaller than it is)
};

enum class MessageId : std::uint8_t {
  kEpoch,
  kStatus,
  kQuaternion,
  kEuler,
  kRate,
  kAngularAccel,
  kAccel,
  kVelocity,
  kPositionNE,
  kPositionD,
  kHealthAdc,
  kHealthSystem,
  kSensorsA,
  kSensorsB,
  kCommand,
  kResponse,
  // Appended after the command/response pair, so the first 14 ids (and every divider index a
  // configuration names) keep their values.
  kAccuracy,
  kAidingCounters,
  kGnssPositionNE,
  kGnssPositionD,
  kGnssVelocity,
  kGnssFixInfo,
  kHeadingInput,
  kCommandCounters,
};
inline constexpr std::size_t kMessageCount = 24;

/// kInput: aiding measurements sent to the board (GNSS, heading), same framing as data frames
/// (counter in bits 52..55 = the fix's sequence id, CRC in byte 7), decoded by aiding_input.hpp.
enum class MessageKind : std::uint8_t { kData, kCommand, kResponse, kInput };

struct MessageDef {
  std::string_view name{};
  MessageId id;
  std::uint16_t base_id;  // CAN identifier of node 0
  MessageKind kind;
  std::uint16_t default_divider;  // of the sample rate; 0 = off (commands/responses: unused)
  std::span<const SignalDef> signals;
  std::string_view sender;  // DBC node
  std::string_view comment{};
};

// ---------------------------------------------------------------------------------------------
// Enumerations

inline constexpr std::array<ValueName, 6> kModeValues{{{0, "Startup"},
                                                       {1, "Aligning"},
                                                       {2, "Navigating"},
                                                       {3, "Calibrating"},
                                                       {4, "Fault"},
                                                       {5, "Replay"}}};

inline constexpr std::array<ValueName, 10> kOpcodeValues{{{1, "Realign"},
                                                          {2, "ResetNavigation"},
                                                          {3, "SetCompensator"},
                                                          {4, "SetDivider"},
                                                          {5, "ReportCalibrationId"},
                                                          {6, "StartCapture"},
                                                          {7, "ReloadCalibration"},
                                                          {8, "SetNodeId"},
                                                          {9, "RestoreDefaults"},
                                                          {10, "SetIdBase"}}};

/// The identifier groups (IdGroup order) as SetIdBase names them.
inline constexpr std::array<ValueName, 4> kIdGroupValues{
    {{0, "Data"}, {1, "Input"}, {2, "Command"}, {3, "Response"}}};

inline constexpr std::array<ValueName, 3> kCompensatorValues{
    {{0, "None"}, {1, "Paper"}, {2, "Exact"}}};

inline constexpr std::array<ValueName, 12> kResultValues{{{0, "Ok"},
                                                          {1, "UnknownOpcode"},
                                                          {2, "BadLength"},
                                                          {3, "BadCrc"},
                                                          {4, "OutOfRange"},
                                                          {5, "Malformed"},
                                                          {6, "Busy"},
                                                          {7, "Failed"},
                                                          {9, "Moving"},
                                                          {10, "BusLoad"},
                                                          {11, "Replayed"},
                                                          {12, "OtherDevice"}}};

/// GfinsCommandCounters.LastRefusal: the Result of the last refused command; 0 (Ok as a Result)
/// means no refusal yet.
constexpr std::array<ValueName, kResultValues.size()> refusal_values() {
  std::array<ValueName, kResultValues.size()> v = kResultValues;
  v[0] = ValueName{0, "None"};
  return v;
}
inline constexpr std::array<ValueName, kResultValues.size()> kRefusalValues = refusal_values();

/// Where the board's CAN settings (node id, dividers) came from (GfinsCommandCounters).
inline constexpr std::array<ValueName, 4> kSettingsSourceValues{
    {{0, "Configuration"}, {1, "Stored"}, {2, "StoredCorrupt"}, {3, "SaveFailed"}}};

inline constexpr std::array<ValueName, 18> kMessageIdValues{{{0, "Epoch"},
                                                             {1, "Status"},
                                                             {2, "Quaternion"},
                                                             {3, "Euler"},
                                                             {4, "AngularRate"},
                                                             {5, "AngularAccel"},
                                                             {6, "Accel"},
                                                             {7, "Velocity"},
                                                             {8, "PositionNE"},
                                                             {9, "PositionD"},
                                                             {10, "HealthAdc"},
                                                             {11, "HealthSystem"},
                                                             {12, "SensorsA"},
                                                             {13, "SensorsB"},
                                                             {14, "Command"},
                                                             {15, "Response"},
                                                             {16, "Accuracy"},
                                                             {17, "AidingCounters"}}};

/// Kinds of aiding update (GfinsAidingCounters.AidKind and the index of Accuracy::aiding).
inline constexpr std::array<ValueName, 5> kAidKindValues{
    {{0, "Zupt"}, {1, "Zaru"}, {2, "GnssPosition"}, {3, "GnssVelocity"}, {4, "Heading"}}};

// ---------------------------------------------------------------------------------------------
// Signal builders (keep the table one row per signal)

inline constexpr std::string_view kAtSample =
    "sampling instant of the epoch's sample (data-ready edge, GfinsEpoch.TimeUs)";
inline constexpr std::string_view kCumulative =
    "cumulative count up to and including the epoch's sample";
inline constexpr std::string_view kAtCommand = "when the frame is received";
inline constexpr std::string_view kAtResponse = "when the response is sent";
inline constexpr std::string_view kOverCapture = "over the capture's N samples";

/// A signed physical value with the most negative raw value reserved for "not available".
constexpr SignalDef physical(std::string_view name, Field field, std::uint8_t index,
                             std::uint8_t start, std::uint8_t length, double factor,
                             std::string_view unit, double min, double max,
                             std::string_view comment) {
  return SignalDef{.name = name,
                   .field = field,
                   .index = index,
                   .start_bit = start,
                   .length = length,
                   .is_signed = true,
                   .factor = factor,
                   .unit = unit,
                   .min = min,
                   .max = max,
                   .has_na = true,
                   .na_raw = -(std::int64_t{1} << (length - 1)),
                   .instant = kAtSample,
                   .comment = comment};
}

/// An unsigned integer that wraps modulo 2^length (counters, times).
constexpr SignalDef wrapping(std::string_view name, Field field, std::uint8_t start,
                             std::uint8_t length, std::string_view unit, std::string_view instant,
                             std::string_view comment) {
  return SignalDef{.name = name,
                   .field = field,
                   .start_bit = start,
                   .length = length,
                   .unit = unit,
                   .min = 0.0,
                   .max = static_cast<double>((std::uint64_t{1} << length) - 1),
                   .overflow = Overflow::kWrap,
                   .instant = instant,
                   .comment = comment};
}

/// An unsigned integer or enumeration, saturating at `max`.
constexpr SignalDef unsigned_int(std::string_view name, Field field, std::uint8_t index,
                                 std::uint8_t start, std::uint8_t length, double max,
                                 std::int16_t mux, std::span<const ValueName> values,
                                 std::string_view instant, std::string_view comment,
                                 double min = 0.0) {
  return SignalDef{.name = name,
                   .field = field,
                   .index = index,
                   .start_bit = start,
                   .length = length,
                   .min = min,
                   .max = max,
                   .mux = mux,
                   .values = values,
                   .instant = instant,
                   .comment = comment};
}

/// A 1σ: unsigned, all ones reserved for "not available", rounded up to the next step and
/// saturating at max (a σ beyond the range is sent as max, which then reads "at least max").
constexpr SignalDef sigma(std::string_view name, Field field, std::uint8_t index,
                          std::uint8_t start, std::uint8_t length, double factor,
                          std::string_view unit, std::string_view comment) {
  const std::uint64_t na = (std::uint64_t{1} << length) - 1;
  return SignalDef{.name = name,
                   .field = field,
                   .index = index,
                   .start_bit = start,
                   .length = length,
                   .factor = factor,
                   .unit = unit,
                   .min = 0.0,
                   // (na - 1) / (1 / factor): the decimal the DBC prints (0.4094, not
                   // the 0.40940000000000004 of 4094 * 1e-4)
                   .max = static_cast<double>(na - 1) / (1.0 / factor),
                   .has_na = true,
                   .na_raw = static_cast<std::int64_t>(na),
                   .instant = kAtSample,
                   .comment = comment,
                   .round_up = true};
}

constexpr SignalDef counter_signal() {
  return wrapping("Counter", Field::kCounter, kCounterStartBit, kCounterLength, "",
                  "the epoch this frame belongs to",
                  "Rolling epoch counter (mod 16): equal to the GfinsEpoch.Counter of the epoch "
                  "this frame belongs to; advances by one per published epoch");
}

constexpr SignalDef crc_signal() {
  return SignalDef{.name = "Crc",
                   .field = Field::kCrc,
                   .start_bit = kCrcStartBit,
                   .length = 8,
                   .max = 255.0,
                   .instant = "the frame",
                   .comment =
                       "CRC-8/SAE-J1850 (poly 0x1D, init 0xFF, xorout 0xFF) over the "
                       "identifier (2 bytes, little-endian) and data bytes 0..6"};
}

// ---------------------------------------------------------------------------------------------
// Signals per message

inline constexpr std::array<SignalDef, 5> kEpochSignals{{
    wrapping("TimeUs", Field::kTimeUs, 0, 32, "us", kAtSample,
             "Device time of the epoch's sample: data-ready edge, CLOCK_MONOTONIC, microseconds "
             "mod 2^32 (wraps every 71.6 min)"),
    wrapping("SampleCount", Field::kSampleCount, 32, 16, "", kAtSample,
             "ADC sample counter of the epoch's sample, mod 2^16"),
    unsigned_int("Mode", Field::kMode, 0, 48, 4, 15.0, kNotMultiplexed, kModeValues, kAtSample,
                 "Operating mode"),
    counter_signal(),
    crc_signal(),
}};

inline constexpr std::array<SignalDef, 4> kStatusSignals{{
    unsigned_int(
        "StatusFlags", Field::kStatusFlags, 0, 0, 20, 1048575.0, kNotMultiplexed, {}, kAtSample,
        "Validity and health bits: 0 aligned, 1 sample gap, 2 input invalid, 3 "
        "compensated, 4 a value of this epoch saturated on CAN, 5 a value was not "
        "available, 6 ADC CRC error, 7 ADC saturated, 8 ADC channel stuck, 9 nominal "
        "calibration, 10 loop overrun, 11 CAN frames dropped, 12 capture active, 13 "
        "health degraded, 14 ADC recovered from a reset, 15 data-ready lost, 16 CAN "
        "bus-off, 17 extra data-ready edge, 18 CAN frames lost on receive, 19 ADC read failed"),
    unsigned_int("CalId", Field::kCalId, 0, 20, 32, 4294967295.0, kNotMultiplexed, {}, kAtSample,
                 "Identity of the calibration in use (0 = nominal parameters)"),
    counter_signal(),
    crc_signal(),
}};

inline constexpr double kQuatFactor = 1.0 / 4095.0;
inline constexpr std::array<SignalDef, 6> kQuaternionSignals{{
    physical(
        "Qw", Field::kQuaternion, 0, 0, 13, kQuatFactor, "", -1.0, 1.0,
        "Attitude quaternion q_nb (body FRD to navigation NED), scalar part; sent with Qw >= 0"),
    physical("Qx", Field::kQuaternion, 1, 13, 13, kQuatFactor, "", -1.0, 1.0,
             "Attitude quaternion q_nb, x"),
    physical("Qy", Field::kQuaternion, 2, 26, 13, kQuatFactor, "", -1.0, 1.0,
             "Attitude quaternion q_nb, y"),
    physical("Qz", Field::kQuaternion, 3, 39, 13, kQuatFactor, "", -1.0, 1.0,
             "Attitude quaternion q_nb, z"),
    counter_signal(),
    crc_signal(),
}};

inline constexpr std::array<SignalDef, 5> kEulerSignals{{
    physical("Roll", Field::kEuler, 0, 0, 16, 1e-4, "rad", -3.1416, 3.1416,
             "Roll, ZYX Euler angles of q_nb (NED to FRD)"),
    physical("Pitch", Field::kEuler, 1, 16, 16, 1e-4, "rad", -1.5708, 1.5708,
             "Pitch, ZYX Euler angles of q_nb"),
    physical("Yaw", Field::kEuler, 2, 32, 16, 1e-4, "rad", -3.1416, 3.1416,
             "Yaw (heading from north), ZYX Euler angles of q_nb"),
    counter_signal(),
    crc_signal(),
}};

inline constexpr std::array<SignalDef, 5> kRateSignals{{
    physical("RateX", Field::kRate, 0, 0, 16, 5e-4, "rad/s", -16.0, 16.0,
             "Angular rate w_nb^b, body x (forward)"),
    physical("RateY", Field::kRate, 1, 16, 16, 5e-4, "rad/s", -16.0, 16.0,
             "Angular rate w_nb^b, body y (right)"),
    physical("RateZ", Field::kRate, 2, 32, 16, 5e-4, "rad/s", -16.0, 16.0,
             "Angular rate w_nb^b, body z (down)"),
    counter_signal(),
    crc_signal(),
}};

inline constexpr std::array<SignalDef, 5> kAngularAccelSignals{{
    physical("AngAccX", Field::kAngularAccel, 0, 0, 16, 5e-3, "rad/s^2", -160.0, 160.0,
             "Angular acceleration dw/dt, body x"),
    physical("AngAccY", Field::kAngularAccel, 1, 16, 16, 5e-3, "rad/s^2", -160.0, 160.0,
             "Angular acceleration dw/dt, body y"),
    physical("AngAccZ", Field::kAngularAccel, 2, 32, 16, 5e-3, "rad/s^2", -160.0, 160.0,
             "Angular acceleration dw/dt, body z"),
    counter_signal(),
    crc_signal(),
}};

inline constexpr std::array<SignalDef, 5> kAccelSignals{{
    physical("AccelX", Field::kAccel, 0, 0, 16, 0.01, "m/s^2", -320.0, 320.0,
             "Specific force f_b at the array centre, body x"),
    physical("AccelY", Field::kAccel, 1, 16, 16, 0.01, "m/s^2", -320.0, 320.0,
             "Specific force f_b at the array centre, body y"),
    physical("AccelZ", Field::kAccel, 2, 32, 16, 0.01, "m/s^2", -320.0, 320.0,
             "Specific force f_b at the array centre, body z"),
    counter_signal(),
    crc_signal(),
}};

inline constexpr std::array<SignalDef, 6> kVelocitySignals{{
    physical("VelN", Field::kVelocity, 0, 0, 16, 0.01, "m/s", -320.0, 320.0, "Velocity v_n, north"),
    physical("VelE", Field::kVelocity, 1, 16, 16, 0.01, "m/s", -320.0, 320.0, "Velocity v_n, east"),
    physical("VelD", Field::kVelocity, 2, 32, 16, 0.01, "m/s", -320.0, 320.0, "Velocity v_n, down"),
    unsigned_int("FilterMode", Field::kFilterMode, 0, 48, 4, 15.0, kNotMultiplexed, {}, kAtSample,
                 "Aiding the filter used within its aiding window, bits: 0 unaided (inertial "
                 "only), 1 standstill (ZUPT/ZARU), 2 GNSS, 3 heading; 0 = no filter running"),
    counter_signal(),
    crc_signal(),
}};

inline constexpr std::array<SignalDef, 4> kPositionNESignals{{
    physical("PosN", Field::kPosition, 0, 0, 26, 0.01, "m", -335000.0, 335000.0,
             "Position r_n from the alignment point, north"),
    physical("PosE", Field::kPosition, 1, 26, 26, 0.01, "m", -335000.0, 335000.0,
             "Position r_n from the alignment point, east"),
    counter_signal(),
    crc_signal(),
}};

inline constexpr std::array<SignalDef, 5> kPositionDSignals{{
    physical("PosD", Field::kPosition, 2, 0, 26, 0.01, "m", -335000.0, 335000.0,
             "Position r_n from the alignment point, down"),
    sigma("SigmaPosH", Field::kSigmaPosition, 0, 26, 13, 0.02, "m",
          "1 sigma of the horizontal position, sqrt(sigma_N^2 + sigma_E^2), from the filter"),
    sigma("SigmaPosV", Field::kSigmaPosition, 1, 39, 13, 0.02, "m",
          "1 sigma of the vertical position (down), from the filter"),
    counter_signal(),
    crc_signal(),
}};

inline constexpr std::array<SignalDef, 7> kHealthAdcSignals{{
    wrapping("MissedEdges", Field::kMissedEdges, 0, 16, "", kCumulative,
             "Data-ready edges the sample loop did not service, mod 2^16"),
    wrapping("AdcCrcErrors", Field::kAdcCrcErrors, 16, 16, "", kCumulative,
             "ADC frames with a CRC mismatch, mod 2^16"),
    wrapping("AdcResets", Field::kAdcResets, 32, 8, "", kCumulative,
             "ADC resets detected and recovered, mod 2^8"),
    unsigned_int("StuckMask", Field::kStuckMask, 0, 40, 6, 63.0, kNotMultiplexed, {}, kAtSample,
                 "Bit c set: ADC channel c+1 judged stuck"),
    wrapping("LogDropped", Field::kLogDropped, 46, 6, "", kCumulative,
             "Log records the firmware's log queue lost (queue full), mod 2^6"),
    counter_signal(),
    crc_signal(),
}};

inline constexpr std::array<SignalDef, 6> kHealthSystemSignals{{
    wrapping("SaturatedSamples", Field::kSaturatedSamples, 0, 16, "", kCumulative,
             "Samples with an ADC channel at full scale, mod 2^16"),
    wrapping("CanTxDropped", Field::kCanTxDropped, 16, 16, "", kCumulative,
             "CAN frames the bus backend dropped, mod 2^16"),
    wrapping("BusOffEvents", Field::kBusOffEvents, 32, 8, "", kCumulative,
             "Transitions into bus-off, mod 2^8"),
    wrapping("LoopOverruns", Field::kLoopOverruns, 40, 12, "", kCumulative,
             "Sample-loop deadline misses, mod 2^12"),
    counter_signal(),
    crc_signal(),
}};

inline constexpr std::array<SignalDef, 5> kSensorsASignals{{
    physical("Sensor1", Field::kSensorAccel, 0, 0, 16, 0.02, "m/s^2", -600.0, 600.0,
             "Compensated specific force of accelerometer 1 along its sensing axis"),
    physical("Sensor2", Field::kSensorAccel, 1, 16, 16, 0.02, "m/s^2", -600.0, 600.0,
             "Compensated specific force of accelerometer 2 along its sensing axis"),
    physical("Sensor3", Field::kSensorAccel, 2, 32, 16, 0.02, "m/s^2", -600.0, 600.0,
             "Compensated specific force of accelerometer 3 along its sensing axis"),
    counter_signal(),
    crc_signal(),
}};

inline constexpr std::array<SignalDef, 5> kSensorsBSignals{{
    physical("Sensor4", Field::kSensorAccel, 3, 0, 16, 0.02, "m/s^2", -600.0, 600.0,
             "Compensated specific force of accelerometer 4 along its sensing axis"),
    physical("Sensor5", Field::kSensorAccel, 4, 16, 16, 0.02, "m/s^2", -600.0, 600.0,
             "Compensated specific force of accelerometer 5 along its sensing axis"),
    physical("Sensor6", Field::kSensorAccel, 5, 32, 16, 0.02, "m/s^2", -600.0, 600.0,
             "Compensated specific force of accelerometer 6 along its sensing axis"),
    counter_signal(),
    crc_signal(),
}};

inline constexpr std::array<SignalDef, 7> kAccuracySignals{{
    sigma("SigmaRoll", Field::kSigmaAttitude, 0, 0, 10, 1e-4, "rad", "1 sigma of roll"),
    sigma("SigmaPitch", Field::kSigmaAttitude, 1, 10, 10, 1e-4, "rad", "1 sigma of pitch"),
    sigma("SigmaHeading", Field::kSigmaAttitude, 2, 20, 11, 1e-3, "rad",
          "1 sigma of heading (yaw)"),
    sigma("SigmaVelH", Field::kSigmaVelocity, 0, 31, 10, 0.01, "m/s",
          "1 sigma of the horizontal velocity, sqrt(sigma_N^2 + sigma_E^2)"),
    sigma("SigmaVelV", Field::kSigmaVelocity, 1, 41, 11, 0.01, "m/s",
          "1 sigma of the vertical velocity (down)"),
    counter_signal(),
    crc_signal(),
}};

// Aiding counters: one kind per frame, the kinds in turn (AidKind = the multiplexor).
inline constexpr std::uint8_t kAidKinds = 5;
constexpr SignalDef with_mux(SignalDef s, std::uint8_t index, std::int16_t mux) {
  s.index = index;
  s.mux = mux;
  return s;
}

inline constexpr std::array<SignalDef, 18> kAidingCountersSignals{{
    SignalDef{.name = "AidKind",
              .field = Field::kAidKind,
              .start_bit = 0,
              .length = 4,
              .max = 4.0,
              .mux = kMultiplexor,
              .values = kAidKindValues,
              .instant = kAtSample,
              .comment = "Which kind of aiding update this frame counts; the kinds take turns"},
#define GFINS_CAN_AID_ROW(NAME, K)                                                          \
  with_mux(wrapping(NAME "Accepted", Field::kAidAccepted, 4, 16, "", kCumulative,           \
                    NAME " updates the filter accepted, mod 2^16"),                         \
           K, K),                                                                           \
      with_mux(wrapping(NAME "Rejected", Field::kAidRejected, 20, 16, "", kCumulative,      \
                        NAME " updates the filter rejected (innovation test), mod 2^16"),   \
               K, K),                                                                       \
      with_mux(sigma(NAME "Since", Field::kAidSinceAccepted, K, 36, 16, 0.01, "s",          \
                     "Time since the last accepted " NAME " update (saturates; N/A = none " \
                     "yet)"),                                                               \
               K, K)
    GFINS_CAN_AID_ROW("Zupt", 0),
    GFINS_CAN_AID_ROW("Zaru", 1),
    GFINS_CAN_AID_ROW("GnssPos", 2),
    GFINS_CAN_AID_ROW("GnssVel", 3),
    GFINS_CAN_AID_ROW("Heading", 4),
#undef GFINS_CAN_AID_ROW
    counter_signal(),
    crc_signal(),
}};

// Aiding inputs (GNSS receiver or a gateway -> board). Every frame of one fix carries the fix id
// in the counter bits; GfinsGnssFixInfo, sent last, completes the fix. Reserved bits are zero.
inline constexpr std::string_view kAtFix =
    "the fix's time of validity (reception of FixInfo - FixAge)";
inline constexpr std::string_view kAtHeading =
    "the heading's time of validity (reception - HeadingAge)";

constexpr SignalDef fix_id_signal() {
  return wrapping("FixId", Field::kCounter, kCounterStartBit, kCounterLength, "",
                  "the fix this frame belongs to",
                  "Fix sequence id (mod 16): equal in every frame of one fix, advances by one "
                  "per fix; a fix with the id of the last accepted one is rejected as stale");
}

/// An input σ: like sigma() but zero is not a σ (min = one step), all ones = not stated.
constexpr SignalDef input_sigma(std::string_view name, Field field, std::uint8_t start,
                                std::uint8_t length, double factor, std::string_view unit,
                                std::string_view instant, std::string_view comment) {
  SignalDef d = sigma(name, field, 0, start, length, factor, unit, comment);
  d.min = factor;
  d.instant = instant;
  return d;
}

constexpr SignalDef input_age(std::string_view name, Field field, std::uint8_t start,
                              std::string_view comment) {
  SignalDef d = sigma(name, field, 0, start, 13, 1e-3, "s", comment);
  d.round_up = false;
  d.instant = "the frame's transmission";
  return d;
}

constexpr SignalDef at_fix(SignalDef d) {
  d.instant = kAtFix;
  return d;
}

inline constexpr std::array<SignalDef, 4> kGnssPositionNESignals{{
    at_fix(physical("GnssPosN", Field::kInGnssPos, 0, 0, 26, 0.01, "m", -335000.0, 335000.0,
                    "GNSS antenna position from the navigation origin (alignment point), north")),
    at_fix(physical("GnssPosE", Field::kInGnssPos, 1, 26, 26, 0.01, "m", -335000.0, 335000.0,
                    "GNSS antenna position from the navigation origin, east")),
    fix_id_signal(),
    crc_signal(),
}};

inline constexpr std::array<SignalDef, 5> kGnssPositionDSignals{{
    at_fix(physical("GnssPosD", Field::kInGnssPos, 2, 0, 26, 0.01, "m", -335000.0, 335000.0,
                    "GNSS antenna position from the navigation origin, down")),
    input_sigma("GnssSigmaPosH", Field::kInGnssSigmaPosH, 26, 13, 0.01, "m", kAtFix,
                "Receiver's 1 sigma of the position, north and east (each)"),
    input_sigma("GnssSigmaPosV", Field::kInGnssSigmaPosV, 39, 13, 0.01, "m", kAtFix,
                "Receiver's 1 sigma of the position, down"),
    fix_id_signal(),
    crc_signal(),
}};

inline constexpr std::array<SignalDef, 5> kGnssVelocitySignals{{
    at_fix(physical("GnssVelN", Field::kInGnssVel, 0, 0, 16, 0.01, "m/s", -320.0, 320.0,
                    "GNSS antenna velocity, north")),
    at_fix(physical("GnssVelE", Field::kInGnssVel, 1, 16, 16, 0.01, "m/s", -320.0, 320.0,
                    "GNSS antenna velocity, east")),
    at_fix(physical("GnssVelD", Field::kInGnssVel, 2, 32, 16, 0.01, "m/s", -320.0, 320.0,
                    "GNSS antenna velocity, down")),
    fix_id_signal(),
    crc_signal(),
}};

inline constexpr std::array<ValueName, 3> kGnssContentValues{
    {{1, "Position"}, {2, "Velocity"}, {3, "PositionVelocity"}}};

inline constexpr std::array<SignalDef, 5> kGnssFixInfoSignals{{
    input_sigma("GnssSigmaVel", Field::kInGnssSigmaVel, 0, 12, 0.001, "m/s", kAtFix,
                "Receiver's 1 sigma of each velocity axis"),
    input_age("GnssFixAge", Field::kInGnssAge, 12,
              "Age of the fix when this frame was sent: transmission - time of validity"),
    unsigned_int("GnssContent", Field::kInGnssContent, 0, 25, 2, 3.0, kNotMultiplexed,
                 kGnssContentValues, kAtFix,
                 "What the fix holds: bit 0 position (PositionNE, PositionD), bit 1 velocity", 1.0),
    fix_id_signal(),
    crc_signal(),
}};

inline constexpr std::array<SignalDef, 5> kHeadingInputSignals{{
    SignalDef{.name = "ExtHeading",
              .field = Field::kInHeading,
              .start_bit = 0,
              .length = 16,
              .is_signed = true,
              .factor = 1e-4,
              .unit = "rad",
              .min = -3.1416,
              .max = 3.1416,
              .has_na = true,
              .na_raw = -32768,
              .instant = kAtHeading,
              .comment = "External heading (yaw of q_nb), e.g. dual-antenna GNSS"},
    input_sigma("ExtHeadingSigma", Field::kInHeadingSigma, 16, 12, 1e-4, "rad", kAtHeading,
                "1 sigma of the external heading"),
    input_age("ExtHeadingAge", Field::kInHeadingAge, 28,
              "Age of the heading when sent: transmission - time of validity"),
    wrapping("Sequence", Field::kCounter, kCounterStartBit, kCounterLength, "",
             "the heading this frame carries",
             "Heading sequence (mod 16), advances by one per heading; a repeat is rejected"),
    crc_signal(),
}};

// Command (host -> board). Opcode is the multiplexor: each opcode's arguments are the signals
// with its value in `mux`. Bits not used by the opcode must be zero.
inline constexpr std::uint8_t kOpRealign = 1;
inline constexpr std::uint8_t kOpResetNavigation = 2;
inline constexpr std::uint8_t kOpSetCompensator = 3;
inline constexpr std::uint8_t kOpSetDivider = 4;
/// Realign's heading range: ±π, rounded up to the signal's 1e-4 rad resolution.
inline constexpr double kHeadingLimitRad = 3.1416;
/// Largest divider of the sample rate a message can have (the configuration's output.* and the
/// SetDivider command alike): 10 s between frames at 1 kHz.
inline constexpr std::uint16_t kMaxDivider = 10000;
inline constexpr std::uint8_t kOpReportCalibrationId = 5;
inline constexpr std::uint8_t kOpStartCapture = 6;
inline constexpr std::uint8_t kOpReloadCalibration = 7;
inline constexpr std::uint8_t kMaxCapturePose = 63;
inline constexpr std::uint8_t kOpSetNodeId = 8;
inline constexpr std::uint8_t kOpRestoreDefaults = 9;
inline constexpr std::uint8_t kOpSetIdBase = 10;
/// Configuration-changing commands carry a sequence number in bits 40..55: it must exceed the
/// last one the board took in this session (0 at start-up), so a frame replayed from a log is
/// refused (docs/can-interface.md, "Sequence numbers").
inline constexpr std::uint8_t kSequenceStartBit = 40;
inline constexpr std::uint8_t kSequenceLength = 16;
inline constexpr double kMaxSequence = 65535.0;

constexpr SignalDef sequence_signal(std::string_view name, std::int16_t op) {
  return unsigned_int(name, Field::kCmdSequence, 0, kSequenceStartBit, kSequenceLength,
                      kMaxSequence, op, {}, kAtCommand,
                      "Sequence number: must exceed the last one the board took since it "
                      "started (every command carrying one takes it, refused or not); a lower "
                      "or equal one is refused as Replayed",
                      1.0);
}

inline constexpr std::array<SignalDef, 23> kCommandSignals{{
    SignalDef{.name = "Opcode",
              .field = Field::kCmdOpcode,
              .start_bit = 0,
              .length = 8,
              .min = 1.0,
              .max = 10.0,
              .mux = kMultiplexor,
              .values = kOpcodeValues,
              .instant = kAtCommand,
              .comment = "Command"},
    unsigned_int("Token", Field::kCmdToken, 0, 8, 8, 255.0, kNotMultiplexed, {}, kAtCommand,
                 "Chosen by the sender, echoed in every response frame"),
    SignalDef{.name = "Heading",
              .field = Field::kCmdHeading,
              .start_bit = 16,
              .length = 16,
              .is_signed = true,
              .factor = 1e-4,
              .unit = "rad",
              .min = -kHeadingLimitRad,
              .max = kHeadingLimitRad,
              .mux = kOpRealign,
              .instant = kAtCommand,
              .comment = "Realign: heading (yaw of q_nb) to align to; roll and pitch from "
                         "static leveling"},
    unsigned_int("RealignForced", Field::kCmdForced, 0, 32, 1, 1.0, kOpRealign, {}, kAtCommand,
                 "Realign: 1 = carry it out even while the board moves (else refused while "
                 "moving)"),
    unsigned_int("ResetForced", Field::kCmdForced, 0, 16, 1, 1.0, kOpResetNavigation, {},
                 kAtCommand,
                 "ResetNavigation: 1 = carry it out even while the board moves (else refused "
                 "while moving)"),
    unsigned_int("Compensator", Field::kCmdCompensator, 0, 16, 8, 2.0, kOpSetCompensator,
                 kCompensatorValues, kAtCommand, "SetCompensator: compensator to use"),
    unsigned_int("DividerMessage", Field::kCmdMessage, 0, 16, 8, 17.0, kOpSetDivider,
                 kMessageIdValues, kAtCommand, "SetDivider: the data message"),
    unsigned_int("Divider", Field::kCmdDivider, 0, 24, 16, double{kMaxDivider}, kOpSetDivider, {},
                 kAtCommand,
                 "SetDivider: new divider of the sample rate (0 = off); a multiple of the "
                 "Epoch divider"),
    unsigned_int("CapturePose", Field::kCmdPose, 0, 16, 8, kMaxCapturePose, kOpStartCapture, {},
                 kAtCommand, "StartCapture: pose index k"),
    unsigned_int("CaptureSamples", Field::kCmdSamples, 0, 24, 16, 65535.0, kOpStartCapture, {},
                 kAtCommand, "StartCapture: number of samples N", 1.0),
    unsigned_int("ReloadForced", Field::kCmdForced, 0, 16, 1, 1.0, kOpReloadCalibration, {},
                 kAtCommand,
                 "ReloadCalibration: 1 = take the file even when its device_id is not the one "
                 "of the calibration in use (else refused as OtherDevice)"),
    unsigned_int("NodeId", Field::kCmdNodeId, 0, 16, 8, double{kMaxNodeId}, kOpSetNodeId, {},
                 kAtCommand, "SetNodeId: the node id the board takes at its next start"),
    unsigned_int("IdGroup", Field::kCmdIdGroup, 0, 16, 8, 3.0, kOpSetIdBase, kIdGroupValues,
                 kAtCommand, "SetIdBase: the identifier group to move"),
    unsigned_int("IdBase", Field::kCmdIdBase, 0, 24, 11, 2047.0, kOpSetIdBase, {}, kAtCommand,
                 "SetIdBase: the group's first identifier from the next start (its messages keep "
                 "their offsets; refused when the group would leave 11 bits or overlap another "
                 "group or can.reserved_ids)"),
    sequence_signal("RealignSequence", kOpRealign),
    sequence_signal("ResetSequence", kOpResetNavigation),
    sequence_signal("CompensatorSequence", kOpSetCompensator),
    sequence_signal("DividerSequence", kOpSetDivider),
    sequence_signal("ReloadSequence", kOpReloadCalibration),
    sequence_signal("NodeIdSequence", kOpSetNodeId),
    sequence_signal("RestoreSequence", kOpRestoreDefaults),
    sequence_signal("IdBaseSequence", kOpSetIdBase),
    crc_signal(),
}};

// Response (board -> host). Part is the multiplexor.
inline constexpr std::uint8_t kPartStatus = 0;
inline constexpr std::uint8_t kPartCalibrationId = 1;
inline constexpr std::uint8_t kPartCaptureDone = 2;
inline constexpr std::uint8_t kPartMean = 0x10;     // + channel 0..5
inline constexpr std::uint8_t kPartStd = 0x20;      // + channel
inline constexpr std::uint8_t kPartCount = 0x30;    // + channel
inline constexpr double kMeanFactor = 1.0 / 256.0;  // ADC counts
inline constexpr double kStdFactor = 1.0 / 4096.0;  // ADC counts

#define GFINS_CAN_CHANNEL_SIGNALS(N, C)                                                           \
  SignalDef{.name = "MeanCh" #N,                                                                  \
            .field = Field::kRspMean,                                                             \
            .index = (C),                                                                         \
            .start_bit = 24,                                                                      \
            .length = 32,                                                                         \
            .is_signed = true,                                                                    \
            .factor = kMeanFactor,                                                                \
            .unit = "count",                                                                      \
            .min = -8388608.0,                                                                    \
            .max = 8388607.0,                                                                     \
            .mux = kPartMean + (C),                                                               \
            .instant = kOverCapture,                                                              \
            .comment = "Capture: mean ADC code of channel " #N},                                  \
      SignalDef{.name = "StdCh" #N,                                                               \
                .field = Field::kRspStd,                                                          \
                .index = (C),                                                                     \
                .start_bit = 24,                                                                  \
                .length = 32,                                                                     \
                .factor = kStdFactor,                                                             \
                .unit = "count",                                                                  \
                .min = 0.0,                                                                       \
                .max = 1048575.0,                                                                 \
                .mux = kPartStd + (C),                                                            \
                .instant = kOverCapture,                                                          \
                .comment = "Capture: standard deviation of channel " #N},                         \
      unsigned_int("CountCh" #N, Field::kRspCount, (C), 24, 16, 65535.0, kPartCount + (C), {},    \
                   kOverCapture, "Capture: samples averaged on channel " #N),                     \
      unsigned_int("SaturatedCh" #N, Field::kRspSaturated, (C), 40, 1, 1.0, kPartCount + (C), {}, \
                   kOverCapture, "Capture: channel " #N " reached full scale"),                   \
      unsigned_int("MotionCh" #N, Field::kRspMotion, (C), 41, 1, 1.0, kPartCount + (C), {},       \
                   kOverCapture, "Capture: channel " #N " varied more than a static pose allows")

inline constexpr std::array<SignalDef, 39> kResponseSignals{{
    unsigned_int("RspOpcode", Field::kRspOpcode, 0, 0, 8, 255.0, kNotMultiplexed, kOpcodeValues,
                 kAtResponse, "Opcode of the command answered (echo, also when unknown)"),
    unsigned_int("RspToken", Field::kRspToken, 0, 8, 8, 255.0, kNotMultiplexed, {}, kAtResponse,
                 "Token of the command answered (echo)"),
    SignalDef{.name = "Part",
              .field = Field::kRspPart,
              .start_bit = 16,
              .length = 8,
              .max = 255.0,
              .mux = kMultiplexor,
              .instant = kAtResponse,
              .comment = "0 status, 1 calibration id, 2 capture done, 0x10+c mean, 0x20+c std, "
                         "0x30+c count and flags of channel c+1"},
    unsigned_int("Result", Field::kRspResult, 0, 24, 8, 255.0, kPartStatus, kResultValues,
                 kAtResponse, "Outcome of the command"),
    unsigned_int(
        "Value", Field::kRspValue, 0, 32, 24, 16777215.0, kPartStatus, {}, kAtResponse,
        "Command-specific: the new divider, the accepted N, the node id or the group base of the "
        "next start; for ReportCalibrationId and Replayed the last sequence number the board "
        "took"),
    unsigned_int("CalId", Field::kRspCalId, 0, 24, 32, 4294967295.0, kPartCalibrationId, {},
                 kAtResponse, "Identity of the calibration in use (0 = nominal)"),
    unsigned_int("DonePose", Field::kRspPose, 0, 24, 8, 255.0, kPartCaptureDone, {}, kOverCapture,
                 "Capture finished: pose index k"),
    unsigned_int("DoneSamples", Field::kRspSamples, 0, 32, 16, 65535.0, kPartCaptureDone, {},
                 kOverCapture, "Capture finished: samples taken"),
    GFINS_CAN_CHANNEL_SIGNALS(1, 0),
    GFINS_CAN_CHANNEL_SIGNALS(2, 1),
    GFINS_CAN_CHANNEL_SIGNALS(3, 2),
    GFINS_CAN_CHANNEL_SIGNALS(4, 3),
    GFINS_CAN_CHANNEL_SIGNALS(5, 4),
    GFINS_CAN_CHANNEL_SIGNALS(6, 5),
    crc_signal(),
}};
#undef GFINS_CAN_CHANNEL_SIGNALS

// Commands and settings (board -> host): what became of the commands received, and where the
// CAN settings in use came from.
inline constexpr std::array<SignalDef, 7> kCommandCountersSignals{{
    wrapping("CommandsDone", Field::kCmdAccepted, 0, 16, "", kCumulative,
             "Commands carried out, mod 2^16"),
    wrapping("CommandsRefused", Field::kCmdRefused, 16, 16, "", kCumulative,
             "Commands refused (each answered with its Result), mod 2^16"),
    wrapping("ReplaysRefused", Field::kCmdReplayed, 32, 8, "", kCumulative,
             "Commands refused as Replayed (sequence number not above the last), mod 2^8"),
    unsigned_int("LastRefusal", Field::kCmdLastRefusal, 0, 40, 8, 255.0, kNotMultiplexed,
                 kRefusalValues, kAtSample, "Result of the last refused command (0 = none yet)"),
    unsigned_int("SettingsSource", Field::kSettingsSource, 0, 48, 2, 3.0, kNotMultiplexed,
                 kSettingsSourceValues, kAtSample,
                 "Where the CAN settings in use came from: 0 the configuration (nothing "
                 "stored), 1 the stored settings, 2 the configuration because the stored "
                 "settings were unreadable or corrupt, 3 a change could not be stored (in use "
                 "until the board restarts)"),
    counter_signal(),
    crc_signal(),
}};

// ---------------------------------------------------------------------------------------------
// The table. Order = MessageId order = transmission order within an epoch.

inline constexpr std::array<MessageDef, kMessageCount> kMessages{{
    {"GfinsEpoch", MessageId::kEpoch, 0x100, MessageKind::kData, 10, kEpochSignals, "GFINS",
     "Opens each epoch: time and sample counter of the sample every following frame refers to"},
    {"GfinsStatus", MessageId::kStatus, 0x110, MessageKind::kData, 10, kStatusSignals, "GFINS",
     "Validity and health bits and calibration identity; sent with every GfinsEpoch"},
    {"GfinsQuaternion", MessageId::kQuaternion, 0x120, MessageKind::kData, 10, kQuaternionSignals,
     "GFINS", "Attitude quaternion q_nb"},
    {"GfinsEuler", MessageId::kEuler, 0x130, MessageKind::kData, 20, kEulerSignals, "GFINS",
     "Attitude as ZYX Euler angles"},
    {"GfinsAngularRate", MessageId::kRate, 0x140, MessageKind::kData, 10, kRateSignals, "GFINS",
     "Angular rate, body frame"},
    {"GfinsAngularAccel", MessageId::kAngularAccel, 0x150, MessageKind::kData, 20,
     kAngularAccelSignals, "GFINS", "Angular acceleration, body frame (Chen's solution)"},
    {"GfinsAccel", MessageId::kAccel, 0x160, MessageKind::kData, 10, kAccelSignals, "GFINS",
     "Specific force at the array centre, body frame"},
    {"GfinsVelocity", MessageId::kVelocity, 0x170, MessageKind::kData, 10, kVelocitySignals,
     "GFINS", "Velocity, navigation frame (NED)"},
    {"GfinsPositionNE", MessageId::kPositionNE, 0x180, MessageKind::kData, 10, kPositionNESignals,
     "GFINS", "Position from the alignment point, north and east"},
    {"GfinsPositionD", MessageId::kPositionD, 0x190, MessageKind::kData, 10, kPositionDSignals,
     "GFINS", "Position from the alignment point, down"},
    {"GfinsHealthAdc", MessageId::kHealthAdc, 0x1A0, MessageKind::kData, 1000, kHealthAdcSignals,
     "GFINS", "ADC and log health counters"},
    {"GfinsHealthSystem", MessageId::kHealthSystem, 0x1B0, MessageKind::kData, 1000,
     kHealthSystemSignals, "GFINS", "Loop and bus health counters"},
    {"GfinsSensorsA", MessageId::kSensorsA, 0x1C0, MessageKind::kData, 0, kSensorsASignals, "GFINS",
     "Compensated accelerometer outputs 1-3 (off by default)"},
    {"GfinsSensorsB", MessageId::kSensorsB, 0x1D0, MessageKind::kData, 0, kSensorsBSignals, "GFINS",
     "Compensated accelerometer outputs 4-6 (off by default)"},
    {"GfinsCommand", MessageId::kCommand, 0x600, MessageKind::kCommand, 0, kCommandSignals, "HOST",
     "Command to the board; answered by GfinsResponse with the same Opcode and Token"},
    {"GfinsResponse", MessageId::kResponse, 0x680, MessageKind::kResponse, 0, kResponseSignals,
     "GFINS", "Response to a GfinsCommand"},
    {"GfinsAccuracy", MessageId::kAccuracy, 0x1E0, MessageKind::kData, 200, kAccuracySignals,
     "GFINS", "1 sigma of attitude and velocity from the filter's covariance"},
    {"GfinsAidingCounters", MessageId::kAidingCounters, 0x1F0, MessageKind::kData, 400,
     kAidingCountersSignals, "GFINS",
     "Accepted and rejected aiding updates per kind, one kind per frame in turn"},
    {"GfinsGnssPositionNE", MessageId::kGnssPositionNE, 0x0C0, MessageKind::kInput, 0,
     kGnssPositionNESignals, "GNSS", "GNSS fix, frame 1 of 4: antenna position north, east"},
    {"GfinsGnssPositionD", MessageId::kGnssPositionD, 0x0D0, MessageKind::kInput, 0,
     kGnssPositionDSignals, "GNSS",
     "GNSS fix, frame 2 of 4: antenna position down and the receiver's position 1 sigma"},
    {"GfinsGnssVelocity", MessageId::kGnssVelocity, 0x0E0, MessageKind::kInput, 0,
     kGnssVelocitySignals, "GNSS", "GNSS fix, frame 3 of 4: antenna velocity"},
    {"GfinsGnssFixInfo", MessageId::kGnssFixInfo, 0x0F0, MessageKind::kInput, 0,
     kGnssFixInfoSignals, "GNSS",
     "GNSS fix, frame 4 of 4 (completes the fix): velocity 1 sigma, age, content"},
    {"GfinsHeadingInput", MessageId::kHeadingInput, 0x0B0, MessageKind::kInput, 0,
     kHeadingInputSignals, "GNSS", "External heading for the filter"},
    {"GfinsCommandCounters", MessageId::kCommandCounters, 0x200, MessageKind::kData, 1000,
     kCommandCountersSignals, "GFINS",
     "Commands carried out and refused, the last refusal, where the CAN settings came from"},
}};

constexpr const MessageDef& message(MessageId id) {
  return kMessages[static_cast<std::size_t>(id)];
}

// ---------------------------------------------------------------------------------------------
// Identifier groups (docs/can-interface.md, "Identifiers"). A configuration may move each group
// as a whole: the data messages, the aiding inputs, the command, the response. A message keeps
// its offset from its group's first identifier; the node id is added as before.

enum class IdGroup : std::uint8_t { kData, kInput, kCommand, kResponse };
inline constexpr std::size_t kIdGroupCount = 4;

constexpr std::size_t id_group(MessageKind k) {
  switch (k) {
    case MessageKind::kInput:
      return static_cast<std::size_t>(IdGroup::kInput);
    case MessageKind::kCommand:
      return static_cast<std::size_t>(IdGroup::kCommand);
    case MessageKind::kResponse:
      return static_cast<std::size_t>(IdGroup::kResponse);
    case MessageKind::kData:
      break;
  }
  return static_cast<std::size_t>(IdGroup::kData);
}

/// The table's own first identifier of each group (IdGroup order): the defaults.
constexpr std::array<std::uint16_t, kIdGroupCount> default_id_bases() {
  std::array<std::uint16_t, kIdGroupCount> b{0x7FF, 0x7FF, 0x7FF, 0x7FF};
  for (const MessageDef& m : kMessages) {
    const std::size_t g = id_group(m.kind);
    if (m.base_id < b[g]) b[g] = m.base_id;
  }
  return b;
}
inline constexpr std::array<std::uint16_t, kIdGroupCount> kDefaultIdBases = default_id_bases();
static_assert(kDefaultIdBases[0] == 0x100 && kDefaultIdBases[1] == 0x0B0 &&
              kDefaultIdBases[2] == 0x600 && kDefaultIdBases[3] == 0x680);

/// Identifiers a group takes from its first one: its last message's offset plus the 16 node ids.
constexpr std::uint32_t id_span(std::size_t group) {
  std::uint32_t span = 0;
  for (const MessageDef& m : kMessages) {
    if (id_group(m.kind) != group) continue;
    const std::uint32_t end = m.base_id - kDefaultIdBases[group] + kNodeIdSpan;
    if (end > span) span = end;
  }
  return span;
}

/// The first identifier of each group in use (IdGroup order).
struct IdBases {
  std::array<std::uint16_t, kIdGroupCount> base = kDefaultIdBases;
  friend constexpr bool operator==(const IdBases&, const IdBases&) = default;
};

constexpr std::uint32_t can_id(MessageId id, std::uint8_t node_id, const IdBases& ids) {
  const MessageDef& m = message(id);
  const std::size_t g = id_group(m.kind);
  return ids.base[g] + (m.base_id - kDefaultIdBases[g]) + node_id;
}

/// The message a standard identifier belongs to, with the groups at `ids`, and its node id;
/// nullptr when unknown.
constexpr const MessageDef* find_message(std::uint32_t can_id, const IdBases& ids,
                                         std::uint8_t* node_id) {
  for (const MessageDef& m : kMessages) {
    const std::size_t g = id_group(m.kind);
    const std::uint32_t first = ids.base[g] + (m.base_id - kDefaultIdBases[g]);
    if (can_id >= first && can_id < first + kNodeIdSpan) {
      if (node_id != nullptr) *node_id = static_cast<std::uint8_t>(can_id - first);
      return &m;
    }
  }
  return nullptr;
}

/// The stock groups' identifier of a message, and the message of a stock identifier.
constexpr std::uint32_t can_id(MessageId id, std::uint8_t node_id) {
  return can_id(id, node_id, IdBases{});
}
constexpr const MessageDef* find_message(std::uint32_t can_id, std::uint8_t* node_id) {
  return find_message(can_id, IdBases{}, node_id);
}

/// Whether group `g` at `ids` takes any identifier of [first, last].
constexpr bool id_group_overlaps(const IdBases& ids, std::size_t g, std::uint32_t first,
                                 std::uint32_t last) {
  return ids.base[g] <= last && first < ids.base[g] + id_span(g);
}

/// Whether the groups at `ids` fit the 11-bit identifier and do not overlap each other.
constexpr bool id_bases_valid(const IdBases& ids) {
  for (std::size_t g = 0; g < kIdGroupCount; ++g) {
    if (ids.base[g] + id_span(g) > 0x800) return false;
    for (std::size_t h = g + 1; h < kIdGroupCount; ++h) {
      if (ids.base[g] < ids.base[h] + id_span(h) && ids.base[h] < ids.base[g] + id_span(g)) {
        return false;
      }
    }
  }
  return true;
}
static_assert(id_bases_valid(IdBases{}));

/// Index of a signal by name within a message (kNoSignal when absent).
inline constexpr std::size_t kNoSignal = static_cast<std::size_t>(-1);
constexpr std::size_t signal_index(const MessageDef& m, std::string_view name) {
  for (std::size_t i = 0; i < m.signals.size(); ++i) {
    if (m.signals[i].name == name) return i;
  }
  return kNoSignal;
}

inline constexpr std::size_t kMaxSignalsPerMessage = 39;

}  // namespace gfins::can
