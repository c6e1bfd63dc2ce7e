// The benchmarks' straightforward baseline (tests/bench/baseline_step.hpp) computes the same
// per-sample step as the core: the side-by-side ratio in docs/performance.md compares two
// implementations of one computation. Oracle: the baseline, written independently of the core's
// fused and padded products (dynamic Eigen, the paper's compensator set by set, sin/cos).
//
// Method: one step at a time. Before each sample the baseline takes over the core's state
// (BaselineStep::resync), both run the same sample, and every output of the step (ω̇, f, ω,
// attitude, a, v, r) is compared with a bound on the rounding of the two implementations,
// computed for that step from its own numbers. Comparing one step keeps the bound at the size of
// one step's rounding (a few units of u times the magnitudes involved): over a free run the
// rounding of the attitude (a few u per step) would have to be allowed to add up linearly over
// 1000 steps and tilt gravity into the velocity, a bound of about 1e-3 m/s in float, larger than
// what a real error in f does in 1 s (a 1e-4 relative error of f: 1e-3 m/s).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

#include "../bench/baseline_step.hpp"
#include "../bench/bench_scenario.hpp"

namespace gfins::bench {
namespace {

using V3 = Eigen::Vector3d;
using V6 = Eigen::Matrix<double, 6, 1>;
using M6 = Eigen::Matrix<double, 6, 6>;
using M3 = Eigen::Matrix3d;

// Rounding model (Higham, "Accuracy and Stability of Numerical Algorithms", 2nd ed., §2.2 and
// Lemmas 3.1, 3.3): each float or double operation returns the exact result times (1 + δ) with
// |δ| ≤ u, the unit roundoff epsilon/2 (round to nearest; nav_core is never built with
// -ffast-math). A chain of n roundings stays within a factor 1 ± γ_n, γ_n = n u / (1 − n u), and
// an n-term dot product summed in any order (the core's SIMD order or Eigen's dynamic one) is
// within γ_n Σ|x_i y_i| of the exact value (Higham eq. (3.5)). So each implementation's result
// is within γ_chain · A of the exact value on the same inputs, A being the formula evaluated on
// absolute values ("shadow", computed here in double); the two differ by at most twice that.
double gamma(int n, double u) { return n * u / (1.0 - n * u); }

// Longest chains of roundings, counted in both implementations (the bound takes the longer):
// front end s = gain·code − b·g (front_end.hpp / baseline front_end()): gain = LSB·g/SF, two
// roundings at set-up; ·code, one (a 24-bit code is exact in float); the subtraction, one.
constexpr int kFrontEndChain = 4;
// u = M s without compensator (kinds none, exact): a 6-term dot product on s.
constexpr int kLinearChain = kFrontEndChain + 6;
// u with the paper compensator. Core: u = F x, F = [M P | −M D] folded at set-up, P = C⁻¹ from
// Eigen's 3×3 cofactor inverse (2×2 minors 2, determinant +3, division +1: 6), M P a 6-term dot
// product on it (12), then the 15-term product F x (27; x = [s; m(ω); ω̇], s with its 4).
// Baseline: Δf·θ (two nested cross products 4, + ω̇×Δρ 5, dot with θ 8), C (Δf·θ) 11,
// s** − 12, C⁻¹ (6) times that 15, M times the result 21. The core's 27 is the longer.
constexpr int kLinearPaperChain = 27;
// [ω̇; f] = u − K m(ω): m(ω) one product, K m a 6-term dot (7), then the subtraction (+1).
int solve_chain(nav::CompensatorKind kind) {
  const int linear = kind == nav::CompensatorKind::kPaper ? kLinearPaperChain : kLinearChain;
  return std::max(linear, 7) + 1;
}
// ω_1 = ω_0 + h/2 (ω̇_0 + ω̇_pred): h = 1/rate (1), the sum (1), the product (1), + ω_0 (1).
constexpr int kRateChain = 4;
// The predictor's ω̇ at ω_pred = ω_0 + h ω̇_0 (two more roundings in ω_pred, one in its square).
constexpr int kPredictorExtra = 3;
// φ = h/2 (ω_0 + ω_1) + h²/12 ω_0 × ω_1: h² / 12 three, cross product two, product one, sum
// one; 6 covers both terms.
constexpr int kRotationVectorChain = 6;
// exp(φ/2) = (c, s φ): the core's Horner polynomials (x = |φ|²/4: 3-term dot 3; three Horner
// stages of a multiply and an add, 6; the rounded reciprocals 1/24, 1/720, 1/12, ..., 1) or the
// baseline's sqrt, cosf/sinf (within one ulp = 2u in glibc) and the division: 10 covers both,
// on terms whose absolute values sum to at most 1 + |φ|.
constexpr int kHalfAngleChain = 10;
// Quaternion product: each component a 4-term dot product of unit quaternions' components (Σ of
// the absolute products ≤ 1 by Cauchy-Schwarz); normalisation: squared norm 4, sqrt and
// division within 4 more, relative.
constexpr int kQuatProductChain = 4;
constexpr int kNormaliseChain = 4;
// Vector rotation v + 2w (q_v × v) + q_v × (2 q_v × v) (Eigen's _transformVector, the core's
// rotate_padded): cross product 2, w· 3, second cross product 4, two sums 6, + g_down 7.
constexpr int kRotateChain = 7;
// Δv = h/2 (a_0 + a_1): h, the sum, the product: 3. Δr = h v_0 + h²/6 (2 a_0 + a_1): h² / 6 is
// three roundings, the sum one, the product one: 5.
constexpr int kVelocityIncrementChain = 3;
constexpr int kPositionIncrementChain = 5;
// Change of the rotated vector R(q)v when the computed q is off by δ (‖δ‖₂ = e): the part of δ
// along q scales q, and the formula above then scales R(q)v − v by (1 + ε)², at most 2·2e‖v‖;
// the part across q rotates by 2e: 2e‖v‖; together at most √(2² + 4²) e ‖v‖ ≤ 4.5 e ‖v‖.
constexpr double kRotationSensitivity = 4.5;

V3 cross_abs(const V3& a, const V3& b) {  // |a| ×abs |b|: the shadow of a × b
  return {std::abs(a(1) * b(2)) + std::abs(a(2) * b(1)),
          std::abs(a(2) * b(0)) + std::abs(a(0) * b(2)),
          std::abs(a(0) * b(1)) + std::abs(a(1) * b(0))};
}

V6 monomials(const V3& w) {  // m(ω) of geometry.hpp: ω_x², ω_y², ω_z², ω_yω_z, ω_xω_z, ω_xω_y
  V6 m;
  m << w(0) * w(0), w(1) * w(1), w(2) * w(2), w(1) * w(2), w(0) * w(2), w(0) * w(1);
  return m;
}

// Bound of |m(ω̃) − m(ω)| per monomial when each |ω̃_i − ω_i| ≤ e_i.
V6 monomial_error(const V3& w, const V3& e) {
  const V3 a = w.cwiseAbs();
  const auto prod = [&](int i, int j) { return a(i) * e(j) + a(j) * e(i) + e(i) * e(j); };
  V6 d;
  d << prod(0, 0), prod(1, 1), prod(2, 2), prod(1, 2), prod(0, 2), prod(0, 1);
  return d;
}

// What one step's bound needs from the configuration, in double.
template <typename T>
struct StepModel {
  nav::CompensatorKind kind{};
  double u = 0;
  double h = 0;
  double g = 0;
  V6 gain;
  V6 offset;
  M6 abs_m;  // |M|
  M6 abs_k;  // |K|
  M6 abs_p;  // |C⁻¹| of each set scattered onto its sensors (paper), else I
  M6 abs_c;  // |C| likewise
  std::array<double, 6> theta_l1{};
  std::array<double, 6> drho_l1{};

