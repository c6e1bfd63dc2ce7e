// The ADS131M06 driver against scripted SPI transactions: every byte the driver must send and
// every byte the chip answers is written here from the datasheet (TI SBAS949A), independently
// of the driver's register header: Table 8-11 (command words and responses), Table 8-12
// (register addresses, reset values, bit positions), §8.5.1.7 (8 words per frame: response,
// 6 channels, CRC; at the default 24-bit word size each word is 3 bytes, 16-bit content MSB
// first then one zero byte), §8.5.1.9 (24-bit two's complement data), §8.3.12 (CRC-16-CCITT,
// 1021h, seed FFFFh, over every byte before the CRC word).
#include <gtest/gtest.h>

#include <cstdint>
#include <deque>
#include <initializer_list>
#include <vector>

#include "gfins/drivers/ads131m06.hpp"

namespace {

using gfins::ErrorCode;
using gfins::RawSample;
using gfins::Result;
using gfins::Status;
using gfins::drivers::Ads131m06;
using gfins::drivers::Ads131m06Config;
using gfins::drivers::Ads131m06State;
using Bytes = std::vector<std::uint8_t>;

// --- the oracle: byte layout and CRC written from the datasheet ------------------------------

// Bitwise CRC-16-CCITT (§8.3.12): the textbook shift register, not the driver's table.
std::uint16_t crc_ccitt(const Bytes& b) {
  std::uint16_t crc = 0xFFFF;
  for (std::uint8_t byte : b) {
    for (int i = 7; i >= 0; --i) {
      const bool in = ((byte >> i) & 1) != 0;
      const bool top = (crc & 0x8000) != 0;
      crc = static_cast<std::uint16_t>(crc << 1);
      if (in != top) crc ^= 0x1021;
    }
  }
  return crc;
}

void put16(Bytes& b, std::uint16_t w) {  // a 16-bit word in a 24-bit slot: MSB, LSB, pad 00
  b.push_back(static_cast<std::uint8_t>(w >> 8));
  b.push_back(static_cast<std::uint8_t>(w & 0xFF));
  b.push_back(0x00);
}

// DIN: command, data words, CRC of the bytes before it, zeros up to 8 words (§8.5.1.7).
Bytes din(std::uint16_t command, std::initializer_list<std::uint16_t> data = {}) {
  Bytes b;
  put16(b, command);
  for (std::uint16_t d : data) put16(b, d);
  put16(b, crc_ccitt(b));
  b.resize(24, 0x00);
  return b;
}

// DOUT: response, six 24-bit codes (MSB first), CRC over the 21 bytes before it.
Bytes dout(std::uint16_t response,
           std::initializer_list<std::uint32_t> codes24 = {0, 0, 0, 0, 0, 0},
           bool corrupt = false) {
  Bytes b;
  put16(b, response);
  for (std::uint32_t c : codes24) {
    b.push_back(static_cast<std::uint8_t>(c >> 16));
    b.push_back(static_cast<std::uint8_t>(c >> 8));
    b.push_back(static_cast<std::uint8_t>(c));
  }
  put16(b, crc_ccitt(b));
  if (corrupt) b[4] ^= 0x10;  // a bit error in channel 0 on the wire
  return b;
}

// Command words (Table 8-11) and register values (Table 8-12), by hand.
constexpr std::uint16_t kNull = 0x0000;      // 0000 0000 0000 0000
constexpr std::uint16_t kReset = 0x0011;     // 0000 0000 0001 0001
constexpr std::uint16_t kResetAck = 0xFF26;  // 1111 1111 0010 0110
constexpr std::uint16_t kRregId = 0xA000;    // 101 000000 0000000: RREG ID (00h), one register
constexpr std::uint16_t kAdsId = 0x2640;     // 26xxh, CHANCNT = 6; low byte arbitrary
// Registers the default configuration writes: MODE (02h), GAIN1 (04h), GAIN2 (05h), CLOCK (03h).
// MODE: RX_CRC_EN (bit 12) | WLENGTH = 01b 24-bit (bits 9:8) | TIMEOUT (bit 4); RESET = 0.
constexpr std::uint16_t kModeValue = 0x1110;
// CLOCK: reserved bit 14 as reset (7F0Eh) | CH5..0_EN | OSR = 101b (4096: 8.192 MHz / 2 / 4096
// = 1000 Hz) at bits 4:2 | PWR = 10b high resolution.
constexpr std::uint16_t kClockValue = 0x7F16;
struct RegWrite {
  std::uint16_t wreg, ack, rreg, value;
};
// WREG 011a aaaa annn nnnn, ack 010a aaaa ammm mmmm, RREG 101a aaaa annn nnnn (a = address).
constexpr RegWrite kMode{0x6100, 0x4100, 0xA100, kModeValue};
constexpr RegWrite kGain1{0x6200, 0x4200, 0xA200, 0x0000};
constexpr RegWrite kGain2{0x6280, 0x4280, 0xA280, 0x0000};
constexpr RegWrite kClock{0x6180, 0x4180, 0xA180, kClockValue};
// STATUS after configuration: WLENGTH 01b (bits 9:8), RESET cleared.
constexpr std::uint16_t kStatusRunning = 0x0100;
constexpr std::uint16_t kStatusAfterReset = 0x0500;  // Table 8-12 reset value
constexpr std::uint16_t kDrdyAll = 0x003F;           // DRDY5..0

// --- fakes -----------------------------------------------------------------------------------

struct Exchange {
  Bytes tx;
  Bytes rx;
};

class ScriptedSpi : public gfins::hal::SpiDevice {
 public:
  void expect(Bytes tx, Bytes rx) { script_.push_back({std::move(tx), std::move(rx)}); }
  bool done() const { return script_.empty(); }
  std::size_t remaining() const { return script_.size(); }

