// The strapdown's feedback entries (integrator.hpp): apply_correction removes an error
// x = estimate − truth exactly as eq. (7) defines φ, and set_bias removes the 6-D bias β = M b of
// per-sensor biases b from every step.
#include <gtest/gtest.h>

#include "gfins/nav_core/error_model.hpp"
#include "gfins/nav_core/integrator.hpp"
#include "nav_core/filter_truth.hpp"

namespace gfins::nav {
namespace {

constexpr double kRounding = 1e-12;  // double rounding of a handful of operations on O(1) values

TEST(StrapdownFeedbackTest, ApplyCorrectionRemovesTheError) {
  const auto solver = ArraySolver<double>::create(table1_geometry(0.1)).value();
  Strapdown<double> nav(solver, GravityModel<double>::constant(testing::kG));
  const testing::Truth x = testing::figure_eight(3.0, 100, 0.1);
  const Vec3<double> phi(0.02, -0.01, 0.3);
  const Vec3<double> dr(1.0, -2.0, 0.5), dv(0.1, 0.2, -0.3), dw(1e-3, -2e-3, 3e-3);
  NavState<double> est = testing::nav_state_of<double>(x);
  est.q_nb = quat_from_rotation_vector<double>(-phi) * x.q_nb;  // Ĉ = exp(−[φ×]) C
  est.r_n += dr;
  est.v_n += dv;
  est.w_b += dw;
  nav.initialize(est, testing::ideal_outputs(solver.geometry(), x));
  ASSERT_NEAR((attitude_error_n(nav.state().q_nb, x.q_nb) - phi).norm(), 0.0, kRounding);
  nav.apply_correction(phi, dr, dv, dw);
  EXPECT_NEAR(attitude_error_n(nav.state().q_nb, x.q_nb).norm(), 0.0, kRounding);
  EXPECT_NEAR((nav.state().r_n - x.r_n).norm(), 0.0, kRounding * 100);  // |r| ≈ 100 m
  EXPECT_NEAR((nav.state().v_n - x.v_n).norm(), 0.0, kRounding);
  EXPECT_NEAR((nav.state().w_b - x.w_b).norm(), 0.0, kRounding);
  // a = C f + g follows the corrected attitude.
  EXPECT_NEAR(
      (nav.state().a_n - (nav.state().q_nb * nav.state().f_b + Vec3<double>(0, 0, testing::kG)))
          .norm(),
      0.0, kRounding * 10);
}

// Biased outputs with set_bias(M b) integrate like unbiased ones: the same numbers up to the
// rounding of one subtraction per sample, accumulated over 2000 steps of 5 ms (at rest the
// velocity and position carry it as t and t²: 1e-9 m/s and 1e-8 m are 10⁴ ulp-scale margins).
TEST(StrapdownFeedbackTest, SetBiasRemovesTheArrayBias) {
  const auto geometry = table1_geometry(0.1);
  const auto solver = ArraySolver<double>::create(geometry).value();
  const auto gravity = GravityModel<double>::constant(testing::kG);
  Strapdown<double> clean(solver, gravity);
  Strapdown<double> biased(solver, gravity);
  Vec6<double> b;
  b << 1e-3, -2e-3, 3e-4, 5e-4, -1e-3, 2e-3;
  const Vec6<double> beta = solver.m() * b;
  const auto truth = [](double t) { return testing::figure_eight(t, 50, 0.2); };
  clean.initialize(testing::nav_state_of<double>(truth(0)),
                   testing::ideal_outputs(geometry, truth(0)));
  biased.initialize(testing::nav_state_of<double>(truth(0)),
                    testing::ideal_outputs(geometry, truth(0)) + b);
  biased.set_bias(beta.head<3>(), beta.tail<3>());
  for (int k = 1; k <= 2000; ++k) {
    const double t = k * 0.005;
    const Vec6<double> s = testing::ideal_outputs(geometry, truth(t));
    clean.step(s, 0.005, std::llround(t * 1e9), static_cast<std::uint32_t>(k));
    biased.step(s + b, 0.005, std::llround(t * 1e9), static_cast<std::uint32_t>(k));
  }
  EXPECT_LT(attitude_error_n(biased.state().q_nb, clean.state().q_nb).norm(), 1e-10);
  EXPECT_LT((biased.state().v_n - clean.state().v_n).norm(), 1e-9);
  EXPECT_LT((biased.state().r_n - clean.state().r_n).norm(), 1e-8);
  // Negative control: without set_bias the same bias moves the solution far beyond that.
  Strapdown<double> raw(solver, gravity);
  raw.initialize(testing::nav_state_of<double>(truth(0)),
                 testing::ideal_outputs(geometry, truth(0)) + b);
  for (int k = 1; k <= 2000; ++k) {
    const double t = k * 0.005;
    raw.step(testing::ideal_outputs(geometry, truth(t)) + b, 0.005, std::llround(t * 1e9),
             static_cast<std::uint32_t>(k));
  }
  EXPECT_GT((raw.state().v_n - clean.state().v_n).norm(), 1.0);
}

}  // namespace
}  // namespace gfins::nav