  StepModel(const nav::PipelineConfig<T>& c, const nav::ArraySolver<T, 6>& solver)
      : kind(c.compensator),
        u(static_cast<double>(std::numeric_limits<T>::epsilon()) / 2.0),
        h(1.0 / static_cast<double>(c.sample_rate_hz)),
        g(static_cast<double>(c.gravity.g_down(T(0)))) {
    const auto& fe = c.front_end;
    for (int j = 0; j < 6; ++j) {
      const auto i = static_cast<std::size_t>(j);
      gain(j) = static_cast<double>(fe.volts_per_count[i]) * static_cast<double>(fe.gravity_mps2) /
                static_cast<double>(fe.scale_v_per_g[i]);
      offset(j) = static_cast<double>(fe.bias_g[i]) * static_cast<double>(fe.gravity_mps2);
      theta_l1[i] = c.nominal.theta_b[i].template cast<double>().template lpNorm<1>();
      drho_l1[i] = c.misalignment.drho_b[i].template cast<double>().template lpNorm<1>();
    }
    abs_m = solver.m().template cast<double>().cwiseAbs();
    abs_k = solver.k().template cast<double>().cwiseAbs();
    abs_p.setIdentity();
    abs_c.setIdentity();
    if (kind == nav::CompensatorKind::kPaper) {
      const auto scatter = [&](const std::array<int, 3>& set, const std::array<T, 6>& angles) {
        const M3 cm = nav::set_matrix(angles).template cast<double>();
        const M3 ci = cm.inverse();
        for (int i = 0; i < 3; ++i) {
          for (int k = 0; k < 3; ++k) {
            abs_p(set[static_cast<std::size_t>(i)], set[static_cast<std::size_t>(k)]) =
                std::abs(ci(i, k));
            abs_c(set[static_cast<std::size_t>(i)], set[static_cast<std::size_t>(k)]) =
                std::abs(cm(i, k));
          }
        }
      };
      scatter(nav::kSetBeta, c.misalignment.orientation.beta);
      scatter(nav::kSetAlpha, c.misalignment.orientation.alpha);
    }
  }

