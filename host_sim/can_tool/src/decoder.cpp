#include "decoder.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "gfins/can/candump.hpp"
#include "gfins/can/signal_codec.hpp"

namespace gfins::can_tool {
namespace {

constexpr std::uint8_t kCounterModulo = 16;
// A forward jump of the 4-bit epoch counter by up to half its range is read as lost epochs; a
// larger one as the counter going back (a late or reordered Epoch frame).
constexpr std::uint8_t kMaxForwardJump = 8;

std::vector<Column> make_columns() {
  std::vector<Column> cols;
  for (const can::MessageDef& m : can::kMessages) {
    if (m.kind != can::MessageKind::kData) continue;
    for (const can::SignalDef& s : m.signals) {
      if (s.field == can::Field::kCounter || s.field == can::Field::kCrc) continue;
      std::string h(s.name);
      if (!s.unit.empty()) h += "[" + std::string(s.unit) + "]";
      cols.push_back(Column{&m, &s, h});
    }
  }
  return cols;
}

std::size_t msg_index(const can::MessageDef& m) { return static_cast<std::size_t>(m.id); }

/// A message's period in epochs at the default dividers (0 when off by default): the prior the
/// drop check starts from, so a frame lost in the first epochs is noticed too.
std::int64_t default_period(const can::MessageDef& m) {
  const std::uint16_t epoch = can::message(can::MessageId::kEpoch).default_divider;
  return m.default_divider == 0 || epoch == 0 ? 0 : m.default_divider / epoch;
}

/// Consecutive equal longer gaps after which a message's period is taken to have changed.
constexpr int kGapsToAdopt = 3;

}  // namespace

const std::vector<Column>& columns() {
  static const std::vector<Column> cols = make_columns();
  return cols;
}

int column_index(std::string_view signal_name) {
  const auto& cols = columns();
  for (std::size_t i = 0; i < cols.size(); ++i) {
    if (cols[i].signal->name == signal_name) return static_cast<int>(i);
  }
  return -1;
}

const char* to_string(IssueKind k) {
  switch (k) {
    case IssueKind::kMalformedLine:
      return "malformed line";
    case IssueKind::kUnknownId:
      return "unknown id";
    case IssueKind::kWrongLength:
      return "wrong length";
    case IssueKind::kBadCrc:
      return "bad crc";
    case IssueKind::kRemoteOrError:
      return "remote/error frame";
    case IssueKind::kEpochDrop:
      return "epoch drop";
    case IssueKind::kFrameDrop:
      return "frame drop";
    case IssueKind::kDuplicate:
      return "duplicate";
    case IssueKind::kReordered:
      return "reordered";
    case IssueKind::kOrphan:
      return "orphan frame";
    case IssueKind::kCount_:
      break;
  }
  return "?";
}

std::uint64_t Summary::total_issues() const {
  std::uint64_t n = 0;
  for (std::uint64_t v : issues) n += v;
  return n;
}

StreamDecoder::StreamDecoder(EpochSink on_epoch, IssueSink on_issue)
    : on_epoch_(std::move(on_epoch)), on_issue_(std::move(on_issue)) {}

void StreamDecoder::issue(IssueKind k, std::uint64_t line, std::string text) {
  ++summary_.issues[static_cast<std::size_t>(k)];
  if (on_issue_) on_issue_(Issue{k, line, std::move(text)});
}

void StreamDecoder::feed_line(std::uint64_t line_no, std::string_view line) {
  ++summary_.lines;
  const Result<can::CandumpRecord> r = can::parse_candump_line(line);
  if (!r.is_ok()) {
    issue(IssueKind::kMalformedLine, line_no, r.status().message());
    return;
  }
  if (r->remote || r->error_frame) {
    ++summary_.frames;
    issue(IssueKind::kRemoteOrError, line_no,
          r->remote ? "remote frame (no data) ignored" : "error frame ignored");
    return;
  }
  feed_frame(line_no, r->time_us(), r->frame);
}

void StreamDecoder::feed_frame(std::uint64_t line_no, std::int64_t time_us,
                               const hal::CanFrame& f) {
  ++summary_.frames;
  std::uint8_t node = 0;
  const can::MessageDef* m = f.extended ? nullptr : can::find_message(f.id, &node);
  if (m == nullptr) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "identifier 0x%X%s is not a gfins message", f.id,
                  f.extended ? " (29-bit)" : "");
    issue(IssueKind::kUnknownId, line_no, buf);
    return;
  }
  if (f.len != can::kFrameLength) {
    issue(IssueKind::kWrongLength, line_no,
          std::string(m->name) + " has " + std::to_string(f.len) + " data bytes, expected 8");
    return;
  }
  if (!can::crc_ok(f)) {
    issue(IssueKind::kBadCrc, line_no, std::string(m->name) + ": CRC-8 mismatch");
    return;
  }
  ++summary_.frames_ok;
  ++summary_.per_message[msg_index(*m)];
  if (m->kind == can::MessageKind::kCommand) {
    ++summary_.commands;
    return;
  }
  if (m->kind == can::MessageKind::kResponse) {
    ++summary_.responses;
    return;
  }
  NodeState& n = nodes_[node];
  const auto counter = static_cast<std::uint8_t>(
      can::extract_bits(can::payload_of(f), can::counter_signal()) & 0x0Fu);

  if (m->id == can::MessageId::kEpoch) {
    if (n.have_counter) {
      const auto d =
          static_cast<std::uint8_t>((counter - n.last_counter + kCounterModulo) % kCounterModulo);
      if (d == 0) {
        issue(IssueKind::kDuplicate, line_no,
              "GfinsEpoch with counter " + std::to_string(counter) + " repeated");
        return;
      }
      if (d > kMaxForwardJump) {
        issue(IssueKind::kReordered, line_no,
              "GfinsEpoch counter went back from " + std::to_string(n.last_counter) + " to " +
                  std::to_string(counter));
        return;
      }
      close_epoch(n);
      if (d > 1) {
        issue(IssueKind::kEpochDrop, line_no,
              std::to_string(d - 1) + " epoch(s) missing: counter " +
                  std::to_string(n.last_counter) + " -> " + std::to_string(counter));
        for (MessageTrack& t : n.tracks) t.last_epoch = -1;  // not also frame drops
      }
      n.epoch_index += d;
    } else {
      n.epoch_index = 0;
    }
    n.have_counter = true;
    n.last_counter = counter;
    open_epoch(n, node, counter, line_no, time_us);
    store(n, *m, f);
    return;
  }

  if (!n.open || counter != n.last_counter) {
    const bool late = n.open && counter == (n.last_counter + kCounterModulo - 1) % kCounterModulo;
    if (late) {
      // It belongs to the previous epoch (already emitted): count it there, not as a drop.
      MessageTrack& t = n.tracks[msg_index(*m)];
      t.last_epoch = std::max(t.last_epoch, n.epoch_index - 1);
    }
    issue(late ? IssueKind::kReordered : IssueKind::kOrphan, line_no,
          std::string(m->name) + " with counter " + std::to_string(counter) +
              (late ? " arrived after the next epoch opened"
                    : (n.open ? " matches no open epoch (counter " +
                                    std::to_string(n.last_counter) + ")"
                              : " before any GfinsEpoch frame")));
    return;
  }
  if (n.seen[msg_index(*m)]) {
    issue(IssueKind::kDuplicate, line_no,
          std::string(m->name) + " twice in epoch " + std::to_string(counter));
    return;
  }
  store(n, *m, f);
}

