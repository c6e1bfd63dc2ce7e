// TI ADS131M06 register map and SPI protocol: the one description shared by the driver
// (drivers/ads131m06) and the register-level chip model (host_sim/chip). std only, header only.
//
// Section numbers refer to the ADS131M06 datasheet (TI SBAS949A, Feb 2021; the ADS131M06-Q1
// datasheet SBASAF2 has the same numbering and tables):
//   §8.3.5/8.3.6/8.3.7  clocking, modulator (fMOD = fCLKIN / 2), digital filter (OSR)
//   §8.3.12             communication CRC (Table 8-7)
//   §8.5.1.7-8.5.1.9    SPI frames, words, ADC conversion data
//   §8.5.1.10           commands (Table 8-11)
//   §8.6                register map (Table 8-12)
// Where the datasheet leaves a point open, the comment says so and says what this code assumes;
// the chip model and the driver make the same assumption, so a test on the model cannot
// confirm it: check it on hardware.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

namespace gfins::drivers::ads131m06 {

inline constexpr int kChannels = 6;

// ---------------------------------------------------------------------------------------------
// Registers (§8.6, Table 8-12). Addresses are 6 bits (the a aaaa a field of RREG/WREG).
// ---------------------------------------------------------------------------------------------
enum class Reg : std::uint8_t {
  kId = 0x00,      // read only
  kStatus = 0x01,  // read only
  kMode = 0x02,
  kClock = 0x03,
  kGain1 = 0x04,  // PGAGAIN3..0
  kGain2 = 0x05,  // PGAGAIN5..4
  kCfg = 0x06,
  kThrshldMsb = 0x07,
  kThrshldLsb = 0x08,
  kCh0Cfg = 0x09,  // then per channel n: CFG, OCAL_MSB, OCAL_LSB, GCAL_MSB, GCAL_LSB at 09h + 5n
  kRegmapCrc = 0x3E,
};
inline constexpr std::size_t kRegisterCount = 64;  // 6-bit address space
inline constexpr std::uint8_t kChannelRegStride = 5;

constexpr std::uint8_t addr(Reg r) { return static_cast<std::uint8_t>(r); }
/// CHn_CFG, CHn_OCAL_MSB, ..., CHn_GCAL_LSB: address of register `k` (0..4) of channel `n`.
constexpr std::uint8_t channel_reg(int n, int k) {
  return static_cast<std::uint8_t>(addr(Reg::kCh0Cfg) + kChannelRegStride * n + k);
}

// Reset values (Table 8-12, "RESET VALUE" column).
inline constexpr std::uint16_t kIdResetValue = 0x2600;  // 26xxh: the low byte is not specified
inline constexpr std::uint16_t kIdMask = 0xFF00;        // compare only the specified part
inline constexpr std::uint16_t kStatusResetValue = 0x0500;
inline constexpr std::uint16_t kModeResetValue = 0x0510;
// 7F0Eh as printed in Table 8-12 of SBASAF2: CH5..CH0_EN set, OSR = 1024, PWR = high resolution.
// Bit 14 is marked RESERVED yet reads 1 in the printed reset value; writes keep it as reset.
inline constexpr std::uint16_t kClockResetValue = 0x7F0E;
inline constexpr std::uint16_t kGainResetValue = 0x0000;
inline constexpr std::uint16_t kCfgResetValue = 0x0600;
inline constexpr std::uint16_t kGcalMsbResetValue = 0x8000;  // gain calibration 1.0

// ID register (§8.6): bits 11:8 CHANCNT = number of channels (6).
namespace id {
inline constexpr std::uint16_t kChanCntShift = 8;
inline constexpr std::uint16_t kChanCntMask = 0x0F00;
}  // namespace id

// STATUS register (§8.6, Table 8-12) — also the response word to NULL (Table 8-11).
namespace status {
inline constexpr std::uint16_t kLock = 1u << 15;     // interface locked (LOCK command)
inline constexpr std::uint16_t kFResync = 1u << 14;  // ADC resynchronised
inline constexpr std::uint16_t kRegMap = 1u << 13;   // register map CRC changed
inline constexpr std::uint16_t kCrcErr = 1u << 12;   // input CRC error in a previous frame
inline constexpr std::uint16_t kCrcType = 1u << 11;  // mirrors MODE.CRC_TYPE
inline constexpr std::uint16_t kReset = 1u << 10;    // mirrors MODE.RESET: a reset happened
inline constexpr std::uint16_t kWlengthShift = 8;    // mirrors MODE.WLENGTH[1:0]
inline constexpr std::uint16_t kWlengthMask = 0x0300;
inline constexpr std::uint16_t kDrdyMask = 0x003F;  // DRDY5..0: new data for channel n
}  // namespace status

// MODE register (§8.6).
namespace mode {
inline constexpr std::uint16_t kRegCrcEn = 1u << 13;  // register map CRC
inline constexpr std::uint16_t kRxCrcEn = 1u << 12;   // check the input (DIN) CRC
inline constexpr std::uint16_t kCrcType = 1u << 11;   // 0: CCITT (x^16+x^12+x^5+1), 1: ANSI
// RESET: set by any reset; the host clears it by writing 0 (§8.6 MODE field description).
inline constexpr std::uint16_t kReset = 1u << 10;
inline constexpr std::uint16_t kWlengthShift = 8;
inline constexpr std::uint16_t kWlengthMask = 0x0300;
inline constexpr std::uint16_t kTimeout = 1u << 4;  // SPI timeout enabled (2^15 CLKIN cycles)
inline constexpr std::uint16_t kDrdySelShift = 2;   // 00: most lagging enabled channel
inline constexpr std::uint16_t kDrdySelMask = 0x000C;
inline constexpr std::uint16_t kDrdyHiZ = 1u << 1;
inline constexpr std::uint16_t kDrdyFmt = 1u << 0;  // 0: level (low until read), 1: pulse
}  // namespace mode

/// WLENGTH[1:0] (§8.5.1.8): bytes per SPI word.
enum class WordLength : std::uint8_t {
  k16 = 0b00,            // 16 bits; conversion data truncated to 16 bits
  k24 = 0b01,            // 24 bits (reset default)
  k32ZeroPad = 0b10,     // 32 bits, data LSB zero padded
  k32SignExtend = 0b11,  // 32 bits, data MSB sign extended
};
constexpr std::size_t word_bytes(WordLength w) {
  return w == WordLength::k16 ? 2 : (w == WordLength::k24 ? 3 : 4);
}

// CLOCK register (§8.6): CHn_EN at bits 8+n, OSR[2:0] at 4:2, PWR[1:0] at 1:0.
namespace clock {
inline constexpr std::uint16_t kChannelEnableShift = 8;
inline constexpr std::uint16_t kChannelEnableMask = 0x3F00;
inline constexpr std::uint16_t kReservedKeep = 0x4000;  // bit 14 as in the reset value
inline constexpr std::uint16_t kOsrShift = 2;
inline constexpr std::uint16_t kOsrMask = 0x001C;
inline constexpr std::uint16_t kPwrMask = 0x0003;
}  // namespace clock

/// OSR[2:0] (§8.3.7, Table 8-2): 000b = 128 ... 111b = 16384 (the datasheet lists 16384 for
/// the last code; fDATA = fMOD / OSR with fMOD = fCLKIN / 2, §8.3.6).
inline constexpr std::array<std::uint32_t, 8> kOsrValues = {128,  256,  512,  1024,
                                                            2048, 4096, 8192, 16384};

/// PWR[1:0] (§8.3.5): CLKIN must follow §6.3 for the chosen mode (nominal 8.192 / 4.096 /
/// 2.048 MHz for HR / LP / VLP).
enum class PowerMode : std::uint8_t {
  kVeryLowPower = 0b00,
  kLowPower = 0b01,
  kHighResolution = 0b10
};

/// PGAGAINn[2:0] (§8.3.3): gain = 2^code, code 0..7 (gain 1..128). GAINn registers hold four
/// 3-bit fields at bits 4n..4n+2 (channel 0-3 in GAIN1, 4-5 in GAIN2).
inline constexpr std::uint16_t kGainFieldMask = 0x7;
constexpr int gain_shift(int channel) { return 4 * (channel % 4); }

// ---------------------------------------------------------------------------------------------
// Commands and responses (§8.5.1.10, Table 8-11). Every response appears in the first word of
// the frame that FOLLOWS the command.
// ---------------------------------------------------------------------------------------------
namespace cmd {
inline constexpr std::uint16_t kNull = 0x0000;      // response: STATUS register
inline constexpr std::uint16_t kReset = 0x0011;     // response: kResetAck
inline constexpr std::uint16_t kStandby = 0x0022;   // response: 0022h
inline constexpr std::uint16_t kWakeup = 0x0033;    // response: 0033h
inline constexpr std::uint16_t kLock = 0x0555;      // response: 0555h
inline constexpr std::uint16_t kUnlock = 0x0655;    // response: 0655h
inline constexpr std::uint16_t kRregBase = 0xA000;  // 101a aaaa annn nnnn
inline constexpr std::uint16_t kWregBase = 0x6000;  // 011a aaaa annn nnnn
inline constexpr std::uint16_t kOpcodeMask = 0xE000;
inline constexpr std::uint16_t kAddrShift = 7;
inline constexpr std::uint16_t kAddrMask = 0x1F80;
inline constexpr std::uint16_t kCountMask = 0x007F;  // number of registers minus one
}  // namespace cmd

/// RESET response, 1111 1111 0010 0110b for the ADS131M06 (Table 8-11).
inline constexpr std::uint16_t kResetAck = 0xFF26;
/// WREG acknowledgment: 010a aaaa ammm mmmm, m = registers written minus one (Table 8-11).
inline constexpr std::uint16_t kWregAckBase = 0x4000;
/// RREG of several registers: acknowledgment 111a aaaa annn nnnn, then the registers (Table
/// 8-11 note 1); a single-register RREG answers with the register itself.
inline constexpr std::uint16_t kRregMultiAckBase = 0xE000;

constexpr std::uint16_t rreg(std::uint8_t address, std::uint8_t count = 1) {
  return static_cast<std::uint16_t>(cmd::kRregBase | ((address & 0x3F) << cmd::kAddrShift) |
                                    ((count - 1) & cmd::kCountMask));
}
constexpr std::uint16_t wreg(std::uint8_t address, std::uint8_t count = 1) {
  return static_cast<std::uint16_t>(cmd::kWregBase | ((address & 0x3F) << cmd::kAddrShift) |
                                    ((count - 1) & cmd::kCountMask));
}
constexpr std::uint16_t wreg_ack(std::uint8_t address, std::uint8_t count = 1) {
  return static_cast<std::uint16_t>(kWregAckBase | ((address & 0x3F) << cmd::kAddrShift) |
                                    ((count - 1) & cmd::kCountMask));
}
constexpr std::uint8_t command_address(std::uint16_t command) {
  return static_cast<std::uint8_t>((command & cmd::kAddrMask) >> cmd::kAddrShift);
}
constexpr std::uint8_t command_count(std::uint16_t command) {
  return static_cast<std::uint8_t>((command & cmd::kCountMask) + 1);
}

// ---------------------------------------------------------------------------------------------
// Frames (§8.5.1.7): a typical frame is (channels + 2) words. DIN: command, [WREG data],
// CRC (when RX_CRC_EN) or zeros, zeros. DOUT: response to the previous command, one word per
// channel, CRC of everything before it. Commands, responses, registers and CRCs are 16 bits,
// MSB aligned and zero padded to the word size; conversion data are 24 bits (§8.5.1.9).
// ---------------------------------------------------------------------------------------------
inline constexpr std::size_t kFrameWords = kChannels + 2;         // 8
inline constexpr WordLength kDriverWordLength = WordLength::k24;  // the reset default
inline constexpr std::size_t kWordBytes = word_bytes(kDriverWordLength);
inline constexpr std::size_t kFrameBytes = kFrameWords * kWordBytes;  // 24
static_assert(kFrameBytes == 24, "an ADS131M06 frame at 24-bit words is 8 words of 3 bytes");

/// Writes the 16-bit value MSB first into a word of `bytes` bytes, zero padded.
constexpr void put_word16(std::span<std::uint8_t> word, std::uint16_t v) {
  word[0] = static_cast<std::uint8_t>(v >> 8);
  word[1] = static_cast<std::uint8_t>(v & 0xFF);
  for (std::size_t i = 2; i < word.size(); ++i) word[i] = 0;
}
constexpr std::uint16_t get_word16(std::span<const std::uint8_t> word) {
  return static_cast<std::uint16_t>((word[0] << 8) | word[1]);
}
/// 24-bit two's complement (§8.5.1.9: 7FFFFFh positive full scale, 800000h negative) →
/// int32 by sign extension. Only the first three bytes of the word carry data at 24/32-bit
/// zero-pad word sizes.
constexpr std::int32_t sign_extend24(std::uint32_t raw24) {
  const std::uint32_t v = raw24 & 0x00FFFFFFu;
  return (v & 0x00800000u) != 0 ? static_cast<std::int32_t>(v) - (1 << 24)
                                : static_cast<std::int32_t>(v);
}
constexpr std::int32_t get_code24(std::span<const std::uint8_t> word) {
  return sign_extend24((static_cast<std::uint32_t>(word[0]) << 16) |
                       (static_cast<std::uint32_t>(word[1]) << 8) | word[2]);
}
constexpr void put_code24(std::span<std::uint8_t> word, std::int32_t code) {
  const auto u = static_cast<std::uint32_t>(code) & 0x00FFFFFFu;
  word[0] = static_cast<std::uint8_t>(u >> 16);
  word[1] = static_cast<std::uint8_t>((u >> 8) & 0xFF);
  word[2] = static_cast<std::uint8_t>(u & 0xFF);
  for (std::size_t i = 3; i < word.size(); ++i) word[i] = 0;
}

// ---------------------------------------------------------------------------------------------
// CRC (§8.3.12, Table 8-7): CCITT x^16 + x^12 + x^5 + 1 (1021h), seed FFFFh, MSB first, no
// reflection, no final XOR (the CRC-16/CCITT-FALSE parameters: check value of "123456789" is
// 29B1h). It covers every word of the frame before the CRC word, padding bits included. The
// output CRC is always present; the input CRC is checked only when MODE.RX_CRC_EN = 1.
// ---------------------------------------------------------------------------------------------
inline constexpr std::uint16_t kCrcPolyCcitt = 0x1021;
inline constexpr std::uint16_t kCrcSeed = 0xFFFF;

namespace detail {
constexpr std::array<std::uint16_t, 256> make_crc_table() {
  std::array<std::uint16_t, 256> t{};
  for (std::uint32_t i = 0; i < 256; ++i) {
    std::uint32_t r = i << 8;
    for (int b = 0; b < 8; ++b) r = (r & 0x8000u) != 0 ? (r << 1) ^ kCrcPolyCcitt : r << 1;
    t[i] = static_cast<std::uint16_t>(r & 0xFFFF);
  }
  return t;
}
inline constexpr std::array<std::uint16_t, 256> kCrcTable = make_crc_table();
}  // namespace detail

/// CRC-16-CCITT of `bytes` starting from `crc` (table driven: one lookup per byte, so a
/// 21-byte frame costs 21 lookups on the sample path).
constexpr std::uint16_t crc16_ccitt(std::span<const std::uint8_t> bytes,
                                    std::uint16_t crc = kCrcSeed) {
  for (const std::uint8_t b : bytes) {
    crc = static_cast<std::uint16_t>((crc << 8) ^ detail::kCrcTable[((crc >> 8) ^ b) & 0xFF]);
  }
  return crc;
}

/// The data rate fDATA = fCLKIN / 2 / OSR (§8.3.6 eq. fMOD = fCLKIN / 2; §8.3.7 eq. 5).
constexpr double data_rate_hz(double clkin_hz, std::uint32_t osr) {
  return clkin_hz / 2.0 / static_cast<double>(osr);
}

}  // namespace gfins::drivers::ads131m06
