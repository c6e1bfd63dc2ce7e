// gfins-can cmd: send one command on a bus and wait for its response frame(s) with a timeout.
#pragma once

#include <chrono>
#include <optional>
#include <string>

#include "gfins/can/command.hpp"
#include "gfins/hal/can_bus.hpp"

namespace gfins::can_tool {

struct CommandOutcome {
  // kIncomplete: StartCapture's CaptureDone arrived but some channel frames did not; `text`
  // names them and `capture` must not be used (the missing fields are not measurements).
  enum class Kind { kOk, kRejected, kTimeout, kSendFailed, kIncomplete } kind = Kind::kTimeout;
  can::ResponseFrame status;                  // the status frame (or the calibration id frame)
  std::optional<std::uint32_t> status_value;  // Value of the status frame, when one came
  can::CaptureResult capture;                 // StartCapture: the collected result
  bool capture_complete = false;
  std::string text;  // one-paragraph human-readable outcome
};

struct CommandTimeouts {
  std::chrono::milliseconds response{1000};  // until the first response frame
  std::chrono::milliseconds capture{0};      // StartCapture: until CaptureDone (0: N/rate + 5 s)
  double sample_rate_hz = 1000.0;            // to size the capture timeout
};

/// Sends `c` to `node_id` and waits. Frames from other nodes, other tokens and data frames are
/// skipped. Waiting uses the bus's receive timeout and a steady clock. `ids`: the board's
/// identifier groups (docs/can-interface.md, "Identifiers").
CommandOutcome run_command(hal::CanBus& bus, const can::Command& c, std::uint8_t node_id,
                           const CommandTimeouts& t, const can::IdBases& ids = {});

/// run_command for a command with a sequence number the sender does not track
/// (docs/can-interface.md, "Sequence numbers"): asks the board for the last number it took
/// (ReportCalibrationId's status Value, token c.token - 1) and sends c with the next; should
/// another host have taken that one meanwhile (Replayed), sends once more with the number after
/// the one the board reported (and the next token). `note` receives a line saying what was done.
/// Commands without a sequence number go as they are.
CommandOutcome run_command_next_sequence(hal::CanBus& bus, can::Command c, std::uint8_t node_id,
                                         const CommandTimeouts& t, std::string* note,
                                         const can::IdBases& ids = {});

}  // namespace gfins::can_tool
