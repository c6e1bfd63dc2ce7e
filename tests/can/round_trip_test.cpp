// Every signal of the table over its full range: min, max, not-available, saturation beyond the
// limits, wrap for counters; and frame layouts written out byte by byte from the ICD.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "gfins/can/publisher.hpp"
#include "gfins/can/signal_codec.hpp"

namespace gfins::can {
namespace {

// Quantisation bound: rounding to the nearest raw step errs by at most half a step; 1e-9 of a
// step covers the double rounding of x / factor.
double half_step(const SignalDef& s) { return 0.5 * s.factor * (1.0 + 1e-9); }
// raw * factor in double: a few ulp of the value.
constexpr double kLimitRounding = 4 * std::numeric_limits<double>::epsilon();

TEST(RoundTrip, EverySignalOverItsRange) {
  int checked = 0;
  for (const MessageDef& m : kMessages) {
    for (const SignalDef& s : m.signals) {
      SCOPED_TRACE(std::string(m.name) + "." + std::string(s.name));
      // Limits and a sweep across the range decode within half a step, without saturation.
      constexpr int kSteps = 997;  // prime: the sweep does not land on raw steps only
      for (int i = 0; i <= kSteps; ++i) {
        const double x = s.min + (s.max - s.min) * i / kSteps;
        const EncodedSignal e = encode_signal(s, x);
        ASSERT_FALSE(e.saturated) << x;
        ASSERT_FALSE(e.not_available) << x;
        if (s.round_up) {
          // σ: rounded up, never shown smaller than it is, by less than one step.
          ASSERT_GE(decode_signal(s, e.bits), x - 1e-9 * s.factor) << x;
          ASSERT_LT(decode_signal(s, e.bits), x + s.factor * (1.0 + 1e-9)) << x;
        } else {
          ASSERT_NEAR(decode_signal(s, e.bits), x, half_step(s)) << x;
        }
      }
      // The limits themselves are exact raw steps (the table's static checks): they come back
      // up to the double rounding of raw * factor.
      const double exact = kLimitRounding * std::max(std::abs(s.min), std::abs(s.max));
      ASSERT_NEAR(decode_signal(s, encode_signal(s, s.min).bits), s.min, exact);
      ASSERT_NEAR(decode_signal(s, encode_signal(s, s.max).bits), s.max, exact);
      // Not available: NaN and inf go out as the reserved code and come back as NaN.
      const EncodedSignal na = encode_signal(s, std::numeric_limits<double>::quiet_NaN());
      EXPECT_TRUE(na.not_available);
      if (s.has_na) {
        EXPECT_EQ(raw_value(s, na.bits), s.na_raw);
        EXPECT_TRUE(std::isnan(decode_signal(s, na.bits)));
        EXPECT_TRUE(std::isnan(decode_signal(s, bits_of(s, s.na_raw))));
      }
      if (s.overflow == Overflow::kSaturate) {
        // Beyond the limits: clipped to the documented limit, and flagged.
        const double span = s.max - s.min + s.factor;
        for (double beyond : {s.max + s.factor, s.max + 10 * span, 1e300}) {
          const EncodedSignal e = encode_signal(s, beyond);
          EXPECT_TRUE(e.saturated);
          EXPECT_NEAR(decode_signal(s, e.bits), s.max, exact);
        }
        for (double beyond : {s.min - s.factor, s.min - 10 * span, -1e300}) {
          const EncodedSignal e = encode_signal(s, beyond);
          EXPECT_TRUE(e.saturated);
          EXPECT_NEAR(decode_signal(s, e.bits), s.min, exact);
        }
      } else {
        // Counters and times wrap modulo 2^length, never saturate.
        const double m2 = std::ldexp(1.0, s.length);
        EXPECT_EQ(decode_signal(s, encode_signal(s, m2).bits), 0.0);
        EXPECT_EQ(decode_signal(s, encode_signal(s, m2 + 5).bits), 5.0);
        EXPECT_FALSE(encode_signal(s, m2 + 5).saturated);
      }
      // In a frame: writing the signal leaves every other bit untouched.
      const std::uint64_t ones = ~std::uint64_t{0};
      const std::uint64_t p = insert_bits(ones, s, encode_signal(s, s.min).bits);
      const std::uint64_t mask = low_mask(s.length) << s.start_bit;
      EXPECT_EQ(p | mask, ones);
      EXPECT_EQ(extract_bits(p, s), encode_signal(s, s.min).bits);
      ++checked;
    }
  }
  EXPECT_GT(checked, 80);
}

Epoch sample_epoch() {
  Epoch e;
  e.nav.t_ns = 1'234'567'891'000;
  e.nav.seq = 70'010;
  e.nav.w_b = nav::Vec3<float>(1.0f, -0.5f, 0.0f);
  e.mode = Mode::kNavigating;
  return e;
}

// Bit-serial CRC written from the definition, so the layout test does not trust the code.
std::uint8_t crc_of(std::uint32_t id, const hal::CanFrame& f) {
  std::uint8_t reg = 0xFF;
  auto feed = [&](std::uint8_t b) {
    for (int i = 7; i >= 0; --i) {
      const bool in = ((b >> i) & 1u) != 0;
      const bool top = (reg & 0x80u) != 0;
      reg = static_cast<std::uint8_t>(reg << 1);
      if (in != top) reg = static_cast<std::uint8_t>(reg ^ 0x1Du);
    }
  };
  feed(static_cast<std::uint8_t>(id & 0xFF));
  feed(static_cast<std::uint8_t>(id >> 8));
  for (int i = 0; i < 7; ++i) feed(f.data[static_cast<std::size_t>(i)]);
  return static_cast<std::uint8_t>(reg ^ 0xFF);
}

TEST(Layout, AngularRateFrameBytesAsTheIcdSays) {
  // ICD: GfinsAngularRate, id 0x140 + node, RateX/Y/Z int16 LE at bytes 0-1/2-3/4-5, 5e-4 rad/s;
  // byte 6 high nibble = epoch counter; byte 7 CRC.
  const hal::CanFrame f =
      encode_data_frame(message(MessageId::kRate), sample_epoch(), 3, 9, nullptr, nullptr);
  EXPECT_EQ(f.id, 0x143u);
  EXPECT_EQ(f.len, 8);
  // 1.0 rad/s / 5e-4 = 2000 = 0x07D0; -0.5 / 5e-4 = -1000 = 0xFC18.
  const std::array<std::uint8_t, 7> expect{0xD0, 0x07, 0x18, 0xFC, 0x00, 0x00, 0x90};
  for (std::size_t i = 0; i < 7; ++i) EXPECT_EQ(f.data[i], expect[i]) << "byte " << i;
  EXPECT_EQ(f.data[7], crc_of(0x143, f));
}

TEST(Layout, EpochFrameBytesAsTheIcdSays) {
  // ICD: GfinsEpoch, TimeUs uint32 at bytes 0-3 (µs mod 2^32), SampleCount uint16 at 4-5,
  // Mode in the low nibble of byte 6, counter in the high nibble.
  const hal::CanFrame f =
      encode_data_frame(message(MessageId::kEpoch), sample_epoch(), 0, 15, nullptr, nullptr);
  EXPECT_EQ(f.id, 0x100u);
  const std::uint32_t t_us = static_cast<std::uint32_t>(1'234'567'891ULL & 0xFFFFFFFFu);
  EXPECT_EQ(f.data[0], t_us & 0xFF);
  EXPECT_EQ(f.data[1], (t_us >> 8) & 0xFF);
  EXPECT_EQ(f.data[2], (t_us >> 16) & 0xFF);
  EXPECT_EQ(f.data[3], (t_us >> 24) & 0xFF);
  EXPECT_EQ(f.data[4], 70'010 & 0xFF);  // 70010 mod 65536 = 4474 = 0x117A
  EXPECT_EQ(f.data[5], (70'010 >> 8) & 0xFF);
  EXPECT_EQ(f.data[6], 0xF2);  // counter 15, mode 2 (Navigating)
  EXPECT_EQ(f.data[7], crc_of(0x100, f));
}

TEST(Layout, QuaternionIsSentWithNonNegativeScalarPart) {
  Epoch e = sample_epoch();
  e.nav.q_nb = nav::Quat<float>(-0.5f, 0.5f, -0.5f, 0.5f);  // same rotation as (0.5,-0.5,0.5,-0.5)
  const MessageDef& m = message(MessageId::kQuaternion);
  const hal::CanFrame f = encode_data_frame(m, e, 0, 0, nullptr, nullptr);
  const std::uint64_t p = payload_of(f);
  EXPECT_NEAR(decode_signal(m.signals[0], extract_bits(p, m.signals[0])), 0.5, 1.0 / 8190);
  EXPECT_NEAR(decode_signal(m.signals[1], extract_bits(p, m.signals[1])), -0.5, 1.0 / 8190);
}

}  // namespace
}  // namespace gfins::can
