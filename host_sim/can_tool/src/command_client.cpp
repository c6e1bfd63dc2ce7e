#include "command_client.hpp"

#include <array>
#include <cstdio>
#include <string>

namespace gfins::can_tool {
namespace {

using Clock = std::chrono::steady_clock;

std::string describe_status(const can::Command& c, const can::ResponseFrame& r) {
  char buf[200];
  std::snprintf(buf, sizeof buf, "%s (token %u): %s, value %u", can::to_string(c.opcode), r.token,
                can::to_string(r.result), r.value);
  return buf;
}

// The capture's per-channel result frames: mean, std, count for each of the 6 channels.
constexpr std::size_t kChannelParts = std::size_t{3} * 6;

// Capture result parts (docs/can-interface.md, "Response parts"): 0x10 + c mean, 0x20 + c
// standard deviation, 0x30 + c count and flags of channel c + 1.
constexpr std::uint8_t kFirstChannelPart = 0x10;
constexpr std::uint8_t kLastChannelPart = 0x35;

/// The capture frames that did not arrive, e.g. "mean of a2, count of a6"; empty when none.
std::string missing_capture_parts(const std::array<bool, kChannelParts>& seen) {
  static constexpr const char* kWhat[3] = {"mean", "std", "count"};
  std::string out;
  for (std::size_t g = 0; g < 3; ++g) {
    for (std::size_t ch = 0; ch < 6; ++ch) {
      if (seen[g * 6 + ch]) continue;
      out += (out.empty() ? "" : ", ") + std::string(kWhat[g]) + " of a" + std::to_string(ch + 1);
    }
  }
  return out;
}

}  // namespace

CommandOutcome run_command(hal::CanBus& bus, const can::Command& c, std::uint8_t node_id,
                           const CommandTimeouts& t, const can::IdBases& ids) {
  CommandOutcome out;
  const hal::CanFrame f = can::encode_command(c, node_id, ids);
  const Status sent = bus.send(f);
  if (!sent.is_ok()) {
    out.kind = CommandOutcome::Kind::kSendFailed;
    out.text = std::string("send failed: ") + sent.message();
    return out;
  }
  auto deadline = Clock::now() + t.response;
  bool accepted = false;  // StartCapture: the status frame arrived, now waiting for the result
  can::CaptureAssembler capture;
  std::array<bool, kChannelParts> seen_parts{};  // mean, std, count of each channel
  while (true) {
    bus.service();
    const auto left = deadline - Clock::now();
    if (left <= Clock::duration::zero()) break;
    const Result<hal::CanFrame> rx =
        bus.receive(std::chrono::duration_cast<std::chrono::nanoseconds>(left).count());
    if (!rx.is_ok()) continue;  // timeout slices and transient errors: loop checks the deadline
    const Result<can::ResponseFrame> r = can::decode_response(*rx, ids);
    // The calibration id frame always carries the ReportCalibrationId opcode, also when it
    // follows a reload (firmware/can command.cpp, encode_calibration_id_response).
    const bool id_after_reload = r.is_ok() && c.opcode == can::Opcode::kReloadCalibration &&
                                 r->part == can::kPartCalibrationId &&
                                 r->opcode == can::kOpReportCalibrationId;
    if (!r.is_ok() || r->node_id != node_id || r->token != c.token ||
        (r->opcode != static_cast<std::uint8_t>(c.opcode) && !id_after_reload)) {
      continue;
    }
    if (r->part == can::kPartStatus) {
      out.status = *r;
      out.status_value = r->value;
      if (r->result != can::ResultCode::kOk) {
        out.kind = CommandOutcome::Kind::kRejected;
        out.text = "rejected: " + describe_status(c, *r);
        return out;
      }
      if (c.opcode == can::Opcode::kStartCapture && !accepted) {
        accepted = true;
        const auto capture_wait =
            t.capture.count() > 0
                ? std::chrono::duration_cast<Clock::duration>(t.capture)
                : std::chrono::duration_cast<Clock::duration>(
                      std::chrono::duration<double>(c.samples / t.sample_rate_hz + 5.0));
        deadline = Clock::now() + capture_wait;
        continue;
      }
      // ReportCalibrationId and ReloadCalibration are answered with a status frame and then the
      // calibration id frame (docs/can-interface.md): wait for the id.
      if (c.opcode != can::Opcode::kReportCalibrationId &&
          c.opcode != can::Opcode::kReloadCalibration && c.opcode != can::Opcode::kStartCapture) {
        out.kind = CommandOutcome::Kind::kOk;
        out.text = "ok: " + describe_status(c, *r);
        return out;
      }
    } else if (r->part == can::kPartCalibrationId) {
      out.status = *r;
      out.kind = CommandOutcome::Kind::kOk;
      char buf[96];
      std::snprintf(buf, sizeof buf, "ok: %scalibration id 0x%08X",
                    c.opcode == can::Opcode::kReloadCalibration ? "reloaded, " : "", r->cal_id);
      out.text = buf;
      return out;
    } else {
      if (r->part >= kFirstChannelPart && r->part <= kLastChannelPart && (r->part & 0x0Fu) < 6) {
        const std::size_t group = static_cast<std::size_t>((r->part >> 4) - 1);
        seen_parts[group * 6 + (r->part & 0x0Fu)] = true;
      }
      capture.add(*r);
      if (capture.done()) {
        out.capture = capture.result();
        out.capture_complete = capture.complete();
        if (out.capture_complete) {
          out.kind = CommandOutcome::Kind::kOk;
          out.text = "ok: capture complete";
        } else {
          out.kind = CommandOutcome::Kind::kIncomplete;
          out.text =
              "incomplete: capture of pose " + std::to_string(out.capture.pose) +
              " done, but these result frames never arrived: " + missing_capture_parts(seen_parts) +
              " (frames lost on the bus; repeat the capture)";
        }
        return out;
      }
    }
  }
  out.kind = CommandOutcome::Kind::kTimeout;
  out.text = std::string("timeout: no ") + (accepted ? "capture result" : "response") + " to " +
             can::to_string(c.opcode);
  return out;
}

CommandOutcome run_command_next_sequence(hal::CanBus& bus, can::Command c, std::uint8_t node_id,
                                         const CommandTimeouts& t, std::string* note,
                                         const can::IdBases& ids) {
  if (!can::carries_sequence(c.opcode)) return run_command(bus, c, node_id, t, ids);
  can::Command ask;
  ask.opcode = can::Opcode::kReportCalibrationId;
  ask.token = static_cast<std::uint8_t>(c.token - 1);
  CommandOutcome asked = run_command(bus, ask, node_id, t, ids);
  if (asked.kind != CommandOutcome::Kind::kOk || !asked.status_value) {
    asked.text = "could not read the board's last sequence number: " + asked.text;
    if (asked.kind == CommandOutcome::Kind::kOk) asked.kind = CommandOutcome::Kind::kTimeout;
    return asked;
  }
  const auto max_sequence = static_cast<std::uint32_t>(can::kMaxSequence);
  std::uint32_t last = *asked.status_value;
  for (int attempt = 0; attempt < 2; ++attempt) {
    if (last >= max_sequence) {
      CommandOutcome full;
      full.kind = CommandOutcome::Kind::kRejected;
      full.text = "not sent: the board has taken sequence number " + std::to_string(last) +
                  ", the last of its session; restart it to send configuration-changing commands";
      return full;
    }
    c.sequence = static_cast<std::uint16_t>(last + 1);
    if (note != nullptr) {
      *note = "sequence number " + std::to_string(c.sequence) + " (the board's last was " +
              std::to_string(last) + ")";
    }
    CommandOutcome out = run_command(bus, c, node_id, t, ids);
    // Another host took the number in between: once more with the one after the board's.
    if (attempt > 0 || out.kind != CommandOutcome::Kind::kRejected ||
        out.status.result != can::ResultCode::kReplayed || !out.status_value) {
      return out;
    }
    last = *out.status_value;
    c.token = static_cast<std::uint8_t>(c.token + 1);
  }
  return {};  // not reached: the second attempt returns
}

}  // namespace gfins::can_tool
