// The linear error model (paper §3, eqs. (7)-(13), error_model.hpp) against the nonlinear
// navigation: one bias on one sensor, noise off. The difference between the perturbed and the
// clean strapdown runs must equal the propagated error x_k = Φ x_{k−1} + input to first order,
// for each state block (φ, δr, δv, δω).
//
// How the tolerance is derived. Write the navigation difference for a bias b as
// Δ(b) = L b + Q b² + O(b³). Running ±b splits it: the even part (Δ(b) + Δ(−b))/2 = Q b² + O(b⁴)
// measures the second-order term, the odd part (Δ(b) − Δ(−b))/2 = L b + O(b³) the first-order
// one. So (1) the linear model must match the odd part to the third-order term plus its own
// discretisation error, and (2) the full difference must match the linear model within the
// measured second-order term (plus the same small allowance).
#include <gtest/gtest.h>

#include <cstdio>
#include <memory>

#include "gfins/host_sim/array_model.hpp"
#include "gfins/host_sim/covariance.hpp"
#include "gfins/host_sim/trajectory.hpp"
#include "gfins/nav_core/error_model.hpp"
#include "gfins/nav_core/integrator.hpp"

namespace gfins::nav {
namespace {

using Model = ErrorModel<double, 6>;
using Vec6d = Vec6<double>;

constexpr double kRhoM = 0.1;
constexpr double kDtS = 1e-3;
constexpr double kDurationS = 2.0;
constexpr int kSensor = 0;          // sensor 1 of Table 1
constexpr double kBiasMps2 = 2e-3;  // ≈ 200 µg: |φ| ≈ 1e-2 rad after 2 s at ρ = 0.1 m

// (1) odd part vs linear model: the third-order term is |φ|² ≈ 1e-4 of the first-order one,
// and the model's discretisation differs from the integrator's by O(h²) per unit time
// (both second order, h = 1 ms): 1e-3 relative covers both with a margin of about 10.
constexpr double kOddRelTol = 1e-3;
// (2) full difference vs linear model: the residual is the second-order term itself plus the
// allowance of (1); a factor 1.2 on the measured term leaves room for the O(b³) part.
constexpr double kSecondOrderMargin = 1.2;
// For the test to be able to fail, the linear part must dominate the allowance: the measured
// second-order term must be below 10 % of it (the linearisation is then meaningful).
constexpr double kMaxNonlinearFraction = 0.1;

struct Errors {
  Vec3<double> phi, dr, dv, dw;
};

NavState<double> initial_state(const sim::TruthState& x) { return sim::to_nav_state<double>(x); }

/// Runs the strapdown over the trajectory with bias_mps2 added to sensor kSensor and returns the
/// navigation states at every sample.
std::vector<NavState<double>> run(const sim::Trajectory& traj,
                                  const ArrayGeometry<double, 6>& geometry, double bias_mps2) {
  const auto gravity = GravityModel<double>::constant(kStandardGravity);
  const sim::IdealArrayModel<6> array(geometry, gravity);
  Strapdown<double> nav(ArraySolver<double>::create(geometry).value(), gravity);
  const auto outputs = [&](double t) {
    Vec6d s = array.outputs(traj.at(t));
    s(kSensor) += bias_mps2;
    return s;
  };
  nav.initialize(initial_state(traj.at(0.0)), outputs(0.0));
  std::vector<NavState<double>> out{nav.state()};
  const auto steps = static_cast<long>(std::llround(kDurationS / kDtS));
  for (long k = 1; k <= steps; ++k) {
    const double t = static_cast<double>(k) * kDtS;
    nav.step(outputs(t), kDtS, static_cast<std::int64_t>(t * 1e9), static_cast<std::uint32_t>(k));
    out.push_back(nav.state());
  }
  return out;
}

Errors difference(const NavState<double>& a, const NavState<double>& clean) {
  return {attitude_error_n(a.q_nb, clean.q_nb), a.r_n - clean.r_n, a.v_n - clean.v_n,
          a.w_b - clean.w_b};
}

/// The linear model's error after kDurationS for the constant δs = bias e_kSensor.
Errors linear(const sim::Trajectory& traj, const ArrayGeometry<double, 6>& geometry,
              double bias_mps2) {
  const auto gravity = GravityModel<double>::constant(kStandardGravity);
  const Model model(ArraySolver<double>::create(geometry).value(), gravity);
  Vec6d ds = Vec6d::Zero();
  ds(kSensor) = bias_mps2;
  Model::StateVec x = Model::StateVec::Zero();
  NavState<double> x0 = sim::truth_nav_state(traj.at(0.0), gravity);
  const auto steps = static_cast<long>(std::llround(kDurationS / kDtS));
  for (long k = 1; k <= steps; ++k) {
    const NavState<double> x1 =
        sim::truth_nav_state(traj.at(static_cast<double>(k) * kDtS), gravity);
    EXPECT_TRUE(model.propagate(x0, x1, kDtS, ds, ds, x).is_ok());
    x0 = x1;
  }
  return {x.segment<3>(err_idx::kPhi), x.segment<3>(err_idx::kPos), x.segment<3>(err_idx::kVel),
          x.segment<3>(err_idx::kRate)};
}

struct Case {
  Errors lin, plus, odd, even;
};

Case make_case(const sim::Trajectory& traj,
               const ArrayGeometry<double, 6>& geometry = table1_geometry<double>(kRhoM)) {
  const auto clean = run(traj, geometry, 0.0);
  const auto plus = run(traj, geometry, kBiasMps2);
  const auto minus = run(traj, geometry, -kBiasMps2);
  const Errors p = difference(plus.back(), clean.back());
  const Errors m = difference(minus.back(), clean.back());
  Case c;
  c.lin = linear(traj, geometry, kBiasMps2);
  c.plus = p;
  c.odd = {(p.phi - m.phi) / 2, (p.dr - m.dr) / 2, (p.dv - m.dv) / 2, (p.dw - m.dw) / 2};
  c.even = {(p.phi + m.phi) / 2, (p.dr + m.dr) / 2, (p.dv + m.dv) / 2, (p.dw + m.dw) / 2};
  return c;
}

void expect_first_order(const char* what, const Vec3<double>& lin, const Vec3<double>& plus,
                        const Vec3<double>& odd, const Vec3<double>& even) {
  std::printf(
      "%-4s |linear| %.4e  |odd - linear| %.3e  |second order| %.3e  |full - linear| %.3e\n", what,
      lin.norm(), (odd - lin).norm(), even.norm(), (plus - lin).norm());
  // Given a measurable linear response, when the bias is injected, then:
  ASSERT_GT(lin.norm(), 0.0) << what;
  EXPECT_LT(even.norm(), kMaxNonlinearFraction * lin.norm()) << what;
  EXPECT_LT((odd - lin).norm(), kOddRelTol * lin.norm()) << what;
  EXPECT_LT((plus - lin).norm(), kSecondOrderMargin * even.norm() + kOddRelTol * lin.norm())
      << what;
}

class ErrorModelFirstOrderTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    // A 6-DoF manoeuvre exercises every block of F: the specific-force coupling (C f)×φ, the
    // centripetal term K J(ω) δω of eq. (12) and the rotating C_b^n.
    const auto traj = sim::make_maneuver(1.0);
    moving_ = std::make_unique<Case>(make_case(*traj));
    const auto rest = sim::make_rest(quat_from_euler(0.1, -0.05, 0.3));
    rest_ = std::make_unique<Case>(make_case(*rest));
    // An asymmetric array (sensors moved off the cube by a few cm): K_w ≠ 0, so ω̇ depends on ω
    // and the rate error couples to itself through −K_w J(ω) δω of the generalised eq. (13).
    auto skewed = table1_geometry<double>(kRhoM);
    skewed.rho_b[0] += Vec3<double>(0.03, 0.0, 0.0);
    skewed.rho_b[2] += Vec3<double>(0.0, 0.02, 0.01);
    skewed.rho_b[4] += Vec3<double>(-0.02, 0.0, 0.03);
    general_ = std::make_unique<Case>(make_case(*traj, skewed));
  }
  static void TearDownTestSuite() {
    moving_.reset();
    rest_.reset();
    general_.reset();
  }
  static std::unique_ptr<Case> moving_;
  static std::unique_ptr<Case> rest_;
  static std::unique_ptr<Case> general_;
};
std::unique_ptr<Case> ErrorModelFirstOrderTest::moving_;
std::unique_ptr<Case> ErrorModelFirstOrderTest::rest_;
std::unique_ptr<Case> ErrorModelFirstOrderTest::general_;

