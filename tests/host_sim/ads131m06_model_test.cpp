// The register-level ADS131M06 model answering raw frames as the datasheet says (TI SBAS949A
// Table 8-11 commands and responses, Table 8-12 reset values, §8.3.12 CRC rules, §8.5.1.8 word
// sizes). Expected bytes are written here by hand.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <vector>

#include "gfins/host_sim/chip/ads131m06_model.hpp"

namespace {

using gfins::sim::Ads131m06Model;
using Bytes = std::vector<std::uint8_t>;

std::uint16_t crc_ccitt(const Bytes& b, std::size_t n) {  // bitwise, seed FFFFh (§8.3.12)
  std::uint16_t crc = 0xFFFF;
  for (std::size_t k = 0; k < n; ++k) {
    for (int i = 7; i >= 0; --i) {
      const bool in = ((b[k] >> i) & 1) != 0;
      const bool top = (crc & 0x8000) != 0;
      crc = static_cast<std::uint16_t>(crc << 1);
      if (in != top) crc ^= 0x1021;
    }
  }
  return crc;
}

// A 24-bit-word DIN frame of 8 words: command, data, then optionally a valid CRC.
Bytes din(std::uint16_t cmd, std::vector<std::uint16_t> data = {}, bool with_crc = true) {
  Bytes b;
  auto put = [&](std::uint16_t w) {
    b.push_back(static_cast<std::uint8_t>(w >> 8));
    b.push_back(static_cast<std::uint8_t>(w));
    b.push_back(0);
  };
  put(cmd);
  for (auto d : data) put(d);
  if (with_crc) put(crc_ccitt(b, b.size()));
  b.resize(24, 0);
  return b;
}

Bytes xfer(Ads131m06Model& m, const Bytes& tx) {
  Bytes rx(tx.size());
  EXPECT_TRUE(m.transfer(tx, rx).is_ok());
  return rx;
}
std::uint16_t word(const Bytes& rx, std::size_t i, std::size_t wb = 3) {
  return static_cast<std::uint16_t>((rx[i * wb] << 8) | rx[i * wb + 1]);
}

TEST(Ads131m06Model, ResetValuesAndNullAnswerWithStatus) {
  Ads131m06Model m;
  const Bytes rx = xfer(m, din(0x0000));
  EXPECT_EQ(word(rx, 0), 0x0500);  // STATUS reset value: RESET, WLENGTH 24-bit
  // Output CRC over the 21 bytes before it (always present, §8.3.12).
  EXPECT_EQ(word(rx, 7), crc_ccitt(rx, 21));
}

TEST(Ads131m06Model, ResetAnswersFF26InTheNextFrame) {
  Ads131m06Model m;
  xfer(m, din(0x0011));
  EXPECT_EQ(word(xfer(m, din(0x0000)), 0), 0xFF26);
}

TEST(Ads131m06Model, SingleAndMultipleRegisterReads) {
  Ads131m06Model m(1.2, 0x42);
  xfer(m, din(0xA000));  // RREG ID
  EXPECT_EQ(word(xfer(m, din(0x0000)), 0), 0x2642);
  // RREG of 3 registers from MODE (02h): ack 111a aaaa annn nnnn = E102h, then MODE, CLOCK,
  // GAIN1 reset values, no conversion data (Table 8-11 note 1).
  xfer(m, din(0xA102));
  const Bytes rx = xfer(m, din(0x0000));
  EXPECT_EQ(word(rx, 0), 0xE102);
  EXPECT_EQ(word(rx, 1), 0x0510);
  EXPECT_EQ(word(rx, 2), 0x7F0E);
  EXPECT_EQ(word(rx, 3), 0x0000);
  EXPECT_EQ(word(rx, 4), crc_ccitt(rx, 12));
}

TEST(Ads131m06Model, WriteOfTwoRegistersIsAcknowledged) {
  Ads131m06Model m;
  xfer(m, din(0x6201, {0x0123, 0x0045}));            // WREG GAIN1, GAIN2
  EXPECT_EQ(word(xfer(m, din(0x0000)), 0), 0x4201);  // 010a aaaa ammm mmmm, m = 1
  EXPECT_EQ(m.reg(gfins::drivers::ads131m06::Reg::kGain1), 0x0123);
  EXPECT_EQ(m.reg(gfins::drivers::ads131m06::Reg::kGain2), 0x0045);
  EXPECT_EQ(m.gain(1), 4);   // PGAGAIN1 = 010b
  EXPECT_EQ(m.gain(5), 16);  // PGAGAIN5 = 100b
}

TEST(Ads131m06Model, InputCrcErrorBlocksCommandsButNotWreg) {
  Ads131m06Model m;
  xfer(m, din(0x6100, {0x1110}));  // MODE: RX_CRC_EN on
  xfer(m, din(0x0000));
  xfer(m, din(0x0022, {}, /*with_crc=*/false));  // STANDBY with a zero (wrong) CRC
  EXPECT_FALSE(m.standby());                     // not executed
  const Bytes rx = xfer(m, din(0x0000));
  EXPECT_EQ(word(rx, 0) & 0x1000, 0x1000);               // CRC_ERR, answered like NULL
  EXPECT_EQ(word(xfer(m, din(0x0000)), 0) & 0x1000, 0);  // cleared once STATUS went out
  xfer(m, din(0x6200, {0x0007}, /*with_crc=*/false));    // WREG with a wrong CRC: executes
  EXPECT_EQ(m.reg(gfins::drivers::ads131m06::Reg::kGain1), 0x0007);
}

TEST(Ads131m06Model, LockAllowsOnlyNullUnlockAndRreg) {
  Ads131m06Model m;
  xfer(m, din(0x0555));
  EXPECT_EQ(word(xfer(m, din(0x6200, {0x0003})), 0), 0x0555);        // LOCK ack
  EXPECT_EQ(m.reg(gfins::drivers::ads131m06::Reg::kGain1), 0x0000);  // WREG refused
  EXPECT_TRUE(m.locked());
  xfer(m, din(0x0655));
  EXPECT_EQ(word(xfer(m, din(0x0000)), 0), 0x0655);
  EXPECT_FALSE(m.locked());
}

TEST(Ads131m06Model, StandbyStopsConversions) {
  Ads131m06Model m;
  xfer(m, din(0x0022));
  EXPECT_FALSE(m.convert({0.1, 0.1, 0.1, 0.1, 0.1, 0.1}));
  xfer(m, din(0x0033));
  EXPECT_TRUE(m.convert({0.1, 0.1, 0.1, 0.1, 0.1, 0.1}));
}

TEST(Ads131m06Model, DrdyBitsShowNewDataUntilRead) {
  Ads131m06Model m;
  ASSERT_TRUE(m.convert({0.6, -0.6, 0, 0, 0, 0}));
  Bytes rx = xfer(m, din(0x0000));
  EXPECT_EQ(word(rx, 0) & 0x3F, 0x3F);
  // Channel 0: 0.6 V of 1.2 V full scale = 2^22 = 400000h; channel 1: -2^22 = C00000h.
  EXPECT_EQ(rx[3], 0x40);
  EXPECT_EQ(rx[6], 0xC0);
  rx = xfer(m, din(0x0000));
  EXPECT_EQ(word(rx, 0) & 0x3F, 0);  // the data went out in the previous frame
}

TEST(Ads131m06Model, ThirtyTwoBitSignExtendedWords) {
  Ads131m06Model m;
  xfer(m, din(0x6100, {0x0310}));  // MODE: WLENGTH = 11b (32-bit, sign extended)
  ASSERT_TRUE(m.convert({-0.6, 0, 0, 0, 0, 0}));
  Bytes tx(32, 0);
  Bytes rx(32);
  ASSERT_TRUE(m.transfer(tx, rx).is_ok());
  // Channel 0 = -2^22 sign extended to 32 bits: FFC00000h.
  EXPECT_EQ(rx[4], 0xFF);
  EXPECT_EQ(rx[5], 0xC0);
  EXPECT_EQ(rx[6], 0x00);
  EXPECT_EQ(word(rx, 7, 4), crc_ccitt(rx, 28));
}

}  // namespace
