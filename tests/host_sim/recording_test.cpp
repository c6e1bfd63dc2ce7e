#include "gfins/host_sim/recording.hpp"

#include <gtest/gtest.h>

#include <bit>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <random>
#include <span>
#include <string>
#include <vector>

#include "gfins/nav_core/geometry.hpp"

namespace gfins::sim {
namespace {

constexpr std::uint32_t kRecordsPerBlock = 16;  // small blocks so a test file has several
constexpr std::size_t kSamples = 100;           // 6 full blocks and a partial one of 4

RecordingHeader test_header() {
  RecordingHeader h;
  h.sample_rate_hz = 1000.0;
  h.records_per_block = kRecordsPerBlock;
  h.volts_per_count.fill(1.2 * 8.33 / 8388608.0);
  h.geometry = nav::table1_geometry(0.1);
  return h;
}

// Samples that exercise every field: negative and extreme codes, negative times, flags.
std::vector<RawSample> test_samples() {
  std::vector<RawSample> v;
  for (std::size_t i = 0; i < kSamples; ++i) {
    RawSample s;
    s.seq = 0xFFFFFFF0u + static_cast<std::uint32_t>(i);  // wraps through 0
    s.t_ns = -5000000 + static_cast<std::int64_t>(i) * 1000000;
    for (std::size_t j = 0; j < 6; ++j) {
      s.counts[j] = static_cast<std::int32_t>((i * 7919 + j * 104729) % 16777216) - 8388608;
    }
    s.flags = static_cast<std::uint32_t>(i % 16);
    v.push_back(s);
  }
  v[3].counts = {8388607, -8388608, -1, 0, 1, -2};
  return v;
}

void expect_same(const std::vector<RawSample>& a, const std::vector<RawSample>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].seq, b[i].seq) << i;
    EXPECT_EQ(a[i].t_ns, b[i].t_ns) << i;
    EXPECT_EQ(a[i].counts, b[i].counts) << i;
    EXPECT_EQ(a[i].flags, b[i].flags) << i;
  }
}

std::vector<std::uint8_t> good_image() {
  const auto samples = test_samples();
  auto image = encode_recording(test_header(), samples);
  EXPECT_TRUE(image.is_ok());
  return image.value();
}

// Offset of block b in a file with kRecordsPerBlock records per block.
constexpr std::size_t block_offset(std::size_t b) {
  return kRecordingHeaderBytes +
         b * (kRecordsPerBlock * kRecordingRecordBytes + kRecordingCrcBytes);
}

std::string temp_path(const char* name) {
  return (std::filesystem::temp_directory_path() / (std::string("gfins_rec_") + name)).string();
}

TEST(RecordingTest, Crc32MatchesTheStandardCheckValue) {
  // Given the ASCII digits 1..9, then CRC-32/IEEE is the catalogued check value 0xCBF43926.
  const std::string digits = "123456789";
  const std::vector<std::uint8_t> b(digits.begin(), digits.end());
  EXPECT_EQ(crc32(b), 0xCBF43926u);
}

TEST(RecordingTest, Crc32EqualsTheBitwiseDefinitionForEveryLengthAndSplit) {
  // The codec computes eight bytes per step with look-up tables (slicing by 8). Oracle: the
  // definition itself, one bit at a time (reflected polynomial 0xEDB88320, init and final xor
  // 0xFFFFFFFF), written here without tables.
  const auto bitwise = [](const std::uint8_t* p, std::size_t n) {
    std::uint32_t c = 0xFFFFFFFFu;
    for (std::size_t i = 0; i < n; ++i) {
      c ^= p[i];
      for (int k = 0; k < 8; ++k) c = (c & 1u) != 0 ? (c >> 1) ^ 0xEDB88320u : c >> 1;
    }
    return ~c;
  };
  std::mt19937 rng(13);
  std::vector<std::uint8_t> bytes(300);
  for (auto& b : bytes) b = static_cast<std::uint8_t>(rng());
  // Every length 0..299 from an odd start (unaligned words, every tail length 0..7),
  for (std::size_t n = 0; n + 1 < bytes.size(); ++n) {
    const std::span<const std::uint8_t> part(bytes.data() + 1, n);
    ASSERT_EQ(crc32(part), bitwise(part.data(), n)) << "length " << n;
  }
  // and a CRC continued over two pieces split anywhere equals the CRC of the whole.
  const std::span<const std::uint8_t> all(bytes);
  for (std::size_t cut = 0; cut <= 40; ++cut) {
    EXPECT_EQ(crc32(all.subspan(cut), crc32(all.first(cut))), crc32(all)) << "cut " << cut;
  }
}

