// gfins-fw --replay (board.kind = "sim" with sim.recording): a raw-sample recording through the
// same loop as on the board (docs/replay.md, "Replay through the firmware"). The samples come
// from the file in order, each stamped with its recorded time (the loop's clock follows them, as
// in fast pacing); the CAN frames the recording board received come back to the loop in the
// cycle that handled them, before any later sample, and nothing else is ever received. With the
// configuration and calibration file of the recording board, the loop does what it did there.
#include <algorithm>
#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "gfins/app/board.hpp"
#include "gfins/app/sample_clock.hpp"
#include "gfins/app/startup.hpp"
#include "gfins/host_sim/board/sim_board.hpp"
#include "gfins/host_sim/progress_interval.hpp"
#include "gfins/host_sim/recording.hpp"

namespace gfins::sim_board {
namespace {

/// The recording read ahead far enough that every frame recorded after sample k is known when
/// sample k is handed over (the frames of the cycle of the last sample of a block are at the
/// start of the next block).
class Player {
 public:
  explicit Player(sim::RecordingReader reader) : reader_(std::move(reader)) {}

  /// The next sample, kUnavailable at the end, kDataLoss (with the reader's message) when the
  /// file breaks: the loop counts it as a read error and the run ends there.
  Result<RawSample> next_sample() {
    fill();
    if (!error_.empty()) return Status(ErrorCode::kDataLoss, error_.c_str());
    if (samples_.empty()) {
      done_ = true;
      return Status(ErrorCode::kUnavailable, "recording: no more samples");
    }
    const RawSample s = samples_.front();
    samples_.pop_front();
    ++delivered_;
    return s;
  }

  /// The next frame the loop received in the cycle of the last sample handed over.
  bool next_frame(hal::CanFrame& out) {
    if (frames_.empty() || frames_.front().samples_before > delivered_) return false;
    out = sim::can_frame_of(frames_.front().frame);
    frames_.pop_front();
    ++frames_delivered_;
    return true;
  }

  /// After the last sample (the read ahead has then met the end): the loop stops there, as on the
  /// simulated board, instead of running one more cycle into a failed read.
  bool finished() const { return done_ || !error_.empty() || (eof_ && samples_.empty()); }
  std::uint64_t delivered() const { return delivered_; }
  std::uint64_t frames_delivered() const { return frames_delivered_; }
  const sim::RecordingHeader& header() const { return reader_.header(); }
  const std::string& error() const { return error_; }

 private:
  void fill() {
    while (!eof_ && error_.empty() && samples_.size() < 2) {
      auto more = reader_.next_block(block_);
      if (!more.is_ok()) {
        error_ = more.error().message;
        return;
      }
      if (!more.value()) {
        eof_ = true;
        return;
      }
      samples_.insert(samples_.end(), block_.begin(), block_.end());
      frames_.insert(frames_.end(), reader_.frames().begin(), reader_.frames().end());
    }
  }

  sim::RecordingReader reader_;
  std::vector<RawSample> block_;
  std::deque<RawSample> samples_;
  std::deque<sim::RecordedFrame> frames_;
  std::uint64_t delivered_ = 0;
  std::uint64_t frames_delivered_ = 0;
  bool eof_ = false;
  bool done_ = false;
  std::string error_;  // kept: the Status returned refers to its characters
};

class RecordingSource final : public app::SampleSource {
 public:
  RecordingSource(Player& player, app::SampleClock& clock, double volts_per_count)
      : player_(player), clock_(clock), volts_per_count_(volts_per_count) {}

 private:
  Result<RawSample> do_read_sample(std::int64_t /*timeout_ns*/) override {
    Result<RawSample> r = player_.next_sample();
    if (r.is_ok()) clock_.set(r.value().t_ns);
    return r;
  }
  app::AdcCounters do_counters() const override { return {}; }
  double do_volts_per_count() const override { return volts_per_count_; }

  Player& player_;
  app::SampleClock& clock_;
  double volts_per_count_;
};

/// The board's bus on replay: frames go to the configured output; the frames received are the
/// recorded ones, in their cycles, and no others.
class RecordedFramesBus final : public hal::CanBus {
 public:
  RecordedFramesBus(std::unique_ptr<hal::CanBus> inner, Player& player)
      : inner_(std::move(inner)), player_(player) {}

