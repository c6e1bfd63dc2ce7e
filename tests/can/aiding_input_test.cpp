// Aiding input frames (GNSS fix, external heading): encode -> decode round trip, and every kind
// of bad input rejected with its Status and counted: bad CRC, wrong length, a stale (repeated)
// id, values out of range or not available, reserved bits, mixed fix ids, incomplete fixes.
#include "gfins/can/aiding_input.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "gfins/can/signal_codec.hpp"

namespace gfins::can {
namespace {

constexpr std::uint8_t kNode = 2;

GnssFix sample_fix(std::uint8_t id) {
  GnssFix f;
  f.fix_id = id;
  f.has_position = true;
  f.has_velocity = true;
  f.r_n_m = {1234.56, -789.01, -12.34};
  f.v_n_mps = {10.01, -3.02, 0.15};
  f.sigma_pos_h_m = 1.5;
  f.sigma_pos_v_m = 2.5;
  f.sigma_vel_mps = 0.05;
  f.age_s = 0.065;
  return f;
}

/// Feeds the frames; returns the last result.
template <std::size_t N>
Result<InputEvent> feed(InputDecoder& d, const std::array<hal::CanFrame, N>& frames) {
  Result<InputEvent> r = InputEvent{};
  for (const hal::CanFrame& f : frames) r = d.add(f);
  return r;
}

std::size_t reason(InputReject r) { return static_cast<std::size_t>(r); }

/// Rewrites one signal's raw bits of a frame and reseals it (a frame a sender got wrong, with a
/// valid CRC, so the check behind the CRC is what rejects it).
hal::CanFrame with_raw(hal::CanFrame f, std::string_view signal, std::int64_t raw) {
  const MessageDef* m = find_message(f.id, nullptr);
  const SignalDef& s = m->signals[signal_index(*m, signal)];
  set_payload(f, insert_bits(payload_of(f), s, bits_of(s, raw)));
  seal_frame(f);
  return f;
}

TEST(GnssInput, AFixRoundTripsWithinHalfAStep) {
  InputDecoder d(kNode);
  const auto frames = encode_gnss_fix(sample_fix(3), kNode);
  EXPECT_EQ(frames[0].id, 0x0C0u + kNode);
  EXPECT_EQ(frames[3].id, 0x0F0u + kNode);
  for (std::size_t i = 0; i < 3; ++i) {
    const Result<InputEvent> r = d.add(frames[i]);
    ASSERT_TRUE(r.is_ok()) << r.status().message();
    EXPECT_EQ(r->kind, InputEventKind::kPending);
  }
  const Result<InputEvent> r = d.add(frames[3]);
  ASSERT_TRUE(r.is_ok()) << r.status().message();
  ASSERT_EQ(r->kind, InputEventKind::kGnssFix);
  const GnssFix& g = r->gnss;
  const GnssFix want = sample_fix(3);
  EXPECT_EQ(g.fix_id, 3);
  EXPECT_TRUE(g.has_position && g.has_velocity);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_NEAR(g.r_n_m[i], want.r_n_m[i], 0.005 + 1e-9);      // 1 cm steps
    EXPECT_NEAR(g.v_n_mps[i], want.v_n_mps[i], 0.005 + 1e-9);  // 1 cm/s steps
  }
  // σ rounds up (never smaller than stated), by less than one step.
  EXPECT_GE(g.sigma_pos_h_m, want.sigma_pos_h_m - 1e-12);
  EXPECT_LT(g.sigma_pos_h_m, want.sigma_pos_h_m + 0.01 + 1e-9);
  EXPECT_GE(g.sigma_pos_v_m, want.sigma_pos_v_m - 1e-12);
  EXPECT_GE(g.sigma_vel_mps, want.sigma_vel_mps - 1e-12);
  EXPECT_LT(g.sigma_vel_mps, want.sigma_vel_mps + 0.001 + 1e-9);
  EXPECT_NEAR(g.age_s, want.age_s, 0.0005 + 1e-9);
  EXPECT_EQ(d.counters().gnss_fixes, 1u);
  EXPECT_EQ(d.counters().total_rejected(), 0u);
}

TEST(GnssInput, AVelocityOnlyFixNeedsNoPositionFrames) {
  InputDecoder d(kNode);
  GnssFix v = sample_fix(5);
  v.has_position = false;
  const auto frames = encode_gnss_fix(v, kNode);
  // The position frames are sent with every value not available: absent, not an error.
  ASSERT_TRUE(d.add(frames[0]).is_ok());
  ASSERT_TRUE(d.add(frames[1]).is_ok());
  ASSERT_TRUE(d.add(frames[2]).is_ok());
  const Result<InputEvent> r = d.add(frames[3]);
  ASSERT_TRUE(r.is_ok()) << r.status().message();
  EXPECT_EQ(r->kind, InputEventKind::kGnssFix);
  EXPECT_FALSE(r->gnss.has_position);
  EXPECT_TRUE(r->gnss.has_velocity);
  EXPECT_EQ(d.counters().total_rejected(), 0u);
  // A FixInfo claiming a position whose frames said "absent" is incomplete.
  InputDecoder e(kNode);
  auto lying = encode_gnss_fix(v, kNode);
  lying[3] = with_raw(lying[3], "GnssContent", 3);
  EXPECT_FALSE(feed(e, lying).is_ok());
  EXPECT_EQ(e.last_reject(), InputReject::kIncomplete);
}

TEST(GnssInput, ACorruptedFrameIsRejectedCountedAndSpoilsItsFix) {
  InputDecoder d(kNode);
  auto frames = encode_gnss_fix(sample_fix(1), kNode);
  frames[1].data[2] ^= 0x10;  // one bit flipped on the way
  EXPECT_TRUE(d.add(frames[0]).is_ok());
  const Result<InputEvent> bad = d.add(frames[1]);
  ASSERT_FALSE(bad.is_ok());
  EXPECT_EQ(bad.status().code(), ErrorCode::kDataLoss);
  EXPECT_EQ(d.last_reject(), InputReject::kBadCrc);
  EXPECT_TRUE(d.add(frames[2]).is_ok());
  const Result<InputEvent> info = d.add(frames[3]);  // PositionD is missing
  ASSERT_FALSE(info.is_ok());
  EXPECT_EQ(d.last_reject(), InputReject::kIncomplete);
  EXPECT_EQ(d.counters().rejected[reason(InputReject::kBadCrc)], 1u);
  EXPECT_EQ(d.counters().rejected[reason(InputReject::kIncomplete)], 1u);
  EXPECT_EQ(d.counters().gnss_fixes, 0u);
}

TEST(GnssInput, AFrameForAnotherNodeFailsItsCrcUnderThisIdentifier) {
  // The CRC covers the identifier: a frame re-addressed without resealing is rejected.
  InputDecoder d(kNode);
  hal::CanFrame f = encode_gnss_fix(sample_fix(1), kNode + 1)[0];
  EXPECT_EQ(d.add(f)->kind, InputEventKind::kIgnored);  // another node's: not ours
  f.id = 0x0C0u + kNode;
  EXPECT_FALSE(d.add(f).is_ok());
  EXPECT_EQ(d.last_reject(), InputReject::kBadCrc);
}

TEST(GnssInput, WrongLengthIsRejected) {
  InputDecoder d(kNode);
  hal::CanFrame f = encode_gnss_fix(sample_fix(1), kNode)[0];
  f.len = 7;
  EXPECT_EQ(d.add(f).status().code(), ErrorCode::kDataLoss);
  EXPECT_EQ(d.last_reject(), InputReject::kBadLength);
}

TEST(GnssInput, ARepeatedFixIdIsStale) {
  InputDecoder d(kNode);
  const auto frames = encode_gnss_fix(sample_fix(7), kNode);
  ASSERT_EQ(feed(d, frames)->kind, InputEventKind::kGnssFix);
  const Result<InputEvent> again = d.add(frames[0]);  // the same fix replayed
  ASSERT_FALSE(again.is_ok());
  EXPECT_EQ(again.status().code(), ErrorCode::kFailedPrecondition);
  EXPECT_EQ(d.last_reject(), InputReject::kStale);
  // The next fix id is accepted again.
  ASSERT_EQ(feed(d, encode_gnss_fix(sample_fix(8), kNode))->kind, InputEventKind::kGnssFix);
  // Fix ids wrap modulo 16: 15 -> 0 is the next one, not a repeat.
  ASSERT_EQ(feed(d, encode_gnss_fix(sample_fix(15), kNode))->kind, InputEventKind::kGnssFix);
  ASSERT_EQ(feed(d, encode_gnss_fix(sample_fix(0), kNode))->kind, InputEventKind::kGnssFix);
  EXPECT_EQ(d.counters().gnss_fixes, 4u);
}

TEST(GnssInput, MixedFixIdsAreRejected) {
  InputDecoder d(kNode);
  const auto a = encode_gnss_fix(sample_fix(4), kNode);
  const auto b = encode_gnss_fix(sample_fix(5), kNode);
  EXPECT_TRUE(d.add(a[0]).is_ok());
  const Result<InputEvent> r = d.add(b[1]);  // PositionD of another fix
  ASSERT_FALSE(r.is_ok());
  EXPECT_EQ(d.last_reject(), InputReject::kMixedFix);
  // Fix 4 was dropped with its position: its velocity opens it again, and its FixInfo finds
  // the position frames missing.
  EXPECT_TRUE(d.add(a[2]).is_ok());
  EXPECT_FALSE(d.add(a[3]).is_ok());
  EXPECT_EQ(d.last_reject(), InputReject::kIncomplete);
  EXPECT_EQ(d.counters().gnss_fixes, 0u);
  // The next complete fix is accepted.
  EXPECT_EQ(feed(d, encode_gnss_fix(sample_fix(6), kNode))->kind, InputEventKind::kGnssFix);
}

TEST(GnssInput, OutOfRangeAndNotAvailableValuesAreRejected) {
  const auto frames = encode_gnss_fix(sample_fix(2), kNode);
  struct Case {
    std::size_t frame;
    const char* signal;
    std::int64_t raw;
  };
  const Case cases[] = {
      {0, "GnssPosN", -(std::int64_t{1} << 25)},     // not available
      {0, "GnssPosE", (std::int64_t{1} << 25) - 1},  // beyond 335 km
      {1, "GnssSigmaPosH", 8191},                    // not available
      {1, "GnssSigmaPosV", 0},                       // a σ of zero is no σ
      {2, "GnssVelD", -32768},                       // not available
      {2, "GnssVelN", 32767},                        // beyond 320 m/s
      {3, "GnssFixAge", 8191},                       // not available
      {3, "GnssSigmaVel", 0},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.signal);
    InputDecoder d(kNode);
    auto f = frames;
    f[c.frame] = with_raw(f[c.frame], c.signal, c.raw);
    const Result<InputEvent> r = feed(d, f);
    ASSERT_FALSE(r.is_ok());
    EXPECT_EQ(d.counters().gnss_fixes, 0u);
    EXPECT_GE(d.counters().rejected[reason(InputReject::kOutOfRange)], 1u);
  }
}

