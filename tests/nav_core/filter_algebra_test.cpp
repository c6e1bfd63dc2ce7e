// The covariance algebra of the error-state filter against the dense formulas written here:
// the propagation's block-sparse products (filter/block_sparse.hpp) and the Joseph update taken
// as rank-M corrections must give what the textbook products give, on a covariance whose every
// block is correlated (a spinning, accelerating board after GNSS updates), and the structural
// mask of F must cover every entry the process model can fill.
#include <gtest/gtest.h>

#include <cstdio>
#include <random>
#include <unsupported/Eigen/MatrixFunctions>

#include "gfins/nav_core/filter/error_state_filter.hpp"
#include "gfins/nav_core/filter/euler_error.hpp"
#include "gfins/nav_core/filter/zero_update.hpp"
#include "nav_core/filter_truth.hpp"

namespace gfins::nav {
namespace {

using Filter = ErrorStateFilter<double>;
using StateMat = Filter::StateMat;
constexpr int kN = filt_idx::kStates;

// A moving board: random attitude, rates up to 2 rad/s, angular accelerations up to 3 rad/s²,
// accelerations up to 5 m/s² on every axis (so every entry of F that the model can fill is
// filled: the centripetal Jacobian needs ω ≠ 0, the φ column of δv̇ needs f on all axes).
testing::Truth random_truth(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  testing::Truth x;
  x.q_nb = Quat<double>(u(rng), u(rng), u(rng), u(rng)).normalized();
  x.w_b = Vec3<double>(u(rng), u(rng), u(rng)) * 2.0;
  x.wdot_b = Vec3<double>(u(rng), u(rng), u(rng)) * 3.0;
  x.a_n = Vec3<double>(u(rng), u(rng), u(rng)) * 5.0;
  x.v_n = Vec3<double>(u(rng), u(rng), u(rng)) * 10.0;
  x.r_n = Vec3<double>(u(rng), u(rng), u(rng)) * 100.0;
  return x;
}

FilterConfig<double> noisy_config() {
  FilterConfig<double> c;
  c.noise.white_sigma_mps2.fill(3e-4);
  c.noise.bias_rw_mps2_sqrt_s.fill(1e-5);
  c.noise.bias_sigma_mps2.fill(3e-4);
  c.innovation_gate = false;  // the fixes below are arbitrary: every one must be applied
  return c;
}

// Chen's cube as a calibration leaves it: every axis turned by up to 3° and every position moved
// by up to 5 mm. The exact cube decouples ω̇ from ω (its K has no ω̇ rows), which would leave the
// δω → δω̇ block of F empty; a calibrated array does not.
ArrayGeometry<double, 6> calibrated_cube(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  ArrayGeometry<double, 6> g = table1_geometry(0.1);
  for (std::size_t j = 0; j < 6; ++j) {
    const Vec3<double> axis = Vec3<double>(u(rng), u(rng), u(rng)).normalized();
    g.theta_b[j] = (Eigen::AngleAxisd(0.05 * u(rng), axis) * g.theta_b[j]).normalized();
    g.rho_b[j] += Vec3<double>(u(rng), u(rng), u(rng)) * 5e-3;
  }
  return g;
}

struct MovingBoard {
  std::mt19937_64 rng;
  ArraySolver<double> solver;
  // Normal gravity at 24.8° and 50 m: the gravity gradient's entry of F is not zero.
  Strapdown<double> nav{solver, GravityModel<double>::normal(0.4328416544945937, 50.0)};
  Filter filter;
  testing::Truth truth;
  Vec3<double> last_position_fix = Vec3<double>::Zero();  // no lever arm: the array's position

  explicit MovingBoard(std::uint64_t seed, bool heading_known = true)
      : rng(seed), solver(ArraySolver<double>::create(calibrated_cube(rng)).value()) {
    truth = random_truth(rng);
    nav.initialize(testing::nav_state_of<double>(truth),
                   testing::ideal_outputs(solver.geometry(), truth));
    FilterConfig<double> c = noisy_config();
    c.heading_known = heading_known;
    c.track_min_speed_mps = 1e9;  // no heading from the track: heading_known alone decides
    EXPECT_TRUE(filter.configure(c).is_ok());
    filter.start(nav);
  }

