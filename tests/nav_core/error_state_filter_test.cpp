// The aided error-state filter (filter/error_state_filter.hpp) on the array's forward physics
// (filter_truth.hpp): standstill aiding with a bias, GNSS with an outlier, lever arm and latency,
// heading from the track, and the Euler-angle σ. The ten-minute runs (standstill aiding, float
// against double) are in error_state_filter_long.cpp.
#include "gfins/nav_core/filter/error_state_filter.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>

#include "nav_core/filter_run.hpp"

namespace gfins::nav {
namespace {

using testing::Epoch;
using testing::fraction_within;
using testing::RunSpec;

constexpr double kPi = 3.14159265358979323846;

// ---- GNSS on a figure eight ---------------------------------------------------------------

constexpr double kRadiusM = 100;
constexpr double kOmegaRps = 2 * kPi / 60;  // one figure eight per minute, 6.9-10.5 m/s

RunSpec gnss_spec() {
  RunSpec s;
  s.duration_s = 60;
  s.truth = [](double t) { return testing::figure_eight(t, kRadiusM, kOmegaRps); };
  s.gnss = true;
  return s;
}

// An outlier of 100 m in one fix: NIS ≈ 100²/(1.5² + σ²) ≫ χ²_0.999(3) ≈ 16.5: rejected, counted,
// and the navigation unchanged; with the gate off the same fix drags the position by metres.
constexpr double kOutlierM = 100;
constexpr double kOutlierT = 30.0;

TEST(ErrorStateFilterTest, OutlierFixIsRejectedAndCounted) {
  RunSpec spec = gnss_spec();
  spec.duration_s = kOutlierT + 1;
  spec.outlier_m = kOutlierM;
  spec.outlier_t_s = kOutlierT;
  const auto gated = testing::run_aided<double>(spec, testing::filter_config(spec));
  auto config = testing::filter_config(spec);
  config.innovation_gate = false;
  const auto open = testing::run_aided<double>(spec, config);
  const auto kind = static_cast<std::size_t>(AidingKind::kGnssPosition);
  EXPECT_EQ(gated.counters.rejected[kind], 1u);
  EXPECT_EQ(gated.gnss_position_outcomes[static_cast<std::size_t>(kOutlierT * 5) - 1].status,
            UpdateStatus::kRejected);
  EXPECT_EQ(open.counters.rejected[kind], 0u);
  // The position error one second after the outlier, against 3σ.
  const Epoch& g = gated.epochs.back();
  const Epoch& o = open.epochs.back();
  const double sigma_n = std::sqrt(g.p(3, 3));
  std::printf("north error after the outlier: gated %.2f m, open %.2f m (sigma %.2f m)\n", g.err(3),
              o.err(3), sigma_n);
  EXPECT_LE(std::abs(g.err(3)), 3 * sigma_n);
  EXPECT_GT(std::abs(o.err(3)), 3 * std::sqrt(o.p(3, 3)));  // negative control
}

// The outlier leaves the state untouched: the strapdown after a rejected update is bit for bit
// the one before it.
TEST(ErrorStateFilterTest, RejectedUpdateLeavesStateAndCovarianceUntouched) {
  static ErrorStateFilter<double> filter;
  const auto solver = ArraySolver<double>::create(table1_geometry(0.1)).value();
  const auto gravity = GravityModel<double>::constant(testing::kG);
  Strapdown<double> nav(solver, gravity);
  const testing::Truth x = testing::rest(Quat<double>::Identity());
  nav.initialize(testing::nav_state_of<double>(x), testing::ideal_outputs(solver.geometry(), x));
  ASSERT_TRUE(filter.configure(FilterConfig<double>{}).is_ok());
  filter.start(nav);
  ASSERT_TRUE(filter.propagate(nav, 0.05).is_ok());
  const auto p_before = filter.covariance();
  const NavState<double> s_before = nav.state();
  GnssFix<double> fix;
  fix.t_valid_ns = nav.state().t_ns;
  fix.value_n = Vec3<double>(kOutlierM, 0, 0);
  fix.sigma = Vec3<double>::Constant(1.5);
  const UpdateOutcome r = filter.update_gnss_position(nav, fix);
  EXPECT_EQ(r.status, UpdateStatus::kRejected);
  EXPECT_GT(static_cast<double>(r.nis), filter.gate_threshold(3));
  EXPECT_EQ(filter.counters().rejected[static_cast<std::size_t>(AidingKind::kGnssPosition)], 1u);
  EXPECT_EQ(filter.covariance(), p_before);
  EXPECT_EQ(nav.state().r_n, s_before.r_n);
  EXPECT_EQ(nav.state().q_nb.coeffs(), s_before.q_nb.coeffs());
  // A fix outside the history (older than every stored state) is invalid, not applied.
  fix.t_valid_ns = -1'000'000'000;
  EXPECT_EQ(filter.update_gnss_position(nav, fix).status, UpdateStatus::kInvalid);
}

// A navigation solution outside its own σ: every fix is 100 m off (the gate's χ²(3) quantile of
// 16.3 against NIS ≈ 100²/(1.5² + 1²) ≈ 3,000), so the gate alone would refuse them forever. The
// lock-out recovery sets the position from the fix at the configured count (the 25th here),
// counted; with the recovery off all 25 stay rejected and the position is unchanged.
struct RestFilter {
  ErrorStateFilter<double> filter;
  ArraySolver<double> solver = ArraySolver<double>::create(table1_geometry(0.1)).value();
  Strapdown<double> nav{solver, GravityModel<double>::constant(testing::kG)};
  explicit RestFilter(const FilterConfig<double>& config) {
    const testing::Truth x = testing::rest(Quat<double>::Identity());
    nav.initialize(testing::nav_state_of<double>(x), testing::ideal_outputs(solver.geometry(), x));
    EXPECT_TRUE(filter.configure(config).is_ok());
    filter.start(nav);
    EXPECT_TRUE(filter.propagate(nav, 0.05).is_ok());
  }
  GnssFix<double> fix_at(const Vec3<double>& r) const {
    GnssFix<double> fix;
    fix.t_valid_ns = nav.state().t_ns;
    fix.value_n = r;
    fix.sigma = Vec3<double>::Constant(1.5);
    return fix;
  }
};

TEST(ErrorStateFilterTest, LockOutRecoveryTakesThePositionFromTheFixAfterTheCount) {
  FilterConfig<double> config;
  config.gnss_lockout_fixes = 25;
  static RestFilter on(config);
  const Vec3<double> far(kOutlierM, -40.0, 2.0);
  const auto kind = static_cast<std::size_t>(AidingKind::kGnssPosition);
  for (int i = 0; i < 24; ++i) {
    EXPECT_EQ(on.filter.update_gnss_position(on.nav, on.fix_at(far)).status,
              UpdateStatus::kRejected);
  }
  EXPECT_EQ(on.filter.counters().gnss_lockout_resets, 0u);
  EXPECT_LT(on.nav.state().r_n.norm(), 1e-9);  // still where it started
  // The 25th: still reported rejected (not applied as a measurement), but the position is reset.
  EXPECT_EQ(on.filter.update_gnss_position(on.nav, on.fix_at(far)).status, UpdateStatus::kRejected);
  EXPECT_EQ(on.filter.counters().gnss_lockout_resets, 1u);
  EXPECT_EQ(on.filter.counters().rejected[kind], 25u);
  EXPECT_LT((on.nav.state().r_n - far).norm(), 1e-9);  // no lever arm: the array is at the fix
  const auto& p = on.filter.covariance();
  EXPECT_NEAR(p(filt_idx::kPos, filt_idx::kPos), 1.5 * 1.5, 1e-12);
  // The next fix at the same place is accepted: the filter is back.
  EXPECT_EQ(on.filter.update_gnss_position(on.nav, on.fix_at(far)).status, UpdateStatus::kAccepted);

  config.gnss_lockout_fixes = 0;  // negative control: no recovery
  static RestFilter off(config);
  for (int i = 0; i < 30; ++i) (void)off.filter.update_gnss_position(off.nav, off.fix_at(far));
  EXPECT_EQ(off.filter.counters().rejected[kind], 30u);
  EXPECT_EQ(off.filter.counters().gnss_lockout_resets, 0u);
  EXPECT_LT(off.nav.state().r_n.norm(), 1e-9);
}

// The velocity lock-out with the antenna 1 m forward and the board turning at 0.5 rad/s: the
// antenna moves at ω × l = (0, 0.5, 0) m/s beside the array, so the reset sets the array's
// velocity, the fix's minus that, with |l|² (tr P₀,ωω + |ω̂|²) added to the fix's variance.
TEST(ErrorStateFilterTest, LockOutRecoveryTakesTheArraysVelocityFromTheAntennasFix) {
  FilterConfig<double> config;
  config.gnss_lockout_fixes = 25;
  config.gnss_lever_arm_b = Vec3<double>(1.0, 0.0, 0.0);
  RestFilter r(config);
  // ω̂ = (0, 0, 0.5) rad/s (apply_correction subtracts its rate term).
  r.nav.apply_correction(Vec3<double>::Zero(), Vec3<double>::Zero(), Vec3<double>::Zero(),
                         Vec3<double>(0, 0, -0.5));
  ASSERT_NEAR(r.nav.state().w_b.z(), 0.5, 1e-12);
  GnssFix<double> fix = r.fix_at(Vec3<double>(40.0, -30.0, 5.0));  // every one gated out
  for (int i = 0; i < 25; ++i) {
    fix.t_valid_ns = r.nav.state().t_ns;
    EXPECT_EQ(r.filter.update_gnss_velocity(r.nav, fix).status, UpdateStatus::kRejected);
  }
  ASSERT_EQ(r.filter.counters().gnss_lockout_resets, 1u);
  // Level, heading north: Ĉ = I, and ω̂ × l = (0, 0.5, 0).
  EXPECT_LT((r.nav.state().v_n - Vec3<double>(40.0, -30.5, 5.0)).norm(), 1e-9);
  const double rate_var = 3 * config.init_sigma_rate_rps * config.init_sigma_rate_rps;
  const auto& p = r.filter.covariance();
  EXPECT_NEAR(p(filt_idx::kVel, filt_idx::kVel), 1.5 * 1.5 + 1.0 * (rate_var + 0.25), 1e-9);
}

// Divergence: a rate of 20 rad/s (above max_rate_rps, 10) is a solution that has run away; the
// restart zeroes the rate, forgets the heading and widens the tilt to half the limit. A rate of
// 1 rad/s with the initial covariance is not a divergence.
TEST(ErrorStateFilterTest, DivergedSolutionRestarts) {
  FilterConfig<double> config;
  static RestFilter f(config);
  f.nav.apply_correction(Vec3<double>::Zero(), Vec3<double>::Zero(), Vec3<double>::Zero(),
                         Vec3<double>(-1.0, 0, 0));  // ω̂ = 1 rad/s about x
  EXPECT_FALSE(f.filter.restart_if_diverged(f.nav));
  EXPECT_EQ(f.filter.counters().divergence_restarts, 0u);
  f.nav.apply_correction(Vec3<double>::Zero(), Vec3<double>::Zero(), Vec3<double>::Zero(),
                         Vec3<double>(0, -20.0, 0));  // |ω̂| ≈ 20 rad/s
  ASSERT_GT(f.nav.state().w_b.norm(), config.max_rate_rps);
  EXPECT_TRUE(f.filter.restart_if_diverged(f.nav));
  EXPECT_EQ(f.filter.counters().divergence_restarts, 1u);
  EXPECT_LT(f.nav.state().w_b.norm(), 1e-12);
  EXPECT_FALSE(f.filter.heading_aligned());
  const auto& p = f.filter.covariance();
  const double half = config.diverged_sigma_tilt_rad / 2;
  EXPECT_NEAR(p(filt_idx::kPhi, filt_idx::kPhi), half * half, 1e-12);
  EXPECT_NEAR(p(filt_idx::kRate, filt_idx::kRate),
              config.restart_sigma_rate_rps * config.restart_sigma_rate_rps, 1e-12);
  // The restarted filter is not diverged (the restart leaves room below the limit).
  EXPECT_FALSE(f.filter.restart_if_diverged(f.nav));
}

// After a restart the covariance no longer describes the errors (the linear model failed before
// the test fired): every σ is not available (NaN, no valid bit) until a fix sets its quantity
// again — position with a GNSS position fix, velocity with a velocity fix, the attitude with the
// heading alignment that follows (here an external heading).
TEST(ErrorStateFilterTest, SigmaIsNotAvailableAfterARestartUntilFixesSetTheQuantities) {
  FilterConfig<double> config;
  RestFilter f(config);
  NavAccuracy<double> a = f.filter.accuracy(f.nav.state());
  ASSERT_TRUE(a.euler_sigma_rad.allFinite() && a.vel_sigma_mps.allFinite() &&
              a.pos_sigma_m.allFinite());
  f.nav.apply_correction(Vec3<double>::Zero(), Vec3<double>::Zero(), Vec3<double>::Zero(),
                         Vec3<double>(0, -20.0, 0));
  ASSERT_TRUE(f.filter.restart_if_diverged(f.nav));
  a = f.filter.accuracy(f.nav.state());
  EXPECT_TRUE(a.euler_sigma_rad.array().isNaN().all());
  EXPECT_TRUE(a.vel_sigma_mps.array().isNaN().all());
  EXPECT_TRUE(a.pos_sigma_m.array().isNaN().all());
  EXPECT_EQ(a.valid, 0);

  ASSERT_EQ(f.filter.update_gnss_position(f.nav, f.fix_at(Vec3<double>(3, 4, 0))).status,
            UpdateStatus::kReset);
  a = f.filter.accuracy(f.nav.state());
  EXPECT_NEAR(a.pos_sigma_m.x(), 1.5, 1e-9);  // the fix's σ (no lever arm)
  EXPECT_TRUE(a.vel_sigma_mps.array().isNaN().all());
  EXPECT_TRUE(a.euler_sigma_rad.array().isNaN().all());

  GnssFix<double> vel = f.fix_at(Vec3<double>::Zero());  // at rest: below the track speed
  vel.sigma = Vec3<double>::Constant(0.1);
  ASSERT_EQ(f.filter.update_gnss_velocity(f.nav, vel).status, UpdateStatus::kReset);
  a = f.filter.accuracy(f.nav.state());
  EXPECT_NEAR(a.vel_sigma_mps.x(), 0.1, 1e-9);
  EXPECT_TRUE(a.euler_sigma_rad.array().isNaN().all());  // no heading yet
  EXPECT_FALSE(f.filter.heading_aligned());

  ASSERT_EQ(
      f.filter.update_heading(f.nav, HeadingFix<double>{f.nav.state().t_ns, 0.0, 0.01}).status,
      UpdateStatus::kReset);
  a = f.filter.accuracy(f.nav.state());
  // The heading is set, the tilt not found: only two velocity fixes re-level it
  // (AHeadingFixAfterARestartLeavesTheTiltLostUntilTheFixesRelevelIt), so the Euler angles' σ
  // stay not available.
  EXPECT_TRUE(f.filter.heading_aligned());
  EXPECT_TRUE(a.euler_sigma_rad.array().isNaN().all());
  EXPECT_EQ(f.filter.counters().divergence_restarts, 1u);
}

// After a restart the tilt can be tens of degrees off (a long outage), outside what the linear
// update can bring back. Two GNSS velocity fixes re-level it: Δv/dt − g from the fixes against
// the strapdown's own Δv̂/dt − g. The true board is level with heading north, at rest or moving
// north (constant speed or acceleration, so its sensor outputs are constant); the estimate is
// rolled by 30° and pitched by −20° (the highway outage's restart left 32° and 20°), or turned
// 90° in heading. Fixes are exact at 5 Hz: the re-levelling leaves the propagation's rate
// error over 0.2 s, well below 0.5°, with the tilt σ the fixes' noise gives
// (√2 · 0.1 m/s / 0.2 s / |f|: 4.1° at rest).
struct TiltedRestart {
  static constexpr double kRate = 200;
  ArraySolver<double> solver = ArraySolver<double>::create(table1_geometry(0.1)).value();
  Strapdown<double> nav{solver, GravityModel<double>::constant(testing::kG)};
  ErrorStateFilter<double> filter;
  Vec6<double> outputs;
  Vec3<double> v0 = Vec3<double>::Zero();
  Vec3<double> a_n = Vec3<double>::Zero();
  int k = 0;

