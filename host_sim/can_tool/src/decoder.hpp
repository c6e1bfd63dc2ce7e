// Host-side decoder of a gfins CAN stream (candump log or live bus): frames -> epochs of
// engineering values, with the end-to-end checks of docs/can-interface.md: CRC, epoch continuity,
// per-message drops, duplicates, reordering, unknown identifiers, wrong lengths. Every problem is
// reported with its line number and never stops the decode.
//
// Epochs are placed on the sample axis by GfinsEpoch.SampleCount (16 bits) and confirmed by the
// 4-bit rolling counter, so a gap of any size, a restart, a stale or reordered Epoch frame and a
// change of the epoch divider are told apart. Each message's period is the sample spacing of
// its frames as seen on the bus; a longer gap is judged when the message's next frame shows
// whether the old period resumed (frames lost) or the new spacing holds (a slower divider).
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "gfins/can/aiding_input.hpp"
#include "gfins/can/message_table.hpp"
#include "gfins/hal/can_bus.hpp"

namespace gfins::can_tool {

/// One output column: a signal of a data message other than counter/CRC, in table order.
struct Column {
  const can::MessageDef* message;
  const can::SignalDef* signal;
  std::string header;  // "Name[unit]" or "Name"
};
const std::vector<Column>& columns();
/// Column index of a signal by name (-1 when absent).
int column_index(std::string_view signal_name);

struct DecodedEpoch {
  std::uint8_t node_id = 0;
  std::uint8_t counter = 0;
  std::uint64_t line = 0;        // line of the GfinsEpoch frame
  std::int64_t log_time_us = 0;  // log timestamp of the GfinsEpoch frame
  std::vector<double> values;    // per column; NaN when absent or not available
  std::vector<bool> present;     // per column: the frame carrying it arrived
};

enum class IssueKind : std::uint8_t {
  kMalformedLine,
  kUnknownId,
  kWrongLength,
  kBadCrc,
  kRemoteOrError,
  kEpochDrop,      // whole epochs missing (sample count and counter agree on how many)
  kFrameDrop,      // frames of a message missing where its observed spacing says they were due
  kDuplicate,      // the same message twice in one epoch, or the same Epoch frame twice
  kReordered,      // a frame after the next epoch opened or before its own Epoch frame, or a
                   // stale Epoch frame
  kOrphan,         // data frames whose Epoch frame was lost (one per lost Epoch frame), or a
                   // frame whose counter matches no epoch near the open one
  kInputRejected,  // an aiding input frame the board would reject (stale or mixed fix id,
                   // value out of range, reserved bits, incomplete fix)
  kSequence,       // CRC-valid but impossible: SampleCount stuck or going back while the counter
                   // advances; TimeUs standing still or off the rate its epochs showed
  kLogTime,        // the log's timestamps go back
  kOutOfRange,     // a decoded value outside the signal's documented [min, max]
  kCount_,
};
const char* to_string(IssueKind k);

struct Issue {
  IssueKind kind;
  std::uint64_t line;
  std::string text;
};

/// Facts worth printing that are not problems: a board restart, the partial epoch a log
/// started in.
struct Notice {
  std::uint64_t line;
  std::string text;
};

/// A GNSS fix or heading decoded from the aiding input frames (as the board would accept it).
struct DecodedInput {
  std::uint8_t node_id = 0;
  std::uint64_t line = 0;        // line of the frame that completed it (FixInfo, HeadingInput)
  std::int64_t log_time_us = 0;  // its log timestamp
  can::InputEvent event;         // kind kGnssFix or kHeadingFix
};

struct Summary {
  std::uint64_t lines = 0;
  std::uint64_t comment_lines = 0;   // blank lines and comments (not starting with '('), skipped
  std::uint64_t leading_frames = 0;  // data frames of a node before its first GfinsEpoch frame
  std::uint64_t restarts = 0;        // sample count and epoch counter started again
  std::uint16_t nodes_seen = 0;      // bit n: a GfinsEpoch frame of node n decoded
  std::uint64_t frames = 0;          // parsed frames
  std::uint64_t frames_ok = 0;       // known id, length 8, CRC ok
  std::uint64_t epochs = 0;
  std::uint64_t responses = 0;  // GfinsResponse frames seen
  std::uint64_t commands = 0;   // GfinsCommand frames seen
  std::uint64_t inputs = 0;     // aiding input frames seen (GNSS, heading)
  std::uint64_t fixes = 0;      // complete GNSS fixes and headings decoded from them
  std::array<std::uint64_t, static_cast<std::size_t>(IssueKind::kCount_)> issues{};
  std::array<std::uint64_t, can::kMessageCount> per_message{};
  std::uint64_t total_issues() const;
};

class StreamDecoder {
 public:
  using EpochSink = std::function<void(const DecodedEpoch&)>;
  using IssueSink = std::function<void(const Issue&)>;
  using NoticeSink = std::function<void(const Notice&)>;
  using InputSink = std::function<void(const DecodedInput&)>;

