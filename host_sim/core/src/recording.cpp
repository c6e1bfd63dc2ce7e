// The host's file layer of the recording format (docs/recording-format.md): whole images, the
// streaming reader and writer. The bytes themselves are the codec's (gfins/recording/codec.hpp);
// here its CodecStatus becomes a HostError whose message names the offset and the values.
#include "gfins/host_sim/recording.hpp"

#include "gfins/drivers/lnx/output_paths.hpp"

#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <sstream>
#include <utility>

namespace gfins::sim {
namespace {

using recording::CodecStatus;

HostError error_at(ErrorCode code, std::uint64_t offset, const std::string& what) {
  std::ostringstream m;
  m << "recording: " << what << " (byte offset " << offset << ")";
  return HostError{code, m.str(), offset};
}

std::string hex32(std::uint64_t v) {
  std::ostringstream m;
  m << "0x" << std::hex << v;
  return m.str();
}

/// The message of a header status (the same words for a file and for bytes in memory).
HostError header_error(const CodecStatus& c) {
  const std::string what = c.what;
  if (what == "truncated header") {
    return error_at(c.code, c.offset,
                    "truncated header: the file ends after " + std::to_string(c.found) +
                        " bytes, the header needs " + std::to_string(c.expected));
  }
  if (what == "unsupported version") {
    return error_at(c.code, c.offset,
                    "unsupported version " + std::to_string(c.found) + " (this reader knows " +
                        std::to_string(c.expected) + ")");
  }
  if (what == "header CRC-32 mismatch") {
    return error_at(c.code, c.offset,
                    "header CRC-32 mismatch (stored " + hex32(c.found) + ", computed " +
                        hex32(c.expected) + "): header corrupt");
  }
  if (what == "channel count is not 6") {
    return error_at(c.code, c.offset, "channel count " + std::to_string(c.found) + " is not 6");
  }
  return error_at(c.code, c.offset, what);
}

std::optional<HostError> writable_error(const RecordingHeader& h) {
  const CodecStatus c = recording::check_writable(h);
  if (c.ok()) return std::nullopt;
  return error_at(c.code, c.offset, c.what);
}

}  // namespace

HostResult<RecordingHeader> decode_header(std::span<const std::uint8_t> bytes) {
  RecordingHeader h;
  const CodecStatus c = recording::decode_header(bytes, h);
  if (!c.ok()) return header_error(c);
  return h;
}

HostResult<std::array<std::uint8_t, kRecordingRecordBytes>> encode_record(const RawSample& s) {
  std::array<std::uint8_t, kRecordingRecordBytes> b{};
  const CodecStatus c = recording::encode_record(s, b);
  if (c.ok()) return b;
  if (std::string(c.what).find("flags") != std::string::npos) {
    return error_at(c.code, 0,
                    "sample " + std::to_string(s.seq) +
                        ": flags at or above bit 15 do not fit (bit 15 marks a frame record)");
  }
  return error_at(c.code, 0,
                  "sample " + std::to_string(s.seq) + ": count " +
                      std::to_string(s.counts[static_cast<std::size_t>(c.found)]) +
                      " is not a 24-bit two's-complement code");
}

HostResult<std::vector<std::uint8_t>> encode_recording(RecordingHeader header,
                                                       std::span<const RawSample> samples,
                                                       std::span<const RecordedFrame> frames) {
  if (auto bad = writable_error(header)) return *bad;
  for (std::size_t k = 0; k < frames.size(); ++k) {
    if (frames[k].samples_before > samples.size() ||
        (k > 0 && frames[k].samples_before < frames[k - 1].samples_before)) {
      return HostError{
          ErrorCode::kInvalidArgument,
          "recording: frame " + std::to_string(k) + " is out of order or after the last sample", 0};
    }
  }
  const std::size_t total = samples.size() + frames.size();
  header.record_count = total;
  const auto head = encode_header(header);
  std::vector<std::uint8_t> out(head.begin(), head.end());
  const std::size_t rpb = header.records_per_block;
  const std::size_t blocks = (total + rpb - 1) / rpb;
  out.reserve(out.size() + total * kRecordingRecordBytes + blocks * kRecordingCrcBytes);
  std::size_t next_sample = 0, next_frame = 0;
  for (std::size_t first = 0; first < total; first += rpb) {
    const std::size_t block_start = out.size();
    const std::size_t n = std::min(rpb, total - first);
    for (std::size_t i = 0; i < n; ++i) {
      // Frames due after the samples written so far come first, then the next sample.
      if (next_frame < frames.size() && frames[next_frame].samples_before <= next_sample) {
        std::array<std::uint8_t, kRecordingRecordBytes> rec{};
        const CodecStatus c = recording::encode_frame_record(frames[next_frame].frame, rec);
        if (!c.ok()) {
          return error_at(c.code, out.size(),
                          "frame " + std::to_string(next_frame) + ": " + c.what);
        }
        out.insert(out.end(), rec.begin(), rec.end());
        ++next_frame;
        continue;
      }
      const auto rec = encode_record(samples[next_sample++]);
      if (!rec.is_ok()) {
        HostError e = rec.error();
        e.byte_offset = out.size();
        return e;
      }
      out.insert(out.end(), rec.value().begin(), rec.value().end());
    }
    std::array<std::uint8_t, kRecordingCrcBytes> crc{};
    recording::put_block_crc(std::span(out).subspan(block_start), crc);
    out.insert(out.end(), crc.begin(), crc.end());
  }
  return out;
}

namespace {

// Appends every block `reader` still holds to rec.samples; the first broken block ends the read
// with its error (which names the byte offset).
HostResult<Recording> read_remaining_blocks(RecordingReader& reader, Recording rec) {
  std::vector<RawSample> block;
  for (;;) {
    auto more = reader.next_block(block);
    if (!more.is_ok()) return more.error();
    if (!more.value()) break;
    rec.samples.insert(rec.samples.end(), block.begin(), block.end());
    rec.frames.insert(rec.frames.end(), reader.frames().begin(), reader.frames().end());
  }
  return rec;
}

}  // namespace

HostResult<Recording> decode_recording(std::span<const std::uint8_t> bytes) {
  auto reader = RecordingReader::from_bytes(bytes);
  if (!reader.is_ok()) return reader.error();
  Recording rec;
  rec.header = reader.value().header();
  if (rec.header.record_count != kRecordCountUnknown) {
    // Reserve only what the bytes can hold, so a corrupt count cannot ask for a huge buffer.
    rec.samples.reserve(static_cast<std::size_t>(
        std::min<std::uint64_t>(rec.header.record_count, bytes.size() / kRecordingRecordBytes)));
  }
  return read_remaining_blocks(reader.value(), std::move(rec));
}

HostResult<Recording> read_recording(const std::string& path) {
  auto reader = RecordingReader::open(path);
  if (!reader.is_ok()) return reader.error();
  Recording rec;
  rec.header = reader.value().header();
  return read_remaining_blocks(reader.value(), std::move(rec));
}

// ---------------------------------------------------------------------------------------------

RecordingReader::RecordingReader(RecordingReader&& other) noexcept
    : file_(std::exchange(other.file_, nullptr)),
      path_(std::move(other.path_)),
      bytes_(other.bytes_),
      size_(other.size_),
      header_(std::move(other.header_)),
      pos_(other.pos_),
      index_(other.index_),
      samples_(other.samples_),
      block_(other.block_),
      frames_(std::move(other.frames_)),
      file_pos_(other.file_pos_),
      stdio_buffer_(std::move(other.stdio_buffer_)),
      buffer_(std::move(other.buffer_)) {}

RecordingReader& RecordingReader::operator=(RecordingReader&& other) noexcept {
  if (this != &other) {
    // The file is open for reading only: a failed close loses no data, so there is nothing to
    // report.
    if (file_ != nullptr) (void)std::fclose(file_);
    file_ = std::exchange(other.file_, nullptr);
    path_ = std::move(other.path_);
    bytes_ = other.bytes_;
    size_ = other.size_;
    header_ = std::move(other.header_);
    pos_ = other.pos_;
    index_ = other.index_;
    samples_ = other.samples_;
    block_ = other.block_;
    frames_ = std::move(other.frames_);
    file_pos_ = other.file_pos_;
    stdio_buffer_ = std::move(other.stdio_buffer_);  // after fclose of the stream that used ours
    buffer_ = std::move(other.buffer_);
  }
  return *this;
}

RecordingReader::~RecordingReader() {
  // Read-only file: a failed close loses no data (see operator=).
  if (file_ != nullptr) (void)std::fclose(file_);
}

HostStatus RecordingReader::read_at(std::uint64_t offset, std::size_t n, std::uint8_t* dst) {
  if (file_ == nullptr) {
    std::memcpy(dst, bytes_.data() + offset, n);
    return Done{};
  }
  // Blocks are read in order: seek only when the position is not already the one wanted (a
  // seek empties stdio's buffer and costs a system call).
  if ((offset != file_pos_ && std::fseek(file_, static_cast<long>(offset), SEEK_SET) != 0) ||
      std::fread(dst, 1, n, file_) != n) {
    file_pos_ = kUnknownPos;
    return HostError{
        ErrorCode::kIoError,
        "recording: read error in " + path_ + " at byte offset " + std::to_string(offset), offset};
  }
  file_pos_ = offset + n;
  return Done{};
}

HostResult<RecordingReader> RecordingReader::from_bytes(std::span<const std::uint8_t> bytes) {
  RecordingReader r;
  r.bytes_ = bytes;
  r.size_ = bytes.size();
  auto head = decode_header(bytes.first(std::min(bytes.size(), kRecordingHeaderBytes)));
  if (!head.is_ok()) {
    HostError e = head.error();
    return e;
  }
  r.header_ = head.value();
  return r;
}

HostResult<RecordingReader> RecordingReader::open(const std::string& path) {
  RecordingReader r;
  r.path_ = path;
  r.file_ = std::fopen(path.c_str(), "rb");
  if (r.file_ == nullptr) {
    return HostError{ErrorCode::kIoError,
                     "recording: cannot open " + path + ": " + std::strerror(errno), 0};
  }
  // The reader sizes the file and reads it by offset: a device (/dev/zero would read as a file
  // of 0 bytes), a FIFO or a folder is named as what it is.
  struct stat st {};
  const bool stat_ok = ::fstat(::fileno(r.file_), &st) == 0;
  if (const char* what =
          stat_ok ? gfins::drivers::lnx::non_regular_kind(st.st_mode) : "not readable";
      what != nullptr) {
    return HostError{ErrorCode::kInvalidArgument,
                     "recording: " + path + " is " + what +
                         ", not a recording file (a recording is read from a regular file: it is "
                         "sized and read by offset)",
                     0};
  }
  // One read system call per kReadBufferBytes (32 blocks of the default size) instead of two
  // per block. Must come before any other operation on the stream; the buffer is ours (glibc
  // ignores the size when it is asked to allocate one) and lives on the heap, so it stays where
  // it is when the reader is moved.
  r.stdio_buffer_ = std::make_unique<char[]>(kReadBufferBytes);
  if (std::setvbuf(r.file_, r.stdio_buffer_.get(), _IOFBF, kReadBufferBytes) != 0) {
    return HostError{ErrorCode::kIoError, "recording: cannot set a read buffer for " + path, 0};
  }
  if (std::fseek(r.file_, 0, SEEK_END) != 0) {
    return HostError{ErrorCode::kIoError, "recording: cannot seek in " + path, 0};
  }
  r.file_pos_ = kUnknownPos;
  const long end = std::ftell(r.file_);
  if (end < 0) return HostError{ErrorCode::kIoError, "recording: cannot size " + path, 0};
  r.size_ = static_cast<std::uint64_t>(end);
  std::array<std::uint8_t, kRecordingHeaderBytes> head_bytes{};
  const std::size_t n =
      static_cast<std::size_t>(std::min<std::uint64_t>(r.size_, head_bytes.size()));
  auto got = r.read_at(0, n, head_bytes.data());
  if (!got.is_ok()) return got.error();
  auto head = decode_header(std::span<const std::uint8_t>(head_bytes.data(), n));
  if (!head.is_ok()) return head.error();
  r.header_ = head.value();
  return r;
}

HostResult<bool> RecordingReader::check_end() {
  if (pos_ != size_) {
    return error_at(ErrorCode::kDataLoss, pos_,
                    std::to_string(size_ - pos_) + " bytes after the last of the " +
                        std::to_string(index_) + " records the header announces");
  }
  return false;
}

HostResult<bool> RecordingReader::next_block(std::vector<RawSample>& out) {
  out.clear();
  const std::uint64_t rpb = header_.records_per_block;
  const std::uint64_t remaining = size_ - pos_;
  std::uint64_t n = 0;  // records in this block
  if (header_.record_count != kRecordCountUnknown) {
    n = std::min(rpb, header_.record_count - index_);
    if (n == 0) return check_end();
  } else {
    if (remaining == 0) return false;
    const std::uint64_t full = rpb * kRecordingRecordBytes + kRecordingCrcBytes;
    n = remaining >= full ? rpb
                          : (remaining - std::min<std::uint64_t>(remaining, kRecordingCrcBytes)) /
                                kRecordingRecordBytes;
    if (remaining < full &&
        (n == 0 || n * kRecordingRecordBytes + kRecordingCrcBytes != remaining)) {
      const std::uint64_t at = pos_ + (remaining / kRecordingRecordBytes) * kRecordingRecordBytes;
      return error_at(ErrorCode::kDataLoss, at,
                      "truncated: block " + std::to_string(block_) + " at byte offset " +
                          std::to_string(pos_) + " ends inside a record or its CRC (file is " +
                          std::to_string(size_) + " bytes)");
    }
  }
  const std::uint64_t need = n * kRecordingRecordBytes + kRecordingCrcBytes;
  if (remaining < need) {
    const std::uint64_t whole = std::min(n, remaining / kRecordingRecordBytes);
    const std::uint64_t at = pos_ + whole * kRecordingRecordBytes;
    return error_at(ErrorCode::kDataLoss, at,
                    "truncated: the file ends at byte " + std::to_string(size_) + " inside block " +
                        std::to_string(block_) + " (starts at byte offset " + std::to_string(pos_) +
                        ", needs " + std::to_string(need) + " bytes); header promises " +
                        std::to_string(header_.record_count) + " records, " +
                        std::to_string(index_ + whole) + " are complete");
  }
  std::span<const std::uint8_t> block;  // the block's records and CRC
  if (file_ == nullptr) {
    block = bytes_.subspan(static_cast<std::size_t>(pos_), static_cast<std::size_t>(need));
  } else {
    buffer_.resize(static_cast<std::size_t>(need));
    auto got = read_at(pos_, buffer_.size(), buffer_.data());
    if (!got.is_ok()) return got.error();
    block = buffer_;
  }
  const auto data = block.first(static_cast<std::size_t>(n * kRecordingRecordBytes));
  if (const CodecStatus c = recording::check_block(block, pos_); !c.ok()) {
    return error_at(c.code, pos_,
                    "block " + std::to_string(block_) + " (records " + std::to_string(index_) +
                        ".." + std::to_string(index_ + n - 1) + ") at byte offset " +
                        std::to_string(pos_) + ": CRC-32 mismatch (stored " + hex32(c.found) +
                        ", computed " + hex32(c.expected) + ")");
  }
  out.resize(static_cast<std::size_t>(n));  // keeps its capacity from block to block
  frames_.clear();
  std::size_t samples = 0;
  for (std::size_t i = 0; i < out.size(); ++i) {
    const auto rec = data.subspan(i * kRecordingRecordBytes).first<kRecordingRecordBytes>();
    if (!recording::is_frame_record(rec, header_.version)) {
      out[samples++] = decode_record(rec);
      continue;
    }
    RecordedFrame f;
    f.samples_before = samples_ + samples;
    if (const CodecStatus c = recording::decode_frame_record(rec, f.frame); !c.ok()) {
      const std::uint64_t at = pos_ + i * kRecordingRecordBytes;
      return error_at(c.code, at + c.offset,
                      "record " + std::to_string(index_ + i) + " at byte offset " +
                          std::to_string(at) + ": " + c.what);
    }
    frames_.push_back(f);
  }
  out.resize(samples);
  samples_ += samples;
  index_ += n;
  pos_ += need;
  ++block_;
  return true;
}

HostStatus write_recording(const std::string& path, const RecordingHeader& header,
                           std::span<const RawSample> samples) {
  auto w = RecordingWriter::open(path, header);
  if (!w.is_ok()) return w.error();
  for (const auto& s : samples) {
    auto r = w.value().append(s);
    if (!r.is_ok()) return r.error();
  }
  return w.value().close();
}

// ---------------------------------------------------------------------------------------------

RecordingWriter::RecordingWriter(std::FILE* file, const RecordingHeader& header)
    : file_(file), header_(header) {
  header_.record_count = kRecordCountUnknown;
}

RecordingWriter::RecordingWriter(RecordingWriter&& other) noexcept
    : file_(std::exchange(other.file_, nullptr)),
      header_(std::move(other.header_)),
      block_(std::move(other.block_)),
      records_(other.records_),
      offset_(other.offset_) {}

RecordingWriter& RecordingWriter::operator=(RecordingWriter&& other) noexcept {
  if (this != &other) {
    // Finish the file this writer holds as the destructor does (last block, record_count), so a
    // writer replaced by assignment leaves the same file as one destroyed. A noexcept assignment
    // cannot report close()'s error: callers who need it call close() first.
    if (file_ != nullptr) (void)close();
    file_ = std::exchange(other.file_, nullptr);
    header_ = std::move(other.header_);
    block_ = std::move(other.block_);
    records_ = other.records_;
    offset_ = other.offset_;
  }
  return *this;
}

RecordingWriter::~RecordingWriter() {
  if (file_ != nullptr) (void)close();
}

HostError RecordingWriter::io_error(const char* what) const {
  return HostError{ErrorCode::kIoError,
                   std::string("recording: ") + what + " at byte offset " +
                       std::to_string(offset_) + ": " + std::strerror(errno),
                   offset_};
}

HostResult<RecordingWriter> RecordingWriter::open(const std::string& path,
                                                  const RecordingHeader& header) {
  if (auto bad = writable_error(header)) return *bad;
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr) {
    return HostError{ErrorCode::kIoError,
                     "recording: cannot create " + path + ": " + std::strerror(errno), 0};
  }
  RecordingWriter w(f, header);
  const auto head = encode_header(w.header_);
  if (std::fwrite(head.data(), 1, head.size(), f) != head.size()) {
    return w.io_error("header write failed");
  }
  w.offset_ = head.size();
  w.block_.reserve(header.records_per_block * kRecordingRecordBytes);
  return w;
}

