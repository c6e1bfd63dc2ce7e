// The ADS131M06 driver against scripted SPI transactions: every byte the driver must send and
// every byte the chip answers is written here from the datasheet (TI SBAS949A), independently
// of the driver's register header: Table 8-11 (command words and responses), Table 8-12
// (register addresses, reset values, bit positions), §8.5.1.7 (8 words per frame: response,
// 6 channels, CRC; at the default 24-bit word size each word is 3 bytes, 16-bit content MSB
// first then one zero byte), §8.5.1.9 (24-bit two's complement data), §8.3.12 (CRC-16-CCITT,
// 1021h, seed FFFFh, over every byte before the CRC word).
#include <gtest/gtest.h>

#include <array>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
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
using gfins::drivers::Ads131m06Counters;
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
constexpr std::uint16_t kStatusCrcErr = 0x1000;      // CRC_ERR (bit 12): an input CRC error
constexpr std::uint16_t kModeResetValue = 0x0510;    // Table 8-12

// A failed transfer as the Linux spidev backend reports it: kIoError with errno (EIO).
constexpr Status kSpiEio(ErrorCode::kIoError, "spidev: SPI_IOC_MESSAGE failed", EIO);

// --- fakes -----------------------------------------------------------------------------------

struct Exchange {
  Bytes tx;
  Bytes rx;
  Status result;  // what the backend reports (ok, or the failure of a broken transfer)
};

class ScriptedSpi : public gfins::hal::SpiDevice {
 public:
  void expect(Bytes tx, Bytes rx) { script_.push_back({std::move(tx), std::move(rx), {}}); }
  /// A transfer the backend reports as failed (spidev: ioctl(SPI_IOC_MESSAGE) returned -1):
  /// the driver must have sent `tx`; `rx` is left holding `rx_junk`, which it must not decode.
  void fail(Bytes tx, Status error, Bytes rx_junk) {
    script_.push_back({std::move(tx), std::move(rx_junk), error});
  }
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
    return e.result;
  }
  std::deque<Exchange> script_;
};

class ScriptedLine : public gfins::hal::DataReadyLine {
 public:
  void edge(std::int64_t t, std::uint32_t seq) { q_.push_back(Result<Edge>(Edge{t, seq})); }
  /// A failure of the line itself (libgpiod read error), not a timeout.
  void error(Status st) { q_.push_back(Result<Edge>(st)); }

 private:
  using Edge = gfins::hal::DataReadyEdge;
  Result<Edge> do_wait_edge(std::int64_t) override {
    if (q_.empty()) return Status(ErrorCode::kTimeout, "no edge");
    const Result<Edge> e = q_.front();
    q_.pop_front();
    return e;
  }
  std::deque<Result<Edge>> q_;
};

// RESET, then read ID. Each command's answer comes in the next frame (Table 8-11).
void script_reset_and_id(ScriptedSpi& spi, std::uint16_t id = kAdsId) {
  spi.expect(din(kReset), dout(kStatusRunning));
  spi.expect(din(kNull), dout(kResetAck));
  spi.expect(din(kRregId), dout(kStatusAfterReset));
  spi.expect(din(kNull), dout(id));
}

// One register written, acknowledged, read back and found as written.
void script_register(ScriptedSpi& spi, const RegWrite& r) {
  spi.expect(din(r.wreg, {r.value}), dout(kStatusAfterReset));
  spi.expect(din(kNull), dout(r.ack));
  spi.expect(din(r.rreg), dout(kStatusRunning));
  spi.expect(din(kNull), dout(r.value));
}

// The final STATUS read (a NULL, answered by STATUS in the next frame).
void script_final_status(ScriptedSpi& spi, std::uint16_t status = kStatusRunning) {
  spi.expect(din(kNull), dout(kStatusRunning));
  spi.expect(din(kNull), dout(status));
}