TEST(RecordingTest, InMemoryRoundTripIsExact) {
  // Given samples and a header, when encoded and decoded,
  const auto samples = test_samples();
  const auto image = good_image();
  // then the file is header + 7 blocks of records with a CRC each (32 bytes per sample),
  EXPECT_EQ(image.size(), kRecordingHeaderBytes + kSamples * kRecordingRecordBytes + 7 * 4);
  const auto rec = decode_recording(image);
  ASSERT_TRUE(rec.is_ok()) << rec.error().message;
  // and every field comes back bit for bit.
  expect_same(rec.value().samples, samples);
  const RecordingHeader& h = rec.value().header;
  const RecordingHeader want = test_header();
  EXPECT_EQ(h.record_count, kSamples);
  EXPECT_EQ(h.sample_rate_hz, want.sample_rate_hz);
  EXPECT_EQ(h.volts_per_count, want.volts_per_count);
  for (std::size_t j = 0; j < 6; ++j) {
    EXPECT_EQ(h.geometry.rho_b[j], want.geometry.rho_b[j]);
    EXPECT_EQ(h.geometry.theta_b[j], want.geometry.theta_b[j]);
  }
}

TEST(RecordingTest, FileRoundTripThroughTheStreamingWriterIsExact) {
  // Given a file written sample by sample,
  const std::string path = temp_path("roundtrip.gfr");
  const auto samples = test_samples();
  const auto w = write_recording(path, test_header(), samples);
  ASSERT_TRUE(w.is_ok()) << w.error().message;
  // when read back,
  const auto rec = read_recording(path);
  ASSERT_TRUE(rec.is_ok()) << rec.error().message;
  // then it equals the samples and the in-memory image byte for byte.
  expect_same(rec.value().samples, samples);
  EXPECT_EQ(std::filesystem::file_size(path), good_image().size());
  std::filesystem::remove(path);
}

TEST(RecordingTest, UnclosedFileIsReadableUpToItsLastCompleteBlock) {
  // Given a writer that wrote 40 samples (2 full blocks + 8) and whose process died before
  // close() (simulated: the file is copied while the writer is still open),
  const std::string path = temp_path("unclosed.gfr");
  const std::string copy = temp_path("unclosed_copy.gfr");
  const auto samples = test_samples();
  {
    auto w = RecordingWriter::open(path, test_header());
    ASSERT_TRUE(w.is_ok());
    for (std::size_t i = 0; i < 40; ++i) ASSERT_TRUE(w.value().append(samples[i]).is_ok());
    std::filesystem::copy_file(path, copy, std::filesystem::copy_options::overwrite_existing);
    ASSERT_TRUE(w.value().close().is_ok());
  }
  // when the copy is read,
  const auto rec = read_recording(copy);
  // then record_count says unknown and the two complete blocks come back.
  ASSERT_TRUE(rec.is_ok()) << rec.error().message;
  EXPECT_EQ(rec.value().header.record_count, kRecordCountUnknown);
  ASSERT_EQ(rec.value().samples.size(), 2u * kRecordsPerBlock);
  EXPECT_EQ(rec.value().samples[31].t_ns, samples[31].t_ns);
  std::filesystem::remove(path);
  std::filesystem::remove(copy);
}

