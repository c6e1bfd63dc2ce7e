// Strapdown integrator of the gyro-free array: ω from ω̇, attitude, velocity and position.
//
// Scheme (docs/math.md derives it and states its order). Samples s_k arrive at t_k; the state
// after step k refers to t_k. Over [t_{k-1}, t_k], with h = t_k − t_{k-1}:
//   1. angular rate, Heun (trapezoid with an Euler predictor), because ω̇ depends on ω through the
//      centripetal term (eq. (4)/(6) for Table 1, K m(ω) in general):
//        ω̇_p = u_k − K_top m(ω_{k-1} + h ω̇_{k-1});  ω_k = ω_{k-1} + h/2 (ω̇_{k-1} + ω̇_p)
//   2. [ω̇_k; f_k] = u_k − K m(ω_k) with u_k = M s_k (eqs. (4)-(6))
//   3. attitude, two-sample rotation vector for ω linear over the step (eq. (1) integrated):
//        φ = h/2 (ω_{k-1} + ω_k) + h²/12 ω_{k-1} × ω_k;   q_k = q_{k-1} ⊗ exp(φ), normalised
//   4. a_k = C(q_k) f_k + g_n(r_{k-1}) (gravity added back with the current attitude, eq. (5))
//   5. v_k = v_{k-1} + h/2 (a_{k-1} + a_k)
//      r_k = r_{k-1} + h v_{k-1} + h²/6 (2 a_{k-1} + a_k)   (exact for a linear in t)
// Every stage is second order in h; velocity and position are accumulated with compensated
// (Kahan) summation so that small increments are not lost in float32 over long runs.
#pragma once

#include <cstdint>

#include "gfins/nav_core/geometry.hpp"
#include "gfins/nav_core/gravity.hpp"
#include "gfins/nav_core/nav_state.hpp"

namespace gfins::nav {

/// Vector sum with Kahan compensation: the rounding error of each addition is carried into the
/// next one. Requires IEEE arithmetic as written (never build nav_core with -ffast-math). V is a
/// 3-vector, plain or padded (ArraySolver::PaddedVec3).
template <typename T, typename V = Vec3<T>>
struct CompensatedVec3 {
  V sum = V::Zero();
  V carry = V::Zero();

  void reset(const V& v) {
    sum = v;
    carry.setZero();
  }
  void add(const V& delta) {
    const V y = delta - carry;
    const V t = sum + y;
    carry = (t - sum) - y;
    sum = t;
  }
};

template <typename T, int N = kNumSensors>
class Strapdown {
 public:
  using Solver = ArraySolver<T, N>;
  using Outputs = typename Solver::Outputs;
  /// The per-sample 3-vectors, padded to whole SIMD packets (lane 3 zero with SSE).
  using PVec = typename Solver::PaddedVec3;
  static constexpr int kP = Solver::kHalfRows;

  Strapdown() = default;
  Strapdown(const Solver& solver, const GravityModel<T>& gravity)
      : solver_(solver), gravity_(gravity), wdot_free_of_w_(wdot_independent_of_rate(solver)) {}

  /// Replaces the array solver (for a new calibration) without touching the state.
  void set_solver(const Solver& solver) {
    solver_ = solver;
    wdot_free_of_w_ = wdot_independent_of_rate(solver);
  }
  const Solver& solver() const { return solver_; }
  const GravityModel<T>& gravity() const { return gravity_; }

  /// Starts integration at the first sample: `initial` gives t, attitude, ω, v and r; s0 are the
  /// compensated outputs of that sample, from which ω̇ and f at t0 are computed.
  void initialize(const NavState<T>& initial, const Outputs& s0) {
    state_ = initial;
    state_.status |= nav_status::kAligned;
    state_.q_nb.normalize();
    solver_.solve(s0, state_.w_b, state_.wdot_b, state_.f_b);
    state_.wdot_b -= bias_.template head<3>();
    state_.f_b -= bias_.template segment<3>(kP);
    state_.a_n = state_.q_nb * state_.f_b + gravity_.g_n(state_.r_n);
    q_ = state_.q_nb;
    w_ = pad(state_.w_b);
    wdot_ = pad(state_.wdot_b);
    a_ = pad(state_.a_n);
    v_.reset(pad(state_.v_n));
    r_.reset(pad(state_.r_n));
  }