void StreamDecoder::open_epoch(NodeState& n, std::uint8_t node, std::uint8_t counter,
                               std::uint64_t line, std::int64_t time_us) {
  const std::size_t nc = columns().size();
  n.open = true;
  n.seen.fill(false);
  n.epoch.node_id = node;
  n.epoch.counter = counter;
  n.epoch.line = line;
  n.epoch.log_time_us = time_us;
  n.epoch.values.assign(nc, std::numeric_limits<double>::quiet_NaN());
  n.epoch.present.assign(nc, false);
}

void StreamDecoder::store(NodeState& n, const can::MessageDef& m, const hal::CanFrame& f) {
  const std::size_t mi = msg_index(m);
  n.seen[mi] = true;
  MessageTrack& t = n.tracks[mi];
  if (t.period == 0) t.period = default_period(m);
  if (t.last_epoch >= 0) {
    const std::int64_t gap = n.epoch_index - t.last_epoch;
    if (t.period == 0 || gap < t.period) {
      t.period = gap;  // first sighting of an unknown period, or a faster divider than assumed
      t.longer_gaps = 0;
    } else if (gap > t.period) {
      // The same longer gap several times in a row is a slower divider (SetDivider), not drops.
      t.longer_gaps = gap == t.last_gap ? t.longer_gaps + 1 : 1;
      if (t.longer_gaps >= kGapsToAdopt) {
        t.period = gap;
      } else if (gap % t.period == 0) {
        issue(IssueKind::kFrameDrop, n.epoch.line,
              std::string(m.name) + ": " + std::to_string(gap / t.period - 1) +
                  " frame(s) missing before this epoch (period " + std::to_string(t.period) +
                  " epochs)");
      }
    } else {
      t.longer_gaps = 0;
    }
    t.last_gap = gap;
  }
  t.last_epoch = n.epoch_index;
  const std::uint64_t p = can::payload_of(f);
  const auto& cols = columns();
  for (std::size_t i = 0; i < cols.size(); ++i) {
    if (cols[i].message != &m) continue;
    const can::SignalDef& s = *cols[i].signal;
    n.epoch.values[i] = can::decode_signal(s, can::extract_bits(p, s));
    n.epoch.present[i] = true;
  }
}

void StreamDecoder::close_epoch(NodeState& n) {
  if (!n.open) return;
  n.open = false;
  ++summary_.epochs;
  if (on_epoch_) on_epoch_(n.epoch);
}

void StreamDecoder::finish() {
  for (auto& [node, n] : nodes_) close_epoch(n);
}

}  // namespace gfins::can_tool
