// A board powering up on a moving vehicle (docs/math.md, "In-motion alignment"), written here
// independently of the code under test: a level figure-eight drive (filter_truth.hpp) seen by a
// board mounted on the vehicle with a tilt (roll 2°, pitch −3°), the array's forward physics with
// white noise and a constant bias per sensor, the counts a converter would deliver, and a GNSS
// receiver of stated accuracy (0.05 m/s, 1 m per axis, 5 Hz) whose fixes arrive 100 ms after
// their time of validity, with the antenna at the array or at a lever arm l from it (the fixes
// then the antenna's: position r + C l, velocity v + C (ω × l)).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>

#include "gfins/nav_core/pipeline.hpp"
#include "nav_core/filter_truth.hpp"

namespace gfins::nav::testing {

inline constexpr double kDriveRateHz = 1000.0;
// Figure eight: speed 5.3-10.6 m/s, turns up to 0.48 rad/s, up to 2.4 m/s² of acceleration.
inline constexpr double kDriveRadius = 50.0;
inline constexpr double kDriveOmega = 0.15;
inline constexpr double kDrivePeriodS = 2.0 * 3.14159265358979323846 / kDriveOmega;  // 41.9 s
inline constexpr double kGnssPeriodS = 0.2;
inline constexpr double kGnssLatencyS = 0.1;
inline constexpr double kGnssSigmaVel = 0.05;  // m/s per axis
inline constexpr double kGnssSigmaPos = 1.0;   // m per axis
inline constexpr double kArrayNoiseMps2 = 1e-3;
inline constexpr double kArrayBiasMps2 = 2e-4;
inline constexpr double kDeg = 3.14159265358979323846 / 180.0;

/// The board's truth: the vehicle's (level, heading along the track) turned by the mount.
/// t: time since power-up; t0: where on the figure eight the board powers up (s), its position
/// there the origin.
inline Truth board_truth(double t, double t0) {
  static const Quat<double> mount = quat_from_euler(2.0 * kDeg, -3.0 * kDeg, 0.0);
  Truth x = figure_eight(t + t0, kDriveRadius, kDriveOmega);
  x.r_n -= figure_eight(t0, kDriveRadius, kDriveOmega).r_n;
  x.q_nb = x.q_nb * mount;
  x.w_b = mount.conjugate() * x.w_b;
  x.wdot_b = mount.conjugate() * x.wdot_b;
  return x;
}

/// The navigation errors against the truth, and the σ the filter publishes for them.
struct DriveCheck {
  std::uint32_t sample = 0;  // index since power-up
  double t_s = 0;
  Vec3<double> euler_err_rad;  // roll, pitch, heading (wrapped)
  Vec3<double> vel_err_mps;
  Vec3<double> pos_err_m;
  NavAccuracy<double> accuracy;
};

class InMotionDrive {
 public:
  /// in_motion: PipelineConfig::align_in_motion; track_sigma_deg: the filter's
  /// track_heading_sigma_rad in degrees (0: not a vehicle, no heading from the track).
  /// t0: the power-up's place on the figure eight (board_truth). lever_b: the antenna from the
  /// array, body axes (m); the filter is told it.
  InMotionDrive(bool in_motion, unsigned seed, double t0, double track_sigma_deg = 0.5,
                const Vec3<double>& lever_b = Vec3<double>::Zero())
      : rng_(seed), t0_(t0), lever_b_(lever_b) {
    config_.front_end.volts_per_count.fill(10.0 / 8388608.0);
    config_.front_end.scale_v_per_g.fill(1.33);
    config_.gravity = GravityModel<double>::constant(kG);
    config_.align_in_motion = in_motion;
    AidingConfig<double>& a = config_.aiding;
    a.enabled = true;
    a.filter.noise.white_sigma_mps2.fill(kArrayNoiseMps2);
    a.filter.noise.bias_sigma_mps2.fill(kArrayBiasMps2);
    a.filter.heading_known = false;
    a.filter.track_heading_sigma_rad = track_sigma_deg * kDeg;
    a.filter.gnss_lever_arm_b = lever_b;
    a.standstill.white_sigma_mps2 = kArrayNoiseMps2;
    a.standstill.gravity_mps2 = kG;
    configured_ = pipeline_.configure(config_).is_ok();
    for (int j = 0; j < 6; ++j) bias_(j) = kArrayBiasMps2 * unit_(rng_);
  }

