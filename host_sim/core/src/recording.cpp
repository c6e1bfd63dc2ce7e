// Implementation of the recording format of docs/recording-format.md. Encoding is done byte by
// byte with shifts, so the file is little-endian whatever the host's byte order.
#include "gfins/host_sim/recording.hpp"

#include <algorithm>
#include <bit>
#include <cerrno>
#include <cstring>
#include <sstream>
#include <utility>

namespace gfins::sim {
namespace {

// Header field offsets (docs/recording-format.md, "Header").
constexpr std::size_t kOffMagic = 0;
constexpr std::size_t kOffVersion = 8;
constexpr std::size_t kOffHeaderBytes = 10;
constexpr std::size_t kOffChannels = 12;
constexpr std::size_t kOffRecordBytes = 14;
constexpr std::size_t kOffRecordsPerBlock = 16;
constexpr std::size_t kOffRecordCount = 24;
constexpr std::size_t kOffSampleRate = 32;
constexpr std::size_t kOffVoltsPerCount = 40;
constexpr std::size_t kOffRho = 88;
constexpr std::size_t kOffTheta = 232;
constexpr std::size_t kOffHeaderCrc = 380;

// Record field offsets (docs/recording-format.md, "Records").
constexpr std::size_t kRecSeq = 0;
constexpr std::size_t kRecTime = 4;
constexpr std::size_t kRecCounts = 12;
constexpr std::size_t kRecFlags = 30;

constexpr std::int32_t kCode24Max = (1 << 23) - 1;
constexpr std::int32_t kCode24Min = -(1 << 23);

constexpr std::array<std::uint32_t, 256> make_crc_table() {
  std::array<std::uint32_t, 256> t{};
  for (std::uint32_t i = 0; i < 256; ++i) {
    std::uint32_t c = i;
    for (int k = 0; k < 8; ++k) c = (c & 1u) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
    t[i] = c;
  }
  return t;
}
constexpr std::array<std::uint32_t, 256> kCrcTable = make_crc_table();

void put_u16(std::uint8_t* p, std::uint16_t v) {
  p[0] = static_cast<std::uint8_t>(v);
  p[1] = static_cast<std::uint8_t>(v >> 8);
}
void put_u32(std::uint8_t* p, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}
void put_u64(std::uint8_t* p, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}
void put_f64(std::uint8_t* p, double v) { put_u64(p, std::bit_cast<std::uint64_t>(v)); }

std::uint16_t get_u16(const std::uint8_t* p) {
  return static_cast<std::uint16_t>(p[0] | (p[1] << 8));
}
std::uint32_t get_u32(const std::uint8_t* p) {
  std::uint32_t v = 0;
  for (int i = 0; i < 4; ++i) v |= static_cast<std::uint32_t>(p[i]) << (8 * i);
  return v;
}
std::uint64_t get_u64(const std::uint8_t* p) {
  std::uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v |= static_cast<std::uint64_t>(p[i]) << (8 * i);
  return v;
}
double get_f64(const std::uint8_t* p) { return std::bit_cast<double>(get_u64(p)); }

HostError error_at(ErrorCode code, std::uint64_t offset, const std::string& what) {
  std::ostringstream m;
  m << "recording: " << what << " (byte offset " << offset << ")";
  return HostError{code, m.str(), offset};
}

std::string hex32(std::uint32_t v) {
  std::ostringstream m;
  m << "0x" << std::hex << v;
  return m.str();
}

// What a writer must refuse to write, because the reader would refuse to read it.
std::optional<HostError> check_writable(const RecordingHeader& h) {
  if (h.version != kRecordingVersion) {
    return error_at(ErrorCode::kInvalidArgument, kOffVersion, "header version is not 1");
  }
  if (h.channel_count != kAdcChannels) {
    return error_at(ErrorCode::kInvalidArgument, kOffChannels, "header channel count is not 6");
  }
  if (h.records_per_block == 0) {
    return error_at(ErrorCode::kInvalidArgument, kOffRecordsPerBlock, "records per block is 0");
  }
  return std::nullopt;
}

}  // namespace

std::uint32_t crc32(std::span<const std::uint8_t> bytes, std::uint32_t crc) {
  std::uint32_t c = ~crc;
  for (const std::uint8_t b : bytes) c = kCrcTable[(c ^ b) & 0xFFu] ^ (c >> 8);
  return ~c;
}

std::array<std::uint8_t, kRecordingHeaderBytes> encode_header(const RecordingHeader& h) {
  std::array<std::uint8_t, kRecordingHeaderBytes> b{};
  std::memcpy(b.data() + kOffMagic, kRecordingMagic.data(), kRecordingMagic.size());
  put_u16(b.data() + kOffVersion, h.version);
  put_u16(b.data() + kOffHeaderBytes, static_cast<std::uint16_t>(kRecordingHeaderBytes));
  put_u16(b.data() + kOffChannels, h.channel_count);
  put_u16(b.data() + kOffRecordBytes, static_cast<std::uint16_t>(kRecordingRecordBytes));
  put_u32(b.data() + kOffRecordsPerBlock, h.records_per_block);
  put_u64(b.data() + kOffRecordCount, h.record_count);
  put_f64(b.data() + kOffSampleRate, h.sample_rate_hz);
  for (std::size_t j = 0; j < 6; ++j) {
    put_f64(b.data() + kOffVoltsPerCount + 8 * j, h.volts_per_count[j]);
    for (std::size_t k = 0; k < 3; ++k) {
      const auto r = static_cast<Eigen::Index>(k);
      put_f64(b.data() + kOffRho + 8 * (3 * j + k), h.geometry.rho_b[j](r));
      put_f64(b.data() + kOffTheta + 8 * (3 * j + k), h.geometry.theta_b[j](r));
    }
  }
  put_u32(b.data() + kOffHeaderCrc, crc32(std::span(b.data(), kOffHeaderCrc)));
  return b;
}

HostResult<RecordingHeader> decode_header(std::span<const std::uint8_t> bytes) {
  if (bytes.size() < kRecordingHeaderBytes) {
    return error_at(ErrorCode::kDataLoss, bytes.size(),
                    "truncated header: the file ends after " + std::to_string(bytes.size()) +
                        " bytes, the header needs " + std::to_string(kRecordingHeaderBytes));
  }
  const std::uint8_t* p = bytes.data();
  if (std::memcmp(p + kOffMagic, kRecordingMagic.data(), kRecordingMagic.size()) != 0) {
    return error_at(ErrorCode::kInvalidArgument, kOffMagic,
                    "wrong magic: not a gfins raw-sample recording (expected \"GFINSRAW\")");
  }
  RecordingHeader h;
  h.version = get_u16(p + kOffVersion);
  if (h.version != kRecordingVersion) {
    return error_at(ErrorCode::kUnimplemented, kOffVersion,
                    "unsupported version " + std::to_string(h.version) + " (this reader knows " +
                        std::to_string(kRecordingVersion) + ")");
  }
  const std::uint32_t stored = get_u32(p + kOffHeaderCrc);
  const std::uint32_t computed = crc32(bytes.first(kOffHeaderCrc));
  if (stored != computed) {
    return error_at(ErrorCode::kDataLoss, 0,
                    "header CRC-32 mismatch (stored " + hex32(stored) + ", computed " +
                        hex32(computed) + "): header corrupt");
  }
  if (get_u16(p + kOffHeaderBytes) != kRecordingHeaderBytes) {
    return error_at(ErrorCode::kInvalidArgument, kOffHeaderBytes, "header size is not 384");
  }
  h.channel_count = get_u16(p + kOffChannels);
  if (h.channel_count != kAdcChannels) {
    return error_at(ErrorCode::kInvalidArgument, kOffChannels,
                    "channel count " + std::to_string(h.channel_count) + " is not 6");
  }
  if (get_u16(p + kOffRecordBytes) != kRecordingRecordBytes) {
    return error_at(ErrorCode::kInvalidArgument, kOffRecordBytes, "record size is not 32");
  }
  h.records_per_block = get_u32(p + kOffRecordsPerBlock);
  if (h.records_per_block == 0) {
    return error_at(ErrorCode::kInvalidArgument, kOffRecordsPerBlock, "records per block is 0");
  }
  h.record_count = get_u64(p + kOffRecordCount);
  h.sample_rate_hz = get_f64(p + kOffSampleRate);
  for (std::size_t j = 0; j < 6; ++j) {
    h.volts_per_count[j] = get_f64(p + kOffVoltsPerCount + 8 * j);
    for (std::size_t k = 0; k < 3; ++k) {
      const auto r = static_cast<Eigen::Index>(k);
      h.geometry.rho_b[j](r) = get_f64(p + kOffRho + 8 * (3 * j + k));
      h.geometry.theta_b[j](r) = get_f64(p + kOffTheta + 8 * (3 * j + k));
    }
  }
  return h;
}

HostResult<std::array<std::uint8_t, kRecordingRecordBytes>> encode_record(const RawSample& s) {
  std::array<std::uint8_t, kRecordingRecordBytes> b{};
  if (s.flags > 0xFFFFu) {
    return error_at(ErrorCode::kOutOfRange, 0,
                    "sample " + std::to_string(s.seq) + ": flags above bit 15 do not fit");
  }
  put_u32(b.data() + kRecSeq, s.seq);
  put_u64(b.data() + kRecTime, static_cast<std::uint64_t>(s.t_ns));
  for (std::size_t j = 0; j < 6; ++j) {
    const std::int32_t c = s.counts[j];
    if (c > kCode24Max || c < kCode24Min) {
      return error_at(ErrorCode::kOutOfRange, 0,
                      "sample " + std::to_string(s.seq) + ": count " + std::to_string(c) +
                          " is not a 24-bit two's-complement code");
    }
    const auto u = static_cast<std::uint32_t>(c);  // two's complement, low 24 bits kept
    for (std::size_t k = 0; k < 3; ++k) {
      b[kRecCounts + 3 * j + k] = static_cast<std::uint8_t>(u >> (8 * k));
    }
  }
  put_u16(b.data() + kRecFlags, static_cast<std::uint16_t>(s.flags));
  return b;
}

RawSample decode_record(std::span<const std::uint8_t, kRecordingRecordBytes> bytes) {
  const std::uint8_t* p = bytes.data();
  RawSample s;
  s.seq = get_u32(p + kRecSeq);
  s.t_ns = static_cast<std::int64_t>(get_u64(p + kRecTime));
  for (std::size_t j = 0; j < 6; ++j) {
    const std::uint8_t* c = p + kRecCounts + 3 * j;
    std::uint32_t u = static_cast<std::uint32_t>(c[0]) | (static_cast<std::uint32_t>(c[1]) << 8) |
                      (static_cast<std::uint32_t>(c[2]) << 16);
    if (u & 0x800000u) u |= 0xFF000000u;  // sign-extend the 24-bit code
    s.counts[j] = static_cast<std::int32_t>(u);
  }
  s.flags = get_u16(p + kRecFlags);
  return s;
}

HostResult<std::vector<std::uint8_t>> encode_recording(RecordingHeader header,
                                                       std::span<const RawSample> samples) {
  if (auto bad = check_writable(header)) return *bad;
  header.record_count = samples.size();
  const auto head = encode_header(header);
  std::vector<std::uint8_t> out(head.begin(), head.end());
  const std::size_t rpb = header.records_per_block;
  const std::size_t blocks = (samples.size() + rpb - 1) / rpb;
  out.reserve(out.size() + samples.size() * kRecordingRecordBytes + blocks * kRecordingCrcBytes);
  for (std::size_t first = 0; first < samples.size(); first += rpb) {
    const std::size_t block_start = out.size();
    const std::size_t n = std::min(rpb, samples.size() - first);
    for (std::size_t i = first; i < first + n; ++i) {
      const auto rec = encode_record(samples[i]);
      if (!rec.is_ok()) {
        HostError e = rec.error();
        e.byte_offset = out.size();
        return e;
      }
      out.insert(out.end(), rec.value().begin(), rec.value().end());
    }
    std::array<std::uint8_t, 4> crc{};
    put_u32(crc.data(), crc32(std::span(out).subspan(block_start)));
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
      block_(other.block_),
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
    block_ = other.block_;
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
  if (std::fseek(file_, static_cast<long>(offset), SEEK_SET) != 0 ||
      std::fread(dst, 1, n, file_) != n) {
    return HostError{
        ErrorCode::kIoError,
        "recording: read error in " + path_ + " at byte offset " + std::to_string(offset), offset};
  }
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
  if (std::fseek(r.file_, 0, SEEK_END) != 0) {
    return HostError{ErrorCode::kIoError, "recording: cannot seek in " + path, 0};
  }
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
    n = remaining >= full
            ? rpb
            : (remaining - std::min(remaining, kRecordingCrcBytes)) / kRecordingRecordBytes;
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
  buffer_.resize(static_cast<std::size_t>(need));
  auto got = read_at(pos_, buffer_.size(), buffer_.data());
  if (!got.is_ok()) return got.error();
  const auto data = std::span<const std::uint8_t>(buffer_).first(
      static_cast<std::size_t>(n * kRecordingRecordBytes));
  const std::uint32_t stored = get_u32(buffer_.data() + data.size());
  const std::uint32_t computed = crc32(data);
  if (stored != computed) {
    return error_at(ErrorCode::kDataLoss, pos_,
                    "block " + std::to_string(block_) + " (records " + std::to_string(index_) +
                        ".." + std::to_string(index_ + n - 1) + ") at byte offset " +
                        std::to_string(pos_) + ": CRC-32 mismatch (stored " + hex32(stored) +
                        ", computed " + hex32(computed) + ")");
  }
  out.reserve(static_cast<std::size_t>(n));
  for (std::uint64_t i = 0; i < n; ++i) {
    out.push_back(decode_record(data.subspan(static_cast<std::size_t>(i * kRecordingRecordBytes))
                                    .first<kRecordingRecordBytes>()));
  }
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
  if (auto bad = check_writable(header)) return *bad;
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
  if (file_ == nullptr) {
    return HostError{ErrorCode::kFailedPrecondition, "recording: append after close", offset_};
  }
  const auto rec = encode_record(s);
  if (!rec.is_ok()) {
    HostError e = rec.error();
    e.byte_offset = offset_ + block_.size();
    return e;
  }
  block_.insert(block_.end(), rec.value().begin(), rec.value().end());
  ++records_;
  if (block_.size() == header_.records_per_block * kRecordingRecordBytes) return flush_block();
  return Done{};
}

HostStatus RecordingWriter::flush_block() {
  if (block_.empty()) return Done{};
  std::array<std::uint8_t, 4> crc{};
  put_u32(crc.data(), crc32(block_));
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
