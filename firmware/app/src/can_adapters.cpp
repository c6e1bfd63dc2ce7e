#include "gfins/app/can_adapters.hpp"

#include <algorithm>

#include <cmath>

#include "gfins/app/sample_loop.hpp"
#include "gfins/can/command.hpp"

namespace gfins::app {

static_assert(kNumMessages == static_cast<std::size_t>(can::MessageId::kCommand),
              "[output] names one divider per data message of the CAN table, in its order");
static_assert(status_bits::kAligned == can::status_bits::kAligned &&
                  status_bits::kSampleGap == can::status_bits::kSampleGap &&
                  status_bits::kInputInvalid == can::status_bits::kInputInvalid &&
                  status_bits::kCompensated == can::status_bits::kCompensated &&
                  status_bits::kCrcError == can::status_bits::kAdcCrcError &&
                  status_bits::kSaturated == can::status_bits::kAdcSaturated &&
                  status_bits::kStuckChannel == can::status_bits::kAdcChannelStuck &&
                  status_bits::kUncalibrated == can::status_bits::kNominalCalibration &&
                  status_bits::kLoopOverrun == can::status_bits::kLoopOverrun &&
                  status_bits::kCanTxDrop == can::status_bits::kCanTxDropped &&
                  status_bits::kCaptureActive == can::status_bits::kCaptureActive &&
                  status_bits::kDegraded == can::status_bits::kHealthDegraded,
              "the firmware's status bits are the CAN status frame's");
static_assert(status_bits::kExtraEdge < can::status_bits::kAllBits,
              "the firmware's own bits fit the 20-bit StatusFlags field");
static_assert(static_cast<int>(CommandKind::kRealign) == can::kOpRealign &&
                  static_cast<int>(CommandKind::kResetNavigation) == can::kOpResetNavigation &&
                  static_cast<int>(CommandKind::kSetCompensator) == can::kOpSetCompensator &&
                  static_cast<int>(CommandKind::kSetDivider) == can::kOpSetDivider &&
                  static_cast<int>(CommandKind::kReportCalibration) ==
                      can::kOpReportCalibrationId &&
                  static_cast<int>(CommandKind::kCaptureCalibration) == can::kOpStartCapture &&
                  static_cast<int>(CommandKind::kReloadCalibration) == can::kOpReloadCalibration,
              "command kinds are the CAN opcodes");
static_assert(
    static_cast<int>(CommandResult::kFailed) == static_cast<int>(can::ResultCode::kFailed) &&
        static_cast<int>(CommandResult::kBusy) == static_cast<int>(can::ResultCode::kBusy) &&
        static_cast<int>(CommandResult::kMoving) == static_cast<int>(can::ResultCode::kMoving),
    "command results are the CAN result codes");
static_assert(kMaxPose == can::kMaxCapturePose, "one pose range");
static_assert(kMaxNodeId == can::kMaxNodeId, "one node id range");

can::Epoch to_can_epoch(const Epoch& e) {
  can::Epoch c;
  c.nav = e.nav;
  c.accel_mps2 = e.accel_mps2;
  switch (e.mode) {
    case Mode::kStartup:
      c.mode = static_cast<std::uint8_t>(can::Mode::kStartup);
      break;
    case Mode::kAligning:
      c.mode = static_cast<std::uint8_t>(can::Mode::kAligning);
      break;
    case Mode::kNavigating:
    case Mode::kDegraded:  // the HealthDegraded bit says which
      c.mode = static_cast<std::uint8_t>(can::Mode::kNavigating);
      break;
  }
  if ((e.status_bits & status_bits::kCaptureActive) != 0 && e.mode != Mode::kAligning) {
    c.mode = static_cast<std::uint8_t>(can::Mode::kCalibrating);
  }
  c.status_bits = e.status_bits & can::status_bits::kAllBits;
  c.cal_id = e.cal_id;
  c.health.missed_drdy_edges = e.health.missed_edges;
  c.health.adc_crc_errors = e.health.crc_errors;
  c.health.adc_resets = e.health.adc_resets;
  c.health.saturated_samples = e.health.saturated_samples;
  c.health.stuck_channel_mask = e.health.stuck_mask;
  c.health.can_tx_dropped = e.health.can_tx_dropped;
  c.health.bus_off_events = e.health.bus_off_events;
  c.health.loop_overruns = e.health.loop_overruns;
  c.health.log_dropped = e.health.log_dropped;
  c.valid = e.valid;
  c.accuracy = e.accuracy;
  return c;
}

can::Dividers to_can_dividers(const FwConfig& c) {
  can::Dividers d{};
  for (std::size_t m = 0; m < kNumMessages; ++m) d[m] = c.dividers[m];
  // With aiding on, the filter's accuracy and aiding counters go out at the table's rates
  // (GfinsAccuracy 5 Hz, GfinsAidingCounters 2.5 Hz at 1 kHz), rounded up to a multiple of the
  // epoch divider as every message must be; without a filter they have nothing to say.
  const std::uint32_t epoch = std::max<std::uint32_t>(c.dividers[0], 1);
  for (const can::MessageId id : {can::MessageId::kAccuracy, can::MessageId::kAidingCounters}) {
    const std::uint32_t table = can::message(id).default_divider;
    const std::uint32_t div = (table + epoch - 1) / epoch * epoch;
    d[static_cast<std::size_t>(id)] =
        c.aiding ? static_cast<std::uint16_t>(std::min<std::uint32_t>(div, kMaxDivider)) : 0;
  }
  return d;
}

CanEpochSink::CanEpochSink(hal::CanBus& bus, std::uint8_t node_id, const can::Dividers& dividers)
    : publisher_(bus, can::PublisherConfig{node_id, dividers}) {}

std::uint32_t CanEpochSink::publish(const Epoch& e) {
  const can::PublisherCounters before = publisher_.counters();
  publisher_.publish(to_can_epoch(e));
  const can::PublisherCounters& after = publisher_.counters();
  return (after.frames_sent - before.frames_sent) + (after.send_failures - before.send_failures);
}

Status CanEpochSink::set_divider(std::size_t message, std::uint16_t divider) {
  if (message >= kNumMessages) return Status(ErrorCode::kOutOfRange, "no such data message");
  return publisher_.set_divider(static_cast<can::MessageId>(message), divider);
}

DecodedFrame CanCommandCodec::decode(const hal::CanFrame& f) const {
  const can::DecodedCommand d = can::decode_command(f, node_id_);
  DecodedFrame out;
  out.addressed = d.addressed;
  if (!d.addressed) return out;
  out.ok = d.ok();
  if (!out.ok) {
    out.error = static_cast<CommandResult>(d.error.code);
    out.raw_opcode = d.error.opcode;
    out.token = d.error.token;
    return out;
  }
  const can::Command& c = d.command;
  out.raw_opcode = static_cast<std::uint8_t>(c.opcode);
  out.token = c.token;
  out.command.kind = static_cast<CommandKind>(c.opcode);
  out.command.token = c.token;
  out.command.heading_rad = c.heading_rad;
  out.command.forced = c.forced;
  out.command.compensator = c.compensator;
  out.command.message = static_cast<std::uint8_t>(c.message);
  out.command.divider = c.divider;
  out.command.pose = c.pose;
  out.command.samples = c.samples;
  return out;
}

std::size_t CanCommandCodec::encode(const Response& r,
                                    std::array<hal::CanFrame, 24>& frames) const {
  std::size_t n = 0;
  if (r.has_capture) {
    can::CaptureResult c;
    c.pose = r.capture.pose;
    c.samples = r.capture.samples;
    for (std::size_t j = 0; j < kAdcChannels; ++j) {
      const CaptureChannel& ch = r.capture.channels[j];
      c.channels[j].mean_counts = ch.mean_counts;
      c.channels[j].std_counts = ch.std_counts;
      c.channels[j].count = static_cast<std::uint16_t>(std::min<std::uint32_t>(ch.count, 65535));
      c.channels[j].saturated = ch.saturated;
      c.channels[j].motion = ch.motion;
    }
    const auto capture = can::encode_capture_result(c, r.token, node_id_);
    for (const hal::CanFrame& f : capture) frames[n++] = f;
    return n;
  }
  const can::Response rsp{r.raw_opcode, r.token, static_cast<can::ResultCode>(r.result),
                          r.value & 0xFFFFFFu};
  frames[n++] = can::encode_response(rsp, node_id_);
  if (r.result == CommandResult::kOk &&
      (r.kind == CommandKind::kReportCalibration || r.kind == CommandKind::kReloadCalibration)) {
    frames[n++] = can::encode_calibration_id_response(r.token, r.cal_id, node_id_);
  }
  return n;
}

}  // namespace gfins::app