TEST_F(ErrorModelFirstOrderTest, AttitudeErrorMatchesToFirstOrder) {
  expect_first_order("phi", moving_->lin.phi, moving_->plus.phi, moving_->odd.phi,
                     moving_->even.phi);
  expect_first_order("phi", rest_->lin.phi, rest_->plus.phi, rest_->odd.phi, rest_->even.phi);
  expect_first_order("phi", general_->lin.phi, general_->plus.phi, general_->odd.phi,
                     general_->even.phi);
}

TEST_F(ErrorModelFirstOrderTest, PositionErrorMatchesToFirstOrder) {
  expect_first_order("dr", moving_->lin.dr, moving_->plus.dr, moving_->odd.dr, moving_->even.dr);
  expect_first_order("dr", rest_->lin.dr, rest_->plus.dr, rest_->odd.dr, rest_->even.dr);
  expect_first_order("dr", general_->lin.dr, general_->plus.dr, general_->odd.dr,
                     general_->even.dr);
}

TEST_F(ErrorModelFirstOrderTest, VelocityErrorMatchesToFirstOrder) {
  expect_first_order("dv", moving_->lin.dv, moving_->plus.dv, moving_->odd.dv, moving_->even.dv);
  expect_first_order("dv", rest_->lin.dv, rest_->plus.dv, rest_->odd.dv, rest_->even.dv);
  expect_first_order("dv", general_->lin.dv, general_->plus.dv, general_->odd.dv,
                     general_->even.dv);
}