  static Quat<double> tilted() {
    return Quat<double>(Eigen::AngleAxisd(-20 * kPi / 180, Vec3<double>::UnitY()) *
                        Eigen::AngleAxisd(30 * kPi / 180, Vec3<double>::UnitX()));
  }

  explicit TiltedRestart(const Quat<double>& estimate = tilted(),
                         const Vec3<double>& velocity = Vec3<double>::Zero(),
                         const Vec3<double>& accel = Vec3<double>::Zero())
      : v0(velocity), a_n(accel) {
    testing::Truth truth = testing::rest(Quat<double>::Identity());
    truth.v_n = v0;
    truth.a_n = a_n;
    outputs = testing::ideal_outputs(solver.geometry(), truth);
    testing::Truth est = truth;
    est.q_nb = estimate;
    nav.initialize(testing::nav_state_of<double>(est), outputs);
    EXPECT_TRUE(filter.configure(FilterConfig<double>{}).is_ok());
    filter.start(nav);
    restart();
  }

  void restart() {
    nav.apply_correction(Vec3<double>::Zero(), Vec3<double>::Zero(), Vec3<double>::Zero(),
                         Vec3<double>(0, -20.0, 0));  // a runaway rate: the restart fires
    EXPECT_TRUE(filter.restart_if_diverged(nav));
  }