  /// Advances to the sample s_k taken dt_s after the previous one.
  void step(const Outputs& s_k, T dt_s, std::int64_t t_ns, std::uint32_t seq) {
    step_linear(solver_.padded_linear_part(s_k), dt_s, t_ns, seq);
  }

  /// step() with u_k = M s_k already formed (padded layout of ArraySolver::kRows: ω̇ rows in the
  /// first kP, f rows in the last kP): the pipeline folds the paper compensator into this
  /// product (Compensator::padded_linear_part). The arithmetic runs on padded 3-vectors (PVec),
  /// element by element the same operations as on plain ones; the state is kept in that form
  /// (q_, w_, wdot_, a_, v_, r_) and copied to the NavState once per step.
  void step_linear(const typename Solver::PaddedVec& u, T dt_s, std::int64_t t_ns,
                   std::uint32_t seq) {
    // The estimated bias of [ω̇; f] (set_bias), removed before anything else: one padded
    // subtract per half of u (a SIMD packet each for floats), zero by default.
    const PVec u_wdot = u.template head<kP>() - bias_.template head<kP>();
    const PVec u_f = u.template tail<kP>() - bias_.template tail<kP>();
    const T h = dt_s;
    const PVec w0 = w_;
    const PVec wdot0 = wdot_;
    const PVec a0 = a_;
    const PVec v0 = v_.sum;

    // When K's top rows are zero (a symmetric array such as Table 1, where ω̇ = S s/(2ρ) of
    // eq. (4)/(6) has no centripetal term) the predictor is exact and ω̇ needs no product: same
    // values as the general case, which would subtract exact zeros, for a third fewer operations.
    PVec wdot_pred = u_wdot;
    if (!wdot_free_of_w_) {
      const PVec w_pred = w0 + h * wdot0;
      // The whole padded product (whole SIMD packets) is cheaper than its three top rows.
      wdot_pred -=
          solver_.padded_k().lazyProduct(centripetal_monomials(w_pred)).template head<kP>();
    }
    const PVec w1 = w0 + (h / T(2)) * (wdot0 + wdot_pred);
    const Vec6<T> m1 = centripetal_monomials(w1);
    PVec wdot1;
    PVec f1;
    if (wdot_free_of_w_) {
      wdot1 = u_wdot;
      f1 = u_f - solver_.padded_k_force().lazyProduct(m1);
    } else {
      // One fused expression, as without the bias: (u − β̂) − K m(ω), element by element.
      const typename Solver::PaddedVec full = u - bias_ - solver_.padded_k().lazyProduct(m1);
      wdot1 = full.template head<kP>();
      f1 = full.template tail<kP>();
    }

    const PVec phi = (h / T(2)) * (w0 + w1) + (h * h / T(12)) * cross_padded(w0, w1);
    Quat<T> q1 = q_ * quat_from_rotation_vector_padded(phi);
    q1.normalize();

    PVec a1 = rotate_padded(q1, f1);
    a1(2) += gravity_.g_down(r_.sum(2));  // + g_n(r_{k-1}), which has only a down component
    v_.add((h / T(2)) * (a0 + a1));
    r_.add(h * v0 + (h * h / T(6)) * (T(2) * a0 + a1));

    q_ = q1;
    w_ = w1;
    wdot_ = wdot1;
    a_ = a1;
    state_.t_ns = t_ns;
    state_.seq = seq;
    state_.q_nb = q1;
    state_.w_b = w1.template head<3>();
    state_.wdot_b = wdot1.template head<3>();
    state_.f_b = f1.template head<3>();
    state_.a_n = a1.template head<3>();
    state_.v_n = v_.sum.template head<3>();
    state_.r_n = r_.sum.template head<3>();
  }

