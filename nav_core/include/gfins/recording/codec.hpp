// The raw-sample recording format (docs/recording-format.md) as a codec: bytes ↔ values, with no
// I/O, no heap and no exceptions, so the board can use it too (hardware-in-the-loop replay of a
// recording, or recording its own RawSample stream). The host's file layer
// (host_sim/recording.hpp) builds on it and turns CodecStatus into messages with file names.
//
//   header (384 bytes, CRC-32 at byte 380)
//   block 0: records_per_block × 32-byte records, then the CRC-32 of those record bytes
//   ...
//   last block: 1..records_per_block records, then its CRC-32
//
// Little-endian whatever the host's byte order: every field is written byte by byte with shifts.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "gfins/nav_core/geometry.hpp"
#include "gfins/sample/raw_sample.hpp"
#include "gfins/status/status.hpp"

namespace gfins::recording {

inline constexpr std::array<char, 8> kMagic = {'G', 'F', 'I', 'N', 'S', 'R', 'A', 'W'};
inline constexpr std::uint16_t kVersion = 1;
inline constexpr std::size_t kHeaderBytes = 384;
inline constexpr std::size_t kRecordBytes = 32;
inline constexpr std::size_t kCrcBytes = 4;
inline constexpr std::uint32_t kDefaultRecordsPerBlock = 256;
/// record_count of a file whose writer never closed it: a reader takes every complete block.
inline constexpr std::uint64_t kRecordCountUnknown = ~std::uint64_t{0};

// Header field offsets (docs/recording-format.md, "Header").
inline constexpr std::size_t kOffMagic = 0;
inline constexpr std::size_t kOffVersion = 8;
inline constexpr std::size_t kOffHeaderBytes = 10;
inline constexpr std::size_t kOffChannels = 12;
inline constexpr std::size_t kOffRecordBytes = 14;
inline constexpr std::size_t kOffRecordsPerBlock = 16;
inline constexpr std::size_t kOffRecordCount = 24;
inline constexpr std::size_t kOffSampleRate = 32;
inline constexpr std::size_t kOffVoltsPerCount = 40;
inline constexpr std::size_t kOffRho = 88;
inline constexpr std::size_t kOffTheta = 232;
inline constexpr std::size_t kOffHeaderCrc = 380;

/// What a recording says about how its samples were made.
struct Header {
  std::uint16_t version = kVersion;
  double sample_rate_hz = 1000.0;
  std::uint16_t channel_count = kAdcChannels;
  std::uint32_t records_per_block = kDefaultRecordsPerBlock;
  std::uint64_t record_count = kRecordCountUnknown;  // filled in when the writer closes
  std::array<double, 6> volts_per_count{};           // ADC LSB per channel, V at the sensor
  nav::ArrayGeometry<double, 6> geometry{};          // ρ_j (m) and θ_j, body frame
};

/// Why bytes could not be decoded (or a value encoded), without allocating: a static message,
/// the offset in the encoded bytes where the problem starts, and the two numbers that explain it
/// (stored/computed CRC, found/expected version or count) for the caller's message.
struct CodecStatus {
  ErrorCode code = ErrorCode::kOk;
  const char* what = "";
  std::uint64_t offset = 0;
  std::uint64_t found = 0;
  std::uint64_t expected = 0;
  bool ok() const { return code == ErrorCode::kOk; }
};

/// CRC-32 (IEEE 802.3: reflected polynomial 0xEDB88320, init and final xor 0xFFFFFFFF), the one
/// of zlib and PNG. crc32("123456789") = 0xCBF43926. `crc` continues a previous call.
std::uint32_t crc32(std::span<const std::uint8_t> bytes, std::uint32_t crc = 0);

/// The header's 384 bytes (CRC included).
std::array<std::uint8_t, kHeaderBytes> encode_header(const Header& h);
/// Checks size, magic, version, the header CRC and the sizes; fills `out` on success.
CodecStatus decode_header(std::span<const std::uint8_t> bytes, Header& out);
/// What a writer must refuse to write because a reader would refuse to read it.
CodecStatus check_writable(const Header& h);

/// One 32-byte record. kOutOfRange when a count is outside 24-bit two's complement (found = the
/// channel) or flags has bits above 15: the record could not hold them exactly.
CodecStatus encode_record(const RawSample& s, std::span<std::uint8_t, kRecordBytes> out);
RawSample decode_record(std::span<const std::uint8_t, kRecordBytes> bytes);

/// The CRC-32 stored after a block's records (`block` = records then 4 CRC bytes) against the
/// one computed; kDataLoss with found = stored, expected = computed when they differ.
/// `offset` is the block's offset in the file, for the status.
CodecStatus check_block(std::span<const std::uint8_t> block, std::uint64_t offset);
/// Writes the CRC-32 of `records` into `crc_out` (little-endian).
void put_block_crc(std::span<const std::uint8_t> records,
                   std::span<std::uint8_t, kCrcBytes> crc_out);

}  // namespace gfins::recording