  /// Four strapdown steps of 25 ms, each followed by a propagation (a history entry); returns the
  /// state after the first, 75 ms before the last.
  NavState<double> advance_100ms() {
    const Vec6<double> s = testing::ideal_outputs(solver.geometry(), truth);
    NavState<double> first;
    for (int k = 1; k <= 4; ++k) {
      nav.step(s, 0.025, nav.state().t_ns + 25'000'000, nav.state().seq + 1);
      EXPECT_TRUE(filter.propagate(nav, 0.025).is_ok());
      if (k == 1) first = nav.state();
    }
    return first;
  }

  /// Propagations and GNSS updates until every block of P is correlated with every other.
  void correlate() {
    for (int i = 0; i < 40; ++i) {
      ASSERT_TRUE(filter.propagate(nav, 0.05).is_ok());
      if (i % 5 != 4) continue;
      GnssFix<double> fix;
      fix.t_valid_ns = nav.state().t_ns;
      fix.value_n = nav.state().r_n + Vec3<double>(0.3, -0.2, 0.1);
      fix.sigma = Vec3<double>(1.5, 1.5, 3.0);
      // Before the heading is aligned a fix sets the quantity instead (kReset).
      const UpdateStatus applied =
          filter.heading_aligned() ? UpdateStatus::kAccepted : UpdateStatus::kReset;
      ASSERT_EQ(filter.update_gnss_position(nav, fix).status, applied);
      last_position_fix = fix.value_n;
      fix.value_n = nav.state().v_n + Vec3<double>(0.02, 0.01, -0.03);
      fix.sigma = Vec3<double>::Constant(0.1);
      ASSERT_EQ(filter.update_gnss_velocity(nav, fix).status, applied);
    }
  }
};

// |A − B| element by element, scaled by √(B_ii B_jj) (the correlation scale: the bias variances
// are 1e-8 where the position's are 1e0, so a plain maximum would see only the position).
double max_scaled_difference(const StateMat& a, const StateMat& b) {
  double worst = 0;
  for (int i = 0; i < kN; ++i) {
    for (int j = 0; j < kN; ++j) {
      const double scale = std::sqrt(b(i, i) * b(j, j));
      worst = std::max(worst, std::abs(a(i, j) - b(i, j)) / scale);
    }
  }
  return worst;
}

// The smallest correlation magnitude between any two blocks (the largest |ρ| within each pair of
// 3-blocks): the covariance the products are checked on must have no zero block.
double weakest_block_correlation(const StateMat& p) {
  double weakest = 1;
  for (int rb = 0; rb < 6; ++rb) {
    for (int cb = 0; cb < 6; ++cb) {
      double strongest = 0;
      for (int i = 3 * rb; i < 3 * rb + 3; ++i) {
        for (int j = 3 * cb; j < 3 * cb + 3; ++j) {
          if (i != j)
            strongest = std::max(strongest, std::abs(p(i, j)) / std::sqrt(p(i, i) * p(j, j)));
        }
      }
      weakest = std::min(weakest, strongest);
    }
  }
  return weakest;
}

// Rounding of 18-term sums of double products relative to the correlation scale: measured at
// most 8.2e-16 over these seeds (the propagation) and 5.7e-16 (the updates); the bound leaves a
// factor of 100. A block left out of a mask or a product transposed moves the result by the
// weakest correlation (≥ 1e-4 measured) times h‖F‖ (≈ 1e-2): at least 1e-6, far above it. One
// propagation moves P by 1.2e-2 on this scale.
constexpr double kRoundingBound = 1e-13;

TEST(FilterAlgebraTest, ProcessModelIsZeroOutsideItsMaskAndFillsEveryMaskedBlock) {
  // The mask must hold every entry F can have (else the propagation drops terms) and no block F
  // never fills (else its cost is wasted and the figure in docs/performance.md is wrong).
  std::array<bool, 36> seen{};
  const auto slot = [](int rb, int cb) {
    return static_cast<std::size_t>(rb) * 6 + static_cast<std::size_t>(cb);
  };
  for (std::uint64_t seed = 1; seed <= 200; ++seed) {
    MovingBoard board(seed);
    StateMat f;
    StateMat qc;
    board.filter.process_model(board.nav, f, qc);
    for (int i = 0; i < kN; ++i) {
      for (int j = 0; j < kN; ++j) {
        const int rb = i / 3;
        const int cb = j / 3;
        if (blocks::has(Filter::kFMask, rb, cb)) {
          if (f(i, j) != 0.0) seen[slot(rb, cb)] = true;
        } else {
          ASSERT_EQ(f(i, j), 0.0) << "F(" << i << ", " << j << ") outside the mask, seed " << seed;
        }
      }
    }
  }
  for (int rb = 0; rb < 6; ++rb) {
    for (int cb = 0; cb < 6; ++cb) {
      if (blocks::has(Filter::kFMask, rb, cb)) {
        EXPECT_TRUE(seen[slot(rb, cb)])
            << "block (" << rb << ", " << cb << ") of the mask is never filled";
      }
    }
  }
  EXPECT_EQ(blocks::count(Filter::kFMask), 8);
  EXPECT_EQ(blocks::count(Filter::kPhiMask), 18);
}

TEST(FilterAlgebraTest, PropagationEqualsTheDenseProducts) {
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    MovingBoard board(seed);
    board.correlate();
    const StateMat p = board.filter.covariance();
    // No block uncorrelated: a product that dropped one would move the result by at least this
    // correlation times h‖F‖ (≥ 1e-6 · 1e-2), far above the rounding bound.
    ASSERT_GT(weakest_block_correlation(p), 1e-6) << "seed " << seed;
    StateMat f;
    StateMat qc;
    board.filter.process_model(board.nav, f, qc);
    // Dense: Φ = I + F h + F² h²/2, Q_d = Q_c h + (F Q_c + Q_c Fᵀ) h²/2 + F Q_c Fᵀ h³/3.
    const double h = 0.01;
    const StateMat phi = StateMat::Identity() + f * h + f * f * (h * h / 2);
    const StateMat qd = qc * h + (f * qc + qc * f.transpose()) * (h * h / 2) +
                        f * qc * f.transpose() * (h * h * h / 3);
    StateMat expected = phi * p * phi.transpose() + qd;
    expected = ((expected + expected.transpose()) / 2).eval();
    ASSERT_TRUE(board.filter.propagate(board.nav, h).is_ok());
    EXPECT_LT(max_scaled_difference(board.filter.covariance(), expected), kRoundingBound)
        << "seed " << seed;
    // The step did something: the covariance moved by far more than the bound.
    EXPECT_GT(max_scaled_difference(p, expected), 1e3 * kRoundingBound) << "seed " << seed;
  }
}

// The truncation itself, against an oracle that truncates nothing: Eigen's matrix exponential
// (unsupported/Eigen/MatrixFunctions, Padé with scaling and squaring) of Van Loan's block matrix
// A = [−F Q_c; 0 Fᵀ] h gives Φ = e^{F h} = (e^A)₂₂ᵀ and Q_d = ∫₀ʰ e^{F s} Q_c e^{Fᵀ s} ds =
// Φ (e^A)₁₂ for F constant over the step (the filter's assumption too). The filter's series to
// h² (Φ) and h³ (Q_d) leave terms of order ε³/6 on each side of Φ P Φᵀ, ε = ‖D⁻¹ F D h‖₂ the
// step in the coordinates of the correlation scale (D = diag(√P_ii)): the bound is ε³, three
// times the two sides' sum. Measured at 10 ms over these seeds: ε 1.4-3.0e-2, off by 4-11e-8
// against bounds of 2.9e-6 to 2.6e-5; Φ to first order (I + F h, leaving ε² terms) is off by
// 2.2-6.0e-5 and fails every seed's bound.
TEST(FilterAlgebraTest, PropagationMatchesTheMatrixExponentialToItsTruncation) {
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    MovingBoard board(seed);
    board.correlate();
    const StateMat p = board.filter.covariance();
    StateMat f;
    StateMat qc;
    board.filter.process_model(board.nav, f, qc);
    const double h = 0.01;
    // ε in the correlation scale's coordinates: D⁻¹ F D h, D = diag(√P_ii).
    const Eigen::Matrix<double, kN, 1> d = p.diagonal().cwiseSqrt();
    const double eps = (d.cwiseInverse().asDiagonal() * f * d.asDiagonal() * h).operatorNorm();
    const double bound = eps * eps * eps;
    Eigen::Matrix<double, 2 * kN, 2 * kN> a = Eigen::Matrix<double, 2 * kN, 2 * kN>::Zero();
    a.topLeftCorner<kN, kN>() = -f * h;
    a.topRightCorner<kN, kN>() = qc * h;
    a.bottomRightCorner<kN, kN>() = f.transpose() * h;
    const Eigen::Matrix<double, 2 * kN, 2 * kN> e = a.exp();
    const StateMat phi = e.bottomRightCorner<kN, kN>().transpose();
    const StateMat qd = phi * e.topRightCorner<kN, kN>();
    StateMat exact = phi * p * phi.transpose() + qd;
    exact = ((exact + exact.transpose()) / 2).eval();
    const StateMat first_order_phi = StateMat::Identity() + f * h;
    const StateMat first_order = first_order_phi * p * first_order_phi.transpose() + qd;
    ASSERT_TRUE(board.filter.propagate(board.nav, h).is_ok());
    const double off = max_scaled_difference(board.filter.covariance(), exact);
    const double first_off = max_scaled_difference(first_order, exact);
    std::printf(
        "seed %2llu: ||F h|| %.2e; off the matrix exponential by %.2e (bound %.2e; Φ to "
        "first order %.2e)\n",
        static_cast<unsigned long long>(seed), eps, off, bound, first_off);
    EXPECT_LT(off, bound) << "seed " << seed;
    // The bound can be failed: Φ one order shorter is.
    EXPECT_GT(first_off, bound) << "seed " << seed;
  }
}

