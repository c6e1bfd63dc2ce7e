// read_text_file against real files and devices: a small file whole, exactly the limit accepted,
// one byte more refused, /dev/zero refused after the limit (not read until memory runs out), a
// folder and a missing path with their errno. Oracle: the bytes written by the test itself and
// the errno values of open(2)/read(2).
#include "gfins/drivers/lnx/text_file.hpp"

#include "gfins/drivers/lnx/output_paths.hpp"

#include <gtest/gtest.h>

#include <cerrno>
#include <filesystem>
#include <fstream>
#include <string>

#include "support/temp_dir.hpp"

namespace gfins::drivers::lnx {
namespace {

using gfins::testing::TempDir;

void write_bytes(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

TEST(TextFile, ReadsASmallFileWhole) {
  const TempDir dir;
  const std::string p = (dir.path() / "a.toml").string();
  std::string text = "[scenario]\nduration_s = 1.0\n";
  text.push_back('\0');  // bytes, not a C string: a NUL does not end the read
  text += "binary too";
  write_bytes(p, text);
  std::string out = "stale";
  ASSERT_TRUE(read_text_file(p.c_str(), 1024, out).is_ok());
  EXPECT_EQ(out, text);
}

TEST(TextFile, ExactlyTheLimitIsReadAndOneByteMoreIsRefused) {
  const TempDir dir;
  const std::string p = (dir.path() / "big.csv").string();
  constexpr std::size_t kLimit = 200000;  // more than three 64 kB chunks
  write_bytes(p, std::string(kLimit, 'x'));
  std::string out;
  ASSERT_TRUE(read_text_file(p.c_str(), kLimit, out).is_ok());
  EXPECT_EQ(out.size(), kLimit);
  write_bytes(p, std::string(kLimit + 1, 'x'));
  const Status s = read_text_file(p.c_str(), kLimit, out);
  EXPECT_EQ(s.code(), ErrorCode::kOutOfRange);
  EXPECT_TRUE(out.empty());
}

TEST(TextFile, AnEndlessDeviceIsRefusedAfterTheLimit) {
  std::string out;
  const Status s = read_text_file("/dev/zero", kMaxConfigBytes, out);
  EXPECT_EQ(s.code(), ErrorCode::kOutOfRange);
  EXPECT_TRUE(out.empty());
}

TEST(TextFile, AFolderAndAMissingPathGiveTheirErrno) {
  const TempDir dir;
  std::string out;
  const Status folder = read_text_file(dir.path().string().c_str(), 1024, out);
  EXPECT_EQ(folder.code(), ErrorCode::kIoError);
  EXPECT_EQ(folder.os_error(), EISDIR);
  const Status missing = read_text_file((dir.path() / "nope").string().c_str(), 1024, out);
  EXPECT_EQ(missing.code(), ErrorCode::kIoError);
  EXPECT_EQ(missing.os_error(), ENOENT);
}

// Oracle: the paths and links the test makes itself. Spellings of one path, a link to it and a
// hard link are one file; a file in another folder is not; /dev/null may take several outputs.
TEST(OutputPaths, OneFileUnderAnySpellingIsAClashAndDistinctFilesAreNot) {
  const TempDir dir;
  const std::string a = dir.path().string() + "/a.csv";
  const std::string b = dir.path().string() + "/b.csv";
  EXPECT_TRUE(same_output_file(a, a));  // neither exists yet: compared as paths
  EXPECT_TRUE(same_output_file(a, dir.path().string() + "/./sub/../a.csv"));
  EXPECT_FALSE(same_output_file(a, b));
  EXPECT_FALSE(same_output_file(a, ""));
  write_bytes(a, "x");
  std::filesystem::create_symlink(a, dir.path() / "link.csv");
  std::filesystem::create_hard_link(a, dir.path() / "hard.csv");
  EXPECT_TRUE(same_output_file(a, dir.path().string() + "/link.csv"));
  EXPECT_TRUE(same_output_file(dir.path().string() + "/hard.csv", a));
  EXPECT_FALSE(same_output_file("/dev/null", "/dev/null"));
  const NamedOutput outs[] = {
      {"--one", b}, {"--two", a}, {"--three", dir.path().string() + "/link.csv"}};
  const auto clash = output_clash(outs);
  ASSERT_TRUE(clash.has_value());
  EXPECT_EQ(*clash, "--two and --three name the same file '" + dir.path().string() +
                        "/link.csv': each output needs a file of its own");
  const NamedOutput apart[] = {{"--one", b}, {"--two", a}, {"--none", ""}};
  EXPECT_FALSE(output_clash(apart).has_value());
}

}  // namespace
}  // namespace gfins::drivers::lnx
