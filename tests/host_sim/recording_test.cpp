#include "gfins/host_sim/recording.hpp"

#include <gtest/gtest.h>

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
  // and one of version 2 (with a consistent header CRC, as a newer writer would make),
  RecordingHeader h2 = test_header();
  h2.version = 2;
  const auto head = encode_header(h2);
  auto v2 = good_image();
  std::copy(head.begin(), head.end(), v2.begin());
  const auto v = decode_recording(v2);
  // then both are refused, the version naming offset 8 and the version found.
  ASSERT_FALSE(v.is_ok());
  EXPECT_EQ(v.error().code, ErrorCode::kUnimplemented);
  EXPECT_EQ(v.error().byte_offset, 8u);
  EXPECT_NE(v.error().message.find("version 2"), std::string::npos) << v.error().message;
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
  flag.flags = 1u << 16;
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
  // Given headers with 0 records per block, 5 channels or version 2,
  RecordingHeader zero = test_header();
  zero.records_per_block = 0;
  RecordingHeader five = test_header();
  five.channel_count = 5;
  RecordingHeader v2 = test_header();
  v2.version = 2;
  // then neither the encoder nor the writer produces a file from them.
  for (const RecordingHeader& h : {zero, five, v2}) {
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

}  // namespace
}  // namespace gfins::sim