// Joseph form written out densely: (I − KH) P (I − KH)ᵀ + K R Kᵀ, K = P Hᵀ (H P Hᵀ + R)⁻¹.
template <int M>
StateMat dense_joseph(const StateMat& p, const Measurement<double, M>& m) {
  const Eigen::Matrix<double, M, M> s = m.h * p * m.h.transpose() + m.r;
  const Eigen::Matrix<double, kN, M> k = p * m.h.transpose() * s.inverse();
  const StateMat a = StateMat::Identity() - k * m.h;
  StateMat out = a * p * a.transpose() + k * m.r * k.transpose();
  return ((out + out.transpose()) / 2).eval();
}

TEST(FilterAlgebraTest, JosephUpdateEqualsTheDenseProducts) {
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    {
      MovingBoard board(seed);
      board.correlate();
      const StateMat p = board.filter.covariance();
      const StateMat expected = dense_joseph(p, zupt_measurement(board.nav.state(), 0.01));
      ASSERT_EQ(board.filter.update_zupt(board.nav).status, UpdateStatus::kAccepted);
      EXPECT_LT(max_scaled_difference(board.filter.covariance(), expected), kRoundingBound)
          << "ZUPT, seed " << seed;
      EXPECT_GT(max_scaled_difference(p, expected), 1e3 * kRoundingBound);
    }
    {
      MovingBoard board(seed);
      board.correlate();
      const StateMat p = board.filter.covariance();
      const StateMat expected = dense_joseph(p, zaru_measurement(board.nav.state(), 1e-3));
      ASSERT_EQ(board.filter.update_zaru(board.nav).status, UpdateStatus::kAccepted);
      EXPECT_LT(max_scaled_difference(board.filter.covariance(), expected), kRoundingBound)
          << "ZARU, seed " << seed;
    }
    {
      // One row: the external heading at the current instant.
      MovingBoard board(seed);
      board.correlate();
      const StateMat p = board.filter.covariance();
      const HeadingFix<double> fix{board.nav.state().t_ns, 0.3, 0.02};
      const StateMat expected =
          dense_joseph(p, heading_measurement(board.nav.state().q_nb, fix.yaw_rad, fix.sigma_rad));
      ASSERT_EQ(board.filter.update_heading(board.nav, fix).status, UpdateStatus::kAccepted);
      EXPECT_LT(max_scaled_difference(board.filter.covariance(), expected), kRoundingBound)
          << "heading, seed " << seed;
    }
  }
}

