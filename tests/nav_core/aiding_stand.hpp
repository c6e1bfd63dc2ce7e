// A board standing still whose tilt may be lost (Aiding, filter/aiding.hpp), for the re-level at
// rest tests (aiding_rest_relevel_test.cpp, aiding_long_stop_long.cpp). The truth is written here:
// the board at rest at roll 5°, pitch −3°, heading 40°, the array's forward physics
// (filter_truth.hpp) with a constant bias per sensor and white noise.
#pragma once

#include <cmath>

#include "gfins/nav_core/filter/aiding.hpp"
#include "nav_core/filter_truth.hpp"

namespace gfins::nav::rest_stand {

constexpr double kRateHz = 1000.0;
constexpr double kDeg = 3.14159265358979323846 / 180.0;
constexpr double kNoise = 1e-3;  // white noise per sensor and sample, m/s² (about 0.1 mg)
constexpr double kBias = 2e-4;   // constant bias per sensor, 1σ, m/s² (about 20 µg)

struct Stand {
  ArraySolver<double> solver = ArraySolver<double>::create(table1_geometry(0.1)).value();
  Strapdown<double> nav{solver, GravityModel<double>::constant(testing::kG)};
  Aiding<double> aiding;
  testing::Truth truth = testing::rest(quat_from_euler(5.0 * kDeg, -3.0 * kDeg, 40.0 * kDeg));
  testing::SensorErrors errors;
  Vec6<double> ideal;

  // init_sigma_tilt_rad: the filter's initial tilt 1σ; lose: an in-motion start on top (the tilt
  // lost, whatever its σ).
  // wrong_roll_deg: the strapdown's roll at the start (the truth's is 5°); moving: the true
  // velocity is 30 m/s north (a straight drive at constant speed, which reads like rest), the
  // strapdown's too. bias_sigma: the sensors' constant bias 1σ, drawn per seed, and the filter's;
  // zaru_sigma_rps: the ZARU's σ (FilterConfig's default 1e-3).
  Stand(bool standstill_updates, unsigned seed, double init_sigma_tilt_rad = 0.01, bool lose = true,
        double wrong_roll_deg = 25.0, bool moving = false,
        const Vec3<double>& wrong_rate = Vec3<double>::Zero(), double bias_sigma = kBias,
        double zaru_sigma_rps = 1e-3)
      : errors(bias_sigma, kNoise, seed) {
    ideal = testing::ideal_outputs(solver.geometry(), truth);
    testing::Truth wrong = truth;
    wrong.q_nb = quat_from_euler(wrong_roll_deg * kDeg, 12.0 * kDeg, 40.0 * kDeg);
    // Lost: the velocity is anything (7 m/s); not lost, the filter's velocity is right.
    wrong.v_n = moving ? Vec3<double>(30.0, 0.0, 0.0)
                       : (lose ? Vec3<double>(7.0, -2.0, 0.5) : Vec3<double>::Zero());
    if (moving) truth.v_n = wrong.v_n;
    wrong.w_b = wrong_rate;
    NavState<double> s = testing::nav_state_of<double>(wrong);
    s.status |= nav_status::kAligned;
    nav.initialize(s, errors.apply(ideal));
    AidingConfig<double> c;
    c.enabled = true;
    c.standstill_updates = standstill_updates;
    c.filter.heading_known = !lose;
    c.filter.init_sigma_tilt_rad = init_sigma_tilt_rad;
    c.filter.init_sigma_vel_mps = 0.05;
    c.filter.noise.white_sigma_mps2.fill(kNoise);
    c.filter.noise.bias_sigma_mps2.fill(bias_sigma);
    c.filter.zaru_sigma_rps = zaru_sigma_rps;
    c.standstill.white_sigma_mps2 = kNoise;
    c.standstill.gravity_mps2 = testing::kG;
    EXPECT_TRUE(aiding.configure(solver, c).is_ok());
    aiding.start(nav);
    if (lose) aiding.lose_attitude(nav);
  }

  void run(int samples) {
    const double h = 1.0 / kRateHz;
    for (int k = 0; k < samples; ++k) {
      ++n_;
      nav.step(errors.apply(ideal), h, std::int64_t{n_} * 1'000'000,
               static_cast<std::uint32_t>(n_));
      aiding.after_step(nav, h);
    }
  }
  Vec3<double> euler_error() const {
    const Vec3<double> d = euler_from_quat(nav.state().q_nb) - euler_from_quat(truth.q_nb);
    return Vec3<double>(std::remainder(d(0), 2 * 180.0 * kDeg),
                        std::remainder(d(1), 2 * 180.0 * kDeg),
                        std::remainder(d(2), 2 * 180.0 * kDeg));
  }
  NavAccuracy<double> accuracy() const { return aiding.accuracy(nav.state()); }
  const FilterCounters& counters() const { return aiding.filter().counters(); }

 private:
  int n_ = 0;
};

}  // namespace gfins::nav::rest_stand
