// gfins-can decode and the aiding input frames: a GNSS fix and a heading interleaved with a
// board's epochs decode into input records (the board's own codec), disturb nothing of the
// epochs, and a corrupted or stale input frame is a problem with its line.
#include <gtest/gtest.h>

#include <vector>

#include "decoder.hpp"
#include "gfins/can/aiding_input.hpp"
#include "gfins/can/publisher.hpp"
#include "gfins/can/signal_codec.hpp"

namespace gfins::can_tool {
namespace {

class Collect final : public hal::CanBus {
 public:
  std::vector<hal::CanFrame> frames;

 private:
  Status do_send(const hal::CanFrame& f) override {
    frames.push_back(f);
    return Status::ok();
  }
  Result<hal::CanFrame> do_receive(std::int64_t) override {
    return Status(ErrorCode::kTimeout, "none");
  }
  hal::CanBusState do_state() const override { return hal::CanBusState::kErrorActive; }
  hal::CanCounters do_counters() const override { return {}; }
};

can::GnssFix fix(std::uint8_t id) {
  can::GnssFix f;
  f.fix_id = id;
  f.has_position = true;
  f.has_velocity = true;
  f.r_n_m = {10.0 * id, -5.0, -1.25};
  f.v_n_mps = {1.0, 2.0, -0.5};
  f.sigma_pos_h_m = 1.0;
  f.sigma_pos_v_m = 2.0;
  f.sigma_vel_mps = 0.1;
  f.age_s = 0.05;
  return f;
}

struct Decoded {
  std::vector<DecodedEpoch> epochs;
  std::vector<DecodedInput> inputs;
  std::vector<Issue> issues;
  Summary summary;
};

Decoded decode(const std::vector<hal::CanFrame>& frames) {
  Decoded r;
  StreamDecoder dec([&](const DecodedEpoch& e) { r.epochs.push_back(e); },
                    [&](const Issue& i) { r.issues.push_back(i); });
  dec.set_input_sink([&](const DecodedInput& in) { r.inputs.push_back(in); });
  for (std::size_t i = 0; i < frames.size(); ++i) {
    dec.feed_frame(i + 1, static_cast<std::int64_t>(i) * 100, frames[i]);
  }
  dec.finish();
  r.summary = dec.summary();
  return r;
}

/// 50 epochs of a board (node 0) with a GNSS fix to node 0 after every 10th epoch's frames.
std::vector<hal::CanFrame> board_with_gnss(std::vector<std::size_t>* fix_end_lines) {
  Collect bus;
  can::Publisher pub(bus, can::PublisherConfig{});
  std::vector<hal::CanFrame> out;
  std::uint8_t id = 0;
  for (std::uint32_t seq = 0; seq < 500; ++seq) {
    can::Epoch e;
    e.nav.seq = seq;
    e.nav.t_ns = static_cast<std::int64_t>(seq) * 1'000'000;  // 1 kHz: TimeUs advances with it
    pub.publish(e);
    for (const hal::CanFrame& f : bus.frames) out.push_back(f);
    bus.frames.clear();
    if (seq % 100 == 50) {
      for (const hal::CanFrame& f : can::encode_gnss_fix(fix(id++), 0)) out.push_back(f);
      if (fix_end_lines != nullptr) fix_end_lines->push_back(out.size());
    }
  }
  return out;
}

TEST(InputDecode, FixesBetweenEpochsDecodeAndDisturbNothing) {
  std::vector<std::size_t> ends;
  const Decoded r = decode(board_with_gnss(&ends));
  EXPECT_TRUE(r.issues.empty()) << r.issues.front().text;
  EXPECT_EQ(r.epochs.size(), 50u);
  ASSERT_EQ(r.inputs.size(), 5u);
  EXPECT_EQ(r.summary.inputs, 20u);
  EXPECT_EQ(r.summary.fixes, 5u);
  EXPECT_EQ(r.summary.responses, 0u);  // input frames are not responses
  for (std::size_t k = 0; k < r.inputs.size(); ++k) {
    const DecodedInput& in = r.inputs[k];
    EXPECT_EQ(in.line, ends[k]);  // the FixInfo frame completes the fix
    ASSERT_EQ(in.event.kind, can::InputEventKind::kGnssFix);
    EXPECT_EQ(in.event.gnss.fix_id, k);
    EXPECT_NEAR(in.event.gnss.r_n_m[0], 10.0 * static_cast<double>(k), 0.005);
  }
}

TEST(InputDecode, CorruptedAndStaleInputFramesAreProblemsWithTheirLine) {
  std::vector<std::size_t> ends;
  std::vector<hal::CanFrame> frames = board_with_gnss(&ends);
  frames[ends[1] - 3].data[1] ^= 0x40;  // PositionD of fix 1: CRC no longer matches
  // Fix 3 sent twice: the repeat is stale.
  const auto again = can::encode_gnss_fix(fix(3), 0);
  frames.insert(frames.begin() + static_cast<std::ptrdiff_t>(ends[3]), again.begin(), again.end());
  const Decoded r = decode(frames);
  ASSERT_FALSE(r.issues.empty());
  EXPECT_EQ(r.issues[0].kind, IssueKind::kBadCrc);
  EXPECT_EQ(r.issues[0].line, ends[1] - 2);                // 1-based line of the corrupted frame
  EXPECT_EQ(r.issues[1].kind, IssueKind::kInputRejected);  // fix 1's FixInfo: incomplete
  EXPECT_EQ(r.issues[1].line, ends[1]);
  EXPECT_EQ(r.issues[2].kind, IssueKind::kInputRejected);  // the repeat of fix 3
  EXPECT_EQ(r.issues[2].line, ends[3] + 1);
  EXPECT_EQ(r.inputs.size(), 4u);  // fixes 0, 2, 3, 4
  EXPECT_EQ(r.epochs.size(), 50u);
}

TEST(InputDecode, AHeadingDecodes) {
  const can::HeadingFix h{.sequence = 1, .heading_rad = 1.0, .sigma_rad = 0.01, .age_s = 0.1};
  const Decoded r = decode({can::encode_heading_fix(h, 4)});
  ASSERT_EQ(r.inputs.size(), 1u);
  EXPECT_EQ(r.inputs[0].node_id, 4);
  EXPECT_EQ(r.inputs[0].event.kind, can::InputEventKind::kHeadingFix);
  EXPECT_NEAR(r.inputs[0].event.heading.heading_rad, 1.0, 0.5e-4 + 1e-12);
}

}  // namespace
}  // namespace gfins::can_tool
