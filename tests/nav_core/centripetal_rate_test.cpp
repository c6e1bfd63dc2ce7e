// The angular rate from the centripetal terms (redundancy/centripetal_rate.hpp) against the
// Cramér–Rao bound computed here from the full Fisher information of (ω̇, f, ω) — a design matrix
// [H, Q D(ω)] built in this file from the rigid-body equation, inverted whole — and a Monte-Carlo
// of the estimator on outputs made by a forward model written here (paper eq. (22), errata in
// docs/paper-errata.md).
#include "gfins/nav_core/redundancy/centripetal_rate.hpp"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <cstdio>
#include <random>

#include "gfins/nav_core/redundancy/layouts.hpp"
#include "nav_core/array_forward.hpp"

namespace gfins::nav {
namespace {

constexpr double kRho = 0.1;
constexpr double kSigma = 5e-4;  // m/s² per sensor and sample

using test::forward;

// ∂s/∂(ω̇, f, ω) at ω: row j = [(ρ×θ)ᵀ, θᵀ, ∂/∂ω θ·(ω×(ω×ρ))], the last from
// θ·(ω×(ω×ρ)) = (θ·ω)(ρ·ω) − (θ·ρ)|ω|²: gradient (ρ·ω) θ + (θ·ω) ρ − 2 (θ·ρ) ω.
template <int N>
Eigen::Matrix<double, 3, 3> crb_full_fisher(const ArrayGeometry<double, N>& g,
                                            const Vec3<double>& w, double sigma) {
  Eigen::Matrix<double, N, 9> j;
  for (int k = 0; k < N; ++k) {
    const auto& rho = g.rho_b[static_cast<std::size_t>(k)];
    const auto& th = g.theta_b[static_cast<std::size_t>(k)];
    const Vec3<double> dw = rho.dot(w) * th + th.dot(w) * rho - 2.0 * th.dot(rho) * w;
    j.row(k) << rho.cross(th).transpose(), th.transpose(), dw.transpose();
  }
  const Eigen::Matrix<double, 9, 9> fisher = j.transpose() * j / (sigma * sigma);
  const Eigen::Matrix<double, 9, 9> inv = fisher.inverse();
  return inv.bottomRightCorner<3, 3>();
}

template <int N>
CentripetalRateEstimator<double, N> estimator_for(const ArrayGeometry<double, N>& g) {
  CentripetalRateEstimator<double, N> e;
  EXPECT_TRUE(e.configure(ArraySolver<double, N>::create(g).value(), kSigma).is_ok());
  return e;
}

TEST(CentripetalRateTest, BoundIsTheFullFisherInformationsOmegaBlock) {
  // Variable projection's JᵀJ/σ² is the Schur complement of the (ω̇, f) block of the full
  // information: equal to rounding (1e-9 relative in double).
  const Vec3<double> w(1.5, -2.0, 1.0);
  const auto g9 = three_triads<double>(kRho);
  const auto g12 = four_triads<double>(kRho);
  const Mat3<double> b9 = estimator_for<9>(g9).bound(w);
  const Mat3<double> b12 = estimator_for<12>(g12).bound(w);
  const Mat3<double> r9 = crb_full_fisher<9>(g9, w, kSigma);
  const Mat3<double> r12 = crb_full_fisher<12>(g12, w, kSigma);
  EXPECT_LT((b9 - r9).norm(), 1e-9 * r9.norm());
  EXPECT_LT((b12 - r12).norm(), 1e-9 * r12.norm());
  // The information grows with |ω|²: the bound at 2ω is a quarter of the bound at ω.
  const Mat3<double> r9_2 = crb_full_fisher<9>(g9, 2.0 * w, kSigma);
  EXPECT_LT((estimator_for<9>(g9).bound(2.0 * w) - r9_2).norm(), 1e-9 * r9_2.norm());
  EXPECT_NEAR(r9_2.trace(), r9.trace() / 4.0, 1e-9 * r9.trace());
}

Vec3<double> random_direction(std::mt19937_64& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  return Vec3<double>(n(rng), n(rng), n(rng)).normalized();
}

TEST(CentripetalRateTest, TwelveSensorEstimatesReachTheCramerRaoBound) {
  // 2000 single-sample estimates at |ω| = 2.7 rad/s in random directions, seeded 0.2 rad/s off
  // per axis. Their normalised squared errors eᵀ CRB⁻¹ e (CRB at each trial's ω, from the full
  // Fisher information above) average 3 (χ²(3)) for an efficient estimator; the mean of 2000 has
  // a standard deviation of √(6/2000) = 0.055, so [2.7, 3.3] is 5.5σ (a false failure below
  // 1e-7; the estimator's bias at this SNR, √trace(CRB)/|ω| below 1e-3, is far smaller). An
  // estimator that ignored the unknown ω̇ and f (no projection), had a wrong Jacobian or landed on
  // other roots would be far outside.
  const auto g = four_triads<double>(kRho);
  const Vec3<double> wdot(3.0, -1.0, 2.0);
  const Vec3<double> f(0.5, 0.2, -9.8);
  const auto est = estimator_for<12>(g);
  std::mt19937_64 rng(37);
  std::normal_distribution<double> noise(0.0, kSigma);
  std::normal_distribution<double> seed_err(0.0, 0.2);
  double nees = 0.0;
  constexpr int kTrials = 2000;
  for (int k = 0; k < kTrials; ++k) {
    const Vec3<double> w = 2.7 * random_direction(rng);
    Eigen::Matrix<double, 12, 1> s = forward<12>(g, wdot, f, w);
    for (int j = 0; j < 12; ++j) s(j) += noise(rng);
    const Vec3<double> seed_w = w + Vec3<double>(seed_err(rng), seed_err(rng), seed_err(rng));
    const CentripetalRate<double> r = est.estimate(s, seed_w);
    ASSERT_TRUE(r.converged) << k;
    ASSERT_TRUE(r.informative) << k;
    const Vec3<double> e = r.w_b - w;
    nees += e.dot(crb_full_fisher<12>(g, w, kSigma).inverse() * e);
  }
  nees /= kTrials;
  std::printf("N = 12: mean normalised squared error %.3f over %d estimates (3 = the bound)\n",
              nees, kTrials);
  EXPECT_GE(nees, 2.7);
  EXPECT_LE(nees, 3.3);
}

TEST(CentripetalRateTest, NineSensorsFitOtherRatesExactlyAndAreNeverCalledInformative) {
  // three_triads: nine equations, nine unknowns (ω̇, f, ω). Besides ±ω other rates fit the
  // outputs exactly, and Gauss–Newton from a seed 0.2 rad/s off lands on one for a few per cent
  // of directions (measured 1.85 %): over 500 random directions, some estimates are more than
  // 50 (normalised squared error) from the truth, which the residual cannot reveal. Expected
  // about 9; none happens with probability e^−9 ≈ 1e-4. So no nine-sensor estimate is called
  // informative.
  const auto g = three_triads<double>(kRho);
  const auto est = estimator_for<9>(g);
  std::mt19937_64 rng(53);
  std::normal_distribution<double> noise(0.0, kSigma);
  std::normal_distribution<double> seed_err(0.0, 0.2);
  int wrong_roots = 0;
  for (int k = 0; k < 500; ++k) {
    const Vec3<double> w = 2.7 * random_direction(rng);
    Eigen::Matrix<double, 9, 1> s =
        forward<9>(g, Vec3<double>(3, -1, 2), Vec3<double>(0.5, 0.2, -9.8), w);
    for (int j = 0; j < 9; ++j) s(j) += noise(rng);
    const auto r = est.estimate(s, w + Vec3<double>(seed_err(rng), seed_err(rng), seed_err(rng)));
    EXPECT_FALSE(r.informative) << k;
    const Mat3<double> crb = crb_full_fisher<9>(g, w, kSigma);
    const Vec3<double> e = r.w_b - w;
    if (r.converged && crb.allFinite() && e.dot(crb.inverse() * e) > 50.0) ++wrong_roots;
  }
  std::printf("nine sensors: %d of 500 estimates on another exact fit\n", wrong_roots);
  EXPECT_GE(wrong_roots, 1);
}

TEST(CentripetalRateTest, TheSeedChoosesBetweenOmegaAndMinusOmega) {
  // m(−ω) = m(ω): the outputs cannot tell; the estimate takes the seed's side.
  const auto g = four_triads<double>(kRho);
  const auto est = estimator_for<12>(g);
  const Vec3<double> w(0.0, 3.0, -1.0);
  const auto s = forward<12>(g, Vec3<double>::Zero(), Vec3<double>(0, 0, -9.8), w);
  const auto plus = est.estimate(s, Vec3<double>(0.2, 2.5, -1.2));
  const auto minus = est.estimate(s, Vec3<double>(-0.2, -2.5, 1.2));
  EXPECT_LT((plus.w_b - w).norm(), 1e-9);
  EXPECT_LT((minus.w_b + w).norm(), 1e-9);
}

TEST(CentripetalRateTest, SlowRotationCarriesNoInformationAndIsRefused) {
  // The bound's √trace at ω (from the full Fisher information above) against 0.1 |ω|: at
  // 0.027 rad/s it is about 0.2 rad/s per sample, at 2.7 rad/s about 2e-3: refused and accepted.
  const auto g = four_triads<double>(kRho);
  const auto est = estimator_for<12>(g);
  std::mt19937_64 rng(41);
  std::normal_distribution<double> noise(0.0, kSigma);
  for (const double scale : {0.0, 0.01, 1.0}) {
    const Vec3<double> w = Vec3<double>(1.5, -2.0, 1.0) * scale;
    Eigen::Matrix<double, 12, 1> s =
        forward<12>(g, Vec3<double>::Zero(), Vec3<double>(0, 0, -9.8), w);
    for (int j = 0; j < 12; ++j) s(j) += noise(rng);
    const auto r = est.estimate(s, w + Vec3<double>(0.01, 0.01, 0.01));
    const bool expected =
        scale > 0 && std::sqrt(crb_full_fisher<12>(g, w, kSigma).trace()) <= 0.1 * w.norm();
    EXPECT_EQ(r.informative, expected) << scale;
    EXPECT_EQ(r.informative, scale == 1.0) << scale;
  }
}

TEST(CentripetalRateTest, ARotationTheLayoutCannotSeeIsRefused) {
  // three_triads: all sensors lie in the plane of three vertices, and a rate along its normal
  // (1, 1, −1)/√3 has a singular full Fisher information (its condition number, computed here, is
  // beyond 1e12): the estimate must say not informative, whatever it converged to.
  const auto g = three_triads<double>(kRho);
  const auto est = estimator_for<9>(g);
  const Vec3<double> w = Vec3<double>(1.0, 1.0, -1.0).normalized() * 3.0;
  Eigen::Matrix<double, 9, 9> fisher;
  {
    Eigen::Matrix<double, 9, 9> j;
    for (int k = 0; k < 9; ++k) {
      const auto& rho = g.rho_b[static_cast<std::size_t>(k)];
      const auto& th = g.theta_b[static_cast<std::size_t>(k)];
      const Vec3<double> dw = rho.dot(w) * th + th.dot(w) * rho - 2.0 * th.dot(rho) * w;
      j.row(k) << rho.cross(th).transpose(), th.transpose(), dw.transpose();
    }
    fisher = j.transpose() * j;
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 9, 9>> eig(fisher);
  ASSERT_LT(eig.eigenvalues()(0), 1e-12 * eig.eigenvalues()(8));
  const auto s = forward<9>(g, Vec3<double>::Zero(), Vec3<double>(0, 0, -9.8), w);
  EXPECT_FALSE(est.estimate(s, w * 1.05).informative);
  // Table 1 with three corner sensors sees no rate at all: its full information is singular at
  // a generic ω where three_triads' is not (checked here).
  const auto t9 = table1_with_corners<double, 9>(kRho);
  CentripetalRateEstimator<double, 9> et;
  ASSERT_TRUE(et.configure(ArraySolver<double, 9>::create(t9).value(), kSigma).is_ok());
  const Vec3<double> generic(1.5, -2.0, 1.0);
  EXPECT_FALSE(
      et.estimate(forward<9>(t9, Vec3<double>::Zero(), Vec3<double>(0, 0, -9.8), generic), generic)
          .informative);
  EXPECT_TRUE(crb_full_fisher<9>(g, generic, kSigma).allFinite());
  EXPECT_GT(crb_full_fisher<9>(g, generic, kSigma).trace(), 0.0);
}

TEST(CentripetalRateTest, FewerThanNineSensorsAreRefused) {
  CentripetalRateEstimator<double, 8> e8;
  EXPECT_FALSE(
      e8.configure(ArraySolver<double, 8>::create(table1_with_corners<double, 8>(kRho)).value(),
                   kSigma)
          .is_ok());
  // Nine sensors with one excluded: eight active, refused too.
  CentripetalRateEstimator<double, 9> e9;
  const auto g9 = three_triads<double>(kRho);
  using Solver9 = ArraySolver<double, 9>;
  EXPECT_FALSE(e9.configure(Solver9::create_subset(g9, 100.0, 0x1FEU).value(), kSigma).is_ok());
  EXPECT_FALSE(e9.configure(Solver9::create(g9).value(), -1.0).is_ok());
}

TEST(CentripetalRateTest, FloatEstimateAgreesWithDouble) {
  // The board's scalar: outputs of ~10 m/s² in float carry ~1e-6 m/s² of rounding, 0.2 % of σ,
  // so the float estimate is within a few percent of the bound's σ of the double one.
  const auto g = four_triads<double>(kRho);
  CentripetalRateEstimator<float, 12> ef;
  ASSERT_TRUE(ef.configure(ArraySolver<float, 12>::create(g.cast<float>()).value(),
                           static_cast<float>(kSigma))
                  .is_ok());
  const auto ed = estimator_for<12>(g);
  const Vec3<double> w(1.5, -2.0, 1.0);
  std::mt19937_64 rng(43);
  std::normal_distribution<double> noise(0.0, kSigma);
  const double sigma_w = std::sqrt(crb_full_fisher<12>(g, w, kSigma).trace());
  for (int k = 0; k < 50; ++k) {
    Eigen::Matrix<double, 12, 1> s =
        forward<12>(g, Vec3<double>(1, 2, 3), Vec3<double>(0.3, 0, -9.8), w);
    for (int j = 0; j < 12; ++j) s(j) += noise(rng);
    const auto rd = ed.estimate(s, w);
    const auto rf = ef.estimate(s.cast<float>(), w.cast<float>());
    ASSERT_TRUE(rf.converged && rf.informative) << k;
    EXPECT_LT((rf.w_b.cast<double>() - rd.w_b).norm(), 0.05 * sigma_w) << k;
  }
}

}  // namespace
}  // namespace gfins::nav