TEST_F(ErrorModelFirstOrderTest, RateErrorMatchesToFirstOrder) {
  expect_first_order("dw", moving_->lin.dw, moving_->plus.dw, moving_->odd.dw, moving_->even.dw);
  expect_first_order("dw", rest_->lin.dw, rest_->plus.dw, rest_->odd.dw, rest_->even.dw);
  expect_first_order("dw", general_->lin.dw, general_->plus.dw, general_->odd.dw,
                     general_->even.dw);
}

// The Table 1 solver has K_w = 0 and K_f J δω = −ρ δω² (eq. (11)/(12) with the ρ factor the
// paper drops): the generalised F must reproduce that block exactly.
TEST(ErrorModelTest, CentripetalBlockIsRhoTimesDeltaOmegaSquaredOfEq12) {
  const auto geometry = table1_geometry<double>(kRhoM);
  const Model model(ArraySolver<double>::create(geometry).value(),
                    GravityModel<double>::constant(kStandardGravity));
  NavState<double> x;  // identity attitude, so C_b^n = I
  x.w_b = Vec3<double>(0.3, -0.7, 1.1);
  const Model::StateMat f = model.continuous(x);
  const Vec3<double> dw(1e-3, 2e-3, -1.5e-3);
  const Vec3<double> w = x.w_b;
  // δω² of eq. (11); the velocity equation (5) has +ρ ω², so δf = +ρ δω².
  const Vec3<double> dw2(w.y() * dw.z() + w.z() * dw.y(), w.x() * dw.z() + w.z() * dw.x(),
                         w.x() * dw.y() + w.y() * dw.x());
  constexpr double kRoundingTol = 1e-14;  // a few ulps of products of O(1) numbers
  const Mat3<double> f_vel_rate = f.block<3, 3>(err_idx::kVel, err_idx::kRate);
  const Mat3<double> f_rate_rate = f.block<3, 3>(err_idx::kRate, err_idx::kRate);
  EXPECT_LT((f_vel_rate * dw - kRhoM * dw2).norm(), kRoundingTol);
  EXPECT_LT(f_rate_rate.norm(), kRoundingTol);
}