HostStatus RecordingWriter::append(const RawSample& s) {
  const auto rec = encode_record(s);
  if (!rec.is_ok()) {
    HostError e = rec.error();
    e.byte_offset = offset_ + block_.size();
    return e;
  }
  return append_bytes(rec.value());
}

HostStatus RecordingWriter::append_frame(const recording::FrameRecord& f) {
  std::array<std::uint8_t, kRecordingRecordBytes> rec{};
  if (const CodecStatus c = recording::encode_frame_record(f, rec); !c.ok()) {
    return error_at(c.code, offset_ + block_.size(),
                    std::string("frame id ") + hex32(f.id) + ": " + c.what);
  }
  return append_bytes(rec);
}

HostStatus RecordingWriter::append_bytes(std::span<const std::uint8_t, kRecordingRecordBytes> rec) {
  if (file_ == nullptr) {
    return HostError{ErrorCode::kFailedPrecondition, "recording: append after close", offset_};
  }
  block_.insert(block_.end(), rec.begin(), rec.end());
  ++records_;
  if (block_.size() == header_.records_per_block * kRecordingRecordBytes) return flush_block();
  return Done{};
}

HostStatus RecordingWriter::flush_block() {
  if (block_.empty()) return Done{};
  std::array<std::uint8_t, kRecordingCrcBytes> crc{};
  recording::put_block_crc(block_, crc);
  if (std::fwrite(block_.data(), 1, block_.size(), file_) != block_.size() ||
      std::fwrite(crc.data(), 1, crc.size(), file_) != crc.size() ||
      std::fflush(file_) != 0) {  // each complete block reaches the OS: a crash loses ≤ 1 block
    return io_error("block write failed");
  }
  offset_ += block_.size() + crc.size();
  block_.clear();
  return Done{};
}

HostStatus RecordingWriter::close() {
  if (file_ == nullptr) return Done{};
  auto flushed = flush_block();
  if (flushed.is_ok()) {
    header_.record_count = records_;
    const auto head = encode_header(header_);
    if (std::fseek(file_, 0, SEEK_SET) != 0 ||
        std::fwrite(head.data(), 1, head.size(), file_) != head.size()) {
      flushed = io_error("header rewrite failed");
    }
  }
  const bool close_failed = std::fclose(file_) != 0;
  file_ = nullptr;
  if (!flushed.is_ok()) return flushed;
  if (close_failed) return io_error("close failed");
  return Done{};
}

}  // namespace gfins::sim
