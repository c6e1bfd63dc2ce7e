// What tomlplusplus 3.3 cannot be given safely (gfins/toml/header_check.hpp): a table header
// whose key cannot start, and non-ASCII characters where the library asks whether a character is
// whitespace (undefined behaviour for U+00A1..U+0499 and others). The three TOML readers
// (firmware configuration, calibration file, scenario) refuse both with a syntax error on the
// line, and the scan finds exactly those places and no look-alike elsewhere.
// The cases follow TOML 1.0's grammar (toml.io: "Table", "Keys", "String", "Array", "Inline
// Table"), the reproducers of the upstream fix of the header bug (marzer/tomlplusplus pull
// request 301: "[[[1]]]", "[[[a]]", "[[[]]", "[[="), and what the fuzzers found in the
// project's own files ("[.cenario]", "[>board]", "ra0° [qc").
#include <gtest/gtest.h>

#include <string>
#include <string_view>

#include "gfins/app/config.hpp"
#include "gfins/calib_file/calibration_file.hpp"
#include "gfins/host_sim/scenario.hpp"
#include "gfins/toml/header_check.hpp"

namespace {

using gfins::toml_text::kBadHeaderKey;
using gfins::toml_text::kNonAscii;
using gfins::toml_text::unsafe_for_toml_parser;

TEST(TomlGuard, FindsAHeaderWhoseKeyCannotStart) {
  for (const std::string_view text :
       {"[.a]\n", "[>board]\nx = 1\n", "[[[1]]]\n", "[[[a]]\n", "[[[]]\n", "[[=\n", "[\n", "[",
        "[ .a]\n", "[[ =]]\n", "[#]\n"}) {
    const auto p = unsafe_for_toml_parser(text);
    EXPECT_EQ(p.line, 1u) << text;
    EXPECT_EQ(p.what, kBadHeaderKey) << text;
  }
  // The column is the character's: "[ .a]" has the dot at column 3.
  EXPECT_EQ(unsafe_for_toml_parser("[ .a]\n").column, 3u);
  // Later lines count, after comments and values of every kind.
  const std::string_view later =
      "# [.comment]\n"
      "a = \"[.string]\"\n"
      "b = '[.literal]'\n"
      "c = \"\"\"\n[.multi-line basic]\n\"\"\"\n"
      "d = '''\n[.multi-line literal]\n'''\n"
      "e = [\n  [+1.0, 2],\n  [[3]],\n]\n"
      "f = { g = [1, 2] }\n"
      "[ok.\"quoted [.key]\"]\n"
      "[.bad]\n";
  EXPECT_EQ(unsafe_for_toml_parser(later).line, 16u);
}

TEST(TomlGuard, FindsNonAsciiWhereTheParserTestsForWhitespace) {
  struct Case {
    std::string_view text;
    std::size_t column;
  };
  for (const Case& c : {Case{"ra\xC2\xB0 = 1\n", 3}, Case{"x = 1\xC2\xB0\n", 6},
                        Case{"\"\xCF\x83\" = 1\n", 2},                 // a quoted key: σ
                        Case{"x = { \"\xC3\xA9\" = 1 }\n", 8},         // an inline table's key
                        Case{"[a.'\xC2\xB0']\n", 5},                   // a header's key
                        Case{"x = \"\"\"a\\\n  \xC2\xB0\"\"\"\n", 3},  // after a line-ending '\'
                        Case{"x = \"\"\"\\\xC2\xB0\"\"\"\n", 9},       // an escaped character
                        Case{"x = tr\xC2\xB0\n", 7}}) {
    const auto p = unsafe_for_toml_parser(c.text);
    EXPECT_EQ(p.what, kNonAscii) << c.text;
    EXPECT_EQ(p.column, c.column) << c.text;
  }
}

TEST(TomlGuard, FindsABraceWhereAnArrayExpectsAValue) {
  for (const std::string_view text :
       {"x = [1, }]\n", "x = [}]\n", "x = [1, # c\n}]\n", "x = [1 }]\n", "x = [{a = 1}, }]\n"}) {
    EXPECT_EQ(unsafe_for_toml_parser(text).what, gfins::toml_text::kBraceInArray) << text;
  }
  // An inline table's own brace closes it, also inside an array.
  EXPECT_EQ(unsafe_for_toml_parser("x = [{a = 1}, {b = [2]}]\n").what, nullptr);
}

TEST(TomlGuard, AQuoteAfterAMalformedValueStartsNoString) {
  // The library reads "1g'..." as one malformed value up to the next space: the "string" there
  // is part of it, and a non-ASCII character in it is refused like any outside a string.
  const auto p = unsafe_for_toml_parser("eg=1g'avit\xD1\x88t'\n");
  EXPECT_EQ(p.what, kNonAscii);
  EXPECT_EQ(p.column, 11u);
  // A string where a value starts is one.
  EXPECT_EQ(unsafe_for_toml_parser("eg = 'avit\xD1\x88t'\n").what, nullptr);
}

// Found by an independent review, each passed by an earlier version of the scan and reaching the
// library's undefined behaviour or an assertion.
TEST(TomlGuard, FindsWhatAReviewFoundPast) {
  using gfins::toml_text::kDateWithoutTime;
  for (const std::string_view text :
       {// White space after a backslash in a multi-line string, then non-ASCII on the same line.
        "a = \"\"\"\\ \xC3\xA9\"\"\"\n",
        "a = \"\"\"x\\\t\xC2\xB0"
        "C\"\"\"\n",
        // A quote after a malformed value's '.', '=', '[' or '{': no string starts there.
        "a = 1.\"\xC3\xA9\"\n", "a = -.\"\xC3\xA9\"\n", "k = 1.'''\xC3\xA9'''\n",
        "a = 1[\"\xC3\xA9\"]\n", "a = 1=\"\xC3\xA9\"\n", "a = 1{x=\"\xC3\xA9\"}\n",
        "a = [1.\"\xC3\xA9\"]\n", "k = { a = 1, b = 2[\"\xCF\x83\"] }\n",
        "a = 1979-05-27 07:32:00.\"\xC2\xB0\"\n"}) {
    EXPECT_EQ(unsafe_for_toml_parser(text).what, kNonAscii) << text;
  }
  for (const std::string_view text :
       {"k = 1979-05-27T:\n", "k=1979-05-27t:", "k = [1979-05-27T:]\n", "k={a=1979-05-27T:"}) {
    EXPECT_EQ(unsafe_for_toml_parser(text).what, kDateWithoutTime) << text;
  }
  // A date-time with its time, and a bare key that looks like a date, are fine.
  EXPECT_EQ(unsafe_for_toml_parser("k = 1979-05-27T07:32:00Z\n").what, nullptr);
  EXPECT_EQ(unsafe_for_toml_parser("1979-05-27T = 1\n").what, nullptr);
}

TEST(TomlGuard, LeavesEveryValidHeaderValueAndCommentAlone) {
  for (const std::string_view text :
       {"[a]\n", "[ a ]\n", "[[a]]\n", "[[ a.b ]]\n", "[\"quoted\"]\n", "['literal']\n", "[_a]\n",
        "[-a]\n", "[1]\n", "  [indented]\n",
        "x = [\n[+1.0],\n[.5],\n[[[1]]],\n]\n",  // rows of an array value, not headers
        "x = \"\\\"\"\n[a]\n",                   // an escaped quote does not end the string
        "x = \"\"\"a \"\" b\"\"\"\n[a]\n",       // two quotes inside a multi-line string
        "x = { y = [ { z = 1 } ] }\n[a]\n", "# [.a]\n", "x = 1 # [.a]\n",
        // Non-ASCII where TOML allows it and the parser does not test it for whitespace.
        "# 1 \xC2\xB0 = 0.0175 rad, \xCF\x83 and \xCF\x89\n", "x = \"\xC2\xB0\"\n",
        "x = '\xC2\xB0'\n", "x = \"\"\"\n\xC2\xB0\n\"\"\"\n", "x = '''\\\xC2\xB0'''\n",
        "x = [\"\xC3\xA9\", '\xC3\xBC']\n", "x = { a = \"\xC2\xB0\" }\n",
        "x = \"\\\\\xC2\xB0\"\n"}) {
    EXPECT_EQ(unsafe_for_toml_parser(text).what, nullptr) << text;
  }
}

constexpr std::string_view kBadHeader = "# a comment\n[.cenario]\nx = 1\n";
constexpr std::string_view kDegreeKey = "# a comment\nra\xC2\xB0 = 1\n";

TEST(TomlGuard, TheFirmwareConfigurationRefusesBothWithTheLine) {
  const auto header = gfins::app::parse_config(kBadHeader, "fw.toml");
  ASSERT_FALSE(header.ok());
  EXPECT_EQ(header.error.rfind("fw.toml:2: TOML syntax: Error while parsing table header", 0), 0u)
      << header.error;
  const auto degree = gfins::app::parse_config(kDegreeKey, "fw.toml");
  ASSERT_FALSE(degree.ok());
  EXPECT_EQ(degree.error.rfind("fw.toml:2: TOML syntax: a non-ASCII character", 0), 0u)
      << degree.error;
}

TEST(TomlGuard, TheCalibrationFileRefusesBothWithTheLine) {
  const std::string end = std::string(gfins::calib_file::kEndMarker) + "\n";
  const auto header =
      gfins::calib_file::parse_calibration_text(std::string(kBadHeader) + end, "cal.toml");
  ASSERT_FALSE(header.is_ok());
  EXPECT_NE(header.status().message().find("line 2, column 2: TOML syntax error: Error while "
                                           "parsing table header"),
            std::string::npos)
      << header.status().message();
  const auto degree =
      gfins::calib_file::parse_calibration_text(std::string(kDegreeKey) + end, "cal.toml");
  ASSERT_FALSE(degree.is_ok());
  EXPECT_NE(degree.status().message().find("line 2, column 3: TOML syntax error: a non-ASCII"),
            std::string::npos)
      << degree.status().message();
}

TEST(TomlGuard, TheScenarioRefusesBothWithTheLine) {
  const auto header = gfins::sim::parse_scenario(kBadHeader, "s.toml");
  ASSERT_FALSE(header.is_ok());
  EXPECT_EQ(header.error().message.rfind("s.toml:2: TOML syntax error: Error while parsing "
                                         "table header",
                                         0),
            0u)
      << header.error().message;
  const auto degree = gfins::sim::parse_scenario(kDegreeKey, "s.toml");
  ASSERT_FALSE(degree.is_ok());
  EXPECT_EQ(degree.error().message.rfind("s.toml:2: TOML syntax error: a non-ASCII", 0), 0u)
      << degree.error().message;
}

}  // namespace
