// Command codec: every command round-trips; every malformed or out-of-range frame decodes to its
// typed error; responses and the multi-frame capture result round-trip.
#include "gfins/can/command.hpp"

#include <gtest/gtest.h>

#include "gfins/can/signal_codec.hpp"

namespace gfins::can {
namespace {

constexpr std::uint8_t kNode = 2;

// Byte layout of a command written from the ICD: opcode, token, arguments LE from byte 2, CRC.
hal::CanFrame raw_command(std::initializer_list<std::uint8_t> bytes0to6) {
  hal::CanFrame f;
  f.id = 0x600 + kNode;
  f.len = 8;
  std::size_t i = 0;
  for (std::uint8_t b : bytes0to6) f.data[i++] = b;
  seal_frame(f);
  return f;
}

TEST(Command, EveryCommandRoundTrips) {
  std::vector<Command> cmds;
  Command c;
  c.token = 77;
  c.sequence = 4242;
  c.opcode = Opcode::kRealign;
  c.heading_rad = -1.2345f;
  cmds.push_back(c);
  c.opcode = Opcode::kResetNavigation;
  cmds.push_back(c);
  c.opcode = Opcode::kSetCompensator;
  c.compensator = nav::CompensatorKind::kExact;
  cmds.push_back(c);
  c.opcode = Opcode::kSetDivider;
  c.message = MessageId::kSensorsB;
  c.divider = 20;
  cmds.push_back(c);
  c.opcode = Opcode::kReportCalibrationId;
  cmds.push_back(c);
  c.opcode = Opcode::kStartCapture;
  c.pose = 17;
  c.samples = 5000;
  cmds.push_back(c);
  c.opcode = Opcode::kReloadCalibration;
  c.forced = true;
  cmds.push_back(c);
  c.opcode = Opcode::kSetNodeId;
  c.node_id = 15;
  c.forced = false;
  cmds.push_back(c);
  c.opcode = Opcode::kRestoreDefaults;
  cmds.push_back(c);
  c.opcode = Opcode::kSetIdBase;
  c.id_group = IdGroup::kResponse;
  c.id_base = 0x7EF;
  cmds.push_back(c);
  for (const Command& in : cmds) {
    SCOPED_TRACE(to_string(in.opcode));
    const hal::CanFrame f = encode_command(in, kNode);
    EXPECT_EQ(f.id, 0x602u);
    const DecodedCommand d = decode_command(f, kNode);
    ASSERT_TRUE(d.ok()) << d.error.message;
    EXPECT_EQ(d.command.opcode, in.opcode);
    EXPECT_EQ(d.command.token, 77);
    EXPECT_EQ(d.command.sequence, carries_sequence(in.opcode) ? 4242 : 0);
    switch (in.opcode) {
      case Opcode::kRealign:
        EXPECT_NEAR(d.command.heading_rad, -1.2345f, 0.5e-4 + 1e-6);  // half a 1e-4 rad step
        break;
      case Opcode::kSetCompensator:
        EXPECT_EQ(d.command.compensator, nav::CompensatorKind::kExact);
        break;
      case Opcode::kSetDivider:
        EXPECT_EQ(d.command.message, MessageId::kSensorsB);
        EXPECT_EQ(d.command.divider, 20);
        break;
      case Opcode::kStartCapture:
        EXPECT_EQ(d.command.pose, 17);
        EXPECT_EQ(d.command.samples, 5000);
        break;
      case Opcode::kReloadCalibration:
        EXPECT_TRUE(d.command.forced);
        break;
      case Opcode::kSetNodeId:
        EXPECT_EQ(d.command.node_id, 15);
        break;
      case Opcode::kSetIdBase:
        EXPECT_EQ(d.command.id_group, IdGroup::kResponse);
        EXPECT_EQ(d.command.id_base, 0x7EF);
        break;
      default:
        break;
    }
  }
}

TEST(Command, ForcedFlagOfRealignAndResetRoundTripsAtTheIcdBits) {
  // ICD: Realign's RealignForced is bit 32 (byte 4, bit 0) after the heading; ResetNavigation's
  // ResetForced is bit 16 (byte 2, bit 0).
  for (bool forced : {false, true}) {
    SCOPED_TRACE(forced);
    Command c;
    c.opcode = Opcode::kRealign;
    c.heading_rad = 0.5f;
    c.forced = forced;
    c.sequence = 1;
    hal::CanFrame f = encode_command(c, kNode);
    EXPECT_EQ(f.data[4], forced ? 1 : 0);
    DecodedCommand d = decode_command(f, kNode);
    ASSERT_TRUE(d.ok()) << d.error.message;
    EXPECT_EQ(d.command.forced, forced);
    c.opcode = Opcode::kResetNavigation;
    f = encode_command(c, kNode);
    EXPECT_EQ(f.data[2], forced ? 1 : 0);
    d = decode_command(f, kNode);
    ASSERT_TRUE(d.ok()) << d.error.message;
    EXPECT_EQ(d.command.forced, forced);
  }
  // A forced bit on a command that has none is a bit the opcode does not use.
  EXPECT_EQ(decode_command(raw_command({3, 1, 2, 0, 1, 1, 0}), kNode).error.code,
            ResultCode::kMalformed);  // SetCompensator with bit 32 set
  // Bits next to the flag stay reserved.
  EXPECT_EQ(decode_command(raw_command({2, 1, 2, 0, 0, 1, 0}), kNode).error.code,
            ResultCode::kMalformed);  // ResetNavigation with bit 17 set
}

// ICD: the sequence number of a configuration-changing command is a uint16 in bytes 5-6 (bits
// 40..55, little-endian), 1..65535; ReloadCalibration's ReloadForced is bit 16; SetNodeId's
// NodeId byte 2 (0..15). Frames written byte by byte here.
TEST(Command, SequenceNodeIdAndReloadForcedAtTheIcdBits) {
  DecodedCommand d = decode_command(raw_command({3, 9, 2, 0, 0, 0x34, 0x12}), kNode);
  ASSERT_TRUE(d.ok()) << d.error.message;
  EXPECT_EQ(d.command.sequence, 0x1234);
  d = decode_command(raw_command({3, 9, 2, 0, 0, 0xFF, 0xFF}), kNode);
  ASSERT_TRUE(d.ok()) << d.error.message;
  EXPECT_EQ(d.command.sequence, 65535);
  // 0 is below the range: no command can carry it (the board's last number starts at 0).
  EXPECT_EQ(decode_command(raw_command({3, 9, 2, 0, 0, 0, 0}), kNode).error.code,
            ResultCode::kOutOfRange);
  EXPECT_EQ(decode_command(raw_command({9, 9, 0, 0, 0, 0, 0}), kNode).error.code,
            ResultCode::kOutOfRange);  // RestoreDefaults without a number
  // The two commands that change nothing carry none: bytes 5-6 are reserved for them.
  EXPECT_EQ(decode_command(raw_command({5, 9, 0, 0, 0, 1, 0}), kNode).error.code,
            ResultCode::kMalformed);
  d = decode_command(raw_command({7, 9, 1, 0, 0, 2, 0}), kNode);
  ASSERT_TRUE(d.ok()) << d.error.message;
  EXPECT_TRUE(d.command.forced);
  EXPECT_EQ(d.command.sequence, 2);
  d = decode_command(raw_command({8, 9, 15, 0, 0, 3, 0}), kNode);
  ASSERT_TRUE(d.ok()) << d.error.message;
  EXPECT_EQ(d.command.opcode, Opcode::kSetNodeId);
  EXPECT_EQ(d.command.node_id, 15);
  EXPECT_EQ(decode_command(raw_command({8, 9, 16, 0, 0, 3, 0}), kNode).error.code,
            ResultCode::kOutOfRange);  // node id 16
  // The encoder puts them where the ICD says.
  Command c;
  c.opcode = Opcode::kSetNodeId;
  c.node_id = 7;
  c.sequence = 0xBEEF;
  const hal::CanFrame f = encode_command(c, kNode);
  EXPECT_EQ(f.data[2], 7);
  EXPECT_EQ(f.data[5], 0xEF);
  EXPECT_EQ(f.data[6], 0xBE);
}

// ICD: SetIdBase (opcode 10) has IdGroup in byte 2 (0 data, 1 input, 2 command, 3 response)
// and IdBase in bits 24..34 (byte 3, and bits 0-2 of byte 4), then the sequence number. Frames
// written byte by byte here.
TEST(Command, SetIdBaseAtTheIcdBits) {
  // Group 1 (input), base 0x5A3: byte 3 = 0xA3, byte 4 = 0x05.
  DecodedCommand d = decode_command(raw_command({10, 9, 1, 0xA3, 0x05, 4, 0}), kNode);
  ASSERT_TRUE(d.ok()) << d.error.message;
  EXPECT_EQ(d.command.opcode, Opcode::kSetIdBase);
  EXPECT_EQ(d.command.id_group, IdGroup::kInput);
  EXPECT_EQ(d.command.id_base, 0x5A3);
  EXPECT_EQ(d.command.sequence, 4);
  EXPECT_EQ(decode_command(raw_command({10, 9, 4, 0, 1, 4, 0}), kNode).error.code,
            ResultCode::kOutOfRange);  // group 4 does not exist
  EXPECT_EQ(decode_command(raw_command({10, 9, 0, 0, 0x08, 4, 0}), kNode).error.code,
            ResultCode::kMalformed);  // bit 35: above the 11-bit base
  EXPECT_EQ(decode_command(raw_command({10, 9, 0, 0, 3, 0, 0}), kNode).error.code,
            ResultCode::kOutOfRange);  // no sequence number
  Command c;
  c.opcode = Opcode::kSetIdBase;
  c.id_group = IdGroup::kCommand;
  c.id_base = 0x7FF;
  c.sequence = 0x0102;
  const hal::CanFrame f = encode_command(c, kNode);
  EXPECT_EQ(f.data[2], 2);
  EXPECT_EQ(f.data[3], 0xFF);
  EXPECT_EQ(f.data[4], 0x07);
  EXPECT_EQ(f.data[5], 0x02);
  EXPECT_EQ(f.data[6], 0x01);
}

TEST(Command, SetDividerReachesTheAccuracyMessages) {
  Command c;
  c.opcode = Opcode::kSetDivider;
  c.message = MessageId::kAidingCounters;
  c.divider = 100;
  c.sequence = 1;
  const DecodedCommand d = decode_command(encode_command(c, kNode), kNode);
  ASSERT_TRUE(d.ok()) << d.error.message;
  EXPECT_EQ(d.command.message, MessageId::kAidingCounters);
}

TEST(Command, ByteLayoutAsTheIcdSays) {
  // StartCapture pose 3, N = 1000 = 0x03E8, token 0x42.
  const DecodedCommand d = decode_command(raw_command({6, 0x42, 3, 0xE8, 0x03, 0, 0}), kNode);
  ASSERT_TRUE(d.ok()) << d.error.message;
  EXPECT_EQ(d.command.opcode, Opcode::kStartCapture);
  EXPECT_EQ(d.command.pose, 3);
  EXPECT_EQ(d.command.samples, 1000);
  // Realign to heading 1.0 rad = 10000 = 0x2710, sequence 1.
  const DecodedCommand r = decode_command(raw_command({1, 0, 0x10, 0x27, 0, 1, 0}), kNode);
  ASSERT_TRUE(r.ok());
  EXPECT_NEAR(r.command.heading_rad, 1.0f, 1e-6f);
}

struct Bad {
  const char* what;
  hal::CanFrame frame;
  ResultCode code;
};

TEST(Command, MalformedFramesDecodeToTypedErrors) {
  hal::CanFrame short_frame = raw_command({2, 9, 0, 0, 0, 0, 0});
  short_frame.len = 5;
  hal::CanFrame bad_crc = raw_command({2, 9, 0, 0, 0, 0, 0});
  bad_crc.data[7] ^= 0x01;
  // The arguments' cases carry sequence number 1 (byte 5): only the argument is wrong.
  const std::vector<Bad> cases{
      {"short", short_frame, ResultCode::kBadLength},
      {"crc", bad_crc, ResultCode::kBadCrc},
      {"opcode 0", raw_command({0, 9, 0, 0, 0, 0, 0}), ResultCode::kUnknownOpcode},
      {"opcode 99", raw_command({99, 9, 0, 0, 0, 0, 0}), ResultCode::kUnknownOpcode},
      {"reset with argument", raw_command({2, 9, 2, 0, 0, 0, 0}), ResultCode::kMalformed},
      {"byte 6 set", raw_command({5, 9, 0, 0, 0, 0, 0x10}), ResultCode::kMalformed},
      // heading 3.2 rad = 32000 > 31416
      {"heading > pi", raw_command({1, 9, 0x00, 0x7D, 0, 1, 0}), ResultCode::kOutOfRange},
      {"heading N/A", raw_command({1, 9, 0x00, 0x80, 0, 1, 0}), ResultCode::kOutOfRange},
      {"compensator 3", raw_command({3, 9, 3, 0, 0, 1, 0}), ResultCode::kOutOfRange},
      {"divider of message 14", raw_command({4, 9, 14, 10, 0, 1, 0}), ResultCode::kOutOfRange},
      {"capture pose 64", raw_command({6, 9, 64, 10, 0, 0, 0}), ResultCode::kOutOfRange},
      {"capture 0 samples", raw_command({6, 9, 1, 0, 0, 0, 0}), ResultCode::kOutOfRange},
  };
  for (const Bad& b : cases) {
    SCOPED_TRACE(b.what);
    const DecodedCommand d = decode_command(b.frame, kNode);
    EXPECT_TRUE(d.addressed);
    EXPECT_FALSE(d.ok());
    EXPECT_EQ(d.error.code, b.code) << d.error.message;
    EXPECT_EQ(d.error.token, 9);  // echoed so the host can match the error
    EXPECT_NE(std::string(d.error.message), "");
    const hal::CanFrame rsp = encode_response(error_response(d.error), kNode);
    const Result<ResponseFrame> r = decode_response(rsp);
    ASSERT_TRUE(r.is_ok());
    EXPECT_EQ(r->result, b.code);
    EXPECT_EQ(r->token, 9);
  }
}

TEST(Command, FramesForOtherNodesOrExtendedAreNotAddressed) {
  hal::CanFrame f = encode_command(Command{}, 3);
  EXPECT_FALSE(decode_command(f, kNode).addressed);
  f = encode_command(Command{}, kNode);
  f.extended = true;
  EXPECT_FALSE(decode_command(f, kNode).addressed);
}

TEST(Response, StatusAndCalibrationIdRoundTrip) {
  const hal::CanFrame f = encode_response(Response{4, 200, ResultCode::kOk, 20}, kNode);
  EXPECT_EQ(f.id, 0x682u);
  // Bytes: opcode, token, part 0, result, value 24 bits LE, CRC.
  EXPECT_EQ(f.data[0], 4);
  EXPECT_EQ(f.data[1], 200);
  EXPECT_EQ(f.data[2], 0);
  EXPECT_EQ(f.data[3], 0);
  EXPECT_EQ(f.data[4], 20);
  const Result<ResponseFrame> r = decode_response(f);
  ASSERT_TRUE(r.is_ok());
  EXPECT_EQ(r->node_id, kNode);
  EXPECT_EQ(r->value, 20u);
  const Result<ResponseFrame> c =
      decode_response(encode_calibration_id_response(7, 0xCAFEF00D, kNode));
  ASSERT_TRUE(c.is_ok());
  EXPECT_EQ(c->part, kPartCalibrationId);
  EXPECT_EQ(c->cal_id, 0xCAFEF00Du);
  hal::CanFrame broken = f;
  broken.data[4] ^= 0x80;
  EXPECT_EQ(decode_response(broken).status().code(), ErrorCode::kDataLoss);
}

TEST(Response, CaptureResultRoundTripsOverNineteenFrames) {
  CaptureResult in;
  in.pose = 5;
  in.samples = 2000;
  for (std::size_t c = 0; c < 6; ++c) {
    in.channels[c] =
        ChannelCapture{static_cast<float>(-4'000'000.25 + 1e6 * static_cast<double>(c)),
                       static_cast<float>(12.5 + static_cast<double>(c)),
                       static_cast<std::uint16_t>(1990 + c), c == 2, c == 4};
  }
  const auto frames = encode_capture_result(in, 33, kNode);
  CaptureAssembler a;
  for (const hal::CanFrame& f : frames) {
    const Result<ResponseFrame> r = decode_response(f);
    ASSERT_TRUE(r.is_ok()) << r.status().message();
    EXPECT_EQ(r->token, 33);
    EXPECT_EQ(r->opcode, kOpStartCapture);
    a.add(*r);
  }
  ASSERT_TRUE(a.complete());
  EXPECT_EQ(a.result().pose, 5);
  EXPECT_EQ(a.result().samples, 2000);
  for (std::size_t c = 0; c < 6; ++c) {
    // Mean: 1/256 count steps; the float32 input itself is exact to 0.25 count at 4e6.
    EXPECT_NEAR(a.result().channels[c].mean_counts, in.channels[c].mean_counts, 0.5 / 256 + 0.25);
    EXPECT_NEAR(a.result().channels[c].std_counts, in.channels[c].std_counts, 0.5 / 4096);
    EXPECT_EQ(a.result().channels[c].count, in.channels[c].count);
    EXPECT_EQ(a.result().channels[c].saturated, c == 2);
    EXPECT_EQ(a.result().channels[c].motion, c == 4);
  }
}

}  // namespace
}  // namespace gfins::can
