// candump lines as can-utils writes them (candump -L) and the forms its readers accept.
#include "gfins/drivers/lnx/candump.hpp"

#include <gtest/gtest.h>

#include <string>

namespace gfins::drivers::lnx {
namespace {

std::string format(std::int64_t s, std::uint32_t us, std::string_view iface,
                   const hal::CanFrame& f) {
  char buf[kMaxCandumpLine];
  const std::size_t n = format_candump_line(buf, s, us, iface, f);
  return std::string(buf, n);
}

hal::CanFrame frame(std::uint32_t id, std::initializer_list<std::uint8_t> data, bool ext = false) {
  hal::CanFrame f;
  f.id = id;
  f.extended = ext;
  for (std::uint8_t b : data) f.data[f.len++] = b;
  return f;
}

TEST(Candump, FormatsLikeCandumpL) {
  // candump -L: "(%010llu.%06llu) %s %03X#%02X..." (extended: %08X), upper-case hex.
  EXPECT_EQ(format(1700000000, 123456, "can0", frame(0x123, {0xDE, 0xAD, 0xBE, 0xEF})),
            "(1700000000.123456) can0 123#DEADBEEF");
  EXPECT_EQ(format(12, 5, "vcan0", frame(0x7, {})), "(0000000012.000005) vcan0 007#");
  EXPECT_EQ(format(0, 0, "can1", frame(0x1ABCDEF, {0x01}, true)),
            "(0000000000.000000) can1 01ABCDEF#01");
}

TEST(Candump, RefusesWhatCannotBeALine) {
  char buf[kMaxCandumpLine];
  EXPECT_EQ(format_candump_line(buf, 1, 0, "", frame(0x1, {})), 0u);
  EXPECT_EQ(format_candump_line(buf, 1, 0, "can 0", frame(0x1, {})), 0u);
  EXPECT_EQ(format_candump_line(buf, 1, 1000000, "can0", frame(0x1, {})), 0u);
  EXPECT_EQ(format_candump_line(buf, 1, 0, "can0", frame(0x800, {})), 0u);
  char small[10];
  EXPECT_EQ(format_candump_line(small, 1, 0, "can0", frame(0x1, {})), 0u);
}

TEST(Candump, ParsesTheFormsCanUtilsAccepts) {
  auto p = parse_candump_line("(1700000000.123456) can0 123#DEADBEEF\n");
  ASSERT_TRUE(p.is_ok()) << p.status().message();
  EXPECT_EQ(p->seconds, 1700000000);
  EXPECT_EQ(p->micros, 123456u);
  EXPECT_EQ(p->interface, "can0");
  EXPECT_EQ(p->frame.id, 0x123u);
  EXPECT_FALSE(p->frame.extended);
  EXPECT_EQ(p->frame.len, 4);
  EXPECT_EQ(p->frame.data[3], 0xEF);

  p = parse_candump_line("(1.000001) can0 12345678#11.22.33");  // 29-bit, '.' separators
  ASSERT_TRUE(p.is_ok());
  EXPECT_TRUE(p->frame.extended);
  EXPECT_EQ(p->frame.id, 0x12345678u);
  EXPECT_EQ(p->frame.len, 3);
  EXPECT_EQ(p->frame.data[2], 0x33);

  p = parse_candump_line("(1.000001) can0 123#R");  // remote, length 0
  ASSERT_TRUE(p.is_ok());
  EXPECT_TRUE(p->remote);
  EXPECT_EQ(p->frame.len, 0);
  p = parse_candump_line("(1.000001) can0 12345678#R5");  // remote with length
  ASSERT_TRUE(p.is_ok());
  EXPECT_TRUE(p->remote);
  EXPECT_EQ(p->frame.len, 5);

  p = parse_candump_line("(1.000001) can0 123#1122334455667788_C");  // len8_dlc
  ASSERT_TRUE(p.is_ok());
  EXPECT_EQ(p->len8_dlc, 0xC);

  p = parse_candump_line("(1.000001) can0 20000004#0004000000000000");  // error frame
  ASSERT_TRUE(p.is_ok());
  EXPECT_TRUE(p->error_frame);
  EXPECT_EQ(p->frame.id, 4u);

  p = parse_candump_line("(1.000001) can0 123#abcd T");  // lower case, trailing direction flag
  ASSERT_TRUE(p.is_ok());
  EXPECT_EQ(p->frame.data[0], 0xAB);

  p = parse_candump_line("(1.000001) can0 123#");  // zero-length data frame
  ASSERT_TRUE(p.is_ok());
  EXPECT_EQ(p->frame.len, 0);
}

TEST(Candump, MalformedLinesNameWhatIsWrong) {
  struct Case {
    const char* line;
    const char* fragment;  // a word the message must contain
  };
  const Case cases[] = {
      {"", "empty"},
      {"1700000000.1 can0 123#00", "'('"},
      {"(abc.123456) can0 123#00", "seconds"},
      {"(1700000000123456) can0 123#00", "'.'"},
      // The largest second whose time in µs fits an int64 is 9223372036853; one more is refused
      // (it overflowed CandumpRecord::time_us).
      {"(9223372036854.000000) can0 123#00", "beyond"},
      {"(999999999999999999.000000) can0 123#00", "beyond"},
      {"(1.1234567) can0 123#00", "fraction"},
      {"(1.123456 can0 123#00", "')'"},
      {"(1.123456)can0 123#00", "space"},
      {"(1.123456) can0", "frame missing"},
      {"(1.123456) can0 12300", "'#'"},
      {"(1.123456) can0 1234#00", "3 or 8"},
      {"(1.123456) can0 12G#00", "hexadecimal"},
      {"(1.123456) can0 800#00", "0x7FF"},
      {"(1.123456) can0 123#0", "odd"},
      {"(1.123456) can0 123#0G", "hexadecimal"},
      {"(1.123456) can0 123#000102030405060708", "more than 8"},
      {"(1.123456) can0 123#R9", "0..8"},
      {"(1.123456) can0 123#00_C", "DLC"},
      {"(1.123456) can0 123##100", "FD"},
      {"(1.123456) averyveryverylongifname 123#00", "too long"},
      // Linux interface names hold no '/', ':' or white space (dev_valid_name); control
      // characters are refused too, so a log line cannot drive a terminal.
      {"(1.123456) c\x01an0 123#00", "interface name holds"},
      {"(1.123456) can\x1b[2J 123#00", "interface name holds"},
      {"(1.123456) can\r0 123#00", "interface name holds"},
      {"(1.123456) a/b 123#00", "interface name holds"},
      {"(1.123456) vcan:0 123#00", "interface name holds"},
      {"(1.123456) can0 C0000000#00", "flag"},
  };
  for (const Case& c : cases) {
    const auto r = parse_candump_line(c.line);
    ASSERT_FALSE(r.is_ok()) << c.line;
    EXPECT_NE(std::string(r.status().message()).find(c.fragment), std::string::npos)
        << c.line << " -> " << r.status().message();
  }
}

// can-utils 2020.11 (Debian 12) canplayer and log2asc read with fgets and skip every line whose
// first character is not '(' (checked: `log2asc -I` on a log with blank, '#' and text lines
// prints only the frames). Binary junk is not a comment: it is reported.
TEST(Candump, TheLastSecondAMicrosecondTimeHoldsIsAccepted) {
  const auto r = parse_candump_line("(9223372036853.999999) can0 123#00");
  ASSERT_TRUE(r.is_ok()) << r.status().message();
  EXPECT_EQ(r->time_us(), 9'223'372'036'853'999'999);
}

TEST(Candump, CommentLinesAreWhatCanUtilsSkips) {
  for (const char* c : {"", "\n", "\r\n", "   ", "\t", "# recorded on the bench", "a note",
                        "  # indented comment\r\n"}) {
    SCOPED_TRACE(c);
    EXPECT_TRUE(is_candump_comment(c));
  }
  for (std::string_view c :
       {std::string_view("(1700000000.000000) can0 100#00"), std::string_view("  (garbage"),
        std::string_view("\x7f"
                         "ELF"),
        std::string_view("bin\x01"
                         "ary"),
        std::string_view("nul\0in", 6)}) {
    SCOPED_TRACE(std::string(c));
    EXPECT_FALSE(is_candump_comment(c));
  }
}

TEST(Candump, FormatThenParseIsIdentity) {
  for (std::uint32_t id : {0x000u, 0x100u, 0x7FFu}) {
    for (std::uint8_t len = 0; len <= 8; ++len) {
      hal::CanFrame f;
      f.id = id;
      f.len = len;
      for (std::uint8_t i = 0; i < len; ++i) f.data[i] = static_cast<std::uint8_t>(i * 37 + id);
      const std::string line = format(1234567890, 999999, "can0", f);
      const auto r = parse_candump_line(line);
      ASSERT_TRUE(r.is_ok()) << line;
      EXPECT_EQ(r->frame.id, f.id);
      EXPECT_EQ(r->frame.len, f.len);
      EXPECT_EQ(r->frame.data, f.data);
      EXPECT_EQ(r->time_us(), 1234567890LL * 1000000 + 999999);
    }
  }
}

}  // namespace
}  // namespace gfins::drivers::lnx