  bool configured() const { return configured_; }
  const NavPipeline<double>& pipeline() const { return pipeline_; }

  /// Samples k0..k1-1 with the fixes due; check(DriveCheck) at every `every`-th sample.
  template <typename Check>
  void run(std::uint32_t k0, std::uint32_t k1, std::uint32_t every, Check&& check) {
    const auto period = static_cast<std::uint32_t>(std::lround(kGnssPeriodS * kDriveRateHz));
    const auto lag = static_cast<std::uint32_t>(std::lround(kGnssLatencyS * kDriveRateHz));
    for (std::uint32_t k = k0; k < k1; ++k) {
      if (k >= lag && (k - lag) % period == 0) offer_fix((k - lag) / kDriveRateHz);
      pipeline_.process(sample(k));
      if (k % every == 0) check(compare(k));
    }
  }

 private:
  RawSample sample(std::uint32_t k) {
    const Vec6<double> s =
        ideal_outputs(pipeline_.solver().geometry(), board_truth(k / kDriveRateHz, t0_));
    RawSample r;
    for (int j = 0; j < 6; ++j) {
      const double v = s(j) + bias_(j) + kArrayNoiseMps2 * unit_(rng_);
      r.counts[static_cast<std::size_t>(j)] =
          static_cast<std::int32_t>(std::lround(pipeline_.front_end().counts_for(j, v)));
    }
    r.t_ns = static_cast<std::int64_t>(k) * 1'000'000;
    r.seq = k;
    return r;
  }

  // The fix valid at t_valid as the receiver reports it (noise of its stated σ).
  void offer_fix(double t_valid) {
    const Truth x = board_truth(t_valid, t0_);
    GnssFix<double> pos;
    pos.t_valid_ns = std::llround(t_valid * 1e9);
    pos.sigma.setConstant(kGnssSigmaPos);
    GnssFix<double> vel = pos;
    vel.sigma.setConstant(kGnssSigmaVel);
    // The antenna's position and velocity: a point of the rigid body at l.
    const Vec3<double> r_antenna = x.r_n + x.q_nb * lever_b_;
    const Vec3<double> v_antenna = x.v_n + x.q_nb * x.w_b.cross(lever_b_);
    for (int i = 0; i < 3; ++i) {
      pos.value_n(i) = r_antenna(i) + kGnssSigmaPos * unit_(rng_);
      vel.value_n(i) = v_antenna(i) + kGnssSigmaVel * unit_(rng_);
    }
    (void)pipeline_.offer_gnss_position(pos);
    (void)pipeline_.offer_gnss_velocity(vel);
  }

  DriveCheck compare(std::uint32_t k) const {
    const double t = k / kDriveRateHz;
    const Truth x = board_truth(t, t0_);
    const NavState<double>& e = pipeline_.state();
    DriveCheck c;
    c.sample = k;
    c.t_s = t;
    const Vec3<double> de = euler_from_quat(e.q_nb) - euler_from_quat(x.q_nb);
    for (int i = 0; i < 3; ++i) c.euler_err_rad(i) = std::remainder(de(i), 360.0 * kDeg);
    c.vel_err_mps = e.v_n - x.v_n;
    c.pos_err_m = e.r_n - x.r_n;
    c.accuracy = pipeline_.accuracy();
    return c;
  }

  PipelineConfig<double> config_;
  NavPipeline<double> pipeline_;
  std::mt19937 rng_;
  std::normal_distribution<double> unit_{0.0, 1.0};
  Vec6<double> bias_;
  double t0_;
  Vec3<double> lever_b_;
  bool configured_ = false;
};

}  // namespace gfins::nav::testing
