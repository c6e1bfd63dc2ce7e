// The statistics of `gfins-sim consistency` (consistency.hpp) against values that do not come
// from the code under test: printed χ² tables, binomial sums written out here, and NEES of
// errors chosen so that the answer is known by hand.
#include "gfins/host_sim/consistency.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace gfins::sim {
namespace {

using nav::filter_valid::kHeading;
using nav::filter_valid::kPosition;
using nav::filter_valid::kRollPitch;
using nav::filter_valid::kVelocity;
constexpr std::uint8_t kAll = kRollPitch | kHeading | kVelocity | kPosition;

// Printed tables (e.g. NIST/SEMATECH e-Handbook, "Critical values of the chi-square
// distribution", 5 significant figures). Wilson–Hilferty's relative error is below 2e-3 at 30
// degrees of freedom and below 2e-4 at 100 and beyond; a wrong z (1.645, the one-sided 95 %),
// a cube left out or the tails swapped are off by 5 % or more.
TEST(ConsistencyTest, ChiSquareQuantilesMatchPrintedTables) {
  struct Row {
    double dof, p, table;
  };
  for (const Row& r : {Row{30, 0.025, 16.791}, Row{30, 0.975, 46.979}, Row{100, 0.025, 74.222},
                       Row{100, 0.975, 129.561}, Row{100, 0.95, 124.342}, Row{100, 0.05, 77.929}}) {
    const double tol = r.dof < 100 ? 2e-3 : 2e-4;
    EXPECT_NEAR(chi_square_quantile(r.p, r.dof) / r.table, 1.0, tol)
        << "dof " << r.dof << " p " << r.p;
  }
  // 1 and 2 degrees of freedom (a group one or two runs published) are exact: the table's
  // 0.000982, 5.024, 0.0506, 7.378 (4 significant figures, so 1e-3 relative).
  for (const Row& r : {Row{1, 0.025, 0.000982}, Row{1, 0.975, 5.024}, Row{2, 0.025, 0.0506},
                       Row{2, 0.975, 7.378}}) {
    EXPECT_NEAR(chi_square_quantile(r.p, r.dof) / r.table, 1.0, 1e-3)
        << "dof " << r.dof << " p " << r.p;
  }
}

// The verdict: at most 10 % of the judged epochs outside, the event whose complement the
// printed false-failure probability measures.
TEST(ConsistencyTest, TheVerdictAllowsTenPercentOutside) {
  ConsistencySeries c;
  c.offered = 10;
  c.inside = 9;
  EXPECT_TRUE(c.pass());
  c.inside = 8;
  EXPECT_FALSE(c.pass());
  c.offered = 0;
  c.inside = 0;
  EXPECT_FALSE(c.pass());  // nothing judged is no pass
}

// P(X > k) summed from the probability mass written out here, and for Binomial(60, 0.05) the sum
// of comb(60, i) 0.05^i 0.95^(60-i) over i = 7..60 in exact integer binomials (Python's
// math.comb): 0.0296941019548833.
TEST(ConsistencyTest, BinomialUpperTailMatchesTheSumOfItsTerms) {
  EXPECT_NEAR(binomial_upper_tail(2, 0.5, 0), 0.75, 1e-12);
  EXPECT_NEAR(binomial_upper_tail(3, 0.1, 1), 3 * 0.01 * 0.9 + 0.001, 1e-12);
  EXPECT_NEAR(binomial_upper_tail(60, 0.05, 6), 0.0296941019548833, 1e-12);
  EXPECT_EQ(binomial_upper_tail(5, 0.3, 5), 0.0);
}

// Errors of exactly one σ in every published state give NEES = the number of states, whatever
// the σ; states not published are left out (a heading not yet aligned, a diverged velocity).
TEST(ConsistencyTest, NeesCountsOnlyThePublishedStates) {
  Eigen::Matrix<double, 9, 1> sigma;
  sigma << 1e-3, 2e-3, 5e-2, 1.5, 1.5, 3.0, 0.1, 0.1, 0.2;
  const Eigen::Matrix<double, 9, 9> p = sigma.cwiseAbs2().asDiagonal();
  ConsistencyRecorder rec(4, 0);
  EXPECT_EQ(rec.due(0.5), -1);
  ASSERT_EQ(rec.due(1.0), 0);
  rec.add_epoch(0, sigma, p, kAll);
  EXPECT_EQ(rec.due(1.5), -1);  // epoch 0 is done
  rec.add_epoch(1, 2 * sigma, p, kRollPitch | kVelocity);
  rec.add_epoch(2, sigma, p, 0);
  EXPECT_DOUBLE_EQ(rec.run().nees[0], 9.0);
  EXPECT_EQ(rec.run().dof[0], 9);
  EXPECT_DOUBLE_EQ(rec.run().nees[1], 4.0 * 5);  // 2σ in 2 tilt + 3 velocity states
  EXPECT_EQ(rec.run().dof[1], 5);
  EXPECT_TRUE(std::isnan(rec.run().nees[2]));  // nothing published
  EXPECT_TRUE(std::isnan(rec.run().nees[3]));  // never reached
}

// A correlated P: NEES is xᵀ P⁻¹ x, not Σ x²/σ². x along the eigenvector of the small eigenvalue
// of [[1, ρ], [ρ, 1]] (λ = 1 − ρ) gives |x|²/(1 − ρ); with ρ = 0.9 and x = (1, −1)/√2, 10.
TEST(ConsistencyTest, NeesUsesTheCrossCovariance) {
  Eigen::Matrix<double, 9, 9> p = Eigen::Matrix<double, 9, 9>::Identity();
  p(6, 7) = p(7, 6) = 0.9;
  Eigen::Matrix<double, 9, 1> x = Eigen::Matrix<double, 9, 1>::Zero();
  x(6) = 1 / std::sqrt(2.0);
  x(7) = -1 / std::sqrt(2.0);
  ConsistencyRecorder rec(1, 0);
  rec.add_epoch(0, x, p, kVelocity);
  EXPECT_NEAR(rec.run().nees[0], 10.0, 1e-12);
}

// The runs' sums over their degrees of freedom against the bounds of the total; a fix gated in
// one run and reset in the other counts one run.
TEST(ConsistencyTest, SummaryDividesTheSumsByTheDegreesOfFreedom) {
  ConsistencyRun a;
  a.nees = {9.0, 3.0};
  a.dof = {9, 3};
  a.nis_pos = {3.0, 6.0};
  a.nis_vel = {1.5, std::nan("")};
  ConsistencyRun b;
  b.nees = {9.0, std::nan("")};
  b.dof = {9, 0};
  b.nis_pos = {3.0, 0.3};
  b.nis_vel = {4.5, 3.0};
  for (ConsistencyRun* r : {&a, &b}) {
    for (std::size_t g = 0; g < kNeesGroups; ++g) {
      r->group_nees[g] = r->nees;
      r->group_dof[g] = r->dof;
    }
  }
  const ConsistencyResult r = summarize_consistency({a, b}, {0.2, 1.8}, 0.0);
  EXPECT_EQ(r.runs, 2u);
  ASSERT_EQ(r.nees.value.size(), 2u);
  EXPECT_DOUBLE_EQ(r.nees.value[0], 1.0);
  EXPECT_DOUBLE_EQ(r.nees.dof[0], 18.0);
  EXPECT_DOUBLE_EQ(r.nees.value[1], 1.0);
  EXPECT_DOUBLE_EQ(r.nees.dof[1], 3.0);
  EXPECT_DOUBLE_EQ(r.nis_pos.value[1], 6.3 / 6);
  EXPECT_DOUBLE_EQ(r.nis_vel.value[1], 1.0);
  EXPECT_DOUBLE_EQ(r.nis_vel.dof[1], 3.0);
  EXPECT_DOUBLE_EQ(r.nis_vel.value[0], 1.0);
  // χ²(18) 95 % bounds from the table: 8.231 and 31.526.
  EXPECT_NEAR(r.nees.lo[0] * 18, 8.231, 0.05);
  EXPECT_NEAR(r.nees.hi[0] * 18, 31.526, 0.05);
  EXPECT_EQ(r.nees.offered, 2u);
  EXPECT_EQ(r.nees.inside, 2u);
  // Judged from 1.5 s: epoch 1 (t = 2 s) and the second fix (t = 1.8 s) only.
  const ConsistencyResult late = summarize_consistency({a, b}, {0.2, 1.8}, 1.5);
  EXPECT_EQ(late.nees.offered, 1u);
  EXPECT_EQ(late.nis_pos.offered, 1u);
}

}  // namespace
}  // namespace gfins::sim