  /// Steps for `seconds` with propagation at 20 Hz and a velocity fix every `fix_every_s`.
  void run(double seconds, double fix_every_s) {
    const int n = static_cast<int>(seconds * kRate);
    const int fix_every = static_cast<int>(fix_every_s * kRate);
    for (int i = 0; i < n; ++i, ++k) {
      const double t = k / kRate;
      const auto t_ns = static_cast<std::int64_t>(std::llround(t * 1e9));
      nav.step(outputs, 1 / kRate, t_ns, static_cast<std::uint32_t>(k));
      if (k % 10 == 9) {
        EXPECT_TRUE(filter.propagate(nav, 10 / kRate).is_ok());
      }
      if (k % fix_every == fix_every - 1) {
        GnssFix<double> fix;
        fix.t_valid_ns = t_ns;
        fix.value_n = v0 + a_n * t;
        fix.sigma = Vec3<double>::Constant(0.1);
        (void)filter.update_gnss_velocity(nav, fix);
      }
    }
  }

  double tilt_deg() const {
    const Vec3<double> e = euler_from_quat(nav.state().q_nb);
    return std::max(std::abs(e.x()), std::abs(e.y())) * 180 / kPi;
  }
};

TEST(ErrorStateFilterTest, TwoVelocityFixesRelevelALostTilt) {
  TiltedRestart r;
  ASSERT_GT(r.tilt_deg(), 25.0);
  r.run(0.45, 0.2);  // fixes at 0.2 and 0.4 s
  EXPECT_LT(r.tilt_deg(), 0.5);
  const auto& p = r.filter.covariance();
  const double sigma = std::sqrt(2.0) * 0.1 / 0.2 / testing::kG;
  // Set at the fix of 0.4 s, then grown by the propagation to 0.45 s (by 2 % here).
  EXPECT_GE(std::sqrt(p(filt_idx::kPhi, filt_idx::kPhi)), sigma);
  EXPECT_LE(std::sqrt(p(filt_idx::kPhi, filt_idx::kPhi)), 1.05 * sigma);
  EXPECT_FALSE(r.filter.heading_aligned());  // at rest: no track
}

// A heading error under horizontal acceleration turns f̂ about the vertical; the smallest rotation
// onto f would read that as tilt (23° for 90° of heading at 3 m/s²). Level estimate, heading
// 90° off, the board accelerating north at 3 m/s²: the re-levelling leaves the tilt level.
TEST(ErrorStateFilterTest, ReLevellingDoesNotTurnAHeadingErrorIntoTilt) {
  const Quat<double> turned(Eigen::AngleAxisd(kPi / 2, Vec3<double>::UnitZ()));
  TiltedRestart r(turned, Vec3<double>::Zero(), Vec3<double>(3.0, 0, 0));
  ASSERT_LT(r.tilt_deg(), 1e-6);
  r.run(0.45, 0.2);
  EXPECT_LT(r.tilt_deg(), 0.5);
}

// Fixes 3 s apart cannot be differenced (beyond the 2 s limit): the tilt stays off, and on a
// moving board the heading is still taken from the track (the re-levelling does not hold it
// back when it cannot be made, as for a receiver slower than the history spans).
TEST(ErrorStateFilterTest, FixesTooFarApartDoNotRelevelButTheTrackStillSetsTheHeading) {
  TiltedRestart r(TiltedRestart::tilted(), Vec3<double>(10.0, 0, 0));
  r.run(6.1, 3.0);  // fixes at 3 and 6 s
  EXPECT_GT(r.tilt_deg(), 15.0);
  EXPECT_TRUE(r.filter.heading_aligned());
}

// A heading fix before the tilt is found (an external heading after a restart) sets the heading
// alone: roll and pitch stay not available (the tilt is 30° off, the restart's σ 10°; the Euler
// angles' σ go together, J of the heading needs the tilt), then two velocity fixes re-level the
// tilt without turning the heading the fix set.
TEST(ErrorStateFilterTest, AHeadingFixAfterARestartLeavesTheTiltLostUntilTheFixesRelevelIt) {
  TiltedRestart r;
  ASSERT_GT(r.tilt_deg(), 25.0);
  const HeadingFix<double> heading{r.nav.state().t_ns, 0.0, 0.01};
  ASSERT_EQ(r.filter.update_heading(r.nav, heading).status, UpdateStatus::kReset);
  ASSERT_TRUE(r.filter.heading_aligned());
  const NavAccuracy<double> before = r.filter.accuracy(r.nav.state());
  EXPECT_TRUE(before.euler_sigma_rad.array().isNaN().all());
  r.run(0.45, 0.2);  // fixes at 0.2 and 0.4 s
  EXPECT_LT(r.tilt_deg(), 0.5);
  const NavAccuracy<double> after = r.filter.accuracy(r.nav.state());
  // The level's σ, √2·0.1/(0.2 g), grown by the propagation to 0.45 s (2 %).
  const double sigma = std::sqrt(2.0) * 0.1 / 0.2 / testing::kG;
  EXPECT_LE(after.euler_sigma_rad.x(), 1.05 * sigma);
  EXPECT_LE(after.euler_sigma_rad.y(), 1.05 * sigma);
  // The truth's heading is 0 (testing::rest, identity): the fix's 0 is kept, to 3 of its 0.01 rad
  // (the level's turn about a horizontal axis alone moves it by 5.4°).
  EXPECT_LT(std::abs(euler_from_quat(r.nav.state().q_nb).z()), 0.03);
}

// A restart forgets the fix before it: a velocity difference across the diverged stretch means
// nothing. One fix at 0.2 s, a second restart, one fix at 0.4 s: no re-levelling.
TEST(ErrorStateFilterTest, ARestartForgetsThePreviousFix) {
  TiltedRestart r;
  r.run(0.25, 0.2);
  r.restart();
  r.run(0.2, 0.2);
  EXPECT_GT(r.tilt_deg(), 25.0);
}

// A re-level after a restart turns the yaw to the fixes' azimuth while the heading stays unknown
// (below the track speed): a new heading, as unknown as the old one. Each leg keeps its own
// heading's error, and the position σ adds 1.5 (|d₁| + |d₂|)² per axis (docs/math.md: Minkowski's
// bound for the sum of the legs' errors); the heading fix that comes later moves it into P_pp.
// Truth written here: level, heading north, from rest at 0.5 m/s² north (2 m/s after 4 s, below
// the 3 m/s of the track); the estimate level and 90° off in heading, so the fixes' f has an
// azimuth and the re-level at the second fix (2 s) turns the yaw by about 90°. Exact algebra:
// 1e-9 relative is rounding. With the anchor left at the restart the fix adds 1.5 |d₁ + d₂|²
// (14 % less here); with the anchor moved and the first leg forgotten, 1.5 |d₂|².
TEST(ErrorStateFilterTest, AReLevelThatTurnsTheYawStartsANewLegOfTheUnknownHeading) {
  const Quat<double> turned(Eigen::AngleAxisd(kPi / 2, Vec3<double>::UnitZ()));
  TiltedRestart r(turned, Vec3<double>::Zero(), Vec3<double>(0.5, 0, 0));
  const Vec3<double> start = r.nav.state().r_n;  // the restart's anchor
  auto p_pp = [&r] { return r.filter.covariance().block<2, 2>(filt_idx::kPos, filt_idx::kPos); };
  r.run(1.995, 1.0);  // the first fix, at 1 s: velocity reset, nothing to difference yet
  const double yaw_before = euler_from_quat(r.nav.state().q_nb).z();
  r.run(0.005, 1.0);  // the second fix, at 2 s: the re-level
  ASSERT_GT(std::abs(wrap_pi(euler_from_quat(r.nav.state().q_nb).z() - yaw_before)), 1.0)
      << "the re-level turned the yaw";
  ASSERT_FALSE(r.filter.heading_aligned());
  const Vec3<double> relevel = r.nav.state().r_n;
  r.run(0.99, 1.0);  // 1 s more, before the third fix
  const Vec3<double> now = r.nav.state().r_n;
  const double d1 = (relevel - start).head<2>().norm();
  const double d2 = (now - relevel).head<2>().norm();
  ASSERT_GT(d1, 0.5);  // about 1 m
  ASSERT_GT(d2, 0.5);  // about 1.25 m
  // Not in line (0.93 here: the fixes reset the velocity north while the acceleration is
  // integrated along the wrong heading before the re-level), or the two bounds would be one.
  ASSERT_LT((now - start).head<2>().norm(), 0.97 * (d1 + d2)) << "the legs are not in line";
  const Eigen::Matrix2d before_fix = p_pp();
  const HeadingFix<double> heading{r.nav.state().t_ns, 0.0, 0.01};
  ASSERT_EQ(r.filter.update_heading(r.nav, heading).status, UpdateStatus::kReset);
  const Eigen::Matrix2d after_fix = p_pp();
  const double legs = 1.5 * (d1 + d2) * (d1 + d2);
  for (int i = 0; i < 2; ++i) {
    EXPECT_NEAR(after_fix(i, i) - before_fix(i, i), legs, 1e-9 * after_fix(i, i)) << "axis " << i;
  }
}

// Lever arm of 1 m (0.6 m forward, 0.8 m up: the up part offsets the height by 0.8 m whatever the
// heading) and 100 ms latency (1 m along track at 10 m/s). Modelled, the errors stay within 3σ
// (≥ 95 % of the epoch-axis pairs after the first 10 s; for a consistent filter the expected
// fraction is 99.7 %); with the lever arm ignored the height error sits near 0.8 m against a σ of
// a few decimetres and the check fails, as it does with the latency ignored.
constexpr double kWithinFraction = 0.95;
constexpr double kSettleS = 10;

TEST(ErrorStateFilterTest, LeverArmAndLatencyAreHandled) {
  RunSpec spec = gnss_spec();
  spec.lever_true_b = Vec3<double>(0.6, 0.0, -0.8);
  spec.lever_filter_b = spec.lever_true_b;
  spec.latency_s = 0.1;
  const auto good = testing::run_aided<double>(spec, testing::filter_config(spec));
  RunSpec no_lever = spec;
  no_lever.lever_filter_b = Vec3<double>::Zero();
  const auto bad_lever = testing::run_aided<double>(no_lever, testing::filter_config(no_lever));
  RunSpec no_latency = spec;
  no_latency.latency_known = false;
  const auto bad_latency =
      testing::run_aided<double>(no_latency, testing::filter_config(no_latency));
  const double f_good = fraction_within(good.epochs, 3, 3, 3.0, kSettleS);
  const double f_lever = fraction_within(bad_lever.epochs, 3, 3, 3.0, kSettleS);
  const double f_latency = fraction_within(bad_latency.epochs, 3, 3, 3.0, kSettleS);
  std::printf(
      "position within 3 sigma: modelled %.3f, lever arm ignored %.3f, latency ignored "
      "%.3f\n",
      f_good, f_lever, f_latency);
  EXPECT_GE(f_good, kWithinFraction);
  EXPECT_GE(fraction_within(good.epochs, 6, 3, 3.0, kSettleS), kWithinFraction);
  EXPECT_LT(f_lever, kWithinFraction);    // negative control
  EXPECT_LT(f_latency, kWithinFraction);  // negative control
}

// Heading unknown at start: before the track, heading σ is "not available" (π) and not valid;
// the first GNSS velocity above 3 m/s sets it from atan2(v_E, v_N) with σ = σ_v / speed.
TEST(ErrorStateFilterTest, HeadingFromTheGnssTrack) {
  RunSpec spec = gnss_spec();
  spec.duration_s = 20;
  spec.initial_error = false;
  auto config = testing::filter_config(spec);
  config.heading_known = false;
  // Start 1 rad off in heading: the truth is along the track.
  spec.truth = [](double t) { return testing::figure_eight(t, kRadiusM, kOmegaRps); };
  static ErrorStateFilter<double> filter;
  const auto solver = ArraySolver<double>::create(table1_geometry(0.1)).value();
  const auto gravity = GravityModel<double>::constant(testing::kG);
  Strapdown<double> nav(solver, gravity);
  const testing::Truth x0 = spec.truth(0);
  NavState<double> init = testing::nav_state_of<double>(x0);
  init.q_nb = quat_from_rotation_vector<double>(Vec3<double>(0, 0, 1.0)) * x0.q_nb;
  init.status = nav_status::kAligned;
  nav.initialize(init, testing::ideal_outputs(solver.geometry(), x0));
  ASSERT_TRUE(filter.configure(config).is_ok());
  filter.start(nav);
  EXPECT_FALSE(filter.heading_aligned());
  NavAccuracy<double> acc = filter.accuracy(nav.state());
  EXPECT_EQ(acc.valid & filter_valid::kHeading, 0);
  EXPECT_NEAR(acc.euler_sigma_rad(2), kPi, 1e-9);  // level: the yaw σ is φ_D's
  EXPECT_NE(acc.valid & filter_valid::kRollPitch, 0);
  // One propagation step and a GNSS velocity fix at 0.05 s.
  const double h = 0.005;
  for (int k = 1; k <= 10; ++k) {
    const testing::Truth x = spec.truth(k * h);
    nav.step(testing::ideal_outputs(solver.geometry(), x), h, std::llround(k * h * 1e9),
             static_cast<std::uint32_t>(k));
  }
  ASSERT_TRUE(filter.propagate(nav, 0.05).is_ok());
  const testing::Truth xv = spec.truth(0.05);
  GnssFix<double> vel;
  vel.t_valid_ns = nav.state().t_ns;
  vel.value_n = xv.v_n;
  vel.sigma = Vec3<double>::Constant(0.1);
  EXPECT_EQ(filter.update_gnss_velocity(nav, vel).status, UpdateStatus::kReset);
  EXPECT_TRUE(filter.heading_aligned());
  const double yaw_err =
      wrap_pi(euler_from_quat(nav.state().q_nb).z() - euler_from_quat(xv.q_nb).z());
  // Noise-free fix, ideal outputs: the yaw is the track to the integration error of 10 steps.
  constexpr double kYawTol = 1e-6;
  EXPECT_NEAR(yaw_err, 0.0, kYawTol);
  acc = filter.accuracy(nav.state());
  const double speed = xv.v_n.head<2>().norm();
  EXPECT_NEAR(acc.euler_sigma_rad(2), 0.1 / speed, 1e-9);
  EXPECT_NE(acc.valid & filter_valid::kHeading, 0);
  EXPECT_NE(acc.mode & filter_mode::kGnss, 0);
}

// ---- External heading with a time of validity ------------------------------------------------

// A tight figure eight (20 m, one per 10 s: 36°/s of yaw rate at its loops) on ideal outputs. The
// heading frame says the true yaw at 2.8 s and arrives at 3.0 s (age 0.2 s, as ExtHeadingAge
// carries it); the yaw turns by |ψ(3.0) − ψ(2.8)| in between, which the test computes from the
// truth. Compared with the filter's heading at its time of validity the fix is right; stamped
// with its arrival time (the age ignored) it is that many degrees off.
struct HeadingRun {
  UpdateOutcome outcome;
  double yaw_err_rad = 0;  // ψ̂ − ψ at 3.0 s, after the fix
  double turn_rad = 0;     // ψ(3.0) − ψ(2.8) of the truth
};

constexpr double kTv = 2.8, kNow = 3.0;  // the heading's time of validity, its arrival

// The run to kNow, then a heading fix saying the true yaw at kTv, stamped `stamped_s`.
HeadingRun heading_with_age(bool heading_known, double stamped_s) {
  constexpr double kR = 20, kW = 2 * kPi / 10, kRate = 200;
  constexpr int kDecimation = 10;  // propagation (and a history entry) at 20 Hz
  const auto truth = [](double t) { return testing::figure_eight(t, kR, kW); };
  static ErrorStateFilter<double> filter;
  const auto solver = ArraySolver<double>::create(table1_geometry(0.1)).value();
  Strapdown<double> nav(solver, GravityModel<double>::constant(testing::kG));
  RunSpec spec;
  spec.rate_hz = kRate;
  auto config = testing::filter_config(spec);
  config.heading_known = heading_known;
  const testing::Truth x0 = truth(0);
  NavState<double> init = testing::nav_state_of<double>(x0);
  if (!heading_known)
    init.q_nb = quat_from_rotation_vector<double>(Vec3<double>(0, 0, 1.0)) * x0.q_nb;
  init.status = nav_status::kAligned;
  nav.initialize(init, testing::ideal_outputs(solver.geometry(), x0));
  EXPECT_TRUE(filter.configure(config).is_ok());
  filter.start(nav);
  const long steps = std::lround(kNow * kRate);
  for (long k = 1; k <= steps; ++k) {
    const double t = static_cast<double>(k) / kRate;
    nav.step(testing::ideal_outputs(solver.geometry(), truth(t)), 1.0 / kRate,
             std::llround(t * 1e9), static_cast<std::uint32_t>(k));
    if (k % kDecimation == 0) {
      EXPECT_TRUE(filter.propagate(nav, kDecimation / kRate).is_ok());
    }
  }
  const double yaw_tv = euler_from_quat(truth(kTv).q_nb).z();
  const double yaw_now = euler_from_quat(truth(kNow).q_nb).z();
  HeadingFix<double> fix;
  fix.t_valid_ns = std::llround(stamped_s * 1e9);
  fix.yaw_rad = yaw_tv;
  fix.sigma_rad = 0.5 * kPi / 180;
  HeadingRun r;
  r.outcome = filter.update_heading(nav, fix);
  r.yaw_err_rad = wrap_pi(euler_from_quat(nav.state().q_nb).z() - yaw_now);
  r.turn_rad = wrap_pi(yaw_now - yaw_tv);
  return r;
}

TEST(ErrorStateFilterTest, ExternalHeadingIsComparedAtItsTimeOfValidity) {
  // Heading unknown: the fix sets it. With its age, to the interpolation error of the history
  // (slerp between 50 ms entries on ideal outputs: ~1e-4 rad, far below the turn); without,
  // off by the whole turn.
  const HeadingRun set = heading_with_age(false, kTv);
  const HeadingRun set_now = heading_with_age(false, kNow);
  std::printf("turn over the age %.2f deg; reset error with the age %.4f deg, without %.2f deg\n",
              set.turn_rad * 180 / kPi, set.yaw_err_rad * 180 / kPi,
              set_now.yaw_err_rad * 180 / kPi);
  ASSERT_GT(std::abs(set.turn_rad), 3 * kPi / 180) << "the test needs a turn during the age";
  EXPECT_EQ(set.outcome.status, UpdateStatus::kReset);
  constexpr double kInterpTol = 1e-3;  // rad; 17 times below the turn this test needs
  EXPECT_NEAR(set.yaw_err_rad, 0.0, kInterpTol);
  EXPECT_NEAR(set_now.yaw_err_rad, -set.turn_rad, kInterpTol);  // negative control
  // Heading known and right: the fix is an update through the χ² gate. With its age the
  // innovation is the interpolation error (NIS ≪ 1); stamped now it is the turn, over 6σ of
  // 0.5°: rejected by the gate (χ²₁ at the 0.999 gate is 10.8, the turn gives ≥ 36).
  const HeadingRun upd = heading_with_age(true, kTv);
  const HeadingRun upd_now = heading_with_age(true, kNow);
  EXPECT_EQ(upd.outcome.status, UpdateStatus::kAccepted);
  EXPECT_LT(upd.outcome.nis, 1.0F);
  EXPECT_EQ(upd_now.outcome.status, UpdateStatus::kRejected);
  // A fix older than the history (32 entries at 20 Hz: 1.55 s back) is refused, not applied.
  EXPECT_EQ(heading_with_age(true, kNow - 2.0).outcome.status, UpdateStatus::kInvalid);
}

// ---- Position σ while the heading is unknown ---------------------------------------------------

// A level straight drive written here: from rest at yaw 40°, 1 m/s² along the heading for 10 s
// (50 m, 10 m/s), then 10 m/s. The board starts with its heading 1 rad off (heading unknown,
// σ_ψ = π): it integrates the same accelerations along the wrong direction, so its displacement d
// is the true one turned by 1 rad and its position error is 2 sin(0.5) ≈ 0.96 |d| (240 m after
// 30 s). For a heading error δψ uniform on the circle the error (R(δψ) − I) d has, per axis,
// E e_N² = E(cos δψ − 1)² d_N² + E sin²δψ d_E² = 1.5 d_N² + 0.5 d_E² (and E e_E² alike): the
// published σ² must exceed the filter's own P_pp by at least that, and the filter adds 1.5 |d|²
// (the bound for any direction of d), so by at most that. The outputs are ideal and the filter is
// told so (sensor noise and bias 1e-6 m/s², initial tilt 1e-4 rad, velocity 0.01 m/s): P_pp
// alone then has a σ of about 55 m at 30 s (the accelerating phase through the linearised heading
// coupling), which would leave the 240 m error at over 4σ.
struct StraightDrive {
  static constexpr double kYaw = 40 * kPi / 180, kAccel = 1, kAccelS = 10;
  testing::Truth operator()(double t) const {
    testing::Truth x;
    x.q_nb = quat_from_rotation_vector<double>(Vec3<double>(0, 0, kYaw));
    const Vec3<double> u(std::cos(kYaw), std::sin(kYaw), 0);
    const double ta = std::min(t, kAccelS);
    const double speed = kAccel * ta;
    const double dist = 0.5 * kAccel * ta * ta + speed * (t - ta);
    x.a_n = t < kAccelS ? Vec3<double>(kAccel * u) : Vec3<double>::Zero();
    x.v_n = speed * u;
    x.r_n = dist * u;
    return x;
  }
};

struct HeadingUnknownDrive {
  static constexpr double kRate = 200;
  ErrorStateFilter<double> filter;
  ArraySolver<double> solver = ArraySolver<double>::create(table1_geometry(0.1)).value();
  Strapdown<double> nav{solver, GravityModel<double>::constant(testing::kG)};
  StraightDrive truth;
  long k = 0;

