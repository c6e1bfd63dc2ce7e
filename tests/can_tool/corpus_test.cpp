// The malformed-log corpus (tests/golden/can, built by make_corpus.py from hand edits of clean
// logs): every problem is reported once with the line the edit put it on (and, for drops, the
// number of epochs or frames the edit removed), valid variations (dividers, restart, a log
// starting mid-epoch, comments) report nothing, and the decode goes on to the end (the expected
// epoch count).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "decoder.hpp"
#include "host_io.hpp"

namespace gfins::can_tool {
namespace {

namespace fs = std::filesystem;

struct Expected {
  std::size_t epochs = 0;
  std::vector<std::string> issues;  // "LINE KIND"
};

Expected read_expected(const fs::path& p) {
  Expected e;
  std::ifstream in(p);
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("# epochs ", 0) == 0) {
      e.epochs = std::stoul(line.substr(9));
    } else if (!line.empty()) {
      e.issues.push_back(line);
    }
  }
  return e;
}

/// "LINE KIND", plus " N" for drops: N = the count the problem's text starts with.
std::string describe(const Issue& i) {
  std::string s = std::to_string(i.line) + " " + to_string(i.kind);
  if (i.kind == IssueKind::kEpochDrop || i.kind == IssueKind::kFrameDrop) {
    const std::size_t colon = i.text.find(": ");
    const std::size_t at = i.kind == IssueKind::kFrameDrop && colon != std::string::npos
                               ? colon + 2
                               : 0;  // "GfinsEuler: 2 frame(s) ..." / "16 epoch(s) ..."
    s += " " + std::to_string(std::stoul(i.text.substr(at)));
  }
  return s;
}

std::vector<fs::path> corpus() {
  std::vector<fs::path> logs;
  for (const auto& entry : fs::directory_iterator(fs::path(GFINS_TEST_DATA_DIR) / "can")) {
    if (entry.path().extension() == ".expected") logs.push_back(entry.path());
  }
  std::sort(logs.begin(), logs.end());
  return logs;
}

TEST(Corpus, EveryProblemReportedWithItsLineAndNoneStopsTheDecode) {
  const auto cases = corpus();
  ASSERT_GE(cases.size(), 23u);
  for (const fs::path& exp_path : cases) {
    fs::path log = exp_path;
    log.replace_extension(".log");
    SCOPED_TRACE(log.filename().string());
    const Expected want = read_expected(exp_path);
    std::vector<std::string> got;
    std::size_t epochs = 0;
    StreamDecoder dec([&](const DecodedEpoch&) { ++epochs; },
                      [&](const Issue& i) { got.push_back(describe(i)); });
    std::FILE* f = std::fopen(log.c_str(), "rb");
    ASSERT_NE(f, nullptr);
    for_each_line(f, [&](std::uint64_t n, std::string_view text) { dec.feed_line(n, text); });
    ASSERT_EQ(std::fclose(f), 0);
    dec.finish();
    // Problems judged later (a drop is known at the message's next frame) may be reported after
    // later lines' problems: the order of the report is not part of the check.
    std::sort(got.begin(), got.end());
    std::vector<std::string> want_sorted = want.issues;
    std::sort(want_sorted.begin(), want_sorted.end());
    EXPECT_EQ(got, want_sorted);
    EXPECT_EQ(epochs, want.epochs);
    EXPECT_EQ(dec.summary().total_issues(), want.issues.size());
  }
}

TEST(LineReader, LinesAcrossChunkBoundariesAndOverlongLines) {
  // 70000-character line spans two 64 KiB reads; it reaches the callback cut at max_line + 1.
  std::FILE* f = std::tmpfile();
  ASSERT_NE(f, nullptr);
  const std::string longline(70000, 'x');
  std::string text = "first\n" + longline + "\n";
  for (int i = 0; i < 20000; ++i) text += "line" + std::to_string(i) + "\n";
  text += "last-without-newline";
  ASSERT_EQ(std::fwrite(text.data(), 1, text.size(), f), text.size());
  std::rewind(f);
  std::vector<std::string> lines;
  for_each_line(
      f,
      [&](std::uint64_t n, std::string_view l) {
        EXPECT_EQ(n, lines.size() + 1);
        lines.emplace_back(l);
      },
      100);
  ASSERT_EQ(std::fclose(f), 0);
  ASSERT_EQ(lines.size(), 2u + 20000u + 1u);
  EXPECT_EQ(lines[0], "first");
  EXPECT_EQ(lines[1], std::string(101, 'x'));
  for (int i = 0; i < 20000; ++i)
    ASSERT_EQ(lines[2 + static_cast<std::size_t>(i)], "line" + std::to_string(i));
  EXPECT_EQ(lines.back(), "last-without-newline");
}

}  // namespace
}  // namespace gfins::can_tool
