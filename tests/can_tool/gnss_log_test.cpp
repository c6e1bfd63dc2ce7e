// gfins-can gnss: a simulated receiver's fixes as candump lines and on a (fake) live bus; the
// board's codec reads back every fix, with the model's values within a quantisation step, the
// latency as the age, and the send times honoured.
#include "gnss_log.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "gfins/drivers/lnx/candump.hpp"
#include "gfins/host_sim/scenario.hpp"

namespace gfins::can_tool {
namespace {

class RecordingBus final : public hal::CanBus {
 public:
  std::vector<hal::CanFrame> frames;
  std::vector<std::chrono::steady_clock::time_point> at;
  bool refuse = false;

 private:
  Status do_send(const hal::CanFrame& f) override {
    if (refuse) return Status(ErrorCode::kResourceExhausted, "refused");
    frames.push_back(f);
    at.push_back(std::chrono::steady_clock::now());
    return Status::ok();
  }
  Result<hal::CanFrame> do_receive(std::int64_t) override {
    return Status(ErrorCode::kTimeout, "none");
  }
  hal::CanBusState do_state() const override { return hal::CanBusState::kErrorActive; }
  hal::CanCounters do_counters() const override { return {}; }
};

sim::GnssSpec spec() {
  sim::GnssSpec s;
  s.rate_hz = 20.0;
  s.sigma_pos_h_m = 0.8;
  s.sigma_pos_v_m = 1.6;
  s.sigma_vel_mps = 0.03;
  s.latency_s = 0.045;
  s.lever_arm_b_m = sim::Vec3d(0.3, 0.1, -0.5);
  s.outages = {{0.5, 0.7}};
  s.seed = 9;
  return s;
}

TEST(GnssLog, EveryFixReadsBackThroughTheBoardsCodec) {
  const auto traj = sim::make_drive(10.0, 20.0, 20.0);
  const auto fixes = sim::GnssModel(spec(), *traj).fixes(2.0);
  ASSERT_EQ(fixes.size(), 41u - 4u);  // t = 0 .. 2 s at 20 Hz, 0.5, 0.55, 0.6, 0.65 out
  std::FILE* f = std::tmpfile();
  ASSERT_NE(f, nullptr);
  ASSERT_TRUE(write_gnss_log(f, fixes, spec(), 5, 100.0));
  std::rewind(f);
  can::InputDecoder dec(5);
  char line[256];
  std::size_t n = 0;
  std::size_t k = 0;
  while (std::fgets(line, sizeof line, f) != nullptr) {
    std::string text(line);
    text.pop_back();  // '\n'
    const auto rec = drivers::lnx::parse_candump_line(text);
    ASSERT_TRUE(rec.is_ok()) << text;
    // Stamped at the fix's send time after the log start.
    EXPECT_NEAR(static_cast<double>(rec->time_us()) * 1e-6, 100.0 + fixes[n / 4].t_send_s, 1e-6);
    ++n;
    const auto r = dec.add(rec->frame);
    ASSERT_TRUE(r.is_ok()) << r.status().message();
    if (r->kind != can::InputEventKind::kGnssFix) continue;
    const can::GnssFix& g = r->gnss;
    const sim::GnssSample& s = fixes[k++];
    EXPECT_EQ(g.fix_id, s.index % 16);
    for (int i = 0; i < 3; ++i) {
      EXPECT_NEAR(g.r_n_m[static_cast<std::size_t>(i)], s.r_n_m[i], 0.005 + 1e-9);
      EXPECT_NEAR(g.v_n_mps[static_cast<std::size_t>(i)], s.v_n_mps[i], 0.005 + 1e-9);
    }
    EXPECT_NEAR(g.age_s, 0.045, 0.0005 + 1e-9);
    EXPECT_NEAR(g.sigma_pos_h_m, 0.8, 0.01);
    EXPECT_NEAR(g.sigma_vel_mps, 0.03, 0.001);
  }
  std::fclose(f);
  EXPECT_EQ(n, 4 * fixes.size());
  EXPECT_EQ(k, fixes.size());
  EXPECT_EQ(dec.counters().total_rejected(), 0u);
}

TEST(GnssLog, TheLiveSenderKeepsTheSendTimes) {
  const auto traj = sim::make_drive(10.0, 20.0, 20.0);
  const auto fixes = sim::GnssModel(spec(), *traj).fixes(0.3);  // 7 fixes, last sent at 0.345 s
  RecordingBus bus;
  const auto start = std::chrono::steady_clock::now();
  EXPECT_EQ(send_gnss_live(bus, fixes, spec(), 1), 0u);
  ASSERT_EQ(bus.frames.size(), 4 * fixes.size());
  for (std::size_t i = 0; i < bus.frames.size(); ++i) {
    // Never early; the fake bus is immediate, so late only by the scheduler.
    const double t = std::chrono::duration<double>(bus.at[i] - start).count();
    EXPECT_GE(t, fixes[i / 4].t_send_s - 1e-4) << i;
    EXPECT_EQ(bus.frames[i].id & 0xFu, 1u);
  }
  RecordingBus refusing;
  refusing.refuse = true;
  EXPECT_EQ(send_gnss_live(refusing, std::vector<sim::GnssSample>{fixes[0]}, spec(), 1),
            4u);  // counted, not retried
}

}  // namespace
}  // namespace gfins::can_tool
