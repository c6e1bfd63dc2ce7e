// The price of float32: the same noise-free 10 s manoeuvre through the float and the double
// instantiation of the same templates. The float32 error (float result − double result) must be
// below 1 % of the error that 1 milli-g of white noise per sensor causes over the same run.
#include <gtest/gtest.h>

#include <cstdio>

#include "nav_run.hpp"

namespace gfins::nav {
namespace {

using testing::RunOptions;

constexpr double kMilliG = 1e-3 * kStandardGravity;  // m/s², the paper's §6.3 noise level
constexpr double kMaxShare = 0.01;                   // the 1 %
constexpr int kNoiseSeeds = 4;                       // RMS over a few seeds, not one draw

struct Final {
  NavState<double> state;
  sim::TruthState truth;
};

template <typename T>
Final run(const sim::Trajectory& traj, const RunOptions& o) {
  // Same as testing::run_trajectory but keeps the final state to compare two runs directly.
  const auto geometry = table1_geometry<double>(o.rho_m);
  const sim::IdealArrayModel<6> model(geometry, GravityModel<double>::constant(kStandardGravity));
  const auto solver = ArraySolver<T>::create(geometry.template cast<T>()).value();
  Strapdown<T> nav(solver, GravityModel<T>::constant(static_cast<T>(kStandardGravity)));
  std::mt19937_64 rng(o.seed);
  std::normal_distribution<double> n01(0.0, 1.0);
  const auto outputs_at = [&](double t) {
    Vec6<double> s = model.outputs(traj.at(t));
    for (int j = 0; j < 6 && o.noise_mps2 > 0; ++j) s(j) += o.noise_mps2 * n01(rng);
    return Vec6<T>(s.template cast<T>());
  };
  nav.initialize(sim::to_nav_state<T>(traj.at(0)), outputs_at(0));
  const auto steps = static_cast<std::uint32_t>(std::llround(o.duration_s / o.dt_s));
  for (std::uint32_t k = 1; k <= steps; ++k) {
    nav.step(outputs_at(k * o.dt_s), static_cast<T>(o.dt_s), 0, k);
  }
  return {nav.state().template cast<double>(), traj.at(steps * o.dt_s)};
}

TEST(FloatVsDoubleTest, Float32ErrorIsBelowOnePercentOfMilliGNoiseError) {
  const auto traj = sim::make_maneuver(1.0);
  RunOptions o;
  o.duration_s = 10.0;
  o.dt_s = 1e-3;
  const Final ref = run<double>(*traj, o);
  const Final f32 = run<float>(*traj, o);
  const double att_f = ref.state.q_nb.angularDistance(f32.state.q_nb);
  const double vel_f = (ref.state.v_n - f32.state.v_n).norm();
  const double pos_f = (ref.state.r_n - f32.state.r_n).norm();

  double att_n = 0;
  double vel_n = 0;
  double pos_n = 0;
  for (int seed = 1; seed <= kNoiseSeeds; ++seed) {
    RunOptions on = o;
    on.noise_mps2 = kMilliG;
    on.seed = static_cast<unsigned>(seed);
    const Final noisy = run<double>(*traj, on);
    att_n += std::pow(ref.state.q_nb.angularDistance(noisy.state.q_nb), 2);
    vel_n += (ref.state.v_n - noisy.state.v_n).squaredNorm();
    pos_n += (ref.state.r_n - noisy.state.r_n).squaredNorm();
  }
  att_n = std::sqrt(att_n / kNoiseSeeds);
  vel_n = std::sqrt(vel_n / kNoiseSeeds);
  pos_n = std::sqrt(pos_n / kNoiseSeeds);
  std::printf(
      "10 s manoeuvre, 1 kHz, rho 0.1 m\n"
      "              float32 error    1 mg noise error (RMS of %d)   share\n"
      "attitude rad  %.3e        %.3e                      %.2e\n"
      "velocity m/s  %.3e        %.3e                      %.2e\n"
      "position m    %.3e        %.3e                      %.2e\n",
      kNoiseSeeds, att_f, att_n, att_f / att_n, vel_f, vel_n, vel_f / vel_n, pos_f, pos_n,
      pos_f / pos_n);
  ::testing::Test::RecordProperty("float32_position_error_m", std::to_string(pos_f));
  ::testing::Test::RecordProperty("noise_position_error_m", std::to_string(pos_n));
  EXPECT_LT(att_f, kMaxShare * att_n);
  EXPECT_LT(vel_f, kMaxShare * vel_n);
  EXPECT_LT(pos_f, kMaxShare * pos_n);
  // And float32 really differs from double (the comparison is not of a run with itself).
  EXPECT_GT(pos_f, 0.0);
}

}  // namespace
}  // namespace gfins::nav