// The start-up sequence of the default configuration: RESET, read ID, four write/read-back
// pairs, a final STATUS read.
void script_start(ScriptedSpi& spi, std::uint16_t id = kAdsId) {
  script_reset_and_id(spi, id);
  if ((id & 0xFF00) != 0x2600) return;  // the driver stops at a wrong ID
  for (const RegWrite& r : {kMode, kGain1, kGain2, kClock}) script_register(spi, r);
  script_final_status(spi);
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

// --- SPI transfer failures -------------------------------------------------------------------
//
// A transfer the SPI backend reports as failed is one the driver cannot trust: it must not
// decode what the receive buffer holds and must not assume the chip saw the command. The chip,
// for its part, answers each frame with the response to the last command it received
// (§8.5.1.10, Table 8-11), so after a frame that never reached it the next response word is
// still the answer to the frame before.

// What the receive buffer holds after a failed transfer: a well-formed frame (valid CRC) that,
// were it decoded, would read as a chip reset (STATUS.RESET) with every channel at positive full
// scale, so a driver that trusted it would start a recovery the script does not allow.
Bytes junk_frame() {
  return dout(kStatusAfterReset | kDrdyAll,
              {0x7FFFFF, 0x7FFFFF, 0x7FFFFF, 0x7FFFFF, 0x7FFFFF, 0x7FFFFF});
}

TEST_F(Ads131m06Scripted, SpiFailureWhileRunningIsPassedOnCountedAndTheNextFrameReadsNormally) {
  script_start(spi_);
  Ads131m06 adc(spi_, line_, config());
  ASSERT_TRUE(adc.start().is_ok());
  line_.edge(1000, 5);
  spi_.fail(din(kNull), kSpiEio, junk_frame());
  const Result<RawSample> lost = adc.read_sample(kTimeoutNs);
  ASSERT_FALSE(lost.is_ok());
  // The backend's error reaches the caller unchanged: code, text and errno.
  EXPECT_EQ(lost.status().code(), ErrorCode::kIoError);
  EXPECT_STREQ(lost.status().message(), kSpiEio.message());
  EXPECT_EQ(lost.status().os_error(), EIO);
  EXPECT_TRUE(spi_.done());  // one frame tried: no retry inside the call, no reset
  EXPECT_EQ(adc.counters().spi_errors, 1u);
  EXPECT_EQ(adc.counters().frames, 0u);  // nothing was read
  EXPECT_EQ(adc.counters().crc_errors, 0u);
  EXPECT_EQ(adc.counters().chip_resets, 0u);  // the junk was not decoded
  EXPECT_EQ(adc.counters().saturated_samples, 0u);
  EXPECT_EQ(adc.counters().recoveries, 0u);
  EXPECT_EQ(adc.counters().missed_edges, 0u);  // the edge itself arrived
  EXPECT_EQ(adc.state(), Ads131m06State::kRun);
  const Ads131m06Counters after_failure = adc.counters();
  const Ads131m06State state_after_failure = adc.state();

  // SPI works again: the next conversion is read with a plain NULL frame; its response word is
  // STATUS (the answer to the last NULL the chip received) with DRDY5..0 set.
  line_.edge(2000, 6);
  spi_.expect(din(kNull), dout(kStatusRunning | kDrdyAll, {1, 2, 3, 0xFFFFFE, 0x400000, 0xC00000}));
  const Result<RawSample> next = adc.read_sample(kTimeoutNs);
  ASSERT_TRUE(next.is_ok());
  EXPECT_EQ(next->seq, 6u);  // conversion 5 is a gap in the sequence, as any lost sample
  EXPECT_EQ(next->t_ns, 2000);
  const std::array<std::int32_t, 6> want = {1, 2, 3, -2, 0x400000, -0x400000};  // §8.5.1.9
  EXPECT_EQ(next->counts, want);
  EXPECT_EQ(next->flags, 0u);
  EXPECT_EQ(adc.counters().frames, 1u);
  EXPECT_EQ(adc.counters().spi_errors, 1u);
  EXPECT_EQ(adc.state(), Ads131m06State::kRun);
  EXPECT_TRUE(spi_.done());
  std::printf(
      "SPI failure while running: read_sample -> %s (errno %d), spi_errors %u, frames %u, "
      "state %s; SPI back: seq %u, counts %d %d %d %d %d %d, frames %u, state %s\n",
      gfins::to_string(lost.status().code()), lost.status().os_error(),
      static_cast<unsigned>(after_failure.spi_errors), static_cast<unsigned>(after_failure.frames),
      to_string(state_after_failure), static_cast<unsigned>(next->seq), next->counts[0],
      next->counts[1], next->counts[2], next->counts[3], next->counts[4], next->counts[5],
      static_cast<unsigned>(adc.counters().frames), to_string(adc.state()));
}

TEST_F(Ads131m06Scripted, SpiFailureOnAReVerificationFrameSendsTheRregAgain) {
  script_start(spi_);
  Ads131m06Config c = config();
  c.verify_every_frames = 2;
  Ads131m06 adc(spi_, line_, c);
  ASSERT_TRUE(adc.start().is_ok());
  for (std::uint32_t k = 0; k < 4; ++k) line_.edge(1000 * k, k);
  spi_.expect(din(kNull), dout(kStatusRunning | kDrdyAll));
  spi_.fail(din(kMode.rreg), kSpiEio, junk_frame());  // the RREG MODE never reached the chip
  // So the next frame carries it again, and its response is still STATUS (the answer to the
  // NULL of the first frame), not MODE.
  spi_.expect(din(kMode.rreg), dout(kStatusRunning | kDrdyAll, {7, 7, 7, 7, 7, 7}));
  spi_.expect(din(kNull), dout(kModeValue, {8, 8, 8, 8, 8, 8}));  // MODE, as written
  ASSERT_TRUE(adc.read_sample(kTimeoutNs).is_ok());
  EXPECT_EQ(adc.read_sample(kTimeoutNs).status().code(), ErrorCode::kIoError);
  const Result<RawSample> a = adc.read_sample(kTimeoutNs);
  ASSERT_TRUE(a.is_ok());
  EXPECT_EQ(a->counts[0], 7);
  const Result<RawSample> b = adc.read_sample(kTimeoutNs);
  ASSERT_TRUE(b.is_ok());
  EXPECT_EQ(b->counts[0], 8);
  EXPECT_TRUE(spi_.done());
  EXPECT_EQ(adc.counters().spi_errors, 1u);
  EXPECT_EQ(adc.counters().register_mismatches, 0u);
  EXPECT_EQ(adc.counters().recoveries, 0u);
  EXPECT_EQ(adc.state(), Ads131m06State::kRun);
}

TEST_F(Ads131m06Scripted, SpiFailureDuringStartFailsItAndStartSucceedsOnceSpiWorks) {
  spi_.fail(din(kReset), kSpiEio, junk_frame());
  Ads131m06 adc(spi_, line_, config());
  const Status st = adc.start();
  EXPECT_EQ(st.code(), ErrorCode::kIoError);
  EXPECT_EQ(st.os_error(), EIO);
  EXPECT_EQ(adc.state(), Ads131m06State::kFailed);
  EXPECT_EQ(adc.counters().spi_errors, 1u);
  EXPECT_TRUE(spi_.done());
  EXPECT_EQ(adc.read_sample(kTimeoutNs).status().code(), ErrorCode::kFailedPrecondition);
  EXPECT_TRUE(spi_.done());  // a failed driver sends nothing
  script_start(spi_);        // start() may be called again
  ASSERT_TRUE(adc.start().is_ok());
  EXPECT_EQ(adc.state(), Ads131m06State::kRun);
  EXPECT_TRUE(spi_.done());
}

TEST_F(Ads131m06Scripted, SpiFailureOnARegisterWriteIsRetried) {
  script_reset_and_id(spi_);
  spi_.fail(din(kMode.wreg, {kMode.value}), kSpiEio, junk_frame());
  for (const RegWrite& r : {kMode, kGain1, kGain2, kClock}) script_register(spi_, r);
  script_final_status(spi_);
  Ads131m06 adc(spi_, line_, config());
  ASSERT_TRUE(adc.start().is_ok());
  EXPECT_EQ(adc.state(), Ads131m06State::kRun);
  EXPECT_EQ(adc.counters().spi_errors, 1u);
  EXPECT_EQ(adc.counters().register_mismatches, 0u);
  EXPECT_TRUE(spi_.done());
}

TEST_F(Ads131m06Scripted, SpiFailureDuringARecoveryStaysInRecoverAndTheNextCallRecovers) {
  script_start(spi_);
  Ads131m06 adc(spi_, line_, config());
  ASSERT_TRUE(adc.start().is_ok());
  line_.edge(1000, 1);
  spi_.expect(din(kNull), dout(kStatusAfterReset | kDrdyAll));  // STATUS.RESET: chip reset
  spi_.fail(din(kReset), kSpiEio, junk_frame());                // the recovery's RESET is lost
  EXPECT_EQ(adc.read_sample(kTimeoutNs).status().code(), ErrorCode::kIoError);
  EXPECT_EQ(adc.state(), Ads131m06State::kRecover);
  EXPECT_EQ(adc.counters().chip_resets, 1u);
  EXPECT_EQ(adc.counters().recoveries, 1u);
  EXPECT_EQ(adc.counters().spi_errors, 1u);
  EXPECT_TRUE(spi_.done());
  // SPI works again: the next call finishes the recovery first, then reads the conversion.
  script_start(spi_);
  line_.edge(2000, 2);
  spi_.expect(din(kNull), dout(kStatusRunning | kDrdyAll, {4, 4, 4, 4, 4, 4}));
  const Result<RawSample> s = adc.read_sample(kTimeoutNs);
  ASSERT_TRUE(s.is_ok());
  EXPECT_EQ(s->seq, 2u);
  EXPECT_EQ(s->counts[5], 4);
  EXPECT_EQ(adc.state(), Ads131m06State::kRun);
  EXPECT_EQ(adc.counters().recoveries, 2u);
  EXPECT_TRUE(spi_.done());
}

// --- the other error paths of start() --------------------------------------------------------

TEST_F(Ads131m06Scripted, OutputCrcErrorOnTheResetAcknowledgmentFailsStart) {
  spi_.expect(din(kReset), dout(kStatusRunning));
  spi_.expect(din(kNull), dout(kResetAck, {0, 0, 0, 0, 0, 0}, /*corrupt=*/true));
  Ads131m06 adc(spi_, line_, config());
  EXPECT_EQ(adc.start().code(), ErrorCode::kDataLoss);
  EXPECT_EQ(adc.counters().crc_errors, 1u);
  EXPECT_EQ(adc.state(), Ads131m06State::kFailed);
  EXPECT_TRUE(spi_.done());
}

TEST_F(Ads131m06Scripted, OutputCrcErrorOnARegisterReadBackIsRetried) {
  script_reset_and_id(spi_);
  spi_.expect(din(kMode.wreg, {kMode.value}), dout(kStatusAfterReset));
  spi_.expect(din(kNull), dout(kMode.ack));
  spi_.expect(din(kMode.rreg), dout(kStatusRunning));
  spi_.expect(din(kNull), dout(kMode.value, {0, 0, 0, 0, 0, 0}, /*corrupt=*/true));
  for (const RegWrite& r : {kMode, kGain1, kGain2, kClock}) script_register(spi_, r);
  script_final_status(spi_);
  Ads131m06 adc(spi_, line_, config());
  ASSERT_TRUE(adc.start().is_ok());
  EXPECT_EQ(adc.counters().crc_errors, 1u);
  EXPECT_EQ(adc.counters().register_mismatches, 0u);  // a garbled frame is not a mismatch
  EXPECT_TRUE(spi_.done());
}

TEST_F(Ads131m06Scripted, InputCrcErrorOnARegisterWriteIsCountedAndTheWriteRetried) {
  script_reset_and_id(spi_);
  // §8.3.12: the chip saw a bad input CRC: STATUS with CRC_ERR comes back instead of the WREG
  // acknowledgment, and the read-back still shows MODE's reset value.
  spi_.expect(din(kMode.wreg, {kMode.value}), dout(kStatusAfterReset));
  spi_.expect(din(kNull), dout(kStatusAfterReset | kStatusCrcErr));
  spi_.expect(din(kMode.rreg), dout(kStatusAfterReset));
  spi_.expect(din(kNull), dout(kModeResetValue));
  for (const RegWrite& r : {kMode, kGain1, kGain2, kClock}) script_register(spi_, r);
  script_final_status(spi_);
  Ads131m06 adc(spi_, line_, config());
  ASSERT_TRUE(adc.start().is_ok());
  EXPECT_EQ(adc.counters().input_crc_errors, 1u);
  EXPECT_EQ(adc.counters().register_mismatches, 1u);
  EXPECT_EQ(adc.state(), Ads131m06State::kRun);
  EXPECT_TRUE(spi_.done());
}

TEST_F(Ads131m06Scripted, StatusAfterConfigurationMustShowResetClearedAnd24BitWords) {
  // STATUS (Table 8-12): RESET is bit 10, WLENGTH bits 9:8 (01b = 24 bits, 10b = 32 bits).
  const std::uint16_t reset_still_set = 0x0500;
  const std::uint16_t words_32_bit = 0x0200;
  for (const std::uint16_t status : {reset_still_set, words_32_bit}) {
    ScriptedSpi spi;
    script_reset_and_id(spi);
    for (const RegWrite& r : {kMode, kGain1, kGain2, kClock}) script_register(spi, r);
    script_final_status(spi, status);
    Ads131m06 adc(spi, line_, config());
    EXPECT_EQ(adc.start().code(), ErrorCode::kDataLoss) << std::hex << status;
    EXPECT_EQ(adc.state(), Ads131m06State::kFailed);
    EXPECT_TRUE(spi.done());
  }
  // CRC_ERR in that STATUS is counted but does not fail the start.
  script_reset_and_id(spi_);
  for (const RegWrite& r : {kMode, kGain1, kGain2, kClock}) script_register(spi_, r);
  script_final_status(spi_, kStatusRunning | kStatusCrcErr);
  Ads131m06 adc(spi_, line_, config());
  ASSERT_TRUE(adc.start().is_ok());
  EXPECT_EQ(adc.counters().input_crc_errors, 1u);
}

TEST_F(Ads131m06Scripted, ImpossibleGainOrReferenceIsRefusedWithoutTouchingTheChip) {
  // PGAGAIN is 3 bits: gains 1, 2, 4, ..., 128 (Table 8-12); the reference must be positive.
  for (const std::uint8_t gain : {std::uint8_t{0}, std::uint8_t{3}, std::uint8_t{255}}) {
    Ads131m06Config c = config();
    c.pga_gain[2] = gain;
    Ads131m06 adc(spi_, line_, c);
    EXPECT_EQ(adc.start().code(), ErrorCode::kInvalidArgument) << int{gain};
    EXPECT_EQ(adc.state(), Ads131m06State::kFailed);
  }
  for (const double vref : {0.0, -1.2, std::nan("")}) {
    Ads131m06Config c = config();
    c.vref_v = vref;
    Ads131m06 adc(spi_, line_, c);
    EXPECT_EQ(adc.start().code(), ErrorCode::kInvalidArgument) << vref;
  }
  EXPECT_TRUE(spi_.done());
}

// --- the other error paths of read_sample() --------------------------------------------------

TEST_F(Ads131m06Scripted, DataReadyLineErrorIsPassedOnWithoutAFrameOrATimeoutCount) {
  script_start(spi_);
  Ads131m06 adc(spi_, line_, config());
  ASSERT_TRUE(adc.start().is_ok());
  const Status gpio_error(ErrorCode::kIoError, "gpiod: reading the line event failed", EIO);
  line_.error(gpio_error);
  const Result<RawSample> r = adc.read_sample(kTimeoutNs);
  EXPECT_EQ(r.status().code(), ErrorCode::kIoError);
  EXPECT_STREQ(r.status().message(), gpio_error.message());
  EXPECT_EQ(adc.counters().timeouts, 0u);
  EXPECT_EQ(adc.counters().frames, 0u);
  EXPECT_EQ(adc.state(), Ads131m06State::kRun);
  EXPECT_TRUE(spi_.done());  // no frame without an edge
  line_.edge(1000, 1);
  spi_.expect(din(kNull), dout(kStatusRunning | kDrdyAll, {2, 2, 2, 2, 2, 2}));
  ASSERT_TRUE(adc.read_sample(kTimeoutNs).is_ok());
}

TEST_F(Ads131m06Scripted, EdgesWithoutNewDataAtTheLimitEndTheRead) {
  script_start(spi_);
  Ads131m06 adc(spi_, line_, config());
  ASSERT_TRUE(adc.start().is_ok());
  for (int k = 0; k < Ads131m06::kMaxEdgesPerRead; ++k) {
    line_.edge(1000 + k, static_cast<std::uint32_t>(10 + k));
    spi_.expect(din(kNull), dout(kStatusRunning));  // DRDY5..0 all 0: no conversion
  }
  EXPECT_EQ(adc.read_sample(kTimeoutNs).status().code(), ErrorCode::kUnavailable);
  EXPECT_EQ(adc.counters().extra_edges, static_cast<std::uint32_t>(Ads131m06::kMaxEdgesPerRead));
  EXPECT_EQ(adc.state(), Ads131m06State::kRun);
  EXPECT_TRUE(spi_.done());
}

TEST_F(Ads131m06Scripted, ReVerificationAnsweredByStatusWithCrcErrIsConfirmedNotRecovered) {
  script_start(spi_);
  Ads131m06Config c = config();
  c.verify_every_frames = 1;
  Ads131m06 adc(spi_, line_, c);
  ASSERT_TRUE(adc.start().is_ok());
  line_.edge(0, 0);
  line_.edge(1000, 1);
  spi_.expect(din(kMode.rreg), dout(kStatusRunning | kDrdyAll));
  // The chip dropped RREG MODE (input CRC error): STATUS with CRC_ERR instead of MODE.
  spi_.expect(din(kGain1.rreg),
              dout(kStatusRunning | kStatusCrcErr | kDrdyAll, {3, 3, 3, 3, 3, 3}));
  spi_.expect(din(kMode.rreg), dout(kGain1.value));  // confirmation read (answers RREG GAIN1)
  spi_.expect(din(kNull), dout(kModeValue));         // MODE is as written
  ASSERT_TRUE(adc.read_sample(kTimeoutNs).is_ok());
  const Result<RawSample> s = adc.read_sample(kTimeoutNs);
  ASSERT_TRUE(s.is_ok());
  EXPECT_EQ(s->counts[0], 3);
  EXPECT_EQ(adc.counters().input_crc_errors, 1u);
  EXPECT_EQ(adc.counters().register_mismatches, 0u);
  EXPECT_EQ(adc.counters().recoveries, 0u);
  EXPECT_TRUE(spi_.done());
}

TEST_F(Ads131m06Scripted, ReVerificationWhoseConfirmationFailsIsRecovered) {
  script_start(spi_);
  Ads131m06Config c = config();
  c.verify_every_frames = 1;
  Ads131m06 adc(spi_, line_, c);
  ASSERT_TRUE(adc.start().is_ok());
  line_.edge(0, 0);
  line_.edge(1000, 1);
  spi_.expect(din(kMode.rreg), dout(kStatusRunning | kDrdyAll));
  spi_.expect(din(kGain1.rreg), dout(kStatusRunning | kStatusCrcErr | kDrdyAll));
  spi_.fail(din(kMode.rreg), kSpiEio, junk_frame());  // the confirmation read is lost
  script_start(spi_);  // unconfirmed: reset and write the table again
  ASSERT_TRUE(adc.read_sample(kTimeoutNs).is_ok());
  EXPECT_EQ(adc.read_sample(kTimeoutNs).status().code(), ErrorCode::kDataLoss);
  EXPECT_EQ(adc.counters().spi_errors, 1u);
  EXPECT_EQ(adc.counters().register_mismatches, 1u);
  EXPECT_EQ(adc.counters().recoveries, 1u);
  EXPECT_EQ(adc.state(), Ads131m06State::kRun);
  EXPECT_TRUE(spi_.done());
}

TEST_F(Ads131m06Scripted, ARecoveryAfterTimeoutsThatFailsReturnsItsErrorAndStaysInRecover) {
  script_start(spi_);
  Ads131m06 adc(spi_, line_, config());
  ASSERT_TRUE(adc.start().is_ok());
  EXPECT_EQ(adc.read_sample(kTimeoutNs).status().code(), ErrorCode::kTimeout);
  EXPECT_EQ(adc.read_sample(kTimeoutNs).status().code(), ErrorCode::kTimeout);
  script_reset_and_id(spi_, 0x0000);  // the third timeout's recovery: the chip does not identify
  EXPECT_EQ(adc.read_sample(kTimeoutNs).status().code(), ErrorCode::kUnavailable);
  EXPECT_EQ(adc.state(), Ads131m06State::kRecover);
  EXPECT_EQ(adc.counters().timeouts, 3u);
  EXPECT_EQ(adc.counters().recoveries, 1u);
  EXPECT_TRUE(spi_.done());
}

}  // namespace
