// Raw-sample recordings, the host's file layer: a compact little-endian binary file of RawSample
// values with the context needed to replay them (sample rate, ADC LSB, array geometry). The byte
// layout is specified in docs/recording-format.md; this header is its implementation.
//
//   header (384 bytes, CRC-32 at byte 380)
//   block 0: records_per_block × 32-byte records, then the CRC-32 of those record bytes
//   block 1: ...
//   last block: 1..records_per_block records, then its CRC-32
//
// Errors are values (HostResult, error.hpp) that name the byte offset where the file breaks: a
// short header, a record cut in the middle, a block whose CRC does not match, wrong magic or
// version. Nothing here throws (allocation failure aside).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "gfins/hal/can_bus.hpp"
#include "gfins/host_sim/error.hpp"
#include "gfins/nav_core/geometry.hpp"
#include "gfins/recording/codec.hpp"
#include "gfins/sample/raw_sample.hpp"
#include "gfins/status/status.hpp"

namespace gfins::sim {

// The format itself (constants, header, records, CRC) is the codec of nav_core/recording,
// shared with the board; this file is the host's layer on top: whole images and files.
inline constexpr auto kRecordingMagic = recording::kMagic;
inline constexpr std::uint16_t kRecordingVersion = recording::kVersion;
inline constexpr std::size_t kRecordingHeaderBytes = recording::kHeaderBytes;
inline constexpr std::size_t kRecordingRecordBytes = recording::kRecordBytes;
inline constexpr std::size_t kRecordingCrcBytes = recording::kCrcBytes;
inline constexpr std::uint32_t kDefaultRecordsPerBlock = recording::kDefaultRecordsPerBlock;
inline constexpr std::uint64_t kRecordCountUnknown = recording::kRecordCountUnknown;

using RecordingHeader = recording::Header;
using recording::crc32;
using recording::decode_record;
using recording::encode_header;

/// decode_header of the codec with a message naming what is wrong and where.
HostResult<RecordingHeader> decode_header(std::span<const std::uint8_t> bytes);
/// encode_record of the codec with a message naming the sample.
HostResult<std::array<std::uint8_t, kRecordingRecordBytes>> encode_record(const RawSample& s);

/// A frame record (version 2) with its place in the stream: it came after `samples_before`
/// samples (the loop handled it in the cycle of sample samples_before − 1).
struct RecordedFrame {
  std::uint64_t samples_before = 0;
  recording::FrameRecord frame;
};

/// The CAN frame a frame record holds (its identifier, format, length and data; not its time).
inline hal::CanFrame can_frame_of(const recording::FrameRecord& r) {
  hal::CanFrame f;
  f.id = r.id;
  f.extended = r.extended;
  f.len = r.len;
  f.data = r.data;
  return f;
}

struct Recording {
  RecordingHeader header;
  std::vector<RawSample> samples;
  std::vector<RecordedFrame> frames;  // version 2: the CAN frames the loop received, in order
};

/// The whole file in memory (header with record_count set, every block and its CRC): the
/// samples, and each frame after the first `samples_before` of them (frames in stream order;
/// kInvalidArgument when their samples_before decrease or exceed the samples).
HostResult<std::vector<std::uint8_t>> encode_recording(RecordingHeader header,
                                                       std::span<const RawSample> samples,
                                                       std::span<const RecordedFrame> frames = {});
/// Parses a whole file image; errors name the byte offset (docs/recording-format.md).
HostResult<Recording> decode_recording(std::span<const std::uint8_t> bytes);

/// Reads and decodes a file (kIoError when it cannot be opened or read).
HostResult<Recording> read_recording(const std::string& path);
/// Writes a whole recording at once (through RecordingWriter).
HostStatus write_recording(const std::string& path, const RecordingHeader& header,
                           std::span<const RawSample> samples);

/// Streaming reader: the header at open, then one block at a time, with the same checks and
/// error offsets as decode_recording (which is built on it). Memory use is one block, so a
/// recording of any length can be replayed. Reads either a file or a caller-owned byte span
/// (which must outlive the reader).
class RecordingReader {
 public:
  static HostResult<RecordingReader> open(const std::string& path);
  static HostResult<RecordingReader> from_bytes(std::span<const std::uint8_t> bytes);
  RecordingReader(RecordingReader&& other) noexcept;
  RecordingReader& operator=(RecordingReader&& other) noexcept;
  RecordingReader(const RecordingReader&) = delete;
  RecordingReader& operator=(const RecordingReader&) = delete;
  ~RecordingReader();

