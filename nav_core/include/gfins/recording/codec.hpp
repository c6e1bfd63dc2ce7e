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
/// The version a writer writes. Version 2 adds frame records (the CAN frames the loop received,
/// between the samples they followed); a reader takes versions kMinVersion..kVersion.
inline constexpr std::uint16_t kVersion = 2;
inline constexpr std::uint16_t kMinVersion = 1;
/// Bit 15 of a record's last u16 (the sample flags of a sample record): set in a frame record
/// (version 2 on; sample_flags never use it).
inline constexpr std::uint16_t kFrameRecordFlag = 0x8000u;
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

/// One 32-byte sample record. kOutOfRange when a count is outside 24-bit two's complement (found =
/// the channel) or flags has bit 15 (the frame-record mark) or above: the record could not hold
/// them exactly.
CodecStatus encode_record(const RawSample& s, std::span<std::uint8_t, kRecordBytes> out);
RawSample decode_record(std::span<const std::uint8_t, kRecordBytes> bytes);

/// A CAN frame the navigation loop received (an aiding input, a command), recorded after the
/// sample of the cycle that handled it, with that cycle's time: what a replay hands to the same
/// loop at the same point to reproduce its output (docs/recording-format.md, "Frame records").
struct FrameRecord {
  std::int64_t t_ns = 0;  // the handling cycle's time (its sample's data-ready time)
  std::uint32_t id = 0;   // 11-bit or 29-bit identifier
  bool extended = false;  // 29-bit identifier
  std::uint8_t len = 0;   // 0..8
  std::array<std::uint8_t, 8> data{};
};

/// Whether the 32 bytes of a record of a file of `version` are a frame record.
bool is_frame_record(std::span<const std::uint8_t, kRecordBytes> bytes, std::uint16_t version);
/// One 32-byte frame record. kOutOfRange when the identifier or the length does not fit.
CodecStatus encode_frame_record(const FrameRecord& f, std::span<std::uint8_t, kRecordBytes> out);
/// kDataLoss (offset within the record) when the bytes are not a well-formed frame record: an
/// identifier beyond its range, a length above 8, reserved bytes that are not zero.
CodecStatus decode_frame_record(std::span<const std::uint8_t, kRecordBytes> bytes,
                                FrameRecord& out);

/// The CRC-32 stored after a block's records (`block` = records then 4 CRC bytes) against the
/// one computed; kDataLoss with found = stored, expected = computed when they differ.
/// `offset` is the block's offset in the file, for the status.
CodecStatus check_block(std::span<const std::uint8_t> block, std::uint64_t offset);
/// Writes the CRC-32 of `records` into `crc_out` (little-endian).
void put_block_crc(std::span<const std::uint8_t> records,
                   std::span<std::uint8_t, kCrcBytes> crc_out);

}  // namespace gfins::recording