  // Shadow of u = M s (or F x) for the counts, with ω_0 and ω̇_0 of the compensator (eq. (22)).
  V6 linear_shadow(const std::array<std::int32_t, 6>& counts, const V3& w0, const V3& wdot0) const {
    V6 as;
    for (int j = 0; j < 6; ++j) {
      as(j) = std::abs(gain(j) * counts[static_cast<std::size_t>(j)]) + std::abs(offset(j));
    }
    if (kind == nav::CompensatorKind::kPaper) {
      // Δf_j·θ_j = θ_j·(ω×(ω×Δρ_j) + ω̇×Δρ_j): every term, in either form (cross products or
      // the core's D row, compensator.hpp), is one θ component times one Δρ component times
      // ω_a ω_b or one ω̇ component, at most 4 terms per product of those: shadow
      // ≤ 4 ‖θ‖₁ ‖Δρ‖₁ (‖ω‖₁² + ‖ω̇‖₁).
      V6 adf;
      const double wl1 = w0.lpNorm<1>();
      for (int j = 0; j < 6; ++j) {
        const auto i = static_cast<std::size_t>(j);
        adf(j) = 4.0 * theta_l1[i] * drho_l1[i] * (wl1 * wl1 + wdot0.lpNorm<1>());
      }
      // |C⁻¹| (|s**| + |C| |Δf·θ|) covers the baseline's form, and since |C⁻¹||C| ≥ |C⁻¹C| = I
      // also the core's M P s** − M D [m; ω̇].
      as = abs_p * (as + abs_c * adf);
    }
    return abs_m * as;
  }
};

struct Worst {
  double ratio = -1;  // largest |core − baseline| / bound over the steps (-1: none seen yet)
  double diff = 0;
  double bound = 0;
  std::size_t step = 0;
  void add(double d, double b, std::size_t k) {
    if (d / b > ratio) {
      ratio = d / b;
      diff = d;
      bound = b;
      step = k;
    }
  }
};

template <typename T>
void expect_same_step(nav::CompensatorKind kind) {
  const Workload w = make_workload();
  const auto& buf = w.samples;
  auto core = make_pipeline<T>(kind, w);
  const nav::PipelineConfig<T> config = make_config<T>(kind);
  BaselineStep<T> base(config, core.solver());
  base.start(initial_state<T>(w), buf[0]);
  const StepModel<T> model(config, core.solver());
  const double u = model.u;
  const double h = model.h;
  const int n_solve = solve_chain(kind);

  Worst wdot_w, f_w, rate_w, att_w, acc_w, vel_w, pos_w;
  double max_travel = 0;
  for (std::size_t k = 1; k < buf.size(); ++k) {
    RawSample s = buf[k];
    s.seq = static_cast<std::uint32_t>(k);
    s.t_ns = static_cast<std::int64_t>(k) * 1000000;
    const nav::NavState<double> s0 = core.state().template cast<double>();
    base.resync(core.state());
    core.process(s);
    base.step(s);
    const nav::NavState<double> a = core.state().template cast<double>();
    const nav::NavState<double> b = base.state().template cast<double>();

    // Bound of one implementation's error, step by step through the computation.
    const V6 lin = model.linear_shadow(s.counts, s0.w_b, s0.wdot_b);
    const V3 w_pred = s0.w_b + h * s0.wdot_b;
    const V6 shadow_pred = lin + model.abs_k * monomials(w_pred).cwiseAbs();
    const V3 e_pred = gamma(n_solve + kPredictorExtra, u) * shadow_pred.head<3>();
    const V3 e_w =
        gamma(kRateChain, u) *
            (s0.w_b.cwiseAbs() + (h / 2) * (s0.wdot_b.cwiseAbs() + shadow_pred.head<3>())) +
        (h / 2) * e_pred;
    const V3 w1 = a.w_b;
    const V6 e_sol = gamma(n_solve, u) * (lin + model.abs_k * monomials(w1).cwiseAbs()) +
                     model.abs_k * monomial_error(w1, e_w);
    const V3 e_f = e_sol.tail<3>();
    const V3 phi_shadow =
        (h / 2) * (s0.w_b.cwiseAbs() + w1.cwiseAbs()) + (h * h / 12) * cross_abs(s0.w_b, w1);
    const V3 e_phi = gamma(kRotationVectorChain, u) * phi_shadow + (h / 2) * e_w;
    const double e_dq = gamma(kHalfAngleChain, u) * (1.0 + phi_shadow.norm()) + e_phi.norm() / 2;
    // Product: four components each within γ_4 (2-norm 2γ_4), the propagated ‖δdq‖ (unit q_0),
    // then the normalisation's relative γ_4.
    const double e_q = 2 * gamma(kQuatProductChain, u) + e_dq + gamma(kNormaliseChain, u);
    const V3 f1 = a.f_b;
    const V3 qv = a.q_nb.vec();
    const V3 uv = 2 * cross_abs(qv, f1);
    V3 rot_shadow = f1.cwiseAbs() + std::abs(a.q_nb.w()) * uv + cross_abs(qv, uv);
    rot_shadow(2) += std::abs(model.g);
    const V3 e_a = gamma(kRotateChain, u) * rot_shadow +
                   V3::Constant(e_f.norm() + kRotationSensitivity * e_q * f1.norm());
    const V3 dv_shadow = (h / 2) * (s0.a_n.cwiseAbs() + a.a_n.cwiseAbs());
    // v: the core's Kahan carry from the previous step (≤ u|v_0|: it is that sum's rounding
    // error), the roundings of y = Δv − carry and of v_0 + y, the increment's own chain, the
    // propagated error of a_1.
    const V3 e_v = u * s0.v_n.cwiseAbs() + u * (dv_shadow + u * s0.v_n.cwiseAbs()) +
                   u * a.v_n.cwiseAbs() + gamma(kVelocityIncrementChain, u) * dv_shadow +
                   (h / 2) * e_a;
    const V3 dr_shadow =
        h * s0.v_n.cwiseAbs() + (h * h / 6) * (2 * s0.a_n.cwiseAbs() + a.a_n.cwiseAbs());
    const V3 e_r = u * s0.r_n.cwiseAbs() + u * (dr_shadow + u * s0.r_n.cwiseAbs()) +
                   u * a.r_n.cwiseAbs() + gamma(kPositionIncrementChain, u) * dr_shadow +
                   (h * h / 6) * e_a;

    // The two implementations differ by at most the sum of their two errors.
    for (int i = 0; i < 3; ++i) {
      wdot_w.add(std::abs(a.wdot_b(i) - b.wdot_b(i)), 2 * e_sol(i), k);
      f_w.add(std::abs(a.f_b(i) - b.f_b(i)), 2 * e_f(i), k);
      rate_w.add(std::abs(a.w_b(i) - b.w_b(i)), 2 * e_w(i), k);
      acc_w.add(std::abs(a.a_n(i) - b.a_n(i)), 2 * e_a(i), k);
      vel_w.add(std::abs(a.v_n(i) - b.v_n(i)), 2 * e_v(i), k);
      pos_w.add(std::abs(a.r_n(i) - b.r_n(i)), 2 * e_r(i), k);
    }
    // Angle between the two attitudes: ‖vec(q_a* q_b)‖ ≤ ‖q_b − q_a‖₂ ≤ e_q(core) + e_q(base).
    const double att = 2 * std::asin(std::min(1.0, (a.q_nb.conjugate() * b.q_nb).vec().norm()));
    att_w.add(att, 2 * std::asin(std::min(1.0, 2 * e_q)), k);
    max_travel = std::max(max_travel, a.r_n.norm());
  }

  const auto check = [](const char* what, const Worst& x) {
    EXPECT_LE(x.ratio, 1.0) << what << ": |core − baseline| = " << x.diff << " at step " << x.step
                            << ", above its rounding bound " << x.bound;
    ::testing::Test::RecordProperty(std::string("worst_ratio_") + what, std::to_string(x.ratio));
    std::printf("  %-9s worst |core - baseline| / bound = %.3g (%.3g / %.3g, step %zu)\n", what,
                x.ratio, x.diff, x.bound, x.step);
  };
  check("wdot", wdot_w);
  check("f", f_w);
  check("rate", rate_w);
  check("attitude", att_w);
  check("accel", acc_w);
  check("velocity", vel_w);
  check("position", pos_w);
  // Not vacuous: the steps compared cover the manoeuvre (it starts at r = 0 at about 2.8 m/s and
  // travels more than 2 m in the second).
  EXPECT_GT(max_travel, 1.0);
}

TEST(BaselineEquivalence, FloatNone) { expect_same_step<float>(nav::CompensatorKind::kNone); }
TEST(BaselineEquivalence, FloatPaper) { expect_same_step<float>(nav::CompensatorKind::kPaper); }
TEST(BaselineEquivalence, FloatExact) { expect_same_step<float>(nav::CompensatorKind::kExact); }
TEST(BaselineEquivalence, DoubleNone) { expect_same_step<double>(nav::CompensatorKind::kNone); }
TEST(BaselineEquivalence, DoublePaper) { expect_same_step<double>(nav::CompensatorKind::kPaper); }
TEST(BaselineEquivalence, DoubleExact) { expect_same_step<double>(nav::CompensatorKind::kExact); }

}  // namespace
}  // namespace gfins::bench
