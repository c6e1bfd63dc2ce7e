#include "gfins/host_sim/trajectory.hpp"

#include "gfins/host_sim/scenario.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <ostream>
#include <stdexcept>
#include <string>
#include <vector>

#include "gfins/nav_core/math.hpp"

namespace gfins::sim {
namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();
constexpr double kG = nav::kStandardGravity;

// Analytic results go through a few dozen rounded operations on values of order one (times the
// rate or the acceleration); 64 ulps of the size of the quantity bounds that.
constexpr double kRounding = 64.0 * kEps;

// Central differences: x'(t) ≈ (x(t+h) − x(t−h))/(2h) has truncation error h²/6 |x'''| and a
// rounding error of about 2 ε |x| / (2h) per evaluation pair. The rotation vector of
// q(t−h)* ⊗ q(t+h) divided by 2h differs from ω(t) by h²/6 |ω̈| plus the non-commutativity
// (coning) term, at most h²/3 |ω||ω̇| (Bortz expansion over the interval 2h).
constexpr double kStepS = 1e-4;
// Bound on |x'''| (m/s³ for r; |ω̈| + 2|ω||ω̇| for the attitude; |ω̈| for ω̇) over every
// trajectory and time below. The largest comes from the manoeuvre's roll term 0.1 sin(4.1 t),
// whose fourth derivative is 0.1·4.1⁴ = 28 at scale 1 and twice that at scale 2 (the measured
// ω̇ difference error, 1.06e-7, implies |ω̈| ≈ 64 there); coning (Ω = 3, β = 0.4) gives
// Ω³ sin β ≈ 11.
constexpr double kThirdDerivativeBound = 100.0;
// Largest |r|, |v|, |ω| (SI) reached by the cases below, for the rounding part of the tolerance.
constexpr double kMagnitudeBound = 100.0;
constexpr double kFdTolerance =
    kStepS * kStepS / 6.0 * kThirdDerivativeBound + 4.0 * kEps * kMagnitudeBound / kStepS;

struct Case {
  std::string label;
  std::function<std::unique_ptr<Trajectory>()> make;
};

// Names the case in gtest's failure messages instead of dumping its bytes.
void PrintTo(const Case& c, std::ostream* os) { *os << c.label; }

Quatd some_attitude() { return nav::quat_from_euler(0.3, -0.7, 2.1); }

StopAndGoSpec short_stop_and_go() {
  StopAndGoSpec g;
  g.speed_mps = 10.0;
  g.accel_s = 2.0;
  g.cruise_s = 3.0;
  g.stop_s = 1.0;
  g.initial_stop_s = 0.5;
  g.weave_amplitude_m = 20.0;
  g.weave_length_m = 120.0;
  return g;
}

std::vector<Case> all_cases() {
  return {
      {"rest", [] { return make_rest(some_attitude(), Vec3d(1, -2, 3)); }},
      {"constant_acceleration",
       [] {
         return make_constant_acceleration(Vec3d(kG, 0, 0), some_attitude(), Vec3d(5, 0, -1));
       }},
      {"spin", [] { return make_spin(Vec3d(1, -2, 0.5), 7.5, some_attitude()); }},
      {"coning", [] { return make_coning(0.4, 3.0, some_attitude()); }},
      {"maneuver", [] { return make_maneuver(1.0); }},
      {"maneuver_x2", [] { return make_maneuver(2.0); }},
      // Segments chosen so that kTimesS falls in each: initial stop, stop, speed-up, cruise,
      // slow-down, the next cycle's speed-up (peak jerk V·5.77/t_acc² = 14 m/s³).
      {"stop_and_go", [] { return make_stop_and_go(short_stop_and_go()); }},
  };
}

constexpr std::array<double, 6> kTimesS = {0.001, 0.37, 1.9, 4.2, 7.3, 11.05};

class TrajectoryFdTest : public ::testing::TestWithParam<Case> {};

TEST_P(TrajectoryFdTest, VelocityAndAccelerationMatchCentralDifferences) {
  const auto traj = GetParam().make();
  for (const double t : kTimesS) {
    const TruthState x = traj->at(t);
    const TruthState xp = traj->at(t + kStepS);
    const TruthState xm = traj->at(t - kStepS);
    const Vec3d v_fd = (xp.r_n - xm.r_n) / (2.0 * kStepS);
    const Vec3d a_fd = (xp.v_n - xm.v_n) / (2.0 * kStepS);
    EXPECT_LT((x.v_n - v_fd).norm(), kFdTolerance) << "t = " << t;
    EXPECT_LT((x.a_n - a_fd).norm(), kFdTolerance) << "t = " << t;
    EXPECT_EQ(x.t_s, t);
  }
}

TEST_P(TrajectoryFdTest, RateMatchesAttitudeDifferencesAndAngularAccelerationMatchesRate) {
  const auto traj = GetParam().make();
  for (const double t : kTimesS) {
    const TruthState x = traj->at(t);
    const TruthState xp = traj->at(t + kStepS);
    const TruthState xm = traj->at(t - kStepS);
    // Body-frame rotation from t−h to t+h: independent of the ω = 2 vec(q* ⊗ q̇) formula, and it
    // checks the convention (q_nb body-to-navigation, ω in the body frame).
    const Vec3d w_fd =
        nav::rotation_vector_from_quat<double>(xm.q_nb.conjugate() * xp.q_nb) / (2.0 * kStepS);
    const Vec3d wdot_fd = (xp.w_b - xm.w_b) / (2.0 * kStepS);
    EXPECT_LT((x.w_b - w_fd).norm(), kFdTolerance) << "t = " << t;
    EXPECT_LT((x.wdot_b - wdot_fd).norm(), kFdTolerance) << "t = " << t;
  }
}

TEST_P(TrajectoryFdTest, AttitudeStaysUnit) {
  const auto traj = GetParam().make();
  for (int i = 0; i < 1000; ++i) {
    const double t = 0.0137 * i * i;  // up to about 13700 s, where angles are large
    EXPECT_NEAR(traj->at(t).q_nb.norm(), 1.0, kRounding) << "t = " << t;
  }
}

INSTANTIATE_TEST_SUITE_P(AllTrajectories, TrajectoryFdTest, ::testing::ValuesIn(all_cases()),
                         [](const auto& param_info) { return param_info.param.label; });

TEST(TrajectoryTest, NamesSayWhichMotion) {
  EXPECT_EQ(make_rest(Quatd::Identity())->name(), "rest");
  EXPECT_EQ(make_constant_acceleration(Vec3d::Zero(), Quatd::Identity())->name(),
            "constant_acceleration");
  EXPECT_EQ(make_spin(Vec3d::UnitZ(), 1.0, Quatd::Identity())->name(), "spin");
  EXPECT_EQ(make_coning(0.1, 1.0)->name(), "coning");
  EXPECT_EQ(make_maneuver()->name(), "maneuver");
}

TEST(TrajectoryTest, RestIsStillEverywhere) {
  const Quatd q = some_attitude();
  const auto traj = make_rest(q, Vec3d(1, -2, 3));
  const TruthState x = traj->at(12.5);
  EXPECT_EQ(x.q_nb.coeffs(), q.coeffs());
  EXPECT_EQ(x.r_n, Vec3d(1, -2, 3));
  EXPECT_EQ(x.v_n, Vec3d::Zero());
  EXPECT_EQ(x.a_n, Vec3d::Zero());
  EXPECT_EQ(x.w_b, Vec3d::Zero());
  EXPECT_EQ(x.wdot_b, Vec3d::Zero());
}

TEST(TrajectoryTest, ConstantAccelerationIsAParabolaFromRest) {
  // Given the paper's §6.3 motion a_n = [g 0 0] from rest at r0 with a fixed attitude,
  const Vec3d a(kG, 0.0, 0.0);
  const Vec3d r0(5.0, -1.0, 2.0);
  const Quatd q = some_attitude();
  const auto traj = make_constant_acceleration(a, q, r0);
  for (const double t : {0.0, 0.5, 2.0, 10.0}) {
    // when sampled, then r = r0 + a t²/2, v = a t, and the body does not turn.
    const TruthState x = traj->at(t);
    EXPECT_LE((x.r_n - (r0 + 0.5 * t * t * a)).norm(), kRounding * (r0.norm() + kG * t * t));
    EXPECT_LE((x.v_n - t * a).norm(), kRounding * kG * t);
    EXPECT_EQ(x.a_n, a);
    EXPECT_EQ(x.q_nb.coeffs(), q.coeffs());
    EXPECT_EQ(x.w_b, Vec3d::Zero());
    EXPECT_EQ(x.wdot_b, Vec3d::Zero());
  }
}

TEST(TrajectoryTest, SpinHasConstantRateAboutTheGivenBodyAxis) {
  // Given a spin at 7.5 rad/s about a non-unit, non-principal body axis,
  const Vec3d axis(1.0, -2.0, 0.5);
  const double rate = 7.5;
  const Quatd q0 = some_attitude();
  const Vec3d r0(0.0, 3.0, -4.0);
  const auto traj = make_spin(axis, rate, q0, r0);
  const Vec3d u = axis.normalized();
  for (const double t : {0.0, 0.1, 3.3, 100.0}) {
    const TruthState x = traj->at(t);
    // then ω_b = rate·u exactly (to rounding), ω̇ = 0, the centre does not move,
    EXPECT_LT((x.w_b - rate * u).norm(), kRounding * rate) << "t = " << t;
    EXPECT_LT(x.wdot_b.norm(), kRounding * rate * rate) << "t = " << t;
    EXPECT_EQ(x.r_n, r0);
    EXPECT_EQ(x.v_n, Vec3d::Zero());
    EXPECT_EQ(x.a_n, Vec3d::Zero());
    // and the attitude is q0 turned about the body axis by rate·t (Eigen's own angle-axis).
    const Quatd q_ref = q0 * Quatd(Eigen::AngleAxisd(rate * t, u));
    EXPECT_LT(q_ref.angularDistance(x.q_nb), 1e-12 * (1.0 + rate * t)) << "t = " << t;
  }
}

TEST(TrajectoryTest, SpinRejectsAZeroAxis) {
  EXPECT_THROW(make_spin(Vec3d::Zero(), 1.0, Quatd::Identity()), std::invalid_argument);
}

// The scenario path (make_trajectory, used by the simulated board inside gfins-fw) says so with a
// value instead.
TEST(TrajectoryTest, MakeTrajectoryRefusesAZeroOrNanSpinAxisWithAValue) {
  for (const Vec3d& axis :
       {Vec3d(Vec3d::Zero()), Vec3d(std::numeric_limits<double>::quiet_NaN(), 0.0, 1.0)}) {
    TrajectorySpec t;
    t.kind = "spin";
    t.axis_b = axis;
    t.rate_rps = 1.0;
    HostResult<std::unique_ptr<Trajectory>> r = HostError{};
    EXPECT_NO_THROW(r = make_trajectory(t));
    ASSERT_FALSE(r.is_ok());
    EXPECT_NE(r.error().message.find("spin axis"), std::string::npos) << r.error().message;
  }
}

TEST(TrajectoryTest, ConingRateHasTheTextbookForm) {
  // Given coning of half-angle β at Ω about the z axis of q0,
  const double beta = 0.4;
  const double omega = 3.0;
  const Quatd q0 = some_attitude();
  const auto traj = make_coning(beta, omega, q0);
  for (const double t : {0.0, 0.25, 1.0, 2.7, 40.0}) {
    const TruthState x = traj->at(t);
    const double c = std::cos(omega * t);
    const double s = std::sin(omega * t);
    // then ω_b = [−Ω sin β sin Ωt, Ω sin β cos Ωt, −Ω(1 − cos β)] (rotating in the x-y plane with a
    // constant z component) and ω̇_b = [−Ω² sin β cos Ωt, −Ω² sin β sin Ωt, 0],
    const Vec3d w_ref(-omega * std::sin(beta) * s, omega * std::sin(beta) * c,
                      -omega * (1.0 - std::cos(beta)));
    const Vec3d wdot_ref(-omega * omega * std::sin(beta) * c, -omega * omega * std::sin(beta) * s,
                         0.0);
    EXPECT_LT((x.w_b - w_ref).norm(), kRounding * omega) << "t = " << t;
    EXPECT_LT((x.wdot_b - wdot_ref).norm(), kRounding * omega * omega) << "t = " << t;
    // and the body z axis lies on the cone: at β from the cone axis, azimuth turning at Ω.
    const Vec3d z_in_cone_frame = q0.conjugate() * (x.q_nb * Vec3d::UnitZ());
    const Vec3d z_ref(std::sin(beta) * s, -std::sin(beta) * c, std::cos(beta));
    EXPECT_LT((z_in_cone_frame - z_ref).norm(), kRounding) << "t = " << t;
    EXPECT_EQ(x.r_n, Vec3d::Zero());
    EXPECT_EQ(x.a_n, Vec3d::Zero());
  }
}

TEST(TrajectoryTest, ManeuverIsVehicleLikeAtScaleOne) {
  // Given the manoeuvre at scale 1 sampled over a minute, its peaks stay in the documented
  // ranges (trajectory.hpp), and they are not trivially small either.
  const auto traj = make_maneuver(1.0);
  double w_max = 0.0;
  double wdot_max = 0.0;
  double a_max = 0.0;
  double roll_max = 0.0;
  for (int i = 0; i <= 6000; ++i) {
    const TruthState x = traj->at(0.01 * i);
    w_max = std::max(w_max, x.w_b.norm());
    wdot_max = std::max(wdot_max, x.wdot_b.norm());
    a_max = std::max(a_max, x.a_n.norm());
    roll_max = std::max(roll_max, std::abs(nav::euler_from_quat(x.q_nb).x()));
  }
  EXPECT_EQ(traj->at(0.0).r_n, Vec3d::Zero());
  EXPECT_GT(w_max, 0.5);
  EXPECT_LT(w_max, 1.2);
  EXPECT_GT(wdot_max, 1.0);
  EXPECT_LT(wdot_max, 3.0);
  EXPECT_GT(a_max, 1.0);
  EXPECT_LT(a_max, 4.0);
  EXPECT_GT(roll_max, 0.2);  // tens of degrees
}

TEST(TrajectoryTest, ManeuverAtScaleZeroIsRestAtTheOrigin) {
  const auto traj = make_maneuver(0.0);
  const TruthState x = traj->at(3.0);
  EXPECT_EQ(x.r_n, Vec3d::Zero());
  EXPECT_EQ(x.v_n, Vec3d::Zero());
  EXPECT_EQ(x.w_b, Vec3d::Zero());
  EXPECT_NEAR(x.q_nb.angularDistance(Quatd::Identity()), 0.0, kRounding);
}

}  // namespace
}  // namespace gfins::sim

