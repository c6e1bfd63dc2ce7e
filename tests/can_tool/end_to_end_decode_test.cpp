// End to end without the firmware around it: the navigation core's NavState stream (a moving,
// rotating array, exact compensator) -> Publisher -> candump lines -> gfins-can's decoder. Every
// decoded value equals the core's within its signal's quantisation (half a step), every CRC is
// valid, the epoch counters are continuous, and every epoch of the stream arrives.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <vector>

#include "bench/bench_scenario.hpp"
#include "decoder.hpp"
#include "gfins/can/publisher.hpp"
#include "gfins/drivers/lnx/candump.hpp"

namespace gfins::can_tool {
namespace {

constexpr std::uint8_t kNode = 3;

class LineBus final : public hal::CanBus {
 public:
  std::vector<std::string> lines;
  std::int64_t t_us = 0;

 private:
  Status do_send(const hal::CanFrame& f) override {
    char buf[drivers::lnx::kMaxCandumpLine];
    const std::size_t n = drivers::lnx::format_candump_line(
        buf, t_us / 1000000, static_cast<std::uint32_t>(t_us % 1000000), "can0", f);
    lines.emplace_back(buf, n);
    return Status::ok();
  }
  Result<hal::CanFrame> do_receive(std::int64_t) override {
    return Status(ErrorCode::kTimeout, "write only");
  }
  hal::CanBusState do_state() const override { return hal::CanBusState::kErrorActive; }
  hal::CanCounters do_counters() const override { return {}; }
};

// ZYX Euler angles of a body-to-NED quaternion, from their definition (roll about x, pitch about
// y, yaw about z applied as R = Rz(yaw) Ry(pitch) Rx(roll)); elements of R written out.
std::array<double, 3> euler_zyx(const nav::Quat<float>& qf) {
  const Eigen::Matrix3d r = qf.cast<double>().normalized().toRotationMatrix();
  return {std::atan2(r(2, 1), r(2, 2)), -std::asin(std::clamp(r(2, 0), -1.0, 1.0)),
          std::atan2(r(1, 0), r(0, 0))};
}

TEST(EndToEnd, CoreStatesSurviveTheBusWithinQuantisation) {
  const bench::Workload w = bench::make_workload();
  const auto& counts = w.samples;
  auto pipe = bench::make_pipeline<float>(nav::CompensatorKind::kExact, w);
  LineBus bus;
  can::Publisher pub(bus, can::PublisherConfig{
                              .node_id = kNode, .dividers = can::default_dividers(), .budget = {}});
  std::map<std::uint32_t, nav::NavState<float>> states;  // by seq
  for (std::uint32_t k = 1; k < counts.size(); ++k) {
    RawSample s = counts[k];
    s.seq = k;
    s.t_ns = 2'000'000'000 + static_cast<std::int64_t>(k) * 1'000'000;
    ASSERT_EQ(pipe.process(s), nav::PipelinePhase::kNavigating);
    can::Epoch e;
    e.nav = pipe.state();
    e.mode = can::Mode::kNavigating;
    e.cal_id = 77;
    states[k] = e.nav;
    bus.t_us = s.t_ns / 1000;
    pub.publish(e);
  }
  ASSERT_GT(bus.lines.size(), 800u);

  std::vector<DecodedEpoch> epochs;
  std::vector<Issue> issues;
  StreamDecoder dec([&](const DecodedEpoch& e) { epochs.push_back(e); },
                    [&](const Issue& i) { issues.push_back(i); });
  for (std::size_t i = 0; i < bus.lines.size(); ++i) dec.feed_line(i + 1, bus.lines[i]);
  dec.finish();
  EXPECT_TRUE(issues.empty()) << issues.front().text;
  EXPECT_EQ(dec.summary().frames_ok, bus.lines.size());  // every CRC valid
  EXPECT_EQ(epochs.size(), 99u);                         // seq 10, 20, ..., 990

  const auto& cols = columns();
  std::size_t compared = 0;
  for (const DecodedEpoch& e : epochs) {
    EXPECT_EQ(e.node_id, kNode);
    const auto seq =
        static_cast<std::uint32_t>(e.values[static_cast<std::size_t>(column_index("SampleCount"))]);
    ASSERT_TRUE(states.count(seq)) << seq;
    const nav::NavState<float>& n = states[seq];
    const double qsign = n.q_nb.w() < 0 ? -1.0 : 1.0;
    const auto eul = euler_zyx(n.q_nb);
    for (std::size_t c = 0; c < cols.size(); ++c) {
      if (!e.present[c]) continue;
      const can::SignalDef& s = *cols[c].signal;
      double want = 0;
      switch (s.field) {
        case can::Field::kTimeUs:
          want = static_cast<double>(n.t_ns / 1000);
          break;
        case can::Field::kSampleCount:
          want = seq;
          break;
        case can::Field::kMode:
          want = 2;
          break;
        case can::Field::kStatusFlags:
          want = n.status & 0xF;
          break;
        case can::Field::kCalId:
          want = 77;
          break;
        case can::Field::kQuaternion:
          want = qsign * std::array<double, 4>{static_cast<double>(n.q_nb.w()),
                                               static_cast<double>(n.q_nb.x()),
                                               static_cast<double>(n.q_nb.y()),
                                               static_cast<double>(n.q_nb.z())}[s.index];
          break;
        case can::Field::kEuler:
          want = eul[s.index];
          break;
        case can::Field::kRate:
          want = static_cast<double>(n.w_b[s.index]);
          break;
        case can::Field::kAngularAccel:
          want = static_cast<double>(n.wdot_b[s.index]);
          break;
        case can::Field::kAccel:
          want = static_cast<double>(n.f_b[s.index]);
          break;
        case can::Field::kVelocity:
          want = static_cast<double>(n.v_n[s.index]);
          break;
        case can::Field::kPosition:
          want = static_cast<double>(n.r_n[s.index]);
          break;
        default:
          continue;  // health counters and sensor outputs: zero here, covered elsewhere
      }
      // Half a quantisation step; 1e-9 of a step for double rounding, and 1e-9 rad for the two
      // Euler formulas (same float quaternion, different operation order).
      const double tol = 0.5 * s.factor * (1 + 1e-9) + (s.field == can::Field::kEuler ? 1e-9 : 0);
      EXPECT_NEAR(e.values[c], want, tol) << s.name << " at seq " << seq;
      ++compared;
    }
  }
  // 21 values in every epoch, 6 more (Euler, angular acceleration) at seq 20, 40, ..., 980.
  EXPECT_EQ(compared, 99u * 21 + 49u * 6);  // seq 20, 40, ..., 980
}

}  // namespace
}  // namespace gfins::can_tool