// A fix valid Δt before now (GNSS latency): the error it measures is Φ(now, t_v)⁻¹ x_now, so the
// update must be the Joseph form with H (I − F Δt + F² Δt²/2), F the process model now; a
// heading set from such a fix (before the heading is aligned) is the fix's at t_v carried to now,
// P' = T P̃ Tᵀ with P̃ the covariance with φ_D independent of variance σ², T = I + Δt e_D F_D.
// A correlated board moved on by 100 ms: the state 75 ms ago, P and F now.
struct DelayedFix {
  NavState<double> then;
  StateMat p;
  StateMat f;
};
DelayedFix delayed_fix(MovingBoard& board) {
  board.correlate();
  DelayedFix d;
  d.then = board.advance_100ms();
  d.p = board.filter.covariance();
  StateMat qc;
  board.filter.process_model(board.nav, d.f, qc);
  return d;
}

TEST(FilterAlgebraTest, AFixValidEarlierIsReferredToNow) {
  constexpr double kAge = 0.075;
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    {
      MovingBoard board(seed);
      const DelayedFix d = delayed_fix(board);
      const NavState<double>& then = d.then;
      const StateMat& p = d.p;
      const StateMat& f = d.f;
      const HeadingFix<double> fix{then.t_ns, 0.3, 0.02};
      Measurement<double, 1> m = heading_measurement(then.q_nb, fix.yaw_rad, fix.sigma_rad);
      const Measurement<double, 1> at_tv = m;
      m.h = m.h * (StateMat::Identity() - f * kAge + f * f * (kAge * kAge / 2));
      const StateMat expected = dense_joseph(p, m);
      ASSERT_EQ(board.filter.update_heading(board.nav, fix).status, UpdateStatus::kAccepted);
      EXPECT_LT(max_scaled_difference(board.filter.covariance(), expected), kRoundingBound)
          << "delayed heading update, seed " << seed;
      // Referring to now matters here: the update with H at t_v differs by far more.
      EXPECT_GT(max_scaled_difference(dense_joseph(p, at_tv), expected), 1e3 * kRoundingBound);
    }
    {
      MovingBoard board(seed, false);
      const DelayedFix d = delayed_fix(board);
      const StateMat& p = d.p;
      const StateMat& f = d.f;
      const HeadingFix<double> fix{d.then.t_ns, 0.3, 0.02};
      constexpr int kD = filt_idx::kPhi + 2;
      StateMat independent = p;
      // The horizontal velocity gained while the heading was unknown: its variance for a heading
      // error anywhere, 1.5 |v_h|² per axis (docs/math.md, "Re-level at rest"), goes in first.
      const double v2 = board.nav.state().v_n.head<2>().squaredNorm();
      for (int i = 0; i < 2; ++i) independent(filt_idx::kVel + i, filt_idx::kVel + i) += 1.5 * v2;
      // So does the displacement since the last GNSS position set the position: 1.5 |Δr_h|².
      const double r2 = (board.nav.state().r_n - board.last_position_fix).head<2>().squaredNorm();
      for (int i = 0; i < 2; ++i) independent(filt_idx::kPos + i, filt_idx::kPos + i) += 1.5 * r2;
      independent.row(kD).setZero();
      independent.col(kD).setZero();
      independent(kD, kD) = fix.sigma_rad * fix.sigma_rad;
      StateMat t = StateMat::Identity();
      t.row(kD) += kAge * f.row(kD);
      StateMat expected = t * independent * t.transpose();
      expected = ((expected + expected.transpose()) / 2).eval();
      ASSERT_EQ(board.filter.update_heading(board.nav, fix).status, UpdateStatus::kReset);
      EXPECT_LT(max_scaled_difference(board.filter.covariance(), expected), kRoundingBound)
          << "heading set from a delayed fix, seed " << seed;
      EXPECT_GT(max_scaled_difference(independent, expected), 1e3 * kRoundingBound);
    }
  }
}

TEST(FilterAlgebraTest, MultiplyReadsOnlyTheMaskedBlocks) {
  // The kernel against Eigen's product, with the unmasked blocks of A holding garbage that must
  // be ignored (the kernel's contract: they are taken as zero).
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  StateMat a;
  StateMat b;
  for (int i = 0; i < kN * kN; ++i) {
    a.data()[i] = u(rng);
    b.data()[i] = u(rng);
  }
  constexpr blocks::Mask mask = Filter::kPhiMask;
  StateMat a_masked = a;
  for (int i = 0; i < kN; ++i) {
    for (int j = 0; j < kN; ++j) {
      if (!blocks::has(mask, i / 3, j / 3)) a_masked(i, j) = 0;
    }
  }
  StateMat c;
  blocks::multiply(mask, a.data(), b.data(), c.data());
  EXPECT_LT((c - a_masked * b).cwiseAbs().maxCoeff(), 1e-14);
  EXPECT_GT((c - a * b).cwiseAbs().maxCoeff(), 1e-2);  // the garbage mattered to a full product
}

}  // namespace
}  // namespace gfins::nav
