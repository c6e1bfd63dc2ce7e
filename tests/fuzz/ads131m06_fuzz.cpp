// libFuzzer target: the ADS131M06 driver's handling of what comes back over SPI and the
// data-ready line (drivers/ads131m06.hpp). The driver starts against the chip model
// (host_sim/chip), then every transfer is either the model's answer or bytes from the input
// (most with a valid CRC-16, else the fuzzer would stop at the CRC), and every data-ready wait
// an edge (with a sequence jump the input chooses) or a timeout.
// Invariants: a sample the driver returns has 24-bit codes, zero codes when flagged kCrcError,
// sequence numbers that never go back; the fault counters never decrease; the driver never
// reports kRun while it refuses to read, and every error is a Status with a message.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "fuzz_check.hpp"
#include "gfins/drivers/ads131m06.hpp"
#include "gfins/host_sim/chip/ads131m06_model.hpp"

namespace {

constexpr const char* kTarget = "ads131m06";
namespace ads = gfins::drivers::ads131m06;

class FuzzSpi : public gfins::hal::SpiDevice {
 public:
  FuzzSpi(gfins::sim::Ads131m06Model& chip, gfins::fuzz::Bytes& in) : chip_(chip), in_(in) {}
  bool fuzzing = false;

 private:
  gfins::Status do_transfer(std::span<const std::uint8_t> tx, std::span<std::uint8_t> rx) override {
    const gfins::Status st = chip_.transfer(tx, rx);  // the chip sees every command
    if (!fuzzing) return st;
    const std::uint8_t how = in_.u8();
    if ((how & 0x03u) == 0) return st;  // the chip's own answer
    if ((how & 0x03u) == 1) return gfins::Status(gfins::ErrorCode::kIoError, "fuzz: SPI error");
    in_.fill(rx);
    if ((how & 0x04u) == 0 && rx.size() >= ads::kFrameBytes) {
      const std::size_t crc_at = ads::kFrameBytes - ads::kWordBytes;
      const std::uint16_t c = ads::crc16_ccitt(rx.first(crc_at));
      rx[crc_at] = static_cast<std::uint8_t>(c >> 8);
      rx[crc_at + 1] = static_cast<std::uint8_t>(c & 0xFF);
    }
    return gfins::Status();
  }

  gfins::sim::Ads131m06Model& chip_;
  gfins::fuzz::Bytes& in_;
};

class FuzzDrdy : public gfins::hal::DataReadyLine {
 public:
  FuzzDrdy(gfins::sim::Ads131m06Model& chip, gfins::fuzz::Bytes& in) : chip_(chip), in_(in) {}
  bool fuzzing = false;

 private:
  gfins::Result<gfins::hal::DataReadyEdge> do_wait_edge(std::int64_t /*timeout_ns*/) override {
    std::uint32_t jump = 1;
    if (fuzzing) {
      const std::uint8_t how = in_.u8();
      if ((how & 0x07u) == 0) return gfins::Status(gfins::ErrorCode::kTimeout, "fuzz: timeout");
      if ((how & 0x08u) != 0) jump = 1u + (how >> 4);  // 1 to 16 edges missed
    }
    gfins::sim::Ads131m06Model::Codes codes{};
    for (std::size_t j = 0; j < codes.size(); ++j)
      codes[j] = static_cast<std::int32_t>(j * 1000 + seq_);
    chip_.convert_codes(codes);
    seq_ += jump;
    t_ns_ += 1'000'000;
    return gfins::hal::DataReadyEdge{t_ns_, seq_};
  }

  gfins::sim::Ads131m06Model& chip_;
  gfins::fuzz::Bytes& in_;
  std::uint32_t seq_ = 0;
  std::int64_t t_ns_ = 0;
};

bool counters_grew(const gfins::drivers::Ads131m06Counters& a,
                   const gfins::drivers::Ads131m06Counters& b) {
  return b.crc_errors >= a.crc_errors && b.missed_edges >= a.missed_edges &&
         b.extra_edges >= a.extra_edges && b.register_mismatches >= a.register_mismatches &&
         b.spi_errors >= a.spi_errors;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  gfins::fuzz::Bytes in(data, size);
  gfins::sim::Ads131m06Model chip;
  FuzzSpi spi(chip, in);
  FuzzDrdy drdy(chip, in);
  gfins::drivers::Ads131m06Config cfg;
  cfg.verify_every_frames = 3;  // the periodic register check every few frames
  cfg.stuck_after_frames = 4;
  gfins::drivers::Ads131m06 adc(spi, drdy, cfg);
  if (!adc.start().is_ok()) gfins::fuzz::fail(kTarget, "the driver starts on the chip model");
  spi.fuzzing = true;
  drdy.fuzzing = true;
  gfins::drivers::Ads131m06Counters before = adc.counters();
  std::uint32_t last_seq = 0;
  bool have_seq = false;
  for (int reads = 0; reads < 4096 && !in.empty(); ++reads) {
    const auto r = adc.read_sample(1'000'000);
    gfins::fuzz::check(counters_grew(before, adc.counters()), kTarget, "counters never decrease");
    before = adc.counters();
    if (!r.is_ok()) {
      gfins::fuzz::check(r.status().message()[0] != '\0', kTarget, "an error says why");
      if (adc.state() == gfins::drivers::Ads131m06State::kFailed) break;
      continue;
    }
    const gfins::RawSample& s = r.value();
    for (const std::int32_t c : s.counts) {
      gfins::fuzz::check(c >= gfins::kAdcCodeMin && c <= gfins::kAdcCodeMax, kTarget,
                         "codes are 24-bit");
      if ((s.flags & gfins::sample_flags::kCrcError) != 0) {
        gfins::fuzz::check(c == 0, kTarget, "a CRC error's codes are zeroed");
      }
    }
    gfins::fuzz::check(!have_seq || s.seq > last_seq, kTarget, "sequence numbers advance");
    last_seq = s.seq;
    have_seq = true;
  }
  return 0;
}