TEST(RecordingTest, TruncatedFileNamesTheOffsetWhereItBreaks) {
  const auto image = good_image();
  struct Cut {
    std::size_t size;      // file cut to this many bytes
    std::size_t expected;  // byte offset the error must name
  };
  const Cut cuts[] = {
      {100, 100},                                                // inside the header: the file end
      {block_offset(2) + 5 * 32 + 7, block_offset(2) + 5 * 32},  // mid-record: its start
      {block_offset(3) - 2, block_offset(3) - 4},  // inside block 2's CRC: the CRC's start
      {block_offset(6), block_offset(6)},          // a whole block missing: its start
  };
  for (const Cut& c : cuts) {
    // Given the file cut to c.size bytes, when decoded,
    const std::vector<std::uint8_t> cut(image.begin(),
                                        image.begin() + static_cast<std::ptrdiff_t>(c.size));
    const auto rec = decode_recording(cut);
    // then it fails as data loss at the expected offset, and the message says "truncated" and
    // the offset.
    ASSERT_FALSE(rec.is_ok()) << "cut at " << c.size;
    EXPECT_EQ(rec.error().code, ErrorCode::kDataLoss);
    EXPECT_EQ(rec.error().byte_offset, c.expected) << "cut at " << c.size;
    EXPECT_NE(rec.error().message.find("truncated"), std::string::npos) << rec.error().message;
    EXPECT_NE(rec.error().message.find(std::to_string(c.expected)), std::string::npos)
        << rec.error().message;
  }
}

TEST(RecordingTest, CorruptByteIsReportedWithItsBlockOffset) {
  // Given a good file with one bit flipped in a count of record 5 of block 3,
  auto image = good_image();
  const std::size_t at = block_offset(3) + 5 * kRecordingRecordBytes + 14;
  image[at] ^= 0x10;
  // when decoded,
  const auto rec = decode_recording(image);
  // then the CRC of block 3 fails and the error names block 3's offset.
  ASSERT_FALSE(rec.is_ok());
  EXPECT_EQ(rec.error().code, ErrorCode::kDataLoss);
  EXPECT_EQ(rec.error().byte_offset, block_offset(3));
  EXPECT_NE(rec.error().message.find("CRC-32 mismatch"), std::string::npos);
  EXPECT_NE(rec.error().message.find("block 3"), std::string::npos) << rec.error().message;
}

TEST(RecordingTest, DamagedFilesOnDiskGiveTheSameErrorsAsInMemory) {
  // Given a file cut mid-record and a file with a flipped byte, written to disk,
  const auto image = good_image();
  const std::string cut_path = temp_path("cut.gfr");
  const std::string bad_path = temp_path("bad.gfr");
  const std::size_t cut_at = block_offset(4) + 3 * kRecordingRecordBytes + 9;
  auto bad = image;
  bad[block_offset(1) + 40] ^= 0x01;
  {
    std::FILE* f = std::fopen(cut_path.c_str(), "wb");
    ASSERT_NE(f, nullptr);
    ASSERT_EQ(std::fwrite(image.data(), 1, cut_at, f), cut_at);
    std::fclose(f);
    f = std::fopen(bad_path.c_str(), "wb");
    ASSERT_NE(f, nullptr);
    ASSERT_EQ(std::fwrite(bad.data(), 1, bad.size(), f), bad.size());
    std::fclose(f);
  }
  // when read through the streaming reader,
  const auto cut = read_recording(cut_path);
  const auto corrupt = read_recording(bad_path);
  // then the offsets are those of the in-memory decoder: the broken record, the broken block.
  ASSERT_FALSE(cut.is_ok());
  EXPECT_EQ(cut.error().byte_offset, block_offset(4) + 3 * kRecordingRecordBytes);
  ASSERT_FALSE(corrupt.is_ok());
  EXPECT_EQ(corrupt.error().byte_offset, block_offset(1));
  // and a reader streaming block by block returns the blocks before the damage first.
  auto reader = RecordingReader::open(bad_path);
  ASSERT_TRUE(reader.is_ok());
  std::vector<RawSample> block;
  const auto first = reader.value().next_block(block);
  ASSERT_TRUE(first.is_ok());
  EXPECT_TRUE(first.value());
  EXPECT_EQ(block.size(), kRecordsPerBlock);
  EXPECT_FALSE(reader.value().next_block(block).is_ok());
  std::filesystem::remove(cut_path);
  std::filesystem::remove(bad_path);
}

