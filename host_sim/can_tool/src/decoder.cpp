#include "decoder.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "gfins/can/signal_codec.hpp"
#include "gfins/drivers/lnx/candump.hpp"

namespace gfins::can_tool {
namespace {

constexpr std::uint8_t kCounterMask = 0x0F;      // 4-bit rolling counter (message_table.hpp)
constexpr std::int64_t kSampleModulo = 1 << 16;  // GfinsEpoch.SampleCount is 16 bits
// An Epoch frame at most this many epochs behind the open one, with a counter that agrees, is a
// stale (late or replayed) frame; one further back cannot be checked by the 4-bit counter and is
// read as the board starting again.
constexpr std::int64_t kMaxStaleEpochs = kCounterMask;
// A bus loses frames, not one message for this many periods on end while its epochs arrive: a
// longer silence is the message switched off and on again (SetDivider 0, then N), not drops.
constexpr std::int64_t kMaxFramesLostInARow = 15;
// Largest epoch divider the board accepts (output.epoch, docs/can-interface.md): a counter step
// of d epochs cannot span more than d times this many samples.
constexpr std::int64_t kMaxEpochDivider = can::kMaxDivider;
// TimeUs is the data-ready time of the epoch's sample: its advance over a run of samples is the
// sample period times their number, up to the edge's jitter. 10 % of the advance, and at least
// 200 µs (the loop's worst wake-up latency on the board, docs/performance.md), tells a clock
// that jumped or a counter that skipped from jitter.
constexpr double kTimeTolerance = 0.10;
constexpr double kTimeToleranceMinUs = 200.0;
constexpr std::int64_t kTimeModulo = std::int64_t{1} << 32;  // GfinsEpoch.TimeUs is 32 bits

/// The raw bits of GfinsEpoch signal `kSig` (an index into kEpochSignals) in frame `f`.
template <std::size_t kSig>
std::uint64_t epoch_bits(const hal::CanFrame& f) {
  static_assert(kSig != can::kNoSignal);
  return can::extract_bits(can::payload_of(f), can::kEpochSignals[kSig]);
}
constexpr std::size_t kTimeUsSig =
    can::signal_index(can::message(can::MessageId::kEpoch), "TimeUs");
constexpr std::size_t kSampleCountSig =
    can::signal_index(can::message(can::MessageId::kEpoch), "SampleCount");

std::uint32_t time_us_of(const hal::CanFrame& f) {
  return static_cast<std::uint32_t>(epoch_bits<kTimeUsSig>(f));
}

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

/// [first, end) column index of each message (columns are in table order).
struct ColumnRange {
  std::size_t first = 0;
  std::size_t end = 0;
};
const std::array<ColumnRange, can::kMessageCount>& column_ranges() {
  static const auto ranges = [] {
    std::array<ColumnRange, can::kMessageCount> r{};
    const auto& cols = columns();
    for (std::size_t i = cols.size(); i-- > 0;) {
      ColumnRange& c = r[static_cast<std::size_t>(cols[i].message->id)];
      if (c.end == 0) c.end = i + 1;
      c.first = i;
    }
    return r;
  }();
  return ranges;
}

std::size_t msg_index(const can::MessageDef& m) { return static_cast<std::size_t>(m.id); }

/// A message's period in samples at the default dividers (0 when off by default). Only the prior
/// for the first gap: a longer gap than this is judged by the message's next frame like any
/// other, so a log at other dividers decodes without false drops.
std::int64_t default_period(const can::MessageDef& m) { return m.default_divider; }

std::uint16_t sample_count_of(const hal::CanFrame& f) {
  return static_cast<std::uint16_t>(epoch_bits<kSampleCountSig>(f));
}

/// How a new GfinsEpoch frame (counter c, sample count s) follows the open epoch.
enum class EpochJump : std::uint8_t {
  kAdvance,
  kDuplicate,
  kStale,
  kRestart,
  kUnexplained,
  kStuck,      // SampleCount unchanged while the counter advanced
  kBackwards,  // SampleCount went back by less than any forward explanation could span
};
struct EpochStep {
  EpochJump kind = EpochJump::kAdvance;
  std::int64_t epochs = 0;   // kAdvance: epochs advanced (1 = the next one)
  std::int64_t samples = 0;  // kAdvance: samples advanced
  std::int64_t step = 0;     // kAdvance: samples per epoch from now on (0 = unknown)
};

/// The sample count places the epoch (any gap below 2^16 samples); the rolling counter must
/// agree modulo 16, which tells a gap from a change of the epoch divider and from a restart.
EpochStep classify_epoch(std::uint8_t c_old, std::uint16_t s_old, std::int64_t step,
                         std::uint8_t c_new, std::uint16_t s_new) {
  const std::int64_t d = (c_new - c_old) & kCounterMask;
  const std::int64_t fwd = (std::int64_t{s_new} - s_old + kSampleModulo) % kSampleModulo;
  if (fwd == 0) return {d == 0 ? EpochJump::kDuplicate : EpochJump::kStuck};
  const std::int64_t back = kSampleModulo - fwd;
  if (step > 0 && fwd % step == 0 && ((fwd / step) & kCounterMask) == d) {
    return {EpochJump::kAdvance, fwd / step, fwd, step};
  }
  // Not whole epochs forward at the known spacing. The firmware's first epoch after a start is
  // sample 0 with counter 0 (Publisher: seq % divider == 0, counter from 0): a restart, even when
  // it also reads as an Epoch frame a few epochs old.
  if (c_new == 0 && s_new < std::max<std::int64_t>(step, 1)) return {EpochJump::kRestart};
  if (step > 0 && back % step == 0 && back / step <= kMaxStaleEpochs &&
      ((-(back / step)) & kCounterMask) == d) {
    return {EpochJump::kStale};
  }
  // No divider the board accepts makes d epochs this long, or the count went back by less than
  // one epoch: the sample count went back (a board that restarts starts at sample 0, counter 0,
  // above).
  if (d != 0 && (fwd > d * kMaxEpochDivider || (step > 0 && back < step))) {
    return {EpochJump::kBackwards, 0, back};
  }
  if (d != 0) {
    // A new epoch divider (SetDivider GfinsEpoch) or the first spacing seen: the counter counts
    // the epochs; the spacing is learnt when it divides evenly, else at the next epoch.
    return {EpochJump::kAdvance, d, fwd, fwd % d == 0 ? fwd / d : 0};
  }
  return {EpochJump::kUnexplained};
}

std::string counter_text(std::uint8_t c, std::uint16_t s) {
  return "counter " + std::to_string(c) + ", sample count " + std::to_string(s);
}

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
    case IssueKind::kInputRejected:
      return "rejected input";
    case IssueKind::kSequence:
      return "sequence";
    case IssueKind::kLogTime:
      return "log time";
    case IssueKind::kOutOfRange:
      return "out of range";
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
    : on_epoch_(std::move(on_epoch)), on_issue_(std::move(on_issue)) {
  for (NodeState& n : nodes_) reset_tracks(n, true);
  for (std::uint8_t node = 0; node <= can::kMaxNodeId; ++node) inputs_.emplace_back(node);
}

void StreamDecoder::set_id_bases(const can::IdBases& ids) {
  ids_ = ids;
  inputs_.clear();
  for (std::uint8_t node = 0; node <= can::kMaxNodeId; ++node) inputs_.emplace_back(node, ids);
}

void StreamDecoder::issue(IssueKind k, std::uint64_t line, std::string text) {
  ++summary_.issues[static_cast<std::size_t>(k)];
  if (on_issue_) on_issue_(Issue{k, line, std::move(text)});
}

void StreamDecoder::notice(std::uint64_t line, std::string text) {
  if (on_notice_) on_notice_(Notice{line, std::move(text)});
}

void StreamDecoder::feed_line(std::uint64_t line_no, std::string_view line) {
  ++summary_.lines;
  // A byte-order mark (an editor's UTF-8 save) would make the line read as a comment and lose
  // its frame: skipped, and said.
  if (constexpr std::string_view kBom = "\xEF\xBB\xBF"; line.starts_with(kBom)) {
    notice(line_no, "UTF-8 byte-order mark at the start of the line skipped");
    line.remove_prefix(kBom.size());
  }
  if (drivers::lnx::is_candump_comment(line)) {
    ++summary_.comment_lines;
    return;
  }
  const Result<drivers::lnx::CandumpRecord> r = drivers::lnx::parse_candump_line(line);
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
  if (time_us < last_log_time_us_) {
    char buf[128];
    std::snprintf(buf, sizeof buf, "log timestamp goes back by %.6f s (%.6f -> %.6f)",
                  static_cast<double>(last_log_time_us_ - time_us) * 1e-6,
                  static_cast<double>(last_log_time_us_) * 1e-6,
                  static_cast<double>(time_us) * 1e-6);
    issue(IssueKind::kLogTime, line_no, buf);
  }
  last_log_time_us_ = time_us;
  std::uint8_t node = 0;
  const can::MessageDef* m = f.extended ? nullptr : can::find_message(f.id, ids_, &node);
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
  if (m->kind == can::MessageKind::kInput) {
    ++summary_.inputs;
    on_input(f, node, line_no, time_us);
    return;
  }
  if (m->kind != can::MessageKind::kData) {
    ++(m->kind == can::MessageKind::kCommand ? summary_.commands : summary_.responses);
    on_command(f, node, m->kind == can::MessageKind::kResponse);
    return;
  }
  NodeState& n = nodes_[node];
  if (m->id == can::MessageId::kEpoch) {
    on_epoch_frame(n, node, line_no, time_us, f);
    return;
  }
  const auto counter = static_cast<std::uint8_t>(
      can::extract_bits(can::payload_of(f), can::counter_signal()) & kCounterMask);
  on_data_frame(n, *m, counter, line_no, f);
}

void StreamDecoder::on_command(const hal::CanFrame& f, std::uint8_t node, bool response) {
  // A SetDivider changes a message's period on purpose: the frames around it are not drops, so
  // the message's period is learnt again (all messages after an accepted one, whose response does
  // not name the message).
  NodeState& n = nodes_[node];
  const std::uint64_t p = can::payload_of(f);
  if (static_cast<std::uint8_t>(p & 0xFFu) != can::kOpSetDivider) return;
  if (!response) {
    const auto target = static_cast<std::size_t>((p >> 16) & 0xFFu);  // DividerMessage
    if (target < can::kMessageCount) {
      n.tracks[target].period = 0;
      n.tracks[target].pending = 0;
    }
    return;
  }
  const bool status_part = ((p >> 16) & 0xFFu) == can::kPartStatus;
  const bool ok = ((p >> 24) & 0xFFu) == 0;  // Result Ok
  if (status_part && ok) {
    for (MessageTrack& t : n.tracks) {
      t.period = 0;
      t.pending = 0;
    }
  }
}

void StreamDecoder::on_input(const hal::CanFrame& f, std::uint8_t node, std::uint64_t line,
                             std::int64_t time_us) {
  // The board's own codec: what it would accept or reject, and why.
  const Result<can::InputEvent> r = inputs_[node].add(f);
  const can::MessageDef* m = can::find_message(f.id, ids_, nullptr);
  if (!r.is_ok()) {
    issue(IssueKind::kInputRejected, line,
          std::string(m->name) + ": " + can::to_string(inputs_[node].last_reject()) + " (" +
              r.status().message() + ")");
    return;
  }
  if (r->kind != can::InputEventKind::kGnssFix && r->kind != can::InputEventKind::kHeadingFix) {
    return;
  }
  ++summary_.fixes;
  if (on_input_) on_input_(DecodedInput{node, line, time_us, *r});
}

void StreamDecoder::on_epoch_frame(NodeState& n, std::uint8_t node, std::uint64_t line,
                                   std::int64_t time_us, const hal::CanFrame& f) {
  const auto counter = static_cast<std::uint8_t>(
      can::extract_bits(can::payload_of(f), can::counter_signal()) & kCounterMask);
  const std::uint16_t sample = sample_count_of(f);
  summary_.nodes_seen = static_cast<std::uint16_t>(summary_.nodes_seen | (1u << node));
  if (!n.have_epoch) {
    n.have_epoch = true;
    n.counter = counter;
    n.sample = sample;
    n.index = 0;
    n.step = 0;
    n.prev_index = -1;
    n.have_time = true;
    n.time_us = time_us_of(f);
    open_epoch(n, node, line, time_us);
    store(n, can::message(can::MessageId::kEpoch), f, line);
    return;
  }
  EpochStep j = classify_epoch(n.counter, n.sample, n.step, counter, sample);
  if ((j.kind == EpochJump::kStuck || j.kind == EpochJump::kBackwards) && without_conversion(n)) {
    // The loop numbered the epochs without a conversion; the first conversion starts the ADC's
    // own count (docs/faults.md): the sequence starts again, as at a restart.
    j.kind = EpochJump::kUnexplained;
  }
  switch (j.kind) {
    case EpochJump::kDuplicate:
      issue(IssueKind::kDuplicate, line,
            "GfinsEpoch (" + counter_text(counter, sample) + ") repeated");
      return;
    case EpochJump::kStale:
      issue(IssueKind::kReordered, line,
            "GfinsEpoch (" + counter_text(counter, sample) + ") arrived after the epoch with " +
                counter_text(n.counter, n.sample) + " had opened");
      return;
    case EpochJump::kRestart:
    case EpochJump::kUnexplained:
      ++summary_.restarts;
      notice(line, std::string(j.kind == EpochJump::kRestart
                                   ? "the board started again"
                                   : "the epoch sequence started again (no whole number of "
                                     "epochs explains the jump)") +
                       ": " + counter_text(n.counter, n.sample) + " -> " +
                       counter_text(counter, sample) + "; epochs lost before it are not counted");
      resync(n, node, line, time_us, f, counter, sample);
      return;
    case EpochJump::kStuck:
    case EpochJump::kBackwards:
      // CRC-valid frames no board sends: the counter advanced but the sample count did not (or
      // went back). A problem, not a restart; decoding picks up from this epoch.
      issue(IssueKind::kSequence, line,
            (j.kind == EpochJump::kStuck
                 ? "SampleCount did not advance"
                 : "SampleCount went back by " + std::to_string(j.samples) + " samples") +
                " while the counter advanced: " + counter_text(n.counter, n.sample) + " -> " +
                counter_text(counter, sample));
      resync(n, node, line, time_us, f, counter, sample);
      n.have_time = false;  // which of the two epochs is wrong is not known: no time check across
      return;
    case EpochJump::kAdvance:
      break;
  }
  close_epoch(n);
  check_time(n, line, time_us_of(f), j.samples);
  const std::int64_t old_index = n.index;
  const std::uint8_t next_counter = static_cast<std::uint8_t>((n.counter + 1) & kCounterMask);
  std::int64_t missing = j.epochs - 1;
  bool early_belongs_here = counter == next_counter;
  if (n.early_count != 0 && !early_belongs_here) {
    // The frames of the next epoch came without their GfinsEpoch frame: that one frame was lost,
    // not the epoch. Their period bookkeeping stands when that epoch sat one step on.
    const bool placed = missing == 1 && n.step > 0;
    if (placed) {
      const std::int64_t at = old_index + n.step;
      sight(n.tracks[msg_index(can::message(can::MessageId::kEpoch))],
            can::message(can::MessageId::kEpoch), at, line);
      for (std::size_t i = 0; i < n.early.size(); ++i) {
        if (n.early[i].used) sight(n.tracks[i], can::kMessages[i], at, n.early[i].line);
      }
    }
    flush_early_as_orphans(n, next_counter);
    if (missing > 0) --missing;
    if (!placed) reset_tracks(n, false);
  }
  if (missing > 0) {
    issue(IssueKind::kEpochDrop, line,
          std::to_string(missing) + " epoch(s) missing: " + counter_text(n.counter, n.sample) +
              " -> " + counter_text(counter, sample) + " (" + std::to_string(j.samples) +
              " samples)");
    reset_tracks(n, false);  // the messages of the lost epochs are not also frame drops
  }
  n.prev_index = j.epochs == 1 ? old_index : -1;
  n.prev_line = n.epoch.line;
  n.prev_seen = n.seen;
  n.index = old_index + j.samples;
  n.step = j.step;
  n.counter = counter;
  n.sample = sample;
  open_epoch(n, node, line, time_us);
  store(n, can::message(can::MessageId::kEpoch), f, line);
  if (n.early_count != 0) {
    for (std::size_t i = 0; i < n.early.size(); ++i) {
      EarlyFrame& e = n.early[i];
      if (!e.used) continue;
      issue(IssueKind::kReordered, e.line,
            std::string(can::kMessages[i].name) + " of epoch counter " + std::to_string(counter) +
                " arrived before its GfinsEpoch frame (line " + std::to_string(line) + ")");
      store(n, can::kMessages[i], e.frame, e.line);
      e.used = false;
    }
    n.early_count = 0;
  }
}

void StreamDecoder::resync(NodeState& n, std::uint8_t node, std::uint64_t line,
                           std::int64_t time_us, const hal::CanFrame& f, std::uint8_t counter,
                           std::uint16_t sample) {
  close_epoch(n);
  flush_early_as_orphans(n, static_cast<std::uint8_t>((n.counter + 1) & kCounterMask));
  settle_pending(n);
  reset_tracks(n, true);
  n.counter = counter;
  n.sample = sample;
  n.index += kSampleModulo;  // a new run: no gap is measured across it
  n.step = 0;
  n.prev_index = -1;
  n.have_time = true;  // the rate learnt stays: same board, same clock
  n.time_us = time_us_of(f);
  open_epoch(n, node, line, time_us);
  store(n, can::message(can::MessageId::kEpoch), f, line);
}

void StreamDecoder::check_time(NodeState& n, std::uint64_t line, std::uint32_t time_us,
                               std::int64_t samples) {
  // Judged when the epoch closes: its GfinsStatus says whether TimeUs is a data-ready time.
  const std::uint32_t before = n.time_us;
  const bool had = n.have_time;
  n.have_time = true;
  n.time_us = time_us;
  n.time_issue.clear();
  n.time_learn = 0.0;
  if (!had || samples <= 0) return;
  const auto dt = static_cast<double>((std::int64_t{time_us} - before + kTimeModulo) % kTimeModulo);
  char buf[200];
  n.time_issue_line = line;
  if (dt == 0.0) {
    std::snprintf(buf, sizeof buf, "TimeUs did not advance (%u us) over %lld samples", time_us,
                  static_cast<long long>(samples));
    n.time_issue = buf;
    return;
  }
  if (n.us_per_sample <= 0.0) {
    n.time_learn = dt / static_cast<double>(samples);  // the first regular advance
    return;
  }
  const double expected = n.us_per_sample * static_cast<double>(samples);
  if (std::fabs(dt - expected) > std::max(kTimeTolerance * expected, kTimeToleranceMinUs)) {
    std::snprintf(buf, sizeof buf,
                  "TimeUs advanced by %.0f us over %lld samples, %.0f us expected at the %.1f "
                  "us per sample of the earlier epochs (%u -> %u)",
                  dt, static_cast<long long>(samples), expected, n.us_per_sample, before, time_us);
    n.time_issue = buf;
  }
}

bool StreamDecoder::without_conversion(const NodeState& n) {
  // StatusFlags bit 1 sample gap, 2 input invalid, 15 data-ready lost (docs/faults.md): the
  // firmware published the loop's period, numbered and timed by the loop, not a conversion.
  static const int kFlags = column_index("StatusFlags");
  constexpr std::uint32_t kNoConversion = (1u << 1) | (1u << 2) | (1u << 15);
  const double flags = kFlags >= 0 && static_cast<std::size_t>(kFlags) < n.epoch.values.size()
                           ? n.epoch.values[static_cast<std::size_t>(kFlags)]
                           : std::numeric_limits<double>::quiet_NaN();
  return std::isfinite(flags) && (static_cast<std::uint32_t>(flags) & kNoConversion) != 0;
}

void StreamDecoder::settle_time(NodeState& n) {
  // An epoch without a conversion carries the loop's time, not a data-ready edge's: no
  // comparison into or out of it.
  if (without_conversion(n)) {
    n.have_time = false;
  } else if (!n.time_issue.empty()) {
    issue(IssueKind::kSequence, n.time_issue_line, n.time_issue);
    n.have_time = false;  // the next epoch starts the comparison again: one fault, one report
  } else if (n.time_learn > 0.0 && n.us_per_sample <= 0.0) {
    n.us_per_sample = n.time_learn;
  }
  n.time_issue.clear();
  n.time_learn = 0.0;
}

void StreamDecoder::on_data_frame(NodeState& n, const can::MessageDef& m, std::uint8_t counter,
                                  std::uint64_t line, const hal::CanFrame& f) {
  const std::size_t mi = msg_index(m);
  if (!n.have_epoch) {
    // candump started on a running bus: the rest of an epoch whose GfinsEpoch frame came before
    // the log did. Nothing is wrong with it; the summary counts it.
    if (summary_.leading_frames++ == 0) {
      notice(line,
             "the log starts inside an epoch: its frames before the first GfinsEpoch "
             "frame are skipped");
    }
    return;
  }
  if (counter == n.counter) {
    if (n.seen[mi]) {
      issue(IssueKind::kDuplicate, line,
            std::string(m.name) + " twice in epoch counter " + std::to_string(counter));
      return;
    }
    store(n, m, f, line);
    return;
  }
  if (counter == ((n.counter + 1) & kCounterMask)) {
    // Ahead of its GfinsEpoch frame: held until that frame shows (reordered) or is seen lost.
    EarlyFrame& e = n.early[mi];
    if (e.used) {
      issue(IssueKind::kDuplicate, line,
            std::string(m.name) + " twice in epoch counter " + std::to_string(counter));
      return;
    }
    e.used = true;
    e.line = line;
    e.frame = f;
    ++n.early_count;
    return;
  }
  if (counter == ((n.counter + kCounterMask) & kCounterMask) && n.prev_index >= 0) {
    // Belongs to the previous epoch (already emitted): reported, and counted there.
    if (n.prev_seen[mi]) {
      issue(IssueKind::kDuplicate, line,
            std::string(m.name) + " of epoch counter " + std::to_string(counter) +
                " again after the next epoch opened");
      return;
    }
    n.prev_seen[mi] = true;
    sight(n.tracks[mi], m, n.prev_index, n.prev_line);
    issue(IssueKind::kReordered, line,
          std::string(m.name) + " of epoch counter " + std::to_string(counter) +
              " arrived after the next epoch opened");
    return;
  }
  issue(IssueKind::kOrphan, line,
        std::string(m.name) + " with counter " + std::to_string(counter) +
            " matches no epoch near the open one (counter " + std::to_string(n.counter) + ")");
}

void StreamDecoder::flush_early_as_orphans(NodeState& n, std::uint8_t lost_counter) {
  if (n.early_count == 0) return;
  std::uint64_t first = 0;
  std::string names;
  for (std::size_t i = 0; i < n.early.size(); ++i) {
    EarlyFrame& e = n.early[i];
    if (!e.used) continue;
    if (first == 0 || e.line < first) first = e.line;
    if (!names.empty()) names += ", ";
    names += can::kMessages[i].name;
    e.used = false;
  }
  issue(IssueKind::kOrphan, first,
        "GfinsEpoch frame of epoch counter " + std::to_string(lost_counter) +
            " lost: " + std::to_string(n.early_count) +
            " frame(s) of that epoch arrived without it (" + names + ")");
  n.early_count = 0;
}

void StreamDecoder::reset_tracks(NodeState& n, bool forget_periods) {
  for (std::size_t i = 0; i < n.tracks.size(); ++i) {
    MessageTrack& t = n.tracks[i];
    t.last = -1;
    if (forget_periods) {
      t.period = default_period(can::kMessages[i]);
      t.pending = 0;
    }
  }
}

void StreamDecoder::report_pending(MessageTrack& t, const can::MessageDef& m) {
  for (std::size_t i = 0; i < t.pending; ++i) {
    issue(IssueKind::kFrameDrop, t.pending_line[i],
          std::string(m.name) + ": " + std::to_string(t.pending_gap[i] / t.period - 1) +
              " frame(s) missing before this epoch (every " + std::to_string(t.period) +
              " samples, none for " + std::to_string(t.pending_gap[i]) + ")");
  }
  t.pending = 0;
}

void StreamDecoder::sight(MessageTrack& t, const can::MessageDef& m, std::int64_t index,
                          std::uint64_t line, bool adjacent) {
  if (t.last >= 0 && index <= t.last) return;
  const std::int64_t last = t.last;
  t.last = index;
  if (last < 0) return;
  const std::int64_t g = index - last;
  if (t.period == 0 || (adjacent && g != t.period)) {
    // The first spacing seen; or the message came in two consecutive epochs, so no frame of it
    // can be missing in between: its spacing is the epoch spacing now (a new epoch divider, or
    // a message sped up to every epoch), and longer gaps before were that change.
    t.period = g;
    t.pending = 0;
    return;
  }
  if (g == t.period) {
    report_pending(t, m);  // the old spacing resumed: the longer gaps were frames lost
    return;
  }
  if (t.pending == t.pending_gap.size() && g > t.period) {
    // A fourth longer gap in a row: the earlier ones were a slower divider; g is judged
    // against it, and so are those of the earlier gaps that are longer still.
    t.period = *std::min_element(t.pending_gap.begin(), t.pending_gap.end());
    std::size_t kept = 0;
    for (std::size_t i = 0; i < t.pending; ++i) {
      if (t.pending_gap[i] == t.period || t.pending_gap[i] % t.period != 0) continue;
      t.pending_gap[kept] = t.pending_gap[i];
      t.pending_line[kept] = t.pending_line[i];
      ++kept;
    }
    t.pending = kept;
    if (g == t.period) {
      report_pending(t, m);
      return;
    }
  }
  if (g > t.period && g % t.period == 0 && g / t.period - 1 <= kMaxFramesLostInARow) {
    t.pending_gap[t.pending] = g;  // frames lost, or a slower divider: later frames tell
    t.pending_line[t.pending] = line;
    ++t.pending;
    return;
  }
  // A shorter gap (a faster divider), or one no loss explains: a new divider.
  t.period = g;
  t.pending = 0;
}

void StreamDecoder::settle_pending(NodeState& n) {
  // Longer gaps that no later frame judged: frames lost when the log went on for less than one
  // old period after them (nothing contradicts the old spacing), else the message slowed down or
  // stopped.
  for (std::size_t i = 0; i < n.tracks.size(); ++i) {
    MessageTrack& t = n.tracks[i];
    if (t.pending == 0) continue;
    if (t.last >= 0 && n.index - t.last < t.period) {
      report_pending(t, can::kMessages[i]);
    }
    t.pending = 0;
  }
}

void StreamDecoder::open_epoch(NodeState& n, std::uint8_t node, std::uint64_t line,
                               std::int64_t time_us) {
  const std::size_t nc = columns().size();
  n.seen.fill(false);
  n.epoch.node_id = node;
  n.epoch.counter = n.counter;
  n.epoch.line = line;
  n.epoch.log_time_us = time_us;
  n.epoch.values.assign(nc, std::numeric_limits<double>::quiet_NaN());
  n.epoch.present.assign(nc, false);
}

void StreamDecoder::store(NodeState& n, const can::MessageDef& m, const hal::CanFrame& f,
                          std::uint64_t line) {
  const std::size_t mi = msg_index(m);
  n.seen[mi] = true;
  MessageTrack& t = n.tracks[mi];
  sight(t, m, n.index, n.epoch.line, n.prev_index >= 0 && t.last == n.prev_index);
  const std::uint64_t p = can::payload_of(f);
  const auto& cols = columns();
  const ColumnRange r = column_ranges()[mi];
  // A multiplexed message carries only the signals of the selector value it was sent with.
  std::int64_t selector = -1;
  for (const can::SignalDef& s : m.signals) {
    if (s.mux == can::kMultiplexor) {
      selector = static_cast<std::int64_t>(can::extract_bits(p, s));
    }
  }
  for (std::size_t i = r.first; i < r.end; ++i) {
    const can::SignalDef& s = *cols[i].signal;
    if (s.mux >= 0 && s.mux != selector) continue;
    const double v = can::decode_signal(s, can::extract_bits(p, s));
    n.epoch.values[i] = v;
    n.epoch.present[i] = true;
    // The encoder saturates at [min, max] (half a quantisation step of rounding either side);
    // a wrapping signal (TimeUs, SampleCount) has no range to leave.
    const double slack = 0.5 * std::fabs(s.factor);
    if (s.overflow == can::Overflow::kSaturate && s.min < s.max &&
        (v < s.min - slack || v > s.max + slack)) {
      char buf[160];
      std::snprintf(buf, sizeof buf, "%.*s.%.*s = %.9g outside its documented range [%g, %g]",
                    static_cast<int>(m.name.size()), m.name.data(), static_cast<int>(s.name.size()),
                    s.name.data(), v, s.min, s.max);
      issue(IssueKind::kOutOfRange, line, buf);
    }
  }
}

void StreamDecoder::close_epoch(NodeState& n) {
  if (!n.have_epoch || n.epoch.values.empty()) return;
  settle_time(n);
  ++summary_.epochs;
  if (on_epoch_) on_epoch_(n.epoch);
  n.epoch.values.clear();  // emitted once
}

void StreamDecoder::finish() {
  for (NodeState& n : nodes_) {
    if (!n.have_epoch) continue;
    close_epoch(n);
    flush_early_as_orphans(n, static_cast<std::uint8_t>((n.counter + 1) & kCounterMask));
    settle_pending(n);
  }
}

}  // namespace gfins::can_tool
