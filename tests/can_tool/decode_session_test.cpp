// How gfins-can's decode ends (docs/can-interface.md, "Exit codes"), and its live source: a bus
// that delivers nothing ends in "no frames", one that delivers a board's epoch ends "ok"; the
// precedence input error > problems > no frames. The frames are the firmware publisher's own
// (firmware/can), carried by a fake bus standing in for the SocketCAN interface.
#include "decode_session.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <deque>
#include <filesystem>
#include <string>
#include <vector>

#include "gfins/can/publisher.hpp"

namespace gfins::can_tool {
namespace {

/// A live bus: hands out the queued frames one per receive, then times out (as SocketCan does
/// when nothing arrives); or answers kUnavailable like an interface that is down.
class FakeLiveBus final : public hal::CanBus {
 public:
  std::deque<hal::CanFrame> rx;
  std::vector<std::int64_t> receive_timeouts_ns;  // what each receive was asked to wait
  bool down = false;

 private:
  Status do_send(const hal::CanFrame& f) override {
    rx.push_back(f);  // the publisher below "sends" into what the host will receive
    return Status::ok();
  }
  Result<hal::CanFrame> do_receive(std::int64_t timeout_ns) override {
    receive_timeouts_ns.push_back(timeout_ns);
    if (down) return Status(ErrorCode::kUnavailable, "fake: interface down");
    if (rx.empty()) return Status(ErrorCode::kTimeout, "fake: no frame");
    const hal::CanFrame f = rx.front();
    rx.pop_front();
    return f;
  }
  hal::CanBusState do_state() const override {
    return down ? hal::CanBusState::kDown : hal::CanBusState::kErrorActive;
  }
  hal::CanCounters do_counters() const override { return {}; }
};

constexpr std::int64_t kPollNs = 1'000'000;  // any value: the fake returns at once

struct LiveRun {
  std::uint64_t fed = 0;
  Summary summary;
  int epochs = 0;
};

// Runs feed_live for exactly `polls` receives (keep_going counts), like --duration would.
LiveRun run_live(FakeLiveBus& bus, int polls) {
  LiveRun r;
  StreamDecoder dec([&](const DecodedEpoch&) { ++r.epochs; }, [](const Issue&) {});
  int asked = 0;
  std::int64_t t_us = 0;
  r.fed = feed_live(
      bus, dec, [&] { return asked++ < polls; }, [&] { return t_us += 1000; }, kPollNs);
  dec.finish();
  r.summary = dec.summary();
  return r;
}

TEST(DecodeSession, ASilentInterfaceEndsWithNoFrames) {
  // Given a bus on which nothing arrives
  FakeLiveBus bus;
  // When the live decode runs for 5 polls
  const LiveRun r = run_live(bus, 5);
  // Then it asked 5 times, waiting poll_ns each, decoded nothing, and says "no frames"
  ASSERT_EQ(bus.receive_timeouts_ns.size(), 5u);
  for (const std::int64_t t : bus.receive_timeouts_ns) EXPECT_EQ(t, kPollNs);
  EXPECT_EQ(r.fed, 0u);
  EXPECT_EQ(r.summary.frames, 0u);
  EXPECT_EQ(decode_end(r.summary, false), DecodeEnd::kNoFrames);
}

TEST(DecodeSession, AnInterfaceThatIsDownIsPolledNotSpunOn) {
  FakeLiveBus bus;
  bus.down = true;
  const LiveRun r = run_live(bus, 3);
  EXPECT_EQ(bus.receive_timeouts_ns.size(), 3u);  // one receive per keep_going: no inner loop
  EXPECT_EQ(decode_end(r.summary, false), DecodeEnd::kNoFrames);
}

TEST(DecodeSession, ABoardsEpochEndsOk) {
  // Given the frames of one epoch as the firmware's publisher sends them (default dividers: at
  // sample 0 every enabled message is due)
  FakeLiveBus bus;
  can::PublisherConfig pc;
  pc.node_id = 2;
  can::Publisher pub(bus, pc);
  can::Epoch e;
  e.nav.seq = 0;
  pub.publish(e);
  const std::size_t sent = bus.rx.size();
  ASSERT_GT(sent, 2u);  // at least GfinsEpoch, GfinsStatus and one data frame
  // When they are received live, with time to spare
  const LiveRun r = run_live(bus, static_cast<int>(sent) + 3);
  // Then each was fed once, they form one epoch without any problem, and the run is "ok"
  EXPECT_EQ(r.fed, sent);
  EXPECT_EQ(r.summary.frames, sent);
  EXPECT_EQ(r.summary.frames_ok, sent);
  EXPECT_EQ(r.epochs, 1);
  EXPECT_EQ(r.summary.total_issues(), 0u);
  EXPECT_EQ(decode_end(r.summary, false), DecodeEnd::kOk);
}

TEST(DecodeSession, PrecedenceInputErrorThenProblemsThenNoFrames) {
  Summary none;
  EXPECT_EQ(decode_end(none, false), DecodeEnd::kNoFrames);
  EXPECT_EQ(decode_end(none, true), DecodeEnd::kInputError);  // e.g. the only file is missing
  Summary malformed_only;  // a log of malformed lines: no frame, but problems to report
  malformed_only.lines = 4;
  malformed_only.issues[static_cast<std::size_t>(IssueKind::kMalformedLine)] = 4;
  EXPECT_EQ(decode_end(malformed_only, false), DecodeEnd::kProblems);
  EXPECT_EQ(decode_end(malformed_only, true), DecodeEnd::kInputError);
  Summary frames;
  frames.frames = frames.frames_ok = 1;
  EXPECT_EQ(decode_end(frames, false), DecodeEnd::kOk);
}

// `decode --node 3` on a log of node 1 only: nothing to show, said as "no frames" (exit 7),
// not "ok" with an empty output.
TEST(DecodeSession, ANodeFilterMatchingNoNodeIsNoFrames) {
  Summary s;
  s.frames = s.frames_ok = 12;
  s.nodes_seen = 1u << 1;
  EXPECT_EQ(decode_end(s, false, 1), DecodeEnd::kOk);
  EXPECT_EQ(decode_end(s, false, -1), DecodeEnd::kOk);
  EXPECT_EQ(decode_end(s, false, 3), DecodeEnd::kNoFrames);
  s.issues[static_cast<std::size_t>(IssueKind::kBadCrc)] = 1;
  EXPECT_EQ(decode_end(s, false, 3), DecodeEnd::kProblems);  // problems still come first
  EXPECT_EQ(node_list(0), "none");
  EXPECT_EQ(node_list((1u << 0) | (1u << 3) | (1u << 15)), "0, 3, 15");
}

// File names in "FILE:LINE: kind: what" reports: a newline or colon in the name cannot break
// the one-report-per-line format. Expected strings written out by hand.
TEST(DecodeSession, FileNamesAreQuotedWhenTheyCouldBreakTheReportFormat) {
  EXPECT_EQ(display_name("fw.log"), "fw.log");
  EXPECT_EQ(display_name("dir/my log.log"), "dir/my log.log");
  EXPECT_EQ(display_name("new\nline.log"), "\"new\\nline.log\"");
  EXPECT_EQ(display_name("a:12: bad crc"), "\"a:12: bad crc\"");
  EXPECT_EQ(display_name("q\"b\\s\t\r"), "\"q\\\"b\\\\s\\t\\r\"");
  EXPECT_EQ(display_name(std::string("x\x01\xff", 3)), "\"x\\x01\\xff\"");
  EXPECT_EQ(display_name(""), "\"\"");
}

// A directory given as a log is named as one (not "read error"); a missing file names errno's
// text; a readable log is decoded and returns "".
TEST(DecodeSession, DecodeLogNamesWhatIsWrongWithTheInput) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / "gfins_decode_log_test";
  fs::remove_all(dir);
  fs::create_directories(dir);
  StreamDecoder dec(nullptr, nullptr);
  EXPECT_EQ(decode_log(dir.string(), dec),
            "'" + dir.string() + "' is a directory, not a candump log");
  const std::string missing = (dir / "missing.log").string();
  EXPECT_EQ(decode_log(missing, dec), "cannot open '" + missing + "': No such file or directory");
  const fs::path log = dir / "one.log";
  std::FILE* f = std::fopen(log.c_str(), "wb");
  ASSERT_NE(f, nullptr);
  std::fputs("# comment\n(1700000000.000000) can0 100#404B4C000000020A\n", f);
  ASSERT_EQ(std::fclose(f), 0);
  EXPECT_EQ(decode_log(log.string(), dec), "");
  dec.finish();
  EXPECT_EQ(dec.summary().lines, 2u);
  EXPECT_EQ(dec.summary().comment_lines, 1u);
  EXPECT_EQ(dec.summary().epochs, 1u);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace gfins::can_tool