TEST(RecordingTest, AReaderMovedInTheMiddleOfAFileContinuesWhereItWas) {
  // Given a file of several blocks and a reader that has returned two of them (the stream reads
  // through a buffer the reader owns, which must move with it),
  const std::string path = temp_path("moved.gfr");
  const std::string other_path = temp_path("moved_other.gfr");
  const auto samples = test_samples();
  ASSERT_TRUE(write_recording(path, test_header(), samples).is_ok());
  ASSERT_TRUE(write_recording(other_path, test_header(), samples).is_ok());
  std::vector<RawSample> got;
  std::vector<RawSample> block;
  std::optional<RecordingReader> second;
  {
    auto first = RecordingReader::open(path);
    ASSERT_TRUE(first.is_ok()) << first.error().message;
    for (int b = 0; b < 2; ++b) {
      ASSERT_TRUE(first.value().next_block(block).value());
      got.insert(got.end(), block.begin(), block.end());
    }
    // when it is moved into a new reader and the old one is destroyed,
    second.emplace(std::move(first.value()));
  }
  // and that one is moved over a reader of another open file, then destroyed too,
  auto third = RecordingReader::open(other_path);
  ASSERT_TRUE(third.is_ok());
  third.value() = std::move(*second);
  second.reset();
  for (;;) {
    const auto more = third.value().next_block(block);
    ASSERT_TRUE(more.is_ok()) << more.error().message;
    if (!more.value()) break;
    got.insert(got.end(), block.begin(), block.end());
  }
  // then the samples read are those of the file, in order, each once.
  expect_same(got, samples);
  EXPECT_EQ(third.value().records_read(), samples.size());
  std::filesystem::remove(path);
  std::filesystem::remove(other_path);
}

TEST(RecordingTest, CorruptHeaderFailsItsCrc) {
  // Given a good file with one byte of the sample rate changed,
  auto image = good_image();
  image[33] ^= 0x01;
  // then decoding fails on the header CRC.
  const auto rec = decode_recording(image);
  ASSERT_FALSE(rec.is_ok());
  EXPECT_EQ(rec.error().code, ErrorCode::kDataLoss);
  EXPECT_NE(rec.error().message.find("header CRC-32"), std::string::npos);
}

TEST(RecordingTest, WrongMagicAndVersionAreRejected) {
  // Given a file with another magic,
  auto bad_magic = good_image();
  bad_magic[0] = 'X';
  const auto m = decode_recording(bad_magic);
  ASSERT_FALSE(m.is_ok());
  EXPECT_EQ(m.error().byte_offset, 0u);
  EXPECT_NE(m.error().message.find("magic"), std::string::npos);
  // and ones of versions 0 and 3 (with a consistent header CRC, as a newer writer would make),
  for (const std::uint16_t version : {std::uint16_t{0}, std::uint16_t{3}}) {
    RecordingHeader h = test_header();
    h.version = version;
    const auto head = encode_header(h);
    auto image = good_image();
    std::copy(head.begin(), head.end(), image.begin());
    const auto v = decode_recording(image);
    // then all are refused, the version naming offset 8 and the version found.
    ASSERT_FALSE(v.is_ok());
    EXPECT_EQ(v.error().code, ErrorCode::kUnimplemented);
    EXPECT_EQ(v.error().byte_offset, 8u);
    EXPECT_NE(v.error().message.find("version " + std::to_string(version)), std::string::npos)
        << v.error().message;
  }
}