  const RecordingHeader& header() const { return header_; }

  /// Replaces `out` with the samples of the next block, and frames() with its frame records.
  /// Returns false (and an empty `out`) at the clean end of the recording, an error when the
  /// file is truncated or corrupt there (a malformed frame record included).
  HostResult<bool> next_block(std::vector<RawSample>& out);
  /// The frame records of the block next_block() returned last, in file order.
  const std::vector<RecordedFrame>& frames() const { return frames_; }

  /// Records (samples and frames) read so far.
  std::uint64_t records_read() const { return index_; }
  std::uint64_t samples_read() const { return samples_; }
  std::uint64_t frames_read() const { return index_ - samples_; }

 private:
  RecordingReader() = default;
  HostStatus read_at(std::uint64_t offset, std::size_t n, std::uint8_t* dst);
  HostResult<bool> check_end();

  std::FILE* file_ = nullptr;
  std::string path_;
  std::span<const std::uint8_t> bytes_{};
  std::uint64_t size_ = 0;
  RecordingHeader header_{};
  std::uint64_t pos_ = kRecordingHeaderBytes;
  std::uint64_t index_ = 0;
  std::uint64_t samples_ = 0;
  std::uint64_t block_ = 0;
  std::vector<RecordedFrame> frames_;
  static constexpr std::uint64_t kUnknownPos = ~std::uint64_t{0};
  static constexpr std::size_t kReadBufferBytes = std::size_t{256} * 1024;
  std::uint64_t file_pos_ = kUnknownPos;  // where the next fread starts, when known
  std::unique_ptr<char[]> stdio_buffer_;  // the stream's buffer (setvbuf), kReadBufferBytes
  std::vector<std::uint8_t> buffer_;
};

/// Streaming writer: append samples as they come, one block written per records_per_block
/// samples; close() writes the last partial block and patches record_count into the header.
/// A file whose writer died before close() keeps record_count = kRecordCountUnknown and stays
/// readable up to its last complete block.
class RecordingWriter {
 public:
  static HostResult<RecordingWriter> open(const std::string& path, const RecordingHeader& header);
  RecordingWriter(RecordingWriter&& other) noexcept;
  // Both close an open writer (as close() does) without reporting errors: call close() to see
  // them.
  RecordingWriter& operator=(RecordingWriter&& other) noexcept;
  RecordingWriter(const RecordingWriter&) = delete;
  RecordingWriter& operator=(const RecordingWriter&) = delete;
  ~RecordingWriter();

  HostStatus append(const RawSample& s);
  /// A CAN frame the loop received, after the sample of the cycle that handled it.
  HostStatus append_frame(const recording::FrameRecord& f);
  HostStatus close();
  std::uint64_t records_written() const { return records_; }

 private:
  RecordingWriter(std::FILE* file, const RecordingHeader& header);
  HostStatus flush_block();
  HostStatus append_bytes(std::span<const std::uint8_t, kRecordingRecordBytes> rec);
  HostError io_error(const char* what) const;

  std::FILE* file_ = nullptr;
  RecordingHeader header_;
  std::vector<std::uint8_t> block_;  // records of the current block, without CRC
  std::uint64_t records_ = 0;
  std::uint64_t offset_ = 0;  // bytes written so far
};

}  // namespace gfins::sim
