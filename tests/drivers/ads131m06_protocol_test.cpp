// The shared protocol helpers of ads131m06_registers.hpp against outside oracles: the published
// CRC-16/CCITT-FALSE check value, the datasheet's command words and code range, and the OSR
// table (§8.3.7 Table 8-2).
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <string_view>

#include "gfins/drivers/ads131m06.hpp"
#include "gfins/drivers/ads131m06_registers.hpp"

namespace {

namespace reg = gfins::drivers::ads131m06;

std::uint16_t crc_of(std::string_view s) {
  return reg::crc16_ccitt(
      std::span<const std::uint8_t>(reinterpret_cast<const std::uint8_t*>(s.data()), s.size()));
}

TEST(Ads131m06Crc, MatchesTheCcittFalseCheckValue) {
  // CRC-16/CCITT-FALSE (poly 1021h, init FFFFh, no reflection, xorout 0): the catalogue check
  // value of the ASCII string "123456789" is 29B1h.
  EXPECT_EQ(crc_of("123456789"), 0x29B1);
  // Empty input leaves the seed.
  EXPECT_EQ(crc_of(""), 0xFFFF);
  // "A" → B915h (same catalogue parameters).
  EXPECT_EQ(crc_of("A"), 0xB915);
}

TEST(Ads131m06Crc, AppendedCrcChecksToZero) {
  // A property of a non-reflected CRC with no output XOR: running it over data + its own CRC
  // (MSB first) gives 0, so any single flipped bit is caught.
  std::array<std::uint8_t, 5> b = {0x12, 0x34, 0x56, 0, 0};
  const std::uint16_t c = reg::crc16_ccitt(std::span<const std::uint8_t>(b).first(3));
  b[3] = static_cast<std::uint8_t>(c >> 8);
  b[4] = static_cast<std::uint8_t>(c & 0xFF);
  EXPECT_EQ(reg::crc16_ccitt(b), 0);
  b[1] ^= 0x04;
  EXPECT_NE(reg::crc16_ccitt(b), 0);
}

TEST(Ads131m06Protocol, CommandWordsAreTheDatasheetOnes) {
  // Table 8-11: RREG 101a aaaa annn nnnn, WREG 011a aaaa annn nnnn.
  EXPECT_EQ(reg::rreg(0x00), 0xA000);
  EXPECT_EQ(reg::rreg(0x02), 0xA100);         // MODE
  EXPECT_EQ(reg::rreg(0x03, 4), 0xA183);      // CLOCK..CFG: nnn nnnn = 3
  EXPECT_EQ(reg::wreg(0x03), 0x6180);         // CLOCK
  EXPECT_EQ(reg::wreg_ack(0x04, 2), 0x4201);  // GAIN1 and GAIN2 written
  EXPECT_EQ(reg::command_address(0xA183), 0x03);
  EXPECT_EQ(reg::command_count(0xA183), 4);
  EXPECT_EQ(reg::kResetAck, 0xFF26);  // 1111 1111 0010 0110
}

TEST(Ads131m06Protocol, SignExtensionCoversTheWholeCodeRange) {
  EXPECT_EQ(reg::sign_extend24(0x7FFFFF), 8388607);
  EXPECT_EQ(reg::sign_extend24(0x800000), -8388608);
  EXPECT_EQ(reg::sign_extend24(0xFFFFFF), -1);
  EXPECT_EQ(reg::sign_extend24(0x000000), 0);
  // Round trip for a spread of codes: put_code24 then get_code24 is the identity.
  std::array<std::uint8_t, 3> w{};
  for (std::int32_t c = -8388608; c <= 8388607; c += 65521) {
    reg::put_code24(w, c);
    ASSERT_EQ(reg::get_code24(w), c);
  }
}

TEST(Ads131m06Protocol, OsrTableGivesTheDatasheetRates) {
  // §8.3.7 Table 8-2, high-resolution mode, CLKIN 8.192 MHz: OSR 128 → 32 kSPS ... 16384 →
  // 250 SPS; 4096 → 1 kSPS.
  EXPECT_DOUBLE_EQ(reg::data_rate_hz(8.192e6, 128), 32000.0);
  EXPECT_DOUBLE_EQ(reg::data_rate_hz(8.192e6, 4096), 1000.0);
  EXPECT_DOUBLE_EQ(reg::data_rate_hz(8.192e6, 16384), 250.0);
  const auto code = gfins::drivers::Ads131m06::osr_code_for(1000.0, 8.192e6);
  ASSERT_TRUE(code.is_ok());
  EXPECT_EQ(code.value(), 0b101);
  // Low-power mode column: CLKIN 4.096 MHz, 1 kSPS at OSR 2048 (code 100b).
  EXPECT_EQ(gfins::drivers::Ads131m06::osr_code_for(1000.0, 4.096e6).value(), 0b100);
  EXPECT_FALSE(gfins::drivers::Ads131m06::osr_code_for(1000.0, 10e6).is_ok());
}

}  // namespace

namespace {

TEST(Ads131m06Protocol, RegisterTableEncodesGainsAndClockAsTheDatasheetSays) {
  // Table 8-12: PGAGAINn[2:0] at bits 4n+2..4n of GAIN1 (n = 0..3) and GAIN2 (n = 4, 5); code
  // = log2(gain). CLOCK: CHn_EN bits 13:8, OSR[2:0] bits 4:2, PWR[1:0] bits 1:0.
  gfins::drivers::Ads131m06Config c;
  c.pga_gain = {1, 2, 4, 8, 16, 128};
  c.sample_rate_hz = 250.0;  // OSR 16384 = code 111b
  c.power_mode = gfins::drivers::ads131m06::PowerMode::kHighResolution;
  c.input_crc = false;
  std::array<gfins::drivers::RegisterSetting, gfins::drivers::Ads131m06::kTableSize> t{};
  ASSERT_TRUE(gfins::drivers::Ads131m06::make_table(c, t).is_ok());
  EXPECT_EQ(t[0].value, 0x0110);  // MODE: WLENGTH 01b, TIMEOUT; RX_CRC_EN off; RESET cleared
  EXPECT_EQ(t[1].value, 0x3210);  // GAIN1: 011b 010b 001b 000b
  EXPECT_EQ(t[2].value, 0x0074);  // GAIN2: PGAGAIN5 = 111b, PGAGAIN4 = 100b
  EXPECT_EQ(t[3].value, 0x7F1E);  // CLOCK: 7F00h | 111b << 2 | 10b
  c.pga_gain[0] = 3;
  EXPECT_FALSE(gfins::drivers::Ads131m06::make_table(c, t).is_ok());
}

}  // namespace