TEST(RecordingTest, TrailingBytesAfterTheAnnouncedRecordsAreAnError) {
  // Given a good file with 3 extra bytes,
  auto image = good_image();
  const std::size_t end = image.size();
  image.insert(image.end(), {1, 2, 3});
  // then it fails at the end of the announced data.
  const auto rec = decode_recording(image);
  ASSERT_FALSE(rec.is_ok());
  EXPECT_EQ(rec.error().byte_offset, end);
}

TEST(RecordingTest, SamplesThatDoNotFitTheRecordAreRefused) {
  // Given a count beyond 24 bits and a flag above bit 15,
  RawSample big;
  big.counts[2] = 1 << 23;
  RawSample flag;
  flag.flags = 1u << 15;  // the frame-record mark (version 2)
  // then neither encodes (so no sample is ever silently changed).
  EXPECT_FALSE(encode_record(big).is_ok());
  EXPECT_EQ(encode_record(big).error().code, ErrorCode::kOutOfRange);
  EXPECT_FALSE(encode_record(flag).is_ok());
  // and the writer reports the offset the record would have had.
  const std::string path = temp_path("refused.gfr");
  auto w = RecordingWriter::open(path, test_header());
  ASSERT_TRUE(w.is_ok());
  ASSERT_TRUE(w.value().append(RawSample{}).is_ok());
  const auto r = w.value().append(big);
  ASSERT_FALSE(r.is_ok());
  EXPECT_EQ(r.error().byte_offset, kRecordingHeaderBytes + kRecordingRecordBytes);
  ASSERT_TRUE(w.value().close().is_ok());
  std::filesystem::remove(path);
}

TEST(RecordingTest, HeadersTheReaderWouldRefuseAreNotWritten) {
  // Given headers with 0 records per block, 5 channels or version 1 (read, no longer written),
  RecordingHeader zero = test_header();
  zero.records_per_block = 0;
  RecordingHeader five = test_header();
  five.channel_count = 5;
  RecordingHeader v1 = test_header();
  v1.version = 1;
  // then neither the encoder nor the writer produces a file from them.
  for (const RecordingHeader& h : {zero, five, v1}) {
    const auto e = encode_recording(h, test_samples());
    ASSERT_FALSE(e.is_ok());
    EXPECT_EQ(e.error().code, ErrorCode::kInvalidArgument);
    EXPECT_FALSE(RecordingWriter::open(temp_path("refused_header.gfr"), h).is_ok());
  }
}

TEST(RecordingTest, MissingFileIsAnIoError) {
  const auto rec = read_recording(temp_path("does_not_exist.gfr"));
  ASSERT_FALSE(rec.is_ok());
  EXPECT_EQ(rec.error().code, ErrorCode::kIoError);
}

// ---- Version 2: frame records ------------------------------------------------------------

