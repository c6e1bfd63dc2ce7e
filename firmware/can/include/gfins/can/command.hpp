// Command codec (GfinsCommand / GfinsResponse of message_table.hpp): the firmware decodes
// commands and encodes responses; the host encodes commands and decodes responses. Every
// malformed or out-of-range command decodes to a typed error that the firmware answers with an
// error response, changing nothing. No heap, no exceptions.
#pragma once

#include <array>
#include <cstdint>

#include "gfins/can/message_table.hpp"
#include "gfins/hal/can_bus.hpp"
#include "gfins/nav_core/compensator.hpp"
#include "gfins/status/status.hpp"

namespace gfins::can {

enum class Opcode : std::uint8_t {
  kRealign = kOpRealign,                  // re-align with the given heading
  kResetNavigation = kOpResetNavigation,  // restart alignment and integration
  kSetCompensator = kOpSetCompensator,    // switch compensator
  kSetDivider = kOpSetDivider,            // set the output divider of a message
  kReportCalibrationId = kOpReportCalibrationId,
  kStartCapture = kOpStartCapture,            // calibration capture for pose k with N samples
  kReloadCalibration = kOpReloadCalibration,  // reload the calibration file
  kSetNodeId = kOpSetNodeId,                  // the node id of the next start (stored)
  kRestoreDefaults = kOpRestoreDefaults,      // forget the stored CAN settings
  kSetIdBase = kOpSetIdBase,                  // an identifier group's base of the next start
};

/// The opcodes that change the board's state or settings carry a sequence number (Command::
/// sequence) that must exceed the last one the board took in this session.
constexpr bool carries_sequence(Opcode op) {
  return op != Opcode::kReportCalibrationId && op != Opcode::kStartCapture;
}

/// Result byte of a response (VAL_ table "Result" in the DBC).
enum class ResultCode : std::uint8_t {
  kOk = 0,
  kUnknownOpcode = 1,
  kBadLength = 2,
  kBadCrc = 3,
  kOutOfRange = 4,
  kMalformed = 5,  // bits the opcode does not use are not zero
  kBusy = 6,       // e.g. a capture is already running
  kFailed = 7,     // valid command, execution failed (e.g. calibration file unreadable)
  // 8 was "NotReady" in the first drafts of the ICD; no command depends on the mode (every one
  // is valid while aligning or navigating), so it is not a result the board gives.
  kMoving = 9,        // re-align or reset refused: the board is moving (send it forced to insist)
  kBusLoad = 10,      // SetDivider refused: the worst-case bus load would exceed the board's budget
  kReplayed = 11,     // the sequence number is not above the last one taken (Value = that one)
  kOtherDevice = 12,  // ReloadCalibration refused: the file is another board's (send it forced)
};

const char* to_string(ResultCode r);
const char* to_string(Opcode op);

struct Command {
  Opcode opcode = Opcode::kResetNavigation;
  std::uint8_t token = 0;                                          // echoed in the response
  float heading_rad = 0.0f;                                        // kRealign
  nav::CompensatorKind compensator = nav::CompensatorKind::kNone;  // kSetCompensator
  MessageId message = MessageId::kEpoch;                           // kSetDivider
  std::uint16_t divider = 0;                                       // kSetDivider, 0 = off
  std::uint8_t pose = 0;                                           // kStartCapture: k
  std::uint16_t samples = 0;                                       // kStartCapture: N >= 1
  bool forced = false;         // kRealign, kResetNavigation: carry it out even while moving;
                               // kReloadCalibration: take another board's file
  std::uint16_t sequence = 0;  // carries_sequence(opcode): 1..65535, above the last one taken
  std::uint8_t node_id = 0;    // kSetNodeId: 0..kMaxNodeId
  IdGroup id_group = IdGroup::kData;  // kSetIdBase: the group
  std::uint16_t id_base = 0;          // kSetIdBase: its first identifier, 0..0x7FF
};

struct CommandError {
  ResultCode code = ResultCode::kOk;
  std::uint8_t opcode = 0;  // raw opcode byte (0 when the frame had none)
  std::uint8_t token = 0;
  const char* message = "";  // static text naming what is wrong
};

/// What decode_command made of a frame. `addressed` is false for frames that are not a command to
/// this node (other identifier, extended identifier): ignore them, no response. Otherwise either
/// ok() and `command` is valid, or `error` says why, and the firmware answers
/// error_response(error).
struct DecodedCommand {
  bool addressed = false;
  Command command;
  CommandError error;
  bool ok() const { return addressed && error.code == ResultCode::kOk; }
};

DecodedCommand decode_command(const hal::CanFrame& f, std::uint8_t node_id,
                              const IdBases& ids = {});

/// Host side: a command frame (table-driven, CRC sealed). Arguments beyond their signal's range
/// are written as given (raw bits) so tests can produce out-of-range commands.
hal::CanFrame encode_command(const Command& c, std::uint8_t node_id, const IdBases& ids = {});

// ---------------------------------------------------------------------------------------------
// Responses

struct Response {
  std::uint8_t opcode = 0;  // of the command answered (raw, also when unknown)
  std::uint8_t token = 0;
  ResultCode result = ResultCode::kOk;
  std::uint32_t value = 0;  // 24 bits: new divider, accepted N, ...
};

/// Part 0 (status) response frame.
hal::CanFrame encode_response(const Response& r, std::uint8_t node_id, const IdBases& ids = {});
/// The response to a malformed command.
inline Response error_response(const CommandError& e) {
  return Response{e.opcode, e.token, e.code, 0};
}
/// Part 1: the answer to ReportCalibrationId.
hal::CanFrame encode_calibration_id_response(std::uint8_t token, std::uint32_t cal_id,
                                             std::uint8_t node_id, const IdBases& ids = {});

struct ChannelCapture {
  float mean_counts = 0.0f;  // mean ADC code
  float std_counts = 0.0f;   // standard deviation, ADC codes
  std::uint16_t count = 0;   // samples used
  bool saturated = false;    // reached full scale during the capture
  bool motion = false;       // varied more than a static pose allows
};

struct CaptureResult {
  std::uint8_t pose = 0;
  std::uint16_t samples = 0;
  std::array<ChannelCapture, 6> channels{};
  /// A channel's spread says the board moved: the pose was not static.
  bool motion() const {
    for (const ChannelCapture& c : channels) {
      if (c.motion) return true;
    }
    return false;
  }
};

/// A finished capture: 6 mean, 6 std, 6 count/flag frames, then the CaptureDone frame (the host
/// treats CaptureDone as the end of the result).
inline constexpr std::size_t kCaptureResultFrames = 19;
std::array<hal::CanFrame, kCaptureResultFrames> encode_capture_result(const CaptureResult& r,
                                                                      std::uint8_t token,
                                                                      std::uint8_t node_id,
                                                                      const IdBases& ids = {});

/// One decoded response frame (host side).
struct ResponseFrame {
  std::uint8_t node_id = 0;
  std::uint8_t opcode = 0;
  std::uint8_t token = 0;
  std::uint8_t part = 0;
  ResultCode result = ResultCode::kOk;  // part 0
  std::uint32_t value = 0;              // part 0
  std::uint32_t cal_id = 0;             // part 1
  std::uint8_t pose = 0;                // part 2
  std::uint16_t samples = 0;            // part 2
  std::uint8_t channel = 0;             // parts 0x10.. 0x35
  double mean_counts = 0.0;
  double std_counts = 0.0;
  std::uint16_t count = 0;
  bool saturated = false;
  bool motion = false;
};

/// kInvalidArgument: not a response identifier; kDataLoss: wrong length or CRC; kOutOfRange:
/// unknown part.
Result<ResponseFrame> decode_response(const hal::CanFrame& f, const IdBases& ids = {});

/// Collects the frames of a capture result (host side).
class CaptureAssembler {
 public:
  void reset() { *this = CaptureAssembler(); }
  /// Adds one decoded frame; frames of other parts are ignored.
  void add(const ResponseFrame& r);
  /// True once CaptureDone arrived.
  bool done() const { return done_; }
  /// True when every channel's mean, std and count frames arrived as well.
  bool complete() const { return done_ && seen_mask_ == kAllParts; }
  const CaptureResult& result() const { return result_; }

 private:
  static constexpr std::uint32_t kAllParts = (1u << 18) - 1;
  CaptureResult result_{};
  std::uint32_t seen_mask_ = 0;
  bool done_ = false;
};

}  // namespace gfins::can
