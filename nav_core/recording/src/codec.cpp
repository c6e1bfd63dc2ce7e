// Implementation of the recording format of docs/recording-format.md (codec.hpp).
#include "gfins/recording/codec.hpp"

#include <bit>
#include <cstring>

namespace gfins::recording {
namespace {

// Record field offsets (docs/recording-format.md, "Records").
constexpr std::size_t kRecSeq = 0;
constexpr std::size_t kRecTime = 4;
constexpr std::size_t kRecCounts = 12;
constexpr std::size_t kRecFlags = 30;
// Frame records (version 2, docs/recording-format.md, "Frame records"): the identifier with bit
// 31 marking a 29-bit one, the time at kRecTime, the length, the eight data bytes.
constexpr std::size_t kRecFrameId = 0;
constexpr std::size_t kRecFrameLen = 12;
constexpr std::size_t kRecFrameData = 14;
constexpr std::uint32_t kExtendedBit = 0x80000000u;
constexpr std::uint32_t kMaxStandardId = 0x7FFu;
constexpr std::uint32_t kMaxExtendedId = 0x1FFFFFFFu;

// CRC-32 "slicing by 8" (the method of Intel's Kounavis and Berry, 2005): t[0] is the classic
// byte table; t[k][i] is the CRC of byte i followed by k zero bytes, so eight table look-ups
// that do not depend on each other replace eight dependent ones. A block's CRC goes from about
// 2 ns per byte to about 0.3 ns (docs/performance.md, "Replay from a file"); same values.
using CrcTables = std::array<std::array<std::uint32_t, 256>, 8>;
constexpr CrcTables make_crc_tables() {
  CrcTables t{};
  for (std::uint32_t i = 0; i < 256; ++i) {
    std::uint32_t c = i;
    for (int k = 0; k < 8; ++k) c = (c & 1u) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
    t[0][i] = c;
  }
  for (std::size_t k = 1; k < 8; ++k) {
    for (std::size_t i = 0; i < 256; ++i) t[k][i] = (t[k - 1][i] >> 8) ^ t[0][t[k - 1][i] & 0xFFu];
  }
  return t;
}
constexpr CrcTables kCrcTables = make_crc_tables();

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

CodecStatus fail(ErrorCode code, const char* what, std::uint64_t offset, std::uint64_t found = 0,
                 std::uint64_t expected = 0) {
  return CodecStatus{code, what, offset, found, expected};
}

}  // namespace

std::uint32_t crc32(std::span<const std::uint8_t> bytes, std::uint32_t crc) {
  const auto& t = kCrcTables;
  std::uint32_t c = ~crc;
  const std::uint8_t* p = bytes.data();
  std::size_t n = bytes.size();
  for (; n >= 8; n -= 8, p += 8) {
    // Bytes are combined with shifts (little-endian by definition of the reflected CRC), so the
    // result does not depend on the host's byte order; compilers make each a single load.
    const std::uint32_t lo = c ^ get_u32(p);
    const std::uint32_t hi = get_u32(p + 4);
    c = t[7][lo & 0xFFu] ^ t[6][(lo >> 8) & 0xFFu] ^ t[5][(lo >> 16) & 0xFFu] ^ t[4][lo >> 24] ^
        t[3][hi & 0xFFu] ^ t[2][(hi >> 8) & 0xFFu] ^ t[1][(hi >> 16) & 0xFFu] ^ t[0][hi >> 24];
  }
  for (; n > 0; --n, ++p) c = t[0][(c ^ *p) & 0xFFu] ^ (c >> 8);
  return ~c;
}

CodecStatus check_writable(const Header& h) {
  if (h.version != kVersion) {
    return fail(ErrorCode::kInvalidArgument, "header version is not 2", kOffVersion, h.version,
                kVersion);
  }
  if (h.channel_count != kAdcChannels) {
    return fail(ErrorCode::kInvalidArgument, "header channel count is not 6", kOffChannels,
                h.channel_count, kAdcChannels);
  }
  if (h.records_per_block == 0) {
    return fail(ErrorCode::kInvalidArgument, "records per block is 0", kOffRecordsPerBlock);
  }
  return {};
}

std::array<std::uint8_t, kHeaderBytes> encode_header(const Header& h) {
  std::array<std::uint8_t, kHeaderBytes> b{};
  std::memcpy(b.data() + kOffMagic, kMagic.data(), kMagic.size());
  put_u16(b.data() + kOffVersion, h.version);
  put_u16(b.data() + kOffHeaderBytes, static_cast<std::uint16_t>(kHeaderBytes));
  put_u16(b.data() + kOffChannels, h.channel_count);
  put_u16(b.data() + kOffRecordBytes, static_cast<std::uint16_t>(kRecordBytes));
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

CodecStatus decode_header(std::span<const std::uint8_t> bytes, Header& out) {
  if (bytes.size() < kHeaderBytes) {
    return fail(ErrorCode::kDataLoss, "truncated header", bytes.size(), bytes.size(), kHeaderBytes);
  }
  const std::uint8_t* p = bytes.data();
  if (std::memcmp(p + kOffMagic, kMagic.data(), kMagic.size()) != 0) {
    return fail(ErrorCode::kInvalidArgument,
                "wrong magic: not a gfins raw-sample recording (expected \"GFINSRAW\")", kOffMagic);
  }
  Header h;
  h.version = get_u16(p + kOffVersion);
  if (h.version < kMinVersion || h.version > kVersion) {
    return fail(ErrorCode::kUnimplemented, "unsupported version", kOffVersion, h.version, kVersion);
  }
  const std::uint32_t stored = get_u32(p + kOffHeaderCrc);
  const std::uint32_t computed = crc32(bytes.first(kOffHeaderCrc));
  if (stored != computed) {
    return fail(ErrorCode::kDataLoss, "header CRC-32 mismatch", 0, stored, computed);
  }
  if (get_u16(p + kOffHeaderBytes) != kHeaderBytes) {
    return fail(ErrorCode::kInvalidArgument, "header size is not 384", kOffHeaderBytes);
  }
  h.channel_count = get_u16(p + kOffChannels);
  if (h.channel_count != kAdcChannels) {
    return fail(ErrorCode::kInvalidArgument, "channel count is not 6", kOffChannels,
                h.channel_count, kAdcChannels);
  }
  if (get_u16(p + kOffRecordBytes) != kRecordBytes) {
    return fail(ErrorCode::kInvalidArgument, "record size is not 32", kOffRecordBytes);
  }
  h.records_per_block = get_u32(p + kOffRecordsPerBlock);
  if (h.records_per_block == 0) {
    return fail(ErrorCode::kInvalidArgument, "records per block is 0", kOffRecordsPerBlock);
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
  out = h;
  return {};
}

CodecStatus encode_record(const RawSample& s, std::span<std::uint8_t, kRecordBytes> out) {
  std::uint8_t* b = out.data();
  if (s.flags >= kFrameRecordFlag) {
    return fail(ErrorCode::kOutOfRange, "flags at or above bit 15 do not fit", 0, s.flags,
                kFrameRecordFlag - 1u);
  }
  std::memset(b, 0, kRecordBytes);
  put_u32(b + kRecSeq, s.seq);
  put_u64(b + kRecTime, static_cast<std::uint64_t>(s.t_ns));
  for (std::size_t j = 0; j < 6; ++j) {
    const std::int32_t c = s.counts[j];
    if (c > kAdcCodeMax || c < kAdcCodeMin) {
      return fail(ErrorCode::kOutOfRange, "count is not a 24-bit two's-complement code", 0, j,
                  static_cast<std::uint64_t>(static_cast<std::int64_t>(c)));
    }
    const auto u = static_cast<std::uint32_t>(c);  // two's complement, low 24 bits kept
    for (std::size_t k = 0; k < 3; ++k) {
      b[kRecCounts + 3 * j + k] = static_cast<std::uint8_t>(u >> (8 * k));
    }
  }
  put_u16(b + kRecFlags, static_cast<std::uint16_t>(s.flags));
  return {};
}

RawSample decode_record(std::span<const std::uint8_t, kRecordBytes> bytes) {
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

bool is_frame_record(std::span<const std::uint8_t, kRecordBytes> bytes, std::uint16_t version) {
  return version >= 2 && (get_u16(bytes.data() + kRecFlags) & kFrameRecordFlag) != 0;
}

CodecStatus encode_frame_record(const FrameRecord& f, std::span<std::uint8_t, kRecordBytes> out) {
  std::uint8_t* b = out.data();
  const std::uint32_t max_id = f.extended ? kMaxExtendedId : kMaxStandardId;
  if (f.id > max_id) {
    return fail(ErrorCode::kOutOfRange, "frame identifier beyond its range", 0, f.id, max_id);
  }
  if (f.len > f.data.size()) {
    return fail(ErrorCode::kOutOfRange, "frame length above 8", 0, f.len, f.data.size());
  }
  std::memset(b, 0, kRecordBytes);
  put_u32(b + kRecFrameId, f.id | (f.extended ? kExtendedBit : 0u));
  put_u64(b + kRecTime, static_cast<std::uint64_t>(f.t_ns));
  b[kRecFrameLen] = f.len;
  std::memcpy(b + kRecFrameData, f.data.data(), f.data.size());
  put_u16(b + kRecFlags, kFrameRecordFlag);
  return {};
}

CodecStatus decode_frame_record(std::span<const std::uint8_t, kRecordBytes> bytes,
                                FrameRecord& out) {
  const std::uint8_t* p = bytes.data();
  FrameRecord f;
  const std::uint32_t raw_id = get_u32(p + kRecFrameId);
  f.extended = (raw_id & kExtendedBit) != 0;
  f.id = raw_id & ~kExtendedBit;
  const std::uint32_t max_id = f.extended ? kMaxExtendedId : kMaxStandardId;
  if (f.id > max_id) {
    return fail(ErrorCode::kDataLoss, "frame record: identifier beyond its range", kRecFrameId,
                f.id, max_id);
  }
  f.t_ns = static_cast<std::int64_t>(get_u64(p + kRecTime));
  f.len = p[kRecFrameLen];
  if (f.len > f.data.size()) {
    return fail(ErrorCode::kDataLoss, "frame record: length above 8", kRecFrameLen, f.len,
                f.data.size());
  }
  std::memcpy(f.data.data(), p + kRecFrameData, f.data.size());
  for (std::size_t i = kRecFrameLen + 1; i < kRecFrameData; ++i) {
    if (p[i] != 0) return fail(ErrorCode::kDataLoss, "frame record: reserved byte not zero", i);
  }
  for (std::size_t i = kRecFrameData + f.data.size(); i < kRecFlags; ++i) {
    if (p[i] != 0) return fail(ErrorCode::kDataLoss, "frame record: reserved byte not zero", i);
  }
  if (get_u16(p + kRecFlags) != kFrameRecordFlag) {
    return fail(ErrorCode::kDataLoss, "frame record: flags other than the frame mark", kRecFlags,
                get_u16(p + kRecFlags), kFrameRecordFlag);
  }
  out = f;
  return {};
}

CodecStatus check_block(std::span<const std::uint8_t> block, std::uint64_t offset) {
  if (block.size() < kCrcBytes) return fail(ErrorCode::kDataLoss, "block too short", offset);
  const auto records = block.first(block.size() - kCrcBytes);
  const std::uint32_t stored = get_u32(block.data() + records.size());
  const std::uint32_t computed = crc32(records);
  if (stored != computed)
    return fail(ErrorCode::kDataLoss, "CRC-32 mismatch", offset, stored, computed);
  return {};
}

void put_block_crc(std::span<const std::uint8_t> records,
                   std::span<std::uint8_t, kCrcBytes> crc_out) {
  put_u32(crc_out.data(), crc32(records));
}

}  // namespace gfins::recording