// The bytes of a version-1 file, written here field by field from docs/recording-format.md
// (not through the encoder under test): the header of test_header() and `samples`, one block.
std::vector<std::uint8_t> version1_image(const std::vector<RawSample>& samples) {
  std::vector<std::uint8_t> b(kRecordingHeaderBytes, 0);
  const auto put = [&b](std::size_t at, std::uint64_t v, int n) {
    for (int i = 0; i < n; ++i)
      b[at + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(v >> (8 * i));
  };
  const RecordingHeader h = test_header();
  const char* magic = "GFINSRAW";
  for (std::size_t i = 0; i < 8; ++i) b[i] = static_cast<std::uint8_t>(magic[i]);
  put(8, 1, 2);
  put(10, 384, 2);
  put(12, 6, 2);
  put(14, 32, 2);
  put(16, samples.size(), 4);
  put(24, samples.size(), 8);
  put(32, std::bit_cast<std::uint64_t>(h.sample_rate_hz), 8);
  for (std::size_t j = 0; j < 6; ++j) {
    put(40 + 8 * j, std::bit_cast<std::uint64_t>(h.volts_per_count[j]), 8);
    for (std::size_t k = 0; k < 3; ++k) {
      const auto r = static_cast<Eigen::Index>(k);
      put(88 + 8 * (3 * j + k), std::bit_cast<std::uint64_t>(h.geometry.rho_b[j](r)), 8);
      put(232 + 8 * (3 * j + k), std::bit_cast<std::uint64_t>(h.geometry.theta_b[j](r)), 8);
    }
  }
  put(380, crc32(std::span(b.data(), 380)), 4);
  const std::size_t start = b.size();
  for (const RawSample& s : samples) {
    const std::size_t at = b.size();
    b.resize(at + 32, 0);
    put(at, s.seq, 4);
    put(at + 4, static_cast<std::uint64_t>(s.t_ns), 8);
    for (std::size_t j = 0; j < 6; ++j)
      put(at + 12 + 3 * j, static_cast<std::uint32_t>(s.counts[j]), 3);
    put(at + 30, s.flags, 2);
  }
  const std::uint32_t crc = crc32(std::span(b).subspan(start));
  b.resize(b.size() + 4);
  put(b.size() - 4, crc, 4);
  return b;
}

TEST(RecordingV2Test, AVersion1FileStillReadsAndItsBit15IsASampleFlag) {
  // Given a version-1 file written byte by byte, one of whose samples has flag bit 15 set (a
  // version-1 writer allowed it),
  const std::vector<RawSample> all = test_samples();
  std::vector<RawSample> samples(all.begin(), all.begin() + 5);
  samples[2].flags = 0x8001u;
  const auto rec = decode_recording(version1_image(samples));
  // then it reads as five samples and no frame, bit 15 kept as a sample flag.
  ASSERT_TRUE(rec.is_ok()) << rec.error().message;
  EXPECT_EQ(rec.value().header.version, 1u);
  expect_same(rec.value().samples, samples);
  EXPECT_TRUE(rec.value().frames.empty());
}

TEST(RecordingV2Test, FrameRecordsHaveTheDocumentedLayout) {
  // Given a 29-bit frame of 5 bytes at t = -3 ns,
  recording::FrameRecord f;
  f.t_ns = -3;
  f.id = 0x18FEF100u;
  f.extended = true;
  f.len = 5;
  f.data = {1, 2, 3, 4, 5, 0xAA, 0xBB, 0xCC};
  std::array<std::uint8_t, kRecordingRecordBytes> b{};
  ASSERT_TRUE(recording::encode_frame_record(f, b).ok());
  // then the bytes are those of docs/recording-format.md, "Frame records": identifier with bit
  // 31 for a 29-bit one, time, length, a zero byte, all eight data bytes, zeros, flags 0x8000.
  const std::array<std::uint8_t, 32> want = {
      0x00, 0xF1, 0xFE, 0x98,                          // id | 0x80000000, little-endian
      0xFD, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF,  // t_ns = -3
      5,    0,                                         // len, reserved
      1,    2,    3,    4,    5,    0xAA, 0xBB, 0xCC,  // data[8], as given
      0,    0,    0,    0,    0,    0,    0,    0,     // reserved
      0x00, 0x80};                                     // the frame mark
  EXPECT_EQ(b, want);
  recording::FrameRecord back;
  ASSERT_TRUE(recording::decode_frame_record(b, back).ok());
  EXPECT_EQ(back.t_ns, f.t_ns);
  EXPECT_EQ(back.id, f.id);
  EXPECT_TRUE(back.extended);
  EXPECT_EQ(back.len, f.len);
  EXPECT_EQ(back.data, f.data);
}

TEST(RecordingV2Test, FramesComeBackBetweenTheSamplesTheyFollowed) {
  // Given samples with frames after samples 0, 15 (the end of a block of 16), 16 and 99,
  const std::string path = temp_path("frames.gfr");
  const auto samples = test_samples();
  auto w = RecordingWriter::open(path, test_header());
  ASSERT_TRUE(w.is_ok()) << w.error().message;
  const std::vector<std::size_t> after = {0, 15, 15, 16, 99};
  std::size_t next = 0;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    ASSERT_TRUE(w.value().append(samples[i]).is_ok());
    for (; next < after.size() && after[next] == i; ++next) {
      recording::FrameRecord f;
      f.t_ns = samples[i].t_ns;
      f.id = 0x300u + static_cast<std::uint32_t>(next);
      f.len = static_cast<std::uint8_t>(next + 1);
      f.data[0] = static_cast<std::uint8_t>(next);
      ASSERT_TRUE(w.value().append_frame(f).is_ok());
    }
  }
  ASSERT_TRUE(w.value().close().is_ok());
  // when read whole and streamed,
  const auto rec = read_recording(path);
  ASSERT_TRUE(rec.is_ok()) << rec.error().message;
  // then the samples are unchanged, the header counts every record, and each frame comes back
  // with the number of samples before it and its own fields.
  expect_same(rec.value().samples, samples);
  EXPECT_EQ(rec.value().header.record_count, samples.size() + after.size());
  ASSERT_EQ(rec.value().frames.size(), after.size());
  for (std::size_t k = 0; k < after.size(); ++k) {
    const RecordedFrame& f = rec.value().frames[k];
    EXPECT_EQ(f.samples_before, after[k] + 1) << k;
    EXPECT_EQ(f.frame.id, 0x300u + k);
    EXPECT_EQ(f.frame.len, k + 1);
    EXPECT_EQ(f.frame.data[0], k);
    EXPECT_EQ(f.frame.t_ns, samples[after[k]].t_ns);
  }
  auto reader = RecordingReader::open(path);
  ASSERT_TRUE(reader.is_ok());
  std::vector<RawSample> block;
  std::size_t frames = 0;
  while (reader.value().next_block(block).value()) frames += reader.value().frames().size();
  EXPECT_EQ(frames, after.size());
  EXPECT_EQ(reader.value().samples_read(), samples.size());
  EXPECT_EQ(reader.value().frames_read(), after.size());
  std::filesystem::remove(path);
}

