// The standstill updates of Aiding (filter/aiding.hpp) against a board that moves while its
// accelerometers read like rest: a straight drive at constant speed (the specific force is
// gravity alone, no angular acceleration; the ideal outputs of an array at rest). The truth is
// the constant velocity itself: any standstill update that is applied pulls it away.
//  - Filter confident of its velocity (σ 0.05 m/s): the ZUPT's gate rejects a zero velocity
//    against 30 m/s, and the ZARU must not be applied without it (a zero rate passes its own gate
//    through a gentle turn at speed): no ZUPT and no ZARU accepted, every decision a veto.
//  - Filter unsure of its velocity (σ 20 m/s, as after an outage): the ZUPT passes its gate
//    (NIS = 30²/20² ≈ 2.3 < 16.3) and sets the velocity to zero (the negative control shows the
//    hazard); a GNSS fix at 30 m/s vetoes the standstill updates, and the velocity stays.
#include "gfins/nav_core/filter/aiding.hpp"

#include <gtest/gtest.h>

#include "nav_core/filter_truth.hpp"

namespace gfins::nav {
namespace {

constexpr double kSpeedMps = 30.0;
constexpr double kRateHz = 1000.0;
constexpr int kSamples = 3000;  // 30 standstill windows of 100 samples

struct Drive {
  ArraySolver<double> solver = ArraySolver<double>::create(table1_geometry(0.1)).value();
  Strapdown<double> nav{solver, GravityModel<double>::constant(testing::kG)};
  Aiding<double> aiding;
  Vec6<double> outputs;

  explicit Drive(double sigma_vel_mps) {
    testing::Truth x = testing::rest(Quat<double>::Identity());
    outputs = testing::ideal_outputs(solver.geometry(), x);
    x.v_n = Vec3<double>(kSpeedMps, 0, 0);
    NavState<double> s = testing::nav_state_of<double>(x);
    s.status |= nav_status::kAligned;
    nav.initialize(s, outputs);
    AidingConfig<double> c;
    c.enabled = true;
    c.filter.init_sigma_vel_mps = sigma_vel_mps;
    c.filter.noise.white_sigma_mps2.fill(1e-4);
    c.standstill.white_sigma_mps2 = 1e-4;
    c.standstill.gravity_mps2 = testing::kG;
    EXPECT_TRUE(aiding.configure(solver, c).is_ok());
    aiding.start(nav);
  }

  void run(bool gnss_says_moving) {
    const double h = 1.0 / kRateHz;
    for (int k = 1; k <= kSamples; ++k) {
      const std::int64_t t_ns = std::int64_t{k} * 1'000'000;
      nav.step(outputs, h, t_ns, static_cast<std::uint32_t>(k));
      if (gnss_says_moving && k % 200 == 1) {  // 5 Hz from the start, the truth exactly
        GnssFix<double> fix;
        fix.t_valid_ns = t_ns;
        fix.value_n = Vec3<double>(kSpeedMps, 0, 0);
        fix.sigma = Vec3<double>::Constant(0.1);
        (void)aiding.offer_gnss_velocity(nav, fix);
      }
      aiding.after_step(nav, h);
    }
  }
  std::uint32_t accepted(AidingKind k) const {
    return aiding.filter().counters().accepted[static_cast<std::size_t>(k)];
  }
};

TEST(AidingStandstillVeto, NoZeroRateWithoutAnAcceptedZeroVelocity) {
  static Drive d(0.05);
  d.run(false);
  EXPECT_TRUE(d.aiding.at_rest());  // the detector is fooled, as it must be
  EXPECT_EQ(d.accepted(AidingKind::kZupt), 0u);
  EXPECT_EQ(d.accepted(AidingKind::kZaru), 0u);
  // One per detector decision, each "at rest": 30 windows, each decision applied (here vetoed)
  // once, at the propagation after it.
  EXPECT_EQ(d.aiding.motion_vetoes(), 30u);
  EXPECT_NEAR(d.nav.state().v_n.x(), kSpeedMps, 0.01);
}

TEST(AidingStandstillVeto, GnssSpeedVetoesWhatTheGateWouldLetThrough) {
  static Drive fooled(20.0);  // negative control: no GNSS
  fooled.run(false);
  EXPECT_GT(fooled.accepted(AidingKind::kZupt), 0u);
  EXPECT_LT(fooled.nav.state().v_n.x(), kSpeedMps / 2);

  static Drive told(20.0);
  told.run(true);
  EXPECT_EQ(told.accepted(AidingKind::kZupt), 0u);
  EXPECT_EQ(told.accepted(AidingKind::kZaru), 0u);
  EXPECT_EQ(told.aiding.motion_vetoes(), 30u);
  EXPECT_NEAR(told.nav.state().v_n.x(), kSpeedMps, 0.05);
}

}  // namespace
}  // namespace gfins::nav