 private:
  Status do_send(const hal::CanFrame& f) override { return inner_->send(f); }
  Result<hal::CanFrame> do_receive(std::int64_t /*timeout_ns*/) override {
    hal::CanFrame f;
    if (player_.next_frame(f)) return f;
    return Status(ErrorCode::kTimeout, "no recorded frame in this cycle");
  }
  void do_service() override { inner_->service(); }
  hal::CanBusState do_state() const override { return inner_->state(); }
  hal::CanCounters do_counters() const override { return inner_->counters(); }

  std::unique_ptr<hal::CanBus> inner_;
  Player& player_;
};

struct ReplayParts {
  std::unique_ptr<Player> player;
};

// The recording opened once and checked against the configuration: the reader, or what is wrong
// with it, named with the key and where it came from.
struct CheckedRecording {
  std::optional<sim::RecordingReader> reader;
  std::string error;
};

CheckedRecording open_checked(const app::FwConfig& c, const std::string& origin) {
  CheckedRecording out;
  const auto bad = [&](const std::string& why) {
    out.error = origin + ": sim.recording = " + app::quote_text(c.sim_recording) + ": " + why;
    return std::move(out);
  };
  auto reader = sim::RecordingReader::open(c.sim_recording);
  if (!reader.is_ok()) return bad(reader.error().message);
  const sim::RecordingHeader& h = reader.value().header();
  if (h.sample_rate_hz != c.sample_rate_hz) {
    return bad("recorded at " + std::to_string(h.sample_rate_hz) +
               " Hz: adc.sample_rate_hz must be the same");
  }
  for (const double v : h.volts_per_count) {
    if (v != h.volts_per_count[0] || !(v > 0.0)) {
      return bad("the channels' ADC LSB differ or are not positive: not a recording of this board");
    }
  }
  if (c.pacing != app::Pacing::kFast) {
    return bad("a recording is replayed by sample index: sim.pacing must be \"fast\"");
  }
  out.reader.emplace(std::move(reader).value());
  return out;
}

}  // namespace

std::string check_recording(const app::FwConfig& c, const std::string& origin) {
  return open_checked(c, origin).error;
}

app::BoardResult make_replay_board(const app::FwConfig& c) {
  app::BoardResult out;
  CheckedRecording checked = open_checked(c, "sim.recording");
  if (!checked.reader) {
    out.error = checked.error;
    return out;
  }
  sim::RecordingReader& reader = *checked.reader;
  const sim::RecordingHeader header = reader.header();
  auto parts = std::make_shared<ReplayParts>();
  parts->player = std::make_unique<Player>(std::move(reader));
  Player* player = parts->player.get();
  auto b = std::make_unique<app::Board>();
  auto clock = std::make_unique<app::SampleClock>();
  b->source = std::make_unique<RecordingSource>(*player, *clock, header.volts_per_count[0]);
  b->clock = std::move(clock);
  b->finished = [player] { return player->finished(); };
  const double duration = header.record_count == sim::kRecordCountUnknown
                              ? 0.0
                              : static_cast<double>(header.record_count) / header.sample_rate_hz;
  if (duration > 0.0) {
    b->progress = [player, duration, rate = header.sample_rate_hz] {
      return app::BoardProgress{
          std::min(1.0, static_cast<double>(player->delivered()) / (duration * rate)), duration};
    };
    b->progress_interval_s = paths::progress_interval_s();
  }
  if (std::string e = app::open_can_output(c, *b->clock, *b); !e.empty()) {
    out.error = e;
    return out;
  }
  app::add_can_protocol(c, *b);
  b->bus = std::make_unique<RecordedFramesBus>(std::move(b->bus), *player);
  // No factory calibration: the one that counts is the recording board's (calibration.file).
  // Without it, the nominal chain at the recorded LSB.
  b->defaults = app::nominal_calibration(header.volts_per_count[0]);
  b->close = [bus = b->bus.get()] { bus->service(); };
  b->finish_output = [player, inner = b->finish_output]() {
    std::string lost = inner ? inner() : std::string();
    if (!player->error().empty()) {
      lost += (lost.empty() ? "" : "; ") + std::string("replay stopped: ") + player->error();
    }
    return lost;
  };
  b->keep_alive = parts;
  out.board = std::move(b);
  return out;
}

}  // namespace gfins::sim_board