  HeadingUnknownDrive() {
    RunSpec spec;
    spec.rate_hz = kRate;
    spec.noise = 1e-6;
    spec.bias_sigma = 1e-6;
    spec.init_rate = 1e-6;
    spec.init_tilt = 1e-4;
    spec.init_vel = 0.01;
    auto config = testing::filter_config(spec);
    config.heading_known = false;
    config.track_min_speed_mps = 1e9;  // no heading from a GNSS track: fixes set it here
    NavState<double> init = testing::nav_state_of<double>(truth(0));
    init.q_nb = quat_from_rotation_vector<double>(Vec3<double>(0, 0, 1.0)) * init.q_nb;
    init.status = nav_status::kAligned;
    nav.initialize(init, testing::ideal_outputs(solver.geometry(), truth(0)));
    EXPECT_TRUE(filter.configure(config).is_ok());
    filter.start(nav);
  }

  double t() const { return static_cast<double>(k) / kRate; }

  void drive_to(double t_end) {
    while (t() < t_end - 0.5 / kRate) {
      ++k;
      nav.step(testing::ideal_outputs(solver.geometry(), truth(t())), 1.0 / kRate,
               std::llround(t() * 1e9), static_cast<std::uint32_t>(k));
      if (k % 10 == 0) {
        EXPECT_TRUE(filter.propagate(nav, 10 / kRate).is_ok());
      }
    }
  }

