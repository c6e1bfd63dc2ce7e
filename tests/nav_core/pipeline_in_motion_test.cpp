// The pipeline's alignment when the board powers up on a moving vehicle (docs/math.md,
// "In-motion alignment"), on the drive of in_motion_drive.hpp, powered up in a turn (one run; the
// accuracy over 100 power-ups is pipeline_in_motion_long.cpp):
//  - the static alignment never accepts a window while GNSS says the board moves (a smooth
//    acceleration reads like a tilt to accelerometers); without the in-motion start the board
//    keeps aligning, and says why (kGnssMotion); so does a board that is no vehicle (no track);
//  - with it, navigation starts at the first fast fix, and until the fixes have re-levelled the
//    tilt, set the heading from the track and reset velocity and position, every σ is not
//    available (NaN) and no group is valid: a guess is never published as a measurement;
//  - from 20 s on every group is valid, with σ at the levels the receiver allows.
#include <gtest/gtest.h>

#include <cmath>

#include "nav_core/in_motion_drive.hpp"

namespace gfins::nav {
namespace {

using testing::DriveCheck;
using testing::InMotionDrive;
using testing::kDeg;

constexpr unsigned kSeed = 20261128;
// Powered up in a turn: 0.39 rad/s, 2.4 m/s² of acceleration (13° of false tilt at rest), 5.5 m/s.
constexpr double kInATurn = 5.0;
constexpr std::uint8_t kAllValid = filter_valid::kRollPitch | filter_valid::kHeading |
                                   filter_valid::kVelocity | filter_valid::kPosition;

TEST(PipelineInMotion, WithoutTheInMotionStartAMovingBoardKeepsAligning) {
  InMotionDrive d(false, kSeed, kInATurn);
  ASSERT_TRUE(d.configured());
  d.run(0, 20'000, 1000, [](const DriveCheck&) {});
  EXPECT_EQ(d.pipeline().phase(), PipelinePhase::kAligning);
  EXPECT_EQ(d.pipeline().counters().last_refusal, AlignmentRefusal::kGnssMotion);
  EXPECT_EQ(d.pipeline().counters().in_motion_alignments, 0u);
  // The 1 s window is cut by every fix (5 Hz, the first sent at 0.1 s): never finished, so never
  // accepted; each cut is a refusal.
  EXPECT_EQ(d.pipeline().counters().alignment_restarts, 100u);
}

TEST(PipelineInMotion, ABoardThatIsNoVehicleDoesNotStartInMotion) {
  // Without the track (a handheld board) nothing would set the heading: it waits for a standstill.
  InMotionDrive d(true, kSeed, kInATurn, 0.0);
  ASSERT_TRUE(d.configured());
  d.run(0, 5'000, 1000, [](const DriveCheck&) {});
  EXPECT_EQ(d.pipeline().phase(), PipelinePhase::kAligning);
  EXPECT_EQ(d.pipeline().counters().in_motion_alignments, 0u);
  EXPECT_EQ(d.pipeline().counters().last_refusal, AlignmentRefusal::kGnssMotion);
}

TEST(PipelineInMotion, APowerUpWhileDrivingAlignsFromTheFixesAndSaysSoUntilThen) {
  InMotionDrive d(true, kSeed, kInATurn);
  ASSERT_TRUE(d.configured());
  // The first fix (valid at 0, sent at 0.1 s) arms the start; the sample after it starts.
  d.run(0, 100, 1000, [](const DriveCheck&) {});
  EXPECT_EQ(d.pipeline().phase(), PipelinePhase::kAligning);
  d.run(100, 101, 1000, [](const DriveCheck&) {});
  ASSERT_EQ(d.pipeline().phase(), PipelinePhase::kNavigating);
  EXPECT_EQ(d.pipeline().counters().in_motion_alignments, 1u);
  EXPECT_EQ(d.pipeline().alignment().samples, 0u);  // no static alignment: no gravity check
  // The fix also cut the static window in progress (100 samples): refused, and said why.
  EXPECT_EQ(d.pipeline().counters().alignment_restarts, 1u);
  EXPECT_EQ(d.pipeline().counters().last_refusal, AlignmentRefusal::kGnssMotion);
  const auto nothing_available = [](const NavAccuracy<double>& a) {
    bool all_nan = a.valid == 0;
    for (int i = 0; i < 3; ++i) {
      all_nan = all_nan && std::isnan(a.euler_sigma_rad(i)) && std::isnan(a.vel_sigma_mps(i)) &&
                std::isnan(a.pos_sigma_m(i));
    }
    return all_nan;
  };
  EXPECT_TRUE(nothing_available(d.pipeline().accuracy()));
  // The next fix (valid at 0.2 s, sent at 0.3 s) is the first inside the filter's history: it
  // resets velocity and position, but the tilt needs two.
  d.run(101, 301, 100, [](const DriveCheck&) {});
  {
    const NavAccuracy<double> a = d.pipeline().accuracy();
    EXPECT_EQ(a.valid & (filter_valid::kRollPitch | filter_valid::kHeading), 0u);
    EXPECT_TRUE(std::isnan(a.euler_sigma_rad(0)));
    EXPECT_TRUE(std::isnan(a.euler_sigma_rad(2)));
  }
  int checked = 0;
  d.run(301, 30'000, 100, [&](const DriveCheck& c) {
    if (c.t_s < 20.0) return;
    ++checked;
    const NavAccuracy<double>& a = c.accuracy;
    EXPECT_EQ(a.valid, kAllValid) << "t = " << c.t_s;
    // The σ at the receiver's level: roll/pitch 0.3° (the floor 0.05 m/s of GNSS velocity
    // allows on a drive, docs/navigation-accuracy.md), heading 1° (the track: σ_v/speed ≤ 0.5°
    // and the configured slip 0.5°), velocity 0.1 m/s and position 1 m (the receiver's own).
    EXPECT_LT(a.euler_sigma_rad(0), 0.3 * kDeg) << "t = " << c.t_s;
    EXPECT_LT(a.euler_sigma_rad(1), 0.3 * kDeg) << "t = " << c.t_s;
    EXPECT_LT(a.euler_sigma_rad(2), 1.0 * kDeg) << "t = " << c.t_s;
    EXPECT_LT(a.vel_sigma_mps.maxCoeff(), 0.1) << "t = " << c.t_s;
    EXPECT_LT(a.pos_sigma_m.maxCoeff(), 1.0) << "t = " << c.t_s;
    // And they describe the errors: 6σ, which none of 300 runs came near (at most 4.4σ,
    // pipeline_in_motion_long.cpp); a start left with the first guess's tilt or heading is tens
    // of σ off.
    EXPECT_LE(c.euler_err_rad.cwiseAbs().cwiseQuotient(a.euler_sigma_rad).maxCoeff(), 6.0)
        << "t = " << c.t_s;
  });
  EXPECT_EQ(checked, 100);
  EXPECT_EQ(d.pipeline().aiding().filter().counters().divergence_restarts, 0u);
}

}  // namespace
}  // namespace gfins::nav