  StreamDecoder(EpochSink on_epoch, IssueSink on_issue);
  void set_notice_sink(NoticeSink on_notice) { on_notice_ = std::move(on_notice); }
  void set_input_sink(InputSink on_input) { on_input_ = std::move(on_input); }
  /// The identifier groups of the boards on the bus (a board configured with can.*_id_base;
  /// docs/can-interface.md, "Identifiers"). Call before the first frame.
  void set_id_bases(const can::IdBases& ids);

  /// One candump line (parse errors become kMalformedLine issues).
  void feed_line(std::uint64_t line_no, std::string_view line);
  /// One frame with its log time.
  void feed_frame(std::uint64_t line_no, std::int64_t time_us, const hal::CanFrame& f);
  /// Emits the open epochs; call at end of input.
  void finish();

  const Summary& summary() const { return summary_; }

 private:
  /// One message's frames on the sample axis of its node.
  struct MessageTrack {
    std::int64_t last = -1;   // sample index of the epoch it was last seen in (-1 unknown)
    std::int64_t period = 0;  // samples between its frames as seen (0 unknown)
    // Longer gaps (whole multiples of the period) not judged yet: the old spacing coming back
    // makes them frames lost; a fourth longer gap in a row makes the longer spacing a new
    // divider (so only four losses in strict alternation with received frames pass unseen).
    std::array<std::int64_t, 3> pending_gap{};
    std::array<std::uint64_t, 3> pending_line{};  // line of the epoch where each gap showed
    std::size_t pending = 0;
  };
  struct EarlyFrame {
    bool used = false;
    std::uint64_t line = 0;
    hal::CanFrame frame;
  };
  struct NodeState {
    bool have_epoch = false;  // a GfinsEpoch frame seen: an epoch is open
    DecodedEpoch epoch;
    std::uint8_t counter = 0;      // rolling counter of the open epoch
    std::uint16_t sample = 0;      // its SampleCount (mod 2^16)
    std::int64_t index = 0;        // its sample index, unwrapped (the node's first epoch = 0)
    std::int64_t step = 0;         // samples between epochs as seen (the epoch divider), 0 unknown
    std::int64_t prev_index = -1;  // sample index of the previous epoch (-1 when not adjacent)
    std::uint64_t prev_line = 0;
    std::array<bool, can::kMessageCount> seen{};       // in the open epoch
    std::array<bool, can::kMessageCount> prev_seen{};  // in the previous epoch
    std::array<MessageTrack, can::kMessageCount> tracks{};
    std::array<EarlyFrame, can::kMessageCount> early{};  // counter = open counter + 1
    std::size_t early_count = 0;
    bool have_time = false;      // time_us holds the open epoch's TimeUs
    std::uint32_t time_us = 0;   // GfinsEpoch.TimeUs of the open epoch
    double us_per_sample = 0.0;  // TimeUs per sample learnt from the first regular advance
    std::string time_issue;      // the open epoch's TimeUs problem, reported when it closes
    std::uint64_t time_issue_line = 0;
    double time_learn = 0.0;  // the open epoch's us per sample, learnt when it closes
  };

  void issue(IssueKind k, std::uint64_t line, std::string text);
  void notice(std::uint64_t line, std::string text);
  void on_epoch_frame(NodeState& n, std::uint8_t node, std::uint64_t line, std::int64_t time_us,
                      const hal::CanFrame& f);
  void resync(NodeState& n, std::uint8_t node, std::uint64_t line, std::int64_t time_us,
              const hal::CanFrame& f, std::uint8_t counter, std::uint16_t sample);
  void check_time(NodeState& n, std::uint64_t line, std::uint32_t time_us, std::int64_t samples);
  void settle_time(NodeState& n);
  static bool without_conversion(const NodeState& n);
  void on_data_frame(NodeState& n, const can::MessageDef& m, std::uint8_t counter,
                     std::uint64_t line, const hal::CanFrame& f);
  void on_command(const hal::CanFrame& f, std::uint8_t node, bool response);
  void on_input(const hal::CanFrame& f, std::uint8_t node, std::uint64_t line,
                std::int64_t time_us);
  void open_epoch(NodeState& n, std::uint8_t node, std::uint64_t line, std::int64_t time_us);
  void close_epoch(NodeState& n);
  void store(NodeState& n, const can::MessageDef& m, const hal::CanFrame& f, std::uint64_t line);
  void sight(MessageTrack& t, const can::MessageDef& m, std::int64_t index, std::uint64_t line,
             bool adjacent = false);
  void flush_early_as_orphans(NodeState& n, std::uint8_t lost_counter);
  static void reset_tracks(NodeState& n, bool forget_periods);
  void settle_pending(NodeState& n);
  void report_pending(MessageTrack& t, const can::MessageDef& m);

  EpochSink on_epoch_;
  IssueSink on_issue_;
  NoticeSink on_notice_;
  InputSink on_input_;
  Summary summary_;
  std::vector<can::InputDecoder> inputs_;  // one per node id
  can::IdBases ids_{};
  std::int64_t last_log_time_us_ = std::numeric_limits<std::int64_t>::min();
  std::array<NodeState, can::kMaxNodeId + 1> nodes_{};
};

}  // namespace gfins::can_tool
