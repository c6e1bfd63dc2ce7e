// gfins-can cmd against an in-process board: each command gets its response; an error response
// is reported as a rejection; no board means a timeout.
#include "command_client.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <deque>
#include <vector>

#include "gfins/can/signal_codec.hpp"

namespace gfins::can_tool {
namespace {

constexpr std::uint8_t kNode = 4;

/// A bus with a board behind it: every command frame sent is decoded as the firmware would and
/// answered (status, calibration id, capture result), plus unrelated traffic in between.
class BoardBus final : public hal::CanBus {
 public:
  bool answer = true;
  int sent = 0;
  // The board's replay rule (docs/can-interface.md, "Sequence numbers"), written from the ICD:
  // a configuration-changing command must carry a number above the last one taken.
  std::uint16_t last_sequence = 0;
  // Another host that takes the next number right after the board answered a query.
  bool race = false;
  // Capture result parts (docs/can-interface.md, "Response parts") the bus loses.
  std::vector<std::uint8_t> lose_parts;

 private:
  Status do_send(const hal::CanFrame& f) override {
    ++sent;
    if (!answer) return Status::ok();
    // Unrelated traffic first: a data frame and a response with another token.
    hal::CanFrame noise;
    noise.id = 0x140 + kNode;
    noise.len = 8;
    can::seal_frame(noise);
    rx_.push_back(noise);
    rx_.push_back(
        can::encode_response(can::Response{f.data[0], static_cast<std::uint8_t>(f.data[1] + 1),
                                           can::ResultCode::kFailed, 0},
                             kNode));
    const can::DecodedCommand d = can::decode_command(f, kNode);
    if (!d.addressed) return Status::ok();
    if (!d.ok()) {
      rx_.push_back(can::encode_response(can::error_response(d.error), kNode));
      return Status::ok();
    }
    const can::Command& c = d.command;
    const auto op = static_cast<std::uint8_t>(c.opcode);
    const bool numbered =
        c.opcode != can::Opcode::kReportCalibrationId && c.opcode != can::Opcode::kStartCapture;
    if (numbered && c.sequence <= last_sequence) {
      rx_.push_back(can::encode_response(
          {op, c.token, static_cast<can::ResultCode>(11), last_sequence}, kNode));
      return Status::ok();
    }
    if (numbered) last_sequence = c.sequence;
    switch (c.opcode) {
      case can::Opcode::kReportCalibrationId:
        // Status part first, Value = the last sequence number taken (docs/can-interface.md),
        // then the calibration id.
        rx_.push_back(
            can::encode_response({op, c.token, can::ResultCode::kOk, last_sequence}, kNode));
        rx_.push_back(can::encode_calibration_id_response(c.token, 0x1234ABCD, kNode));
        if (race) last_sequence = static_cast<std::uint16_t>(last_sequence + 1);
        break;
      case can::Opcode::kStartCapture: {
        rx_.push_back(can::encode_response({op, c.token, can::ResultCode::kOk, c.samples}, kNode));
        can::CaptureResult r;
        r.pose = c.pose;
        r.samples = c.samples;
        for (std::size_t k = 0; k < 6; ++k) {
          r.channels[k] = {100.0f * static_cast<float>(k), 2.0f, c.samples, false, k == 1};
        }
        for (const auto& fr : can::encode_capture_result(r, c.token, kNode)) {
          // byte 2 of a response is its Part (docs/can-interface.md, GfinsResponse)
          if (std::find(lose_parts.begin(), lose_parts.end(), fr.data[2]) == lose_parts.end()) {
            rx_.push_back(fr);
          }
        }
        break;
      }
      case can::Opcode::kReloadCalibration:
        // The firmware answers a reload with the status frame, then the new calibration id
        // (SampleLoop::send_response in firmware/app, docs/can-interface.md).
        rx_.push_back(can::encode_response({op, c.token, can::ResultCode::kOk, 0}, kNode));
        rx_.push_back(can::encode_calibration_id_response(c.token, 0x0BADCAFE, kNode));
        break;
      default:
        rx_.push_back(can::encode_response({op, c.token, can::ResultCode::kOk, c.divider}, kNode));
    }
    return Status::ok();
  }
  Result<hal::CanFrame> do_receive(std::int64_t) override {
    if (rx_.empty()) return Status(ErrorCode::kTimeout, "no frame");
    const hal::CanFrame f = rx_.front();
    rx_.pop_front();
    return f;
  }
  hal::CanBusState do_state() const override { return hal::CanBusState::kErrorActive; }
  hal::CanCounters do_counters() const override { return {}; }
  std::deque<hal::CanFrame> rx_;
};

CommandTimeouts short_timeouts() {
  CommandTimeouts t;
  t.response = std::chrono::milliseconds(50);
  t.capture = std::chrono::milliseconds(50);
  return t;
}

TEST(CommandClient, EveryCommandGetsItsResponse) {
  BoardBus bus;
  for (can::Opcode op :
       {can::Opcode::kRealign, can::Opcode::kResetNavigation, can::Opcode::kSetCompensator,
        can::Opcode::kSetDivider, can::Opcode::kReloadCalibration}) {
    can::Command c;
    c.opcode = op;
    c.token = 10;
    c.message = can::MessageId::kEuler;
    c.divider = 40;
    c.sequence = static_cast<std::uint16_t>(bus.last_sequence + 1);
    const CommandOutcome r = run_command(bus, c, kNode, short_timeouts());
    EXPECT_EQ(r.kind, CommandOutcome::Kind::kOk) << r.text;
    EXPECT_EQ(r.status.token, 10);
  }
}

// gfins-can cmd without --sequence: the board's last number is read first (ReportCalibrationId's
// status Value) and the command sent with the next, so no frame is refused as a replay; should
// another host take that number in between, the command goes once more with the next.
TEST(CommandClient, WithoutASequenceTheClientAsksTheBoardForItsLastNumber) {
  BoardBus bus;
  bus.last_sequence = 41;
  can::Command c;
  c.opcode = can::Opcode::kSetCompensator;
  c.token = 20;
  std::string note;
  CommandOutcome r = run_command_next_sequence(bus, c, kNode, short_timeouts(), &note);
  EXPECT_EQ(r.kind, CommandOutcome::Kind::kOk) << r.text;
  EXPECT_EQ(r.status.token, 20);
  EXPECT_EQ(bus.last_sequence, 42);
  EXPECT_EQ(bus.sent, 2) << "the query and the command";
  EXPECT_NE(note.find("sequence number 42 (the board's last was 41)"), std::string::npos) << note;
  // Another host took 42 meanwhile: Replayed, then 43 with the next token.
  BoardBus raced;
  raced.last_sequence = 41;
  raced.race = true;
  r = run_command_next_sequence(raced, c, kNode, short_timeouts(), &note);
  EXPECT_EQ(r.kind, CommandOutcome::Kind::kOk) << r.text;
  EXPECT_EQ(r.status.token, 21);
  EXPECT_EQ(raced.last_sequence, 43);
  EXPECT_EQ(raced.sent, 3);
  // A board at the last number: nothing is sent after the query, and the text says why.
  BoardBus full;
  full.last_sequence = 65535;
  r = run_command_next_sequence(full, c, kNode, short_timeouts(), &note);
  EXPECT_EQ(r.kind, CommandOutcome::Kind::kRejected);
  EXPECT_EQ(full.sent, 1);
  EXPECT_NE(r.text.find("restart"), std::string::npos) << r.text;
  // A command without a number goes as it is.
  BoardBus quiet;
  can::Command id;
  id.opcode = can::Opcode::kReportCalibrationId;
  r = run_command_next_sequence(quiet, id, kNode, short_timeouts(), &note);
  EXPECT_EQ(r.kind, CommandOutcome::Kind::kOk) << r.text;
  EXPECT_EQ(quiet.sent, 1);
  // No board: the query times out and nothing else is sent.
  BoardBus silent;
  silent.answer = false;
  r = run_command_next_sequence(silent, c, kNode, short_timeouts(), &note);
  EXPECT_NE(r.kind, CommandOutcome::Kind::kOk);
  EXPECT_EQ(silent.sent, 1);
}

TEST(CommandClient, CalibrationIdAndCapture) {
  BoardBus bus;
  can::Command c;
  c.opcode = can::Opcode::kReportCalibrationId;
  c.token = 1;
  CommandOutcome r = run_command(bus, c, kNode, short_timeouts());
  EXPECT_EQ(r.kind, CommandOutcome::Kind::kOk);
  EXPECT_EQ(r.status.cal_id, 0x1234ABCDu);
  EXPECT_NE(r.text.find("0x1234ABCD"), std::string::npos);
  c.opcode = can::Opcode::kStartCapture;
  c.pose = 9;
  c.samples = 300;
  r = run_command(bus, c, kNode, short_timeouts());
  EXPECT_EQ(r.kind, CommandOutcome::Kind::kOk) << r.text;
  ASSERT_TRUE(r.capture_complete);
  EXPECT_EQ(r.capture.pose, 9);
  EXPECT_EQ(r.capture.channels[5].mean_counts, 500.0f);
  EXPECT_TRUE(r.capture.channels[1].motion);
}

TEST(CommandClient, ACaptureWithLostResultFramesIsIncompleteNamingThem) {
  // Given a bus that loses the mean frame of channel 2 (part 0x11) and the count frame of
  // channel 6 (part 0x35) of a capture result
  BoardBus bus;
  bus.lose_parts = {0x11, 0x35};
  can::Command c;
  c.opcode = can::Opcode::kStartCapture;
  c.token = 7;
  c.pose = 4;
  c.samples = 300;
  // When the capture is run
  const CommandOutcome r = run_command(bus, c, kNode, short_timeouts());
  // Then it is not an "ok" with zeros in place of the lost statistics: it is incomplete, and
  // the message names exactly what is missing.
  EXPECT_EQ(r.kind, CommandOutcome::Kind::kIncomplete) << r.text;
  EXPECT_FALSE(r.capture_complete);
  EXPECT_EQ(r.text.rfind("incomplete:", 0), 0u) << r.text;
  EXPECT_NE(r.text.find("mean of a2, count of a6 "), std::string::npos) << r.text;
  EXPECT_EQ(r.text.find("of a1"), std::string::npos) << r.text;
}

TEST(CommandClient, OutOfRangeCommandIsRejected) {
  BoardBus bus;
  can::Command c;
  c.opcode = can::Opcode::kStartCapture;
  c.token = 3;
  c.pose = 200;  // beyond 63: the board answers OutOfRange
  c.samples = 10;
  const CommandOutcome r = run_command(bus, c, kNode, short_timeouts());
  EXPECT_EQ(r.kind, CommandOutcome::Kind::kRejected);
  EXPECT_EQ(r.status.result, can::ResultCode::kOutOfRange);
  EXPECT_NE(r.text.find("OutOfRange"), std::string::npos);
}

TEST(CommandClient, NoBoardTimesOut) {
  BoardBus bus;
  bus.answer = false;
  const CommandOutcome r = run_command(bus, can::Command{}, kNode, short_timeouts());
  EXPECT_EQ(r.kind, CommandOutcome::Kind::kTimeout);
  EXPECT_EQ(bus.sent, 1);
}

}  // namespace
}  // namespace gfins::can_tool
