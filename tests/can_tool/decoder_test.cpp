// The decoder's checks on streams the firmware's own Publisher writes (firmware/can): valid
// variations (dividers changed at run time, the epoch divider changed, a restart, a stream
// joined mid-epoch) report nothing; frames and epochs the test removes are reported once each,
// with the count the test removed. The oracle is the test's own bookkeeping of what it removed.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <map>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "decoder.hpp"
#include "gfins/can/command.hpp"
#include "gfins/can/publisher.hpp"
#include "gfins/can/signal_codec.hpp"

namespace gfins::can_tool {
namespace {

using can::MessageId;

struct SentFrame {
  std::uint32_t seq;  // sample the frame was published at
  hal::CanFrame frame;
};

/// Collects what the publisher sends, stamped with the sample being published.
class RecordingBus final : public hal::CanBus {
 public:
  std::vector<SentFrame> frames;
  std::uint32_t seq = 0;

 private:
  Status do_send(const hal::CanFrame& f) override {
    frames.push_back({seq, f});
    return Status::ok();
  }
  Result<hal::CanFrame> do_receive(std::int64_t) override {
    return Status(ErrorCode::kTimeout, "recording bus");
  }
  hal::CanBusState do_state() const override { return hal::CanBusState::kErrorActive; }
  hal::CanCounters do_counters() const override { return {}; }
};

/// A dividers change applied before publishing sample `seq`.
struct Change {
  std::uint32_t seq;
  MessageId message;
  std::uint16_t divider;
};

/// Publishes samples [first, first + count) through a fresh Publisher (counter from 0, as after
/// a start), applying `changes` on the way.
/// With `log_commands`, each change also puts its SetDivider command and Ok response frames in
/// the stream, as a candump of the bus would hold them.
void publish(RecordingBus& bus, std::uint32_t first, std::uint32_t count,
             const std::vector<Change>& changes = {}, bool log_commands = false) {
  can::Publisher pub(bus, can::PublisherConfig{});
  for (std::uint32_t s = first; s < first + count; ++s) {
    for (const Change& c : changes) {
      if (c.seq == s) {
        ASSERT_TRUE(pub.set_divider(c.message, c.divider).is_ok()) << s;
        if (log_commands) {
          can::Command cmd;
          cmd.opcode = can::Opcode::kSetDivider;
          cmd.token = 0x42;
          cmd.message = c.message;
          cmd.divider = c.divider;
          bus.frames.push_back({s, can::encode_command(cmd, 0)});
          bus.frames.push_back(
              {s,
               can::encode_response(
                   can::Response{can::kOpSetDivider, 0x42, can::ResultCode::kOk, c.divider}, 0)});
        }
      }
    }
    can::Epoch e;
    e.nav.seq = s;
    e.nav.t_ns = static_cast<std::int64_t>(s) * 1'000'000;  // 1 kHz
    e.mode = can::Mode::kNavigating;
    bus.seq = s;
    pub.publish(e);
  }
}

struct Decoded {
  std::vector<Issue> issues;
  std::size_t epochs = 0;
  Summary summary;
};

Decoded decode(const std::vector<SentFrame>& frames) {
  Decoded d;
  StreamDecoder dec([&](const DecodedEpoch&) { ++d.epochs; },
                    [&](const Issue& i) { d.issues.push_back(i); });
  // The log's clock (the host's) runs on across the board's restarts: never backwards.
  std::int64_t log_us = 0;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    log_us = std::max(log_us + 1, static_cast<std::int64_t>(frames[i].seq) * 1000);
    dec.feed_frame(i + 1, log_us, frames[i].frame);
  }
  dec.finish();
  d.summary = dec.summary();
  return d;
}

std::string dump(const std::vector<Issue>& issues) {
  std::string s;
  for (const Issue& i : issues) {
    s += std::to_string(i.line) + " " + to_string(i.kind) + ": " + i.text + "\n";
  }
  return s;
}

bool is(const hal::CanFrame& f, MessageId m) { return f.id == can::message(m).base_id; }

// Dividers changed on the board while the log runs, without the commands in the log: Euler
// 20 -> 40 -> 80 -> 20, the compensated sensors switched on and off, every 10-divider and then
// the epoch divider itself 10 -> 20. Nothing was lost: no problem.
TEST(DecoderChecks, RuntimeDividerChangesAreNotDrops) {
  RecordingBus bus;
  publish(bus, 0, 6000,
          {{505, MessageId::kEuler, 40},
           {1313, MessageId::kEuler, 80},
           {2001, MessageId::kEuler, 20},
           {2200, MessageId::kSensorsA, 10},
           {2200, MessageId::kSensorsB, 30},
           {3000, MessageId::kSensorsA, 0},
           {3500, MessageId::kSensorsB, 0},
           {4000, MessageId::kQuaternion, 20},
           {4000, MessageId::kRate, 20},
           {4000, MessageId::kAccel, 20},
           {4000, MessageId::kVelocity, 20},
           {4000, MessageId::kPositionNE, 20},
           {4000, MessageId::kPositionD, 20},
           {4007, MessageId::kEpoch, 20}});
  const Decoded d = decode(bus.frames);
  EXPECT_TRUE(d.issues.empty()) << dump(d.issues);
  // Epochs: samples 0..4006 every 10 (401), then 4020..5980 every 20 (99).
  EXPECT_EQ(d.epochs, 401u + 99u);
}

// The epoch divider doubled (every 10-divider first) a few epochs before the log ends: the
// status frame, sent with every epoch, is not missing between two consecutive epochs.
TEST(DecoderChecks, EpochDividerChangeNearTheEndIsNotADrop) {
  RecordingBus bus;
  publish(bus, 0, 2050,
          {{1990, MessageId::kQuaternion, 20},
           {1990, MessageId::kRate, 20},
           {1990, MessageId::kAccel, 20},
           {1990, MessageId::kVelocity, 20},
           {1990, MessageId::kPositionNE, 20},
           {1990, MessageId::kPositionD, 20},
           {1995, MessageId::kEpoch, 20}});
  const Decoded d = decode(bus.frames);
  EXPECT_TRUE(d.issues.empty()) << dump(d.issues);
  EXPECT_EQ(d.epochs, 200u + 3u);  // 0..1990 every 10, then 2000, 2020, 2040
}

// GfinsEuler slowed to 40 at sample 505 and back to 20 at 600: frames at ..500, 520, 560, 600,
// 620.. Two longer gaps and the old spacing again read exactly like two lost frames; with the
// SetDivider commands in the log (a candump of the bus holds them) the decoder learns the
// period afresh at each and reports nothing.
TEST(DecoderChecks, SetDividerCommandsInTheLogResolveAShortLivedChange) {
  const std::vector<Change> changes{{505, MessageId::kEuler, 40}, {600, MessageId::kEuler, 20}};
  RecordingBus with;
  publish(with, 0, 1500, changes, true);
  const Decoded d = decode(with.frames);
  EXPECT_TRUE(d.issues.empty()) << dump(d.issues);
  EXPECT_EQ(d.summary.commands, 2u);
  EXPECT_EQ(d.summary.responses, 2u);
  RecordingBus without;
  publish(without, 0, 1500, changes, false);
  const Decoded u = decode(without.frames);
  EXPECT_EQ(u.issues.size(), 2u) << dump(u.issues);  // the documented ambiguity
}

// After each change above, one frame of the changed message is lost: each loss is reported
// once, as one frame missing, at the epoch where the message is next seen.
TEST(DecoderChecks, LossRightAfterADividerChangeIsCountedAtTheNewPeriod) {
  RecordingBus bus;
  publish(bus, 0, 3000, {{505, MessageId::kEuler, 40}, {1313, MessageId::kEuler, 80}});
  // Euler frames at 0,20,..,500 then 520,560,... (40) then 1360,1440,... (80). Remove the ones
  // at 640 (period 40) and 1600 (period 80).
  std::vector<SentFrame> kept;
  for (const SentFrame& f : bus.frames) {
    if (is(f.frame, MessageId::kEuler) && (f.seq == 640 || f.seq == 1600)) continue;
    kept.push_back(f);
  }
  const Decoded d = decode(kept);
  ASSERT_EQ(d.issues.size(), 2u) << dump(d.issues);
  for (const Issue& i : d.issues) {
    EXPECT_EQ(i.kind, IssueKind::kFrameDrop);
    EXPECT_EQ(i.text.rfind("GfinsEuler: 1 frame(s) missing", 0), 0u) << i.text;
  }
  // Reported at the Epoch frame of the epoch where GfinsEuler is next seen: samples 680, 1680.
  auto epoch_line = [&](std::uint32_t seq) {
    for (std::size_t i = 0; i < kept.size(); ++i) {
      if (kept[i].seq == seq && is(kept[i].frame, MessageId::kEpoch)) return i + 1;
    }
    return std::size_t{0};
  };
  std::set<std::uint64_t> lines{d.issues[0].line, d.issues[1].line};
  EXPECT_EQ(lines, (std::set<std::uint64_t>{epoch_line(680), epoch_line(1680)}));
}

// Isolated losses of any data frame (never two in a row of one message; none in the first 100
// samples, where a message's first frame may be lost unseen, nor in the last second) at random:
// the frame drops reported add up to exactly the frames removed, message by message. Fixed
// seed: the test is deterministic.
TEST(DecoderChecks, EveryIsolatedFrameLossIsReportedOnceWithItsMessage) {
  RecordingBus bus;
  publish(bus, 0, 20000);
  std::mt19937 rng(9);
  std::bernoulli_distribution drop(0.01);
  std::map<std::uint32_t, bool> last_dropped;  // per CAN id: was its previous frame removed
  std::map<std::string, int> removed;
  std::vector<SentFrame> kept;
  for (const SentFrame& f : bus.frames) {
    const bool epoch_frame = is(f.frame, MessageId::kEpoch);
    bool& prev = last_dropped[f.frame.id];
    if (!epoch_frame && !prev && f.seq >= 100 && f.seq < 19000 && drop(rng)) {
      prev = true;
      removed[std::string(can::find_message(f.frame.id, nullptr)->name)] += 1;
      continue;
    }
    prev = false;
    kept.push_back(f);
  }
  ASSERT_GT(removed.size(), 5u);  // enough messages hit for the test to mean something
  const Decoded d = decode(kept);
  std::map<std::string, int> reported;
  for (const Issue& i : d.issues) {
    ASSERT_EQ(i.kind, IssueKind::kFrameDrop) << i.text;
    const std::string name = i.text.substr(0, i.text.find(':'));
    EXPECT_EQ(i.text.substr(name.size(), 4), ": 1 ") << i.text;
    reported[name] += 1;
  }
  EXPECT_EQ(reported, removed);
}

// A board restart (a new Publisher: counter 0, sample count 0) after 3 s, and a capture joined
// in the middle of an epoch: neither is a problem; the summary counts them.
TEST(DecoderChecks, RestartAndMidEpochStartAreNotProblems) {
  RecordingBus bus;
  publish(bus, 0, 3005);
  publish(bus, 0, 2000);
  const std::vector<SentFrame> joined(bus.frames.begin() + 5, bus.frames.end());
  const Decoded d = decode(joined);
  EXPECT_TRUE(d.issues.empty()) << dump(d.issues);
  EXPECT_EQ(d.summary.restarts, 1u);
  // Sample 0 publishes 15 frames (health, accuracy, aiding and command counters included); the
  // first 5 are cut, 10 precede epoch 1.
  EXPECT_EQ(d.summary.leading_frames, 10u);
  EXPECT_EQ(d.epochs, 300u + 200u);  // epochs 1..300 of the first run, 0..199 of the second
}

// Whole epochs removed at every size from 1 to 40 (across the 4-bit counter's wrap): one epoch
// drop with the exact count, never anything else.
TEST(DecoderChecks, EpochGapsOfAnySizeAreCountedExactly) {
  RecordingBus bus;
  publish(bus, 0, 2000);
  for (std::uint32_t lost = 1; lost <= 40; ++lost) {
    SCOPED_TRACE(lost);
    const std::uint32_t from = 500;  // first removed epoch's sample
    std::vector<SentFrame> kept;
    for (const SentFrame& f : bus.frames) {
      if (f.seq >= from && f.seq < from + 10 * lost) continue;
      kept.push_back(f);
    }
    const Decoded d = decode(kept);
    ASSERT_EQ(d.issues.size(), 1u) << dump(d.issues);
    EXPECT_EQ(d.issues[0].kind, IssueKind::kEpochDrop);
    EXPECT_EQ(d.issues[0].text.rfind(std::to_string(lost) + " epoch(s) missing", 0), 0u)
        << d.issues[0].text;
    EXPECT_EQ(d.epochs, 200u - lost);
  }
}

// CRC-valid frames no board sends, made by editing the published Epoch frames and sealing them
// again: each is one problem of its kind at its line, and the decode goes on (every epoch).
// Oracle: the edit (which epoch, which value), not the decoder.
TEST(DecoderChecks, StuckOrBackwardSampleCountAndStalledOrJumpingTimeAreProblems) {
  RecordingBus bus;
  publish(bus, 0, 1000);  // 100 epochs: TimeUs 1000 us per sample, SampleCount +10
  std::vector<std::size_t> epochs;
  for (std::size_t i = 0; i < bus.frames.size(); ++i) {
    if (is(bus.frames[i].frame, MessageId::kEpoch)) epochs.push_back(i);
  }
  ASSERT_EQ(epochs.size(), 100u);
  const can::MessageDef& em = can::message(MessageId::kEpoch);
  const auto rewrite = [&](std::vector<SentFrame>& frames, std::size_t k, const char* signal,
                           std::uint64_t raw) {
    hal::CanFrame& f = frames[epochs[k]].frame;
    const can::SignalDef& s = em.signals[can::signal_index(em, signal)];
    can::set_payload(f, can::insert_bits(can::payload_of(f), s, raw));
    can::seal_frame(f);
  };
  struct Case {
    const char* what;
    std::size_t epoch;
    const char* signal;
    std::uint64_t raw;
    const char* text;
  };
  const Case cases[] = {
      {"stuck", 30, "SampleCount", 290, "SampleCount did not advance"},
      {"back", 40, "SampleCount", 385, "SampleCount went back by 5 samples"},
      {"stall", 50, "TimeUs", 490'000, "TimeUs did not advance"},
      {"jump", 60, "TimeUs", 605'000, "TimeUs advanced by 15000 us over 10 samples, 10000 us"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.what);
    std::vector<SentFrame> frames = bus.frames;
    rewrite(frames, c.epoch, c.signal, c.raw);
    const Decoded d = decode(frames);
    ASSERT_EQ(d.issues.size(), 1u) << dump(d.issues);
    EXPECT_EQ(d.issues[0].kind, IssueKind::kSequence);
    EXPECT_EQ(d.issues[0].line, epochs[c.epoch] + 1);
    EXPECT_NE(d.issues[0].text.find(c.text), std::string::npos) << d.issues[0].text;
    EXPECT_EQ(d.summary.restarts, 0u);
    EXPECT_EQ(d.epochs, 100u);
  }
  // Negative control: the unedited log has none.
  EXPECT_TRUE(decode(bus.frames).issues.empty());
}

// Epochs without a conversion (StatusFlags bit 15, data-ready lost: the firmware publishes the
// loop's periods while the ADC delivers nothing, docs/faults.md) carry the loop's time, not an
// edge's: TimeUs running at another pace there is no problem, and the check resumes after them.
TEST(DecoderChecks, EpochsWithoutAConversionAreNotHeldToTheDataReadyTime) {
  RecordingBus bus;
  can::Publisher pub(bus, can::PublisherConfig{});
  std::int64_t t_ns = 0;
  for (std::uint32_t s = 0; s < 600; ++s) {
    const bool lost = s >= 200 && s < 300;  // 10 epochs of data-ready lost
    t_ns += lost ? 3'000'000 : 1'000'000;   // the loop waits 3 periods per timeout
    can::Epoch e;
    e.nav.seq = s;
    e.nav.t_ns = t_ns;
    e.mode = can::Mode::kNavigating;
    if (lost) e.status_bits = 1u << 15;
    bus.seq = s;
    pub.publish(e);
  }
  const Decoded d = decode(bus.frames);
  EXPECT_TRUE(d.issues.empty()) << dump(d.issues);
  EXPECT_EQ(d.epochs, 60u);
  // The same pace change with the bit clear is a problem: the check is on (negative control).
  RecordingBus plain;
  can::Publisher pub2(plain, can::PublisherConfig{});
  t_ns = 0;
  for (std::uint32_t s = 0; s < 600; ++s) {
    t_ns += s >= 200 && s < 300 ? 3'000'000 : 1'000'000;
    can::Epoch e;
    e.nav.seq = s;
    e.nav.t_ns = t_ns;
    e.mode = can::Mode::kNavigating;
    plain.seq = s;
    pub2.publish(e);
  }
  const Decoded p = decode(plain.frames);
  EXPECT_FALSE(p.issues.empty());
  for (const Issue& i : p.issues) EXPECT_EQ(i.kind, IssueKind::kSequence) << i.text;
}

// A log whose timestamps go back and a value beyond its signal's documented range (the encoder
// saturates there): each one problem at its line.
TEST(DecoderChecks, LogTimeGoingBackAndAValueOutsideItsRangeAreProblems) {
  RecordingBus bus;
  publish(bus, 0, 200);
  std::vector<Issue> issues;
  StreamDecoder d2([](const DecodedEpoch&) {}, [&](const Issue& i) { issues.push_back(i); });
  std::size_t euler_line = 0;
  for (std::size_t i = 0; i < bus.frames.size(); ++i) {
    hal::CanFrame f = bus.frames[i].frame;
    std::int64_t t = static_cast<std::int64_t>(bus.frames[i].seq) * 1000;
    if (i == 50) t -= 2'000'000;  // 2 s back
    if (euler_line == 0 && is(f, MessageId::kEuler)) {
      const can::MessageDef& m = can::message(MessageId::kEuler);
      const can::SignalDef& roll = m.signals[can::signal_index(m, "Roll")];
      can::set_payload(f, can::insert_bits(can::payload_of(f), roll, 32000));  // 3.2 rad
      can::seal_frame(f);
      euler_line = i + 1;
    }
    d2.feed_frame(i + 1, t, f);
  }
  d2.finish();
  ASSERT_EQ(issues.size(), 2u) << dump(issues);
  EXPECT_EQ(issues[0].kind, IssueKind::kOutOfRange);
  EXPECT_EQ(issues[0].line, euler_line);
  EXPECT_NE(issues[0].text.find("GfinsEuler.Roll = 3.2 outside its documented range"),
            std::string::npos)
      << issues[0].text;
  EXPECT_EQ(issues[1].kind, IssueKind::kLogTime);
  EXPECT_EQ(issues[1].line, 51u);
}

}  // namespace
}  // namespace gfins::can_tool