namespace gfins::sim {
namespace {

// Stop and go: still during every stop, V(t_acc + t_cruise) metres north per cycle, cruising
// north at V, and a coordinated turn everywhere (no lateral specific force in the body frame: the
// normal acceleration of a planar path is |ṗ| ψ̇, which the bank tan φ = |ṗ| ψ̇ / g cancels).
TEST(TrajectoryTest, StopAndGoStopsCyclesAndTurnsCoordinated) {
  const StopAndGoSpec g = short_stop_and_go();
  const auto traj = make_stop_and_go(g);
  EXPECT_EQ(traj->name(), "stop_and_go");
  const double cycle_s = g.stop_s + 2.0 * g.accel_s + g.cruise_s;
  const double cycle_m = g.speed_mps * (g.accel_s + g.cruise_s);
  for (int n = 0; n < 3; ++n) {
    const double t0 = g.initial_stop_s + n * cycle_s;
    for (const double dt : {0.01, 0.5, 0.99}) {  // inside the stop of cycle n
      const TruthState x = traj->at(t0 + dt * g.stop_s);
      EXPECT_EQ(x.v_n.norm(), 0.0) << "cycle " << n;
      EXPECT_EQ(x.w_b.norm(), 0.0) << "cycle " << n;
      // The road's x coordinate at the stop: n whole cycles.
      EXPECT_NEAR(x.r_n.x(), n * cycle_m, kRounding * cycle_m * 4) << "cycle " << n;
    }
    // Mid-cruise: progress north at V, ground speed V √(1 + (A k sin k x)²) along the road.
    const TruthState c = traj->at(t0 + g.stop_s + g.accel_s + g.cruise_s / 2);
    const double k = 2.0 * M_PI / g.weave_length_m;
    const double slope = g.weave_amplitude_m * k * std::sin(k * c.r_n.x());
    EXPECT_NEAR(c.v_n.x(), g.speed_mps, kRounding * 100);
    EXPECT_NEAR(c.v_n.norm(), g.speed_mps * std::sqrt(1.0 + slope * slope), kRounding * 100);
  }
  for (double t = 0.0; t < 3 * cycle_s; t += 0.013) {
    const TruthState x = traj->at(t);
    const Vec3d f_b = x.q_nb.conjugate() * (x.a_n - Vec3d(0, 0, kG));
    EXPECT_NEAR(f_b.y(), 0.0, 1e-12 * kG) << "t = " << t;
  }
}

}  // namespace
}  // namespace gfins::sim
