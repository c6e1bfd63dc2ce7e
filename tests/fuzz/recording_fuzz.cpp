// libFuzzer target: the raw-sample recording decoder (sim::decode_recording,
// docs/recording-format.md). When the first input byte is odd the harness first writes the
// header CRC and every block CRC the bytes' own records_per_block implies, so the fuzzer reaches
// the checks behind the CRCs. Invariants: an accepted recording, encoded again, decodes to the
// same records and re-encodes to the same bytes (encode and decode agree on every field), and
// every accepted record's counts are 24-bit codes. Frame records (version 2) take part: they are
// re-encoded between the samples they followed.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <vector>

#include "fuzz_check.hpp"
#include "gfins/host_sim/recording.hpp"

namespace {

constexpr const char* kTarget = "recording";
namespace rec = gfins::recording;

void seal_crcs(std::vector<std::uint8_t>& b) {
  if (b.size() < rec::kHeaderBytes) return;
  const std::uint32_t h = rec::crc32(std::span<const std::uint8_t>(b.data(), 380));
  for (int i = 0; i < 4; ++i)
    b[380 + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(h >> (8 * i));
  std::uint32_t per_block = 0;
  std::memcpy(&per_block, b.data() + 16, sizeof per_block);  // little-endian host (x86, ARM)
  if (per_block == 0 || per_block > (1u << 20)) return;
  std::size_t pos = rec::kHeaderBytes;
  while (pos + rec::kRecordBytes + rec::kCrcBytes <= b.size()) {
    const std::size_t full = std::size_t{per_block} * rec::kRecordBytes;
    const std::size_t left = b.size() - pos - rec::kCrcBytes;
    const std::size_t records = left >= full ? full : left / rec::kRecordBytes * rec::kRecordBytes;
    rec::put_block_crc(
        std::span<const std::uint8_t>(b.data() + pos, records),
        std::span<std::uint8_t, rec::kCrcBytes>(b.data() + pos + records, rec::kCrcBytes));
    pos += records + rec::kCrcBytes;
  }
}

std::vector<std::uint8_t> encode(const gfins::sim::Recording& r) {
  gfins::sim::RecordingHeader h = r.header;
  h.version = rec::kVersion;  // a version-1 file is written again as the current version
  auto e = gfins::sim::encode_recording(h, r.samples, r.frames);
  gfins::fuzz::check(e.is_ok(), kTarget, "an accepted recording encodes");
  return std::move(e).value();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  std::vector<std::uint8_t> bytes(data + 1, data + size);
  if ((data[0] & 1u) != 0) seal_crcs(bytes);
  const auto r = gfins::sim::decode_recording(bytes);
  if (!r.is_ok()) {
    gfins::fuzz::check(r.error().byte_offset <= bytes.size(), kTarget,
                       "an error's offset lies within the file");
    return 0;
  }
  for (const gfins::RawSample& s : r.value().samples) {
    for (const std::int32_t c : s.counts) {
      gfins::fuzz::check(c >= gfins::kAdcCodeMin && c <= gfins::kAdcCodeMax, kTarget,
                         "counts are 24-bit codes");
    }
  }
  // A version-1 sample may carry flag bit 15, which version 2 reserves for frame records: such
  // a file reads, but is not written again (the encoder refuses it, as documented).
  for (const gfins::RawSample& s : r.value().samples) {
    if (s.flags >= rec::kFrameRecordFlag) {
      gfins::fuzz::check(r.value().header.version == 1, kTarget,
                         "only a version-1 sample has flag bit 15");
      return 0;
    }
  }
  const std::vector<std::uint8_t> once = encode(r.value());
  const auto again = gfins::sim::decode_recording(once);
  gfins::fuzz::check(again.is_ok(), kTarget, "a re-encoded recording decodes");
  gfins::fuzz::check(again.value().samples.size() == r.value().samples.size() &&
                         again.value().frames.size() == r.value().frames.size(),
                     kTarget, "a re-encoded recording keeps every record");
  gfins::fuzz::check(encode(again.value()) == once, kTarget,
                     "decode and encode agree on every byte");
  return 0;
}
