// Host-side decoder of a gfins CAN stream (candump log or live bus): frames -> epochs of
// engineering values, with the end-to-end checks of docs/can-interface.md: CRC, epoch counter
// continuity, per-message drops, duplicates, reordering, unknown identifiers, wrong lengths.
// Every problem is reported with its line number and never stops the decode.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

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
  kEpochDrop,  // epoch counter skipped: whole epochs missing
  kFrameDrop,  // a message missing from an epoch where its period says it was due
  kDuplicate,  // the same message twice in one epoch
  kReordered,  // a frame of an earlier epoch, or the epoch counter going back
  kOrphan,     // a data frame whose counter matches no open epoch (its Epoch frame lost)
  kCount_,
};
const char* to_string(IssueKind k);

struct Issue {
  IssueKind kind;
  std::uint64_t line;
  std::string text;
};

struct Summary {
  std::uint64_t lines = 0;
  std::uint64_t frames = 0;     // parsed frames
  std::uint64_t frames_ok = 0;  // known id, length 8, CRC ok
  std::uint64_t epochs = 0;
  std::uint64_t responses = 0;  // GfinsResponse frames seen
  std::uint64_t commands = 0;   // GfinsCommand frames seen
  std::array<std::uint64_t, static_cast<std::size_t>(IssueKind::kCount_)> issues{};
  std::array<std::uint64_t, can::kMessageCount> per_message{};
  std::uint64_t total_issues() const;
};

class StreamDecoder {
 public:
  using EpochSink = std::function<void(const DecodedEpoch&)>;
  using IssueSink = std::function<void(const Issue&)>;

  StreamDecoder(EpochSink on_epoch, IssueSink on_issue);

  /// One candump line (parse errors become kMalformedLine issues).
  void feed_line(std::uint64_t line_no, std::string_view line);
  /// One frame with its log time.
  void feed_frame(std::uint64_t line_no, std::int64_t time_us, const hal::CanFrame& f);
  /// Emits the open epochs; call at end of input.
  void finish();

  const Summary& summary() const { return summary_; }

 private:
  struct MessageTrack {
    std::int64_t last_epoch = -1;  // epoch index where last seen
    std::int64_t period = 0;       // period in epochs (0 = unknown): default divider, then learned
    std::int64_t last_gap = 0;
    int longer_gaps = 0;  // consecutive gaps longer than `period` of equal length
  };
  struct NodeState {
    bool open = false;
    DecodedEpoch epoch;
    std::int64_t epoch_index = -1;  // running epoch number (counter continuity unwrapped)
    std::uint8_t last_counter = 0;
    bool have_counter = false;
    std::array<bool, can::kMessageCount> seen{};
    std::array<MessageTrack, can::kMessageCount> tracks{};
  };

  void issue(IssueKind k, std::uint64_t line, std::string text);
  void open_epoch(NodeState& n, std::uint8_t node, std::uint8_t counter, std::uint64_t line,
                  std::int64_t time_us);
  void close_epoch(NodeState& n);
  void store(NodeState& n, const can::MessageDef& m, const hal::CanFrame& f);

  EpochSink on_epoch_;
  IssueSink on_issue_;
  Summary summary_;
  std::map<std::uint8_t, NodeState> nodes_;
};

}  // namespace gfins::can_tool
