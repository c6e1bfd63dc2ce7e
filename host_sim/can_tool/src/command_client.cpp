#include "command_client.hpp"

#include <cstdio>

namespace gfins::can_tool {
namespace {

using Clock = std::chrono::steady_clock;

std::string describe_status(const can::Command& c, const can::ResponseFrame& r) {
  char buf[200];
  std::snprintf(buf, sizeof buf, "%s (token %u): %s, value %u", can::to_string(c.opcode), r.token,
                can::to_string(r.result), r.value);
  return buf;
}

}  // namespace

CommandOutcome run_command(hal::CanBus& bus, const can::Command& c, std::uint8_t node_id,
                           const CommandTimeouts& t) {
  CommandOutcome out;
  const hal::CanFrame f = can::encode_command(c, node_id);
  const Status sent = bus.send(f);
  if (!sent.is_ok()) {
    out.kind = CommandOutcome::Kind::kSendFailed;
    out.text = std::string("send failed: ") + sent.message();
    return out;
  }
  auto deadline = Clock::now() + t.response;
  bool accepted = false;  // StartCapture: the status frame arrived, now waiting for the result
  can::CaptureAssembler capture;
  while (true) {
    bus.service();
    const auto left = deadline - Clock::now();
    if (left <= Clock::duration::zero()) break;
    const Result<hal::CanFrame> rx =
        bus.receive(std::chrono::duration_cast<std::chrono::nanoseconds>(left).count());
    if (!rx.is_ok()) continue;  // timeout slices and transient errors: loop checks the deadline
    const Result<can::ResponseFrame> r = can::decode_response(*rx);
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
      capture.add(*r);
      if (capture.done()) {
        out.capture = capture.result();
        out.capture_complete = capture.complete();
        out.kind = CommandOutcome::Kind::kOk;
        out.text = out.capture_complete ? "ok: capture complete"
                                        : "ok: capture done, but some channel frames are missing";
        return out;
      }
    }
  }
  out.kind = CommandOutcome::Kind::kTimeout;
  out.text = std::string("timeout: no ") + (accepted ? "capture result" : "response") + " to " +
             can::to_string(c.opcode);
  return out;
}

}  // namespace gfins::can_tool