  Vec3<double> sigma2() const { return filter.accuracy(nav.state()).pos_sigma_m.array().square(); }
  Vec3<double> p_pp() const {
    return filter.covariance().block<3, 3>(filt_idx::kPos, filt_idx::kPos).diagonal();
  }
  Vec3<double> error() const { return nav.state().r_n - truth(t()).r_n; }

  /// The published σ² over P_pp against the bounds above, for the displacement from `anchor`.
  void expect_displacement_term(const Vec3<double>& anchor, const char* where) const {
    const Vec3<double> d = nav.state().r_n - anchor;
    const Vec3<double> extra = sigma2() - p_pp();
    const double uniform[2] = {1.5 * d.x() * d.x() + 0.5 * d.y() * d.y(),
                               0.5 * d.x() * d.x() + 1.5 * d.y() * d.y()};
    for (int i = 0; i < 2; ++i) {
      // 1e-9: the rounding of sqrt and square in double around σ² ~ 1e5 m².
      EXPECT_GE(extra(i), uniform[i] * (1 - 1e-9)) << where << ", axis " << i;
      EXPECT_LE(extra(i), 1.5 * d.head<2>().squaredNorm() * (1 + 1e-9)) << where << ", axis " << i;
    }
    // Covered as well: the actual error within 3σ per horizontal axis.
    const Vec3<double> s = sigma2().cwiseSqrt();
    EXPECT_LE(std::abs(error().x()) / s.x(), 3.0) << where;
    EXPECT_LE(std::abs(error().y()) / s.y(), 3.0) << where;
  }
};

TEST(ErrorStateFilterTest, PositionSigmaCoversTheDistanceDrivenWithTheHeadingUnknown) {
  // On the heap: the filter's matrices and history stay off the stack (a fresh one per test, so
  // --gtest_repeat finds the same start).
  const auto own = std::make_unique<HeadingUnknownDrive>();
  HeadingUnknownDrive& run = *own;
  run.drive_to(30);
  const double driven = run.truth(30).r_n.norm();
  std::printf(
      "after %.0f m with the heading 1 rad off: error %.1f m, σ N %.1f E %.1f m "
      "(P_pp alone: %.1f m)\n",
      driven, run.error().head<2>().norm(), std::sqrt(run.sigma2().x()),
      std::sqrt(run.sigma2().y()), std::sqrt(run.p_pp().x()));
  // The physics of the test, not of the filter: the displacement turned by 1 rad (ideal outputs;
  // 1 % for the strapdown's integration error).
  ASSERT_NEAR(run.error().head<2>().norm(), 2 * std::sin(0.5) * driven, 0.01 * driven);
  run.expect_displacement_term(run.truth(0).r_n, "heading unknown");
  EXPECT_EQ(run.filter.accuracy(run.nav.state()).valid & filter_valid::kPosition, 0);
  // A heading fix sets the heading but does not move the position: P_pp takes the term over, and
  // the published σ stays what it was (1e-9: rounding).
  const Vec3<double> before = run.sigma2();
  HeadingFix<double> fix;
  fix.t_valid_ns = run.nav.state().t_ns;
  fix.yaw_rad = StraightDrive::kYaw;
  fix.sigma_rad = 0.5 * kPi / 180;
  ASSERT_EQ(run.filter.update_heading(run.nav, fix).status, UpdateStatus::kReset);
  ASSERT_TRUE(run.filter.heading_aligned());
  for (int i = 0; i < 2; ++i) EXPECT_NEAR(run.sigma2()(i), before(i), 1e-9 * before(i));
  // And a σ of 300 m does not pass for a valid position (horizon valid_sigma_pos_m).
  EXPECT_EQ(run.filter.accuracy(run.nav.state()).valid & filter_valid::kPosition, 0);
}

TEST(ErrorStateFilterTest, AGnssPositionStartsTheDistanceDrivenWithTheHeadingUnknownAgain) {
  // A position fix at 20 s while the heading is unknown sets the position: only the displacement
  // after it (100 m at 10 m/s) turns with the heading error from then on, not the 250 m since the
  // start (which would give σ ≥ √1.5 × 250 m = 306 m per axis).
  const auto own = std::make_unique<HeadingUnknownDrive>();
  HeadingUnknownDrive& run = *own;
  run.drive_to(20);
  GnssFix<double> fix;
  fix.t_valid_ns = run.nav.state().t_ns;
  fix.value_n = run.truth(20).r_n;
  fix.sigma = Vec3<double>::Constant(1.0);
  ASSERT_EQ(run.filter.update_gnss_position(run.nav, fix).status, UpdateStatus::kReset);
  run.drive_to(30);
  const double since_fix = (run.truth(30).r_n - run.truth(20).r_n).norm();
  ASSERT_NEAR(run.error().head<2>().norm(), 2 * std::sin(0.5) * since_fix, 0.02 * since_fix);
  run.expect_displacement_term(fix.value_n, "after the position fix");
}

TEST(ErrorStateFilterTest, ARestartWithTheHeadingUnknownKeepsTheDistanceDriven) {
  // An in-motion start (lose_attitude: the same restart as a divergence) after 30 s driven with
  // the heading unknown moves the anchor to here; the 250 m driven so far keep their error, so a
  // heading fix right after the restart must put their 1.5 |d|² into P_pp (1e-9: rounding), as
  // it does without the restart.
  const auto own = std::make_unique<HeadingUnknownDrive>();
  HeadingUnknownDrive& run = *own;
  run.drive_to(30);
  const Vec3<double> d = run.nav.state().r_n - run.truth(0).r_n;
  run.filter.lose_attitude(run.nav);
  // The position is not published until a fix sets it (lost), and then from that fix on.
  EXPECT_TRUE(std::isnan(run.filter.accuracy(run.nav.state()).pos_sigma_m.x()));
  const Vec3<double> before = run.p_pp();
  const HeadingFix<double> heading{run.nav.state().t_ns, 0.0, 0.01};
  ASSERT_EQ(run.filter.update_heading(run.nav, heading).status, UpdateStatus::kReset);
  const Vec3<double> after = run.p_pp();
  for (int i = 0; i < 2; ++i) {
    EXPECT_NEAR(after(i) - before(i), 1.5 * d.head<2>().squaredNorm(), 1e-9 * after(i))
        << "axis " << i;
  }
}

// ---- Euler σ: the Jacobian against finite differences of the Euler angles -------------------

TEST(ErrorStateFilterTest, EulerJacobianMatchesFiniteDifferences) {
  const Quat<double> q = quat_from_euler(0.3, -0.4, 2.5);
  const Mat3<double> j = euler_error_jacobian(q);
  constexpr double kStep = 1e-6;
  constexpr double kTol = 1e-8;  // central differences: O(step²) plus rounding/step ≈ 1e-10
  for (int i = 0; i < 3; ++i) {
    Vec3<double> phi = Vec3<double>::Zero();
    phi(i) = kStep;
    // Ĉ = exp(−[φ×]) C (eq. (7)): the computed attitude for an error φ.
    const Vec3<double> ep =
        euler_from_quat(Quat<double>(quat_from_rotation_vector<double>(-phi) * q));
    const Vec3<double> em =
        euler_from_quat(Quat<double>(quat_from_rotation_vector<double>(phi) * q));
    const Vec3<double> col = (ep - em) / (2 * kStep);
    EXPECT_NEAR((col - j.col(i)).norm(), 0.0, kTol) << i;
  }
}

// Why the Joseph form (docs/math.md): in float32 a measurement far more precise than the state
// makes the gain 1 to the last bit, and the short form (I − KH) P then leaves a variance of 0
// (floored to 1e-14: a σ of 1e-7 m/s claimed after a 1e-4 m/s measurement), where (I − KH) P
// (I − KH)ᵀ + K R Kᵀ keeps K R Kᵀ = R. Oracle: a velocity uncorrelated with every other state
// (the initial covariance is diagonal in it) takes a ZUPT of variance R to P R / (P + R) per
// axis, in double here. Bound 1 %: float rounding of the Joseph terms is about 1e-7 relative;
// the short form computed in float below is off by 4.6 % (R = 1e-6) and 100 % (R = 1e-8).
TEST(ErrorStateFilterTest, APreciseUpdateInFloatLeavesTheVarianceTheFormulaGives) {
  static ErrorStateFilter<float> filter;
  const auto solver = ArraySolver<float>::create(table1_geometry(0.1F)).value();
  const auto solver_d = ArraySolver<double>::create(table1_geometry(0.1)).value();
  const testing::Truth truth = testing::rest(Quat<double>::Identity());
  for (const double r : {1e-6, 1e-8}) {
    Strapdown<float> nav(solver, GravityModel<float>::constant(static_cast<float>(testing::kG)));
    nav.initialize(testing::nav_state_of<float>(truth),
                   testing::ideal_outputs(solver_d.geometry(), truth).cast<float>());
    FilterConfig<float> c;
    c.init_sigma_vel_mps = 1.0F;
    c.zupt_sigma_mps = static_cast<float>(std::sqrt(r));
    ASSERT_TRUE(filter.configure(c).is_ok());
    filter.start(nav);
    const double p = 1.0;
    const double exact = p * r / (p + r);
    ASSERT_EQ(filter.update_zupt(nav).status, UpdateStatus::kAccepted) << "R " << r;
    for (int i = 0; i < 3; ++i) {
      const auto got =
          static_cast<double>(filter.covariance()(filt_idx::kVel + i, filt_idx::kVel + i));
      EXPECT_NEAR(got / exact, 1.0, 0.01) << "R " << r << ", axis " << i;
    }
    EXPECT_EQ(filter.counters().covariance_resets, 0U);
    // The short form in float on the same numbers is outside the bound: the bound can fail.
    const float pf = 1.0F;
    const auto rf = static_cast<float>(r);
    const float k = pf / (pf + rf);
    const float short_form = (1.0F - k) * pf;
    EXPECT_GT(std::abs(static_cast<double>(short_form) / exact - 1.0), 0.01) << "R " << r;
  }
}

TEST(ErrorStateFilterTest, RefusesBadConfigurationAndUpdatesBeforeStart) {
  static ErrorStateFilter<float> filter;
  const auto solver = ArraySolver<float>::create(table1_geometry(0.1F)).value();
  FilterConfig<float> c;
  c.gate_probability = 1.0F;
  EXPECT_FALSE(filter.configure(c).is_ok());
  Strapdown<float> nav(solver, GravityModel<float>{});
  EXPECT_EQ(filter.update_zupt(nav).status, UpdateStatus::kInvalid);
  EXPECT_FALSE(filter.propagate(nav, 0.05F).is_ok());
}

}  // namespace
}  // namespace gfins::nav