 private:
  Status do_transfer(std::span<const std::uint8_t> tx, std::span<std::uint8_t> rx) override {
    if (script_.empty()) {
      ADD_FAILURE() << "unexpected SPI transfer";
      return Status(ErrorCode::kUnavailable, "script exhausted");
    }
    const Exchange e = script_.front();
    script_.pop_front();
    EXPECT_EQ(Bytes(tx.begin(), tx.end()), e.tx);
    for (std::size_t i = 0; i < rx.size(); ++i) rx[i] = i < e.rx.size() ? e.rx[i] : 0;
    return Status::ok();
  }
  std::deque<Exchange> script_;
};

class ScriptedLine : public gfins::hal::DataReadyLine {
 public:
  void edge(std::int64_t t, std::uint32_t seq) { q_.push_back({t, seq}); }

 private:
  Result<gfins::hal::DataReadyEdge> do_wait_edge(std::int64_t) override {
    if (q_.empty()) return Status(ErrorCode::kTimeout, "no edge");
    const auto e = q_.front();
    q_.pop_front();
    return e;
  }
  std::deque<gfins::hal::DataReadyEdge> q_;
};

// The start-up sequence of the default configuration: RESET, read ID, four write/read-back
// pairs, a final STATUS read. Each command's answer comes in the next frame (Table 8-11).
void script_start(ScriptedSpi& spi, std::uint16_t id = kAdsId) {
  spi.expect(din(kReset), dout(kStatusRunning));
  spi.expect(din(kNull), dout(kResetAck));
  spi.expect(din(kRregId), dout(kStatusAfterReset));
  spi.expect(din(kNull), dout(id));
  if ((id & 0xFF00) != 0x2600) return;  // the driver stops at a wrong ID
  for (const RegWrite& r : {kMode, kGain1, kGain2, kClock}) {
    spi.expect(din(r.wreg, {r.value}), dout(kStatusAfterReset));
    spi.expect(din(kNull), dout(r.ack));
    spi.expect(din(r.rreg), dout(kStatusRunning));
    spi.expect(din(kNull), dout(r.value));
  }
  spi.expect(din(kNull), dout(kStatusRunning));
  spi.expect(din(kNull), dout(kStatusRunning));
}

constexpr std::int64_t kTimeoutNs = 2'000'000;

class Ads131m06Scripted : public ::testing::Test {
 protected:
  Ads131m06Config config() const {
    Ads131m06Config c;
    c.verify_every_frames = 0;  // tests that want re-verification turn it on
    return c;
  }
  ScriptedSpi spi_;
  ScriptedLine line_;
};

TEST_F(Ads131m06Scripted, StartUpSequenceMatchesTheDatasheetBytes) {
  script_start(spi_);
  Ads131m06 adc(spi_, line_, config());
  ASSERT_TRUE(adc.start().is_ok());
  EXPECT_TRUE(spi_.done());
  EXPECT_EQ(adc.state(), Ads131m06State::kRun);
  EXPECT_EQ(adc.osr(), 4096u);
  EXPECT_EQ(adc.counters().register_mismatches, 0u);
  // 1 LSB = 1.2 V / 2^23 at gain 1 (§8.5.1.9).
  EXPECT_DOUBLE_EQ(adc.volts_per_count(), 1.2 / 8388608.0);
}

TEST_F(Ads131m06Scripted, DataFrameIsDecodedWithSignExtension) {
  script_start(spi_);
  Ads131m06 adc(spi_, line_, config());
  ASSERT_TRUE(adc.start().is_ok());
  line_.edge(123456789, 41);
  spi_.expect(din(kNull), dout(kStatusRunning | kDrdyAll,
                               {0x000001, 0x7FFFFF, 0x800000, 0xFFFFFF, 0x123456, 0xABCDEF}));
  const Result<RawSample> s = adc.read_sample(kTimeoutNs);
  ASSERT_TRUE(s.is_ok());
  EXPECT_EQ(s->seq, 41u);
  EXPECT_EQ(s->t_ns, 123456789);
  EXPECT_EQ(s->counts[0], 1);
  EXPECT_EQ(s->counts[1], 8388607);   // positive full scale
  EXPECT_EQ(s->counts[2], -8388608);  // negative full scale
  EXPECT_EQ(s->counts[3], -1);
  EXPECT_EQ(s->counts[4], 0x123456);
  EXPECT_EQ(s->counts[5], 0xABCDEF - 0x1000000);
  EXPECT_NE(s->flags & gfins::sample_flags::kSaturated, 0u);  // channels 1 and 2 at the rails
  EXPECT_EQ(s->flags & gfins::sample_flags::kCrcError, 0u);
  EXPECT_EQ(adc.counters().saturated_samples, 1u);
  EXPECT_TRUE(spi_.done());
}

TEST_F(Ads131m06Scripted, WrongIdFailsStart) {
  script_start(spi_, 0x2400);  // an ADS131M04 (CHANCNT = 4)
  Ads131m06 adc(spi_, line_, config());
  const Status st = adc.start();
  EXPECT_EQ(st.code(), ErrorCode::kUnavailable);
  EXPECT_EQ(adc.state(), Ads131m06State::kFailed);
  EXPECT_TRUE(spi_.done());
  EXPECT_EQ(adc.read_sample(kTimeoutNs).status().code(), ErrorCode::kFailedPrecondition);
}

TEST_F(Ads131m06Scripted, MissingResetAcknowledgmentFailsStart) {
  spi_.expect(din(kReset), dout(0xFFFF));
  spi_.expect(din(kNull), dout(0x0000));  // no FF26h: nothing answering
  Ads131m06 adc(spi_, line_, config());
  EXPECT_EQ(adc.start().code(), ErrorCode::kUnavailable);
  EXPECT_EQ(adc.state(), Ads131m06State::kFailed);
}

TEST_F(Ads131m06Scripted, OutputCrcErrorFlagsTheSample) {
  script_start(spi_);
  Ads131m06 adc(spi_, line_, config());
  ASSERT_TRUE(adc.start().is_ok());
  line_.edge(1000, 7);
  spi_.expect(din(kNull), dout(kStatusRunning | kDrdyAll, {5, 5, 5, 5, 5, 5}, /*corrupt=*/true));
  const Result<RawSample> s = adc.read_sample(kTimeoutNs);
  ASSERT_TRUE(s.is_ok());
  EXPECT_NE(s->flags & gfins::sample_flags::kCrcError, 0u);
  for (std::int32_t c : s->counts) EXPECT_EQ(c, 0);  // not passed on
  EXPECT_EQ(adc.counters().crc_errors, 1u);
  EXPECT_EQ(adc.state(), Ads131m06State::kRun);
}

TEST_F(Ads131m06Scripted, RegisterReadBackMismatchFailsAfterThreeAttempts) {
  spi_.expect(din(kReset), dout(kStatusRunning));
  spi_.expect(din(kNull), dout(kResetAck));
  spi_.expect(din(kRregId), dout(kStatusAfterReset));
  spi_.expect(din(kNull), dout(kAdsId));
  for (int attempt = 0; attempt < 3; ++attempt) {
    spi_.expect(din(kMode.wreg, {kMode.value}), dout(kStatusAfterReset));
    spi_.expect(din(kNull), dout(kMode.ack));
    spi_.expect(din(kMode.rreg), dout(kStatusAfterReset));
    spi_.expect(din(kNull), dout(0x0510));  // still the reset value: the write did not take
  }
  Ads131m06 adc(spi_, line_, config());
  EXPECT_EQ(adc.start().code(), ErrorCode::kDataLoss);
  EXPECT_EQ(adc.counters().register_mismatches, 3u);
  EXPECT_EQ(adc.state(), Ads131m06State::kFailed);
  EXPECT_TRUE(spi_.done());
}

TEST_F(Ads131m06Scripted, TimeoutsAreCountedAndTheThirdTriggersARecovery) {
  script_start(spi_);
  Ads131m06 adc(spi_, line_, config());
  ASSERT_TRUE(adc.start().is_ok());
  EXPECT_EQ(adc.read_sample(kTimeoutNs).status().code(), ErrorCode::kTimeout);
  EXPECT_EQ(adc.read_sample(kTimeoutNs).status().code(), ErrorCode::kTimeout);
  EXPECT_TRUE(spi_.done());  // no frame without an edge
  script_start(spi_);        // the third timeout resets and reconfigures the chip
  EXPECT_EQ(adc.read_sample(kTimeoutNs).status().code(), ErrorCode::kTimeout);
  EXPECT_TRUE(spi_.done());
  EXPECT_EQ(adc.counters().timeouts, 3u);
  EXPECT_EQ(adc.counters().recoveries, 1u);
  EXPECT_EQ(adc.state(), Ads131m06State::kRun);
}

TEST_F(Ads131m06Scripted, ChipResetMidRunIsDetectedAndRecovered) {
  script_start(spi_);
  Ads131m06 adc(spi_, line_, config());
  ASSERT_TRUE(adc.start().is_ok());
  line_.edge(1000, 1);
  spi_.expect(din(kNull), dout(kStatusAfterReset | kDrdyAll));  // STATUS.RESET = 1
  script_start(spi_);
  const Result<RawSample> s = adc.read_sample(kTimeoutNs);
  EXPECT_EQ(s.status().code(), ErrorCode::kDataLoss);
  EXPECT_TRUE(spi_.done());
  EXPECT_EQ(adc.counters().chip_resets, 1u);
  EXPECT_EQ(adc.counters().recoveries, 1u);
  EXPECT_EQ(adc.state(), Ads131m06State::kRun);
  // And the next frame is a normal sample again.
  line_.edge(2000, 2);
  spi_.expect(din(kNull), dout(kStatusRunning | kDrdyAll, {1, 2, 3, 4, 5, 6}));
  const Result<RawSample> next = adc.read_sample(kTimeoutNs);
  ASSERT_TRUE(next.is_ok());
  EXPECT_EQ(next->counts[5], 6);
}

TEST_F(Ads131m06Scripted, FailedRecoveriesEndInFailed) {
  script_start(spi_);
  Ads131m06Config c = config();
  c.max_recovery_attempts = 2;
  Ads131m06 adc(spi_, line_, c);
  ASSERT_TRUE(adc.start().is_ok());
  line_.edge(1000, 1);
  spi_.expect(din(kNull), dout(kStatusAfterReset | kDrdyAll));
  script_start(spi_, 0x0000);  // the chip no longer identifies
  EXPECT_EQ(adc.read_sample(kTimeoutNs).status().code(), ErrorCode::kUnavailable);
  EXPECT_EQ(adc.state(), Ads131m06State::kRecover);
  script_start(spi_, 0x0000);  // the next call retries, fails again: max reached
  EXPECT_EQ(adc.read_sample(kTimeoutNs).status().code(), ErrorCode::kUnavailable);
  EXPECT_EQ(adc.state(), Ads131m06State::kFailed);
  EXPECT_EQ(adc.counters().recoveries, 2u);
  EXPECT_TRUE(spi_.done());
}

TEST_F(Ads131m06Scripted, EdgeSequenceGapCountsMissedEdges) {
  script_start(spi_);
  Ads131m06 adc(spi_, line_, config());
  ASSERT_TRUE(adc.start().is_ok());
  line_.edge(1000, 10);
  line_.edge(4000, 13);  // 11 and 12 never delivered
  spi_.expect(din(kNull), dout(kStatusRunning | kDrdyAll));
  spi_.expect(din(kNull), dout(kStatusRunning | kDrdyAll));
  ASSERT_TRUE(adc.read_sample(kTimeoutNs).is_ok());
  const Result<RawSample> s = adc.read_sample(kTimeoutNs);
  ASSERT_TRUE(s.is_ok());
  EXPECT_EQ(s->seq, 13u);
  EXPECT_EQ(adc.counters().missed_edges, 2u);
}

TEST_F(Ads131m06Scripted, EdgeWithoutNewDataIsSkippedAndTheSequenceKept) {
  script_start(spi_);
  Ads131m06 adc(spi_, line_, config());
  ASSERT_TRUE(adc.start().is_ok());
  line_.edge(1000, 20);  // a glitch: DRDYn all 0 in its frame
  line_.edge(1500, 21);  // the conversion
  spi_.expect(din(kNull), dout(kStatusRunning));
  spi_.expect(din(kNull), dout(kStatusRunning | kDrdyAll, {9, 9, 9, 9, 9, 9}));
  const Result<RawSample> s = adc.read_sample(kTimeoutNs);
  ASSERT_TRUE(s.is_ok());
  EXPECT_EQ(s->seq, 20u);  // the conversion index, not the glitch-shifted edge number
  EXPECT_EQ(s->t_ns, 1500);
  EXPECT_EQ(s->counts[0], 9);
  EXPECT_EQ(adc.counters().extra_edges, 1u);
  EXPECT_EQ(adc.counters().missed_edges, 0u);
}

TEST_F(Ads131m06Scripted, InputCrcErrorReportedByStatusIsCounted) {
  script_start(spi_);
  Ads131m06 adc(spi_, line_, config());
  ASSERT_TRUE(adc.start().is_ok());
  line_.edge(1000, 1);
  spi_.expect(din(kNull), dout(kStatusRunning | 0x1000 | kDrdyAll));  // CRC_ERR (bit 12)
  ASSERT_TRUE(adc.read_sample(kTimeoutNs).is_ok());
  EXPECT_EQ(adc.counters().input_crc_errors, 1u);
}

TEST_F(Ads131m06Scripted, PeriodicReVerificationPiggybacksOnDataFrames) {
  script_start(spi_);
  Ads131m06Config c = config();
  c.verify_every_frames = 2;
  Ads131m06 adc(spi_, line_, c);
  ASSERT_TRUE(adc.start().is_ok());
  for (std::uint32_t k = 0; k < 3; ++k) line_.edge(1000 * k, k);
  spi_.expect(din(kNull), dout(kStatusRunning | kDrdyAll));
  spi_.expect(din(kMode.rreg), dout(kStatusRunning | kDrdyAll));  // 2nd frame carries RREG MODE
  spi_.expect(din(kNull), dout(kModeValue, {3, 3, 3, 3, 3, 3}));  // answer replaces STATUS
  for (int k = 0; k < 3; ++k) ASSERT_TRUE(adc.read_sample(kTimeoutNs).is_ok());
  EXPECT_EQ(adc.counters().register_mismatches, 0u);
  EXPECT_TRUE(spi_.done());
}

TEST_F(Ads131m06Scripted, ReVerificationMismatchIsConfirmedThenRecovered) {
  script_start(spi_);
  Ads131m06Config c = config();
  c.verify_every_frames = 1;
  Ads131m06 adc(spi_, line_, c);
  ASSERT_TRUE(adc.start().is_ok());
  line_.edge(0, 0);
  line_.edge(1000, 1);
  spi_.expect(din(kMode.rreg), dout(kStatusRunning | kDrdyAll));
  spi_.expect(din(kGain1.rreg), dout(0x0510, {1, 1, 1, 1, 1, 1}));  // MODE upset to reset value
  spi_.expect(din(kMode.rreg), dout(kStatusRunning));               // confirmation read
  spi_.expect(din(kNull), dout(0x0510));
  script_start(spi_);
  ASSERT_TRUE(adc.read_sample(kTimeoutNs).is_ok());
  EXPECT_EQ(adc.read_sample(kTimeoutNs).status().code(), ErrorCode::kDataLoss);
  EXPECT_EQ(adc.counters().register_mismatches, 1u);
  EXPECT_EQ(adc.counters().recoveries, 1u);
  EXPECT_EQ(adc.state(), Ads131m06State::kRun);
  EXPECT_TRUE(spi_.done());
}

TEST_F(Ads131m06Scripted, ImpossibleRateIsRefused) {
  Ads131m06Config c = config();
  c.sample_rate_hz = 1200.0;  // 4.096 MHz / 1200 is not one of 128..16384
  Ads131m06 adc(spi_, line_, c);
  EXPECT_EQ(adc.start().code(), ErrorCode::kInvalidArgument);
  EXPECT_TRUE(spi_.done());
}

}  // namespace