  /// The estimated bias of the array's solution [ω̇; f] (rad/s², m/s², body), subtracted from
  /// u = M s before every step (the aided filter's 6-D bias, error_state_filter.hpp). The values
  /// of the current sample (ω̇, f, a) are re-derived with the new bias, so the next step's
  /// trapezoids start from corrected values.
  void set_bias(const Vec3<T>& b_wdot, const Vec3<T>& b_f) {
    const Vec3<T> d_wdot = b_wdot - bias_.template head<3>();
    const Vec3<T> d_f = b_f - bias_.template segment<3>(kP);
    bias_.template head<3>() = b_wdot;
    bias_.template segment<3>(kP) = b_f;
    wdot_.template head<3>() -= d_wdot;
    state_.wdot_b = wdot_.template head<3>();
    state_.f_b -= d_f;
    refresh_acceleration();
  }
  Vec3<T> bias_wdot() const { return bias_.template head<3>(); }
  Vec3<T> bias_f() const { return bias_.template segment<3>(kP); }

  /// Closed-loop feedback of an estimated error x = estimate − truth (docs/math.md, "Aided
  /// navigation"): attitude error φ_n (rad, n frame, eq. (7): Ĉ Cᵀ = exp(−[φ×]), so the
  /// corrected attitude is q ← exp(φ) ⊗ q̂), position δr_n (m), velocity δv_n (m/s) and angular
  /// rate δω_b (rad/s) are removed from the integration state itself (the padded copies and the
  /// Kahan sums, whose carries are kept). ω̇ and f of the current sample follow the rate
  /// correction to first order (δ[ω̇; f] = −K J(ω) δω, error_model.hpp) and a_n the new attitude.
  void apply_correction(const Vec3<T>& phi_n, const Vec3<T>& dr_n, const Vec3<T>& dv_n,
                        const Vec3<T>& dw_b) {
    q_ = quat_from_rotation_vector<T>(phi_n) * q_;
    q_.normalize();
    v_.add(pad(-dv_n));
    r_.add(pad(-dr_n));
    const Vec3<T> w_old = w_.template head<3>();
    w_.template head<3>() -= dw_b;
    const Vec6<T> dwf = solver_.k() * (centripetal_monomials(w_old) -
                                       centripetal_monomials(Vec3<T>(w_.template head<3>())));
    wdot_.template head<3>() += dwf.template head<3>();
    state_.f_b += dwf.template tail<3>();
    state_.q_nb = q_;
    state_.w_b = w_.template head<3>();
    state_.wdot_b = wdot_.template head<3>();
    state_.v_n = v_.sum.template head<3>();
    state_.r_n = r_.sum.template head<3>();
    refresh_acceleration();
  }

  const NavState<T>& state() const { return state_; }
  /// For the status bits only: the integration state lives in the padded copies above (set by
  /// initialize()); changing q_nb, w_b, ... here would not change the next step.
  NavState<T>& mutable_state() { return state_; }

 private:
  /// True when ω̇ does not depend on ω (the top three rows of K are exactly zero).
  static bool wdot_independent_of_rate(const Solver& solver) {
    return (solver.padded_k().template topRows<3>().array() == T(0)).all();
  }

  /// a = C f + g_n(r) of the current sample after f, q or r changed outside a step.
  void refresh_acceleration() {
    state_.a_n = q_ * state_.f_b + gravity_.g_n(state_.r_n);
    a_ = pad(state_.a_n);
  }

  static PVec pad(const Vec3<T>& v) {
    PVec p = PVec::Zero();
    p.template head<3>() = v;
    return p;
  }

  Solver solver_{};  // owned copy (a few hundred bytes), so the integrator can be copied
  GravityModel<T> gravity_{};
  bool wdot_free_of_w_ = false;
  NavState<T> state_{};
  Quat<T> q_ = Quat<T>::Identity();
  PVec w_ = PVec::Zero();
  PVec wdot_ = PVec::Zero();
  PVec a_ = PVec::Zero();
  CompensatedVec3<T, PVec> v_{};
  CompensatedVec3<T, PVec> r_{};
  typename Solver::PaddedVec bias_ = Solver::PaddedVec::Zero();  // [b_ω̇; b_f], padded layout
};

}  // namespace gfins::nav