// The equivalent output errors of the deterministic sources against the array model: a sensor
// moved by Δρ, tilted by δθ (the array model uses θ as given, eq. (23)) or with gain 1 + ε. The
// rigid-body output is linear in ρ_j, θ_j and the gain, so the first-order δs is exact.
TEST(ErrorModelTest, EquivalentOutputErrorsMatchThePerturbedArray) {
  const auto nominal = table1_geometry<double>(kRhoM);
  const auto gravity = GravityModel<double>::constant(kStandardGravity);
  const auto traj = sim::make_maneuver(1.0);
  const sim::TruthState truth = traj->at(1.3);  // rotating and accelerating
  const NavState<double> x = sim::truth_nav_state(truth, gravity);
  const sim::IdealArrayModel<6> ideal(nominal, gravity);
  const Vec6d s0 = ideal.outputs(truth);
  constexpr int kJ = 2;
  constexpr double kRoundingTol = 1e-12;  // m/s², rounding of outputs of ~10 m/s²

  auto moved = nominal;
  const Vec3<double> drho(1e-3, -2e-3, 0.5e-3);
  moved.rho_b[kJ] += drho;
  const Vec6d ds_loc = sim::IdealArrayModel<6>(moved, gravity).outputs(truth) - s0;
  EXPECT_LT((location_ds<double, 6>(x, nominal, kJ, drho) - ds_loc).norm(), kRoundingTol);
  EXPECT_GT(ds_loc.norm(), 1e3 * kRoundingTol);  // the motion makes it observable

  auto tilted = nominal;
  const Vec3<double> dtheta = nominal.theta_b[kJ].cross(Vec3<double>::UnitX()) * 1e-3;
  tilted.theta_b[kJ] += dtheta;
  const Vec6d ds_ori = sim::IdealArrayModel<6>(tilted, gravity).outputs(truth) - s0;
  EXPECT_LT((orientation_ds<double, 6>(x, nominal, kJ, dtheta) - ds_ori).norm(), kRoundingTol);
  EXPECT_GT(ds_ori.norm(), 1e3 * kRoundingTol);

  constexpr double kEps = 1e-4;
  Vec6d ds_sf = Vec6d::Zero();
  ds_sf(kJ) = kEps * s0(kJ);
  EXPECT_LT((scale_factor_ds<double, 6>(x, nominal, kJ, kEps) - ds_sf).norm(), kRoundingTol);
}

TEST(ErrorModelTest, RefusesNonPositiveStep) {
  const auto geometry = table1_geometry<double>(kRhoM);
  const Model model(ArraySolver<double>::create(geometry).value(),
                    GravityModel<double>::constant(kStandardGravity));
  const NavState<double> x;
  EXPECT_FALSE(model.transition(x, x, 0.0).is_ok());
  Model::StateMat p = Model::StateMat::Zero();
  EXPECT_FALSE(model.propagate_covariance(x, x, {}, -1e-3, p).is_ok());
}

// Float instantiation compiles and agrees with double (templates usable with float).
TEST(ErrorModelTest, FloatAgreesWithDouble) {
  const auto gd = table1_geometry<double>(kRhoM);
  const ErrorModel<float, 6> mf(ArraySolver<float>::create(gd.cast<float>()).value(),
                                GravityModel<float>::constant(9.80665f));
  const Model md(ArraySolver<double>::create(gd).value(),
                 GravityModel<double>::constant(kStandardGravity));
  NavState<double> x;
  x.q_nb = quat_from_euler(0.2, 0.1, -0.4);
  x.w_b = Vec3<double>(0.5, -0.2, 0.8);
  x.f_b = Vec3<double>(0.3, 0.1, -9.8);
  const auto pf = mf.transition(x.cast<float>(), x.cast<float>(), 1e-3f);
  const auto pd = md.transition(x, x, 1e-3);
  ASSERT_TRUE(pf.is_ok() && pd.is_ok());
  constexpr double kFloatTol = 1e-5;  // float32 epsilon 1.2e-7 times entries up to ~30 (M)
  EXPECT_LT((pf.value().cast<double>() - pd.value()).cwiseAbs().maxCoeff(), kFloatTol);

  // And the covariance of a noisy bias over 100 steps: float keeps 1e-4 relative.
  SensorNoiseSpec<float, 6> nf;
  SensorNoiseSpec<double, 6> nd;
  nf.white_sigma_mps2.fill(1e-2f);
  nd.white_sigma_mps2.fill(1e-2);
  nf.bias_sigma_mps2[0] = 1e-3f;
  nd.bias_sigma_mps2[0] = 1e-3;
  auto p_f = ErrorModel<float, 6>::initial_covariance(nf);
  auto p_d = Model::initial_covariance(nd);
  for (int k = 0; k < 100; ++k) {
    ASSERT_TRUE(mf.propagate_covariance(x.cast<float>(), x.cast<float>(), nf, 1e-2f, p_f).is_ok());
    ASSERT_TRUE(md.propagate_covariance(x, x, nd, 1e-2, p_d).is_ok());
  }
  constexpr double kFloatCovRelTol = 1e-4;  // 100 steps of float rounding (1.2e-7 each, ×~30)
  for (int i = 0; i < err_idx::kNav; ++i) {
    EXPECT_NEAR(static_cast<double>(p_f(i, i)) / p_d(i, i), 1.0, kFloatCovRelTol) << i;
  }
}

}  // namespace
}  // namespace gfins::nav