TEST(RecordingV2Test, AMalformedFrameRecordIsAnErrorNamingItsByte) {
  // Given a file whose only record is a frame with length 9 (CRC made consistent, as a hostile
  // file would be),
  const std::string path = temp_path("bad_frame.gfr");
  RecordingHeader h = test_header();
  auto w = RecordingWriter::open(path, h);
  ASSERT_TRUE(w.is_ok());
  recording::FrameRecord f;
  f.id = 0x123;
  f.len = 8;
  ASSERT_TRUE(w.value().append_frame(f).is_ok());
  ASSERT_TRUE(w.value().close().is_ok());
  ASSERT_TRUE(read_recording(path).is_ok());
  std::FILE* fp = std::fopen(path.c_str(), "rb");
  ASSERT_NE(fp, nullptr);
  std::vector<std::uint8_t> image(kRecordingHeaderBytes + 32 + 4);
  ASSERT_EQ(std::fread(image.data(), 1, image.size(), fp), image.size());
  std::fclose(fp);
  image[kRecordingHeaderBytes + 12] = 9;
  const std::uint32_t crc = crc32(std::span(image).subspan(kRecordingHeaderBytes, 32));
  for (int i = 0; i < 4; ++i)
    image[kRecordingHeaderBytes + 32 + static_cast<std::size_t>(i)] =
        static_cast<std::uint8_t>(crc >> (8 * i));
  // then the reader refuses it at the length byte, and an identifier too large for 11 bits too.
  const auto r = decode_recording(image);
  ASSERT_FALSE(r.is_ok());
  EXPECT_EQ(r.error().code, ErrorCode::kDataLoss);
  EXPECT_EQ(r.error().byte_offset, kRecordingHeaderBytes + 12);
  EXPECT_NE(r.error().message.find("length above 8"), std::string::npos) << r.error().message;
  recording::FrameRecord wide;
  wide.id = 0x800;
  std::array<std::uint8_t, kRecordingRecordBytes> b{};
  EXPECT_EQ(recording::encode_frame_record(wide, b).code, ErrorCode::kOutOfRange);
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace gfins::sim