TEST(GnssInput, ReservedBitsAndAnEmptyFixAreMalformed) {
  InputDecoder d(kNode);
  hal::CanFrame v = encode_gnss_fix(sample_fix(2), kNode)[2];
  v.data[6] |= 0x01;  // bit 48: reserved in GfinsGnssVelocity
  seal_frame(v);
  EXPECT_EQ(d.add(v).status().code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(d.last_reject(), InputReject::kMalformed);
  InputDecoder e(kNode);
  auto frames = encode_gnss_fix(sample_fix(2), kNode);
  frames[3] = with_raw(frames[3], "GnssContent", 0);
  EXPECT_EQ(feed(e, frames).status().code(), ErrorCode::kInvalidArgument);
}

TEST(HeadingInput, RoundTripStaleAndRange) {
  InputDecoder d(kNode);
  const HeadingFix h{.sequence = 9, .heading_rad = -2.5, .sigma_rad = 0.0123, .age_s = 0.02};
  const hal::CanFrame f = encode_heading_fix(h, kNode);
  EXPECT_EQ(f.id, 0x0B0u + kNode);
  const Result<InputEvent> r = d.add(f);
  ASSERT_TRUE(r.is_ok()) << r.status().message();
  ASSERT_EQ(r->kind, InputEventKind::kHeadingFix);
  EXPECT_NEAR(r->heading.heading_rad, -2.5, 0.5e-4 + 1e-12);
  EXPECT_GE(r->heading.sigma_rad, 0.0123 - 1e-12);
  EXPECT_LT(r->heading.sigma_rad, 0.0123 + 1e-4 + 1e-12);
  EXPECT_NEAR(r->heading.age_s, 0.02, 0.0005 + 1e-12);
  EXPECT_EQ(d.add(f).status().code(), ErrorCode::kFailedPrecondition);  // repeated sequence
  EXPECT_EQ(d.last_reject(), InputReject::kStale);
  const hal::CanFrame na =
      with_raw(encode_heading_fix({.sequence = 10}, kNode), "ExtHeading", -32768);
  EXPECT_EQ(d.add(na).status().code(), ErrorCode::kOutOfRange);
  hal::CanFrame bad = encode_heading_fix({.sequence = 11, .sigma_rad = 0.01}, kNode);
  bad.data[0] ^= 1;
  EXPECT_EQ(d.add(bad).status().code(), ErrorCode::kDataLoss);
  EXPECT_EQ(d.counters().headings, 1u);
  EXPECT_EQ(d.counters().total_rejected(), 3u);
}

TEST(InputFrames, EverySignalIsInTheTableWithTheGnssReceiverAsSender) {
  int inputs = 0;
  for (const MessageDef& m : kMessages) {
    if (m.kind != MessageKind::kInput) continue;
    ++inputs;
    EXPECT_EQ(m.sender, "GNSS") << m.name;
    EXPECT_EQ(m.default_divider, 0) << m.name;
  }
  EXPECT_EQ(inputs, 5);
}

}  // namespace
}  // namespace gfins::can
