// The per-sample navigation step written the straightforward way, for the side-by-side benchmark
// (baseline_bench.cpp) only: the same equations as nav_core's NavPipeline (front end, the
// paper's compensator set by set, Chen's mechanization [ω̇; f] = M s − K m(ω), Heun for ω,
// rotation-vector attitude, trapezoid velocity, Kahan sums), but with dynamically sized Eigen
// matrices and vectors (heap storage, run-time sizes), every stage a separate pass over its own
// temporaries, the full K product in the predictor and the corrector whatever rows are zero, and
// sin/cos for the rotation-vector exponential. The core folds the front end's output into one
// padded product, skips K's exact-zero rows and uses a Taylor polynomial (docs/performance.md).
//
// The set-up (M and K) is taken from the core's ArraySolver for the same geometry: the benchmark
// compares the per-sample step, not the one-time construction. baseline_equivalence_test.cpp
// checks that this step and the core agree on the same inputs and state, step by step, within a
// rounding bound it derives.
#pragma once

#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <cstdint>

#include "gfins/nav_core/pipeline.hpp"
#include "gfins/sample/raw_sample.hpp"

namespace gfins::bench {

template <typename T>
class BaselineStep {
 public:
  using MatX = Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic>;
  using VecX = Eigen::Matrix<T, Eigen::Dynamic, 1>;

  /// `config` as given to NavPipeline::configure; `solver` the core's solver of the geometry the
  /// compensator selects (NavPipeline::solver()).
  BaselineStep(const nav::PipelineConfig<T>& config, const nav::ArraySolver<T, 6>& solver)
      : kind_(config.compensator),
        gravity_(config.gravity),
        gain_(6),
        offset_(6),
        m_(solver.m()),
        k_(solver.k()),
        theta_(3, 6),
        drho_(3, 6),
        c_beta_(3, 3),
        c_alpha_(3, 3) {
    const auto& fe = config.front_end;
    for (int j = 0; j < 6; ++j) {
      const auto i = static_cast<std::size_t>(j);
      gain_(j) = fe.volts_per_count[i] * fe.gravity_mps2 / fe.scale_v_per_g[i];
      offset_(j) = fe.bias_g[i] * fe.gravity_mps2;
      theta_.col(j) = config.nominal.theta_b[i];
      drho_.col(j) = config.misalignment.drho_b[i];
    }
    c_beta_ = nav::set_matrix(config.misalignment.orientation.beta);
    c_alpha_ = nav::set_matrix(config.misalignment.orientation.alpha);
    c_beta_inv_ = c_beta_.inverse();
    c_alpha_inv_ = c_alpha_.inverse();
    period_s_ = T(1) / static_cast<T>(config.sample_rate_hz);
  }

  void start(const nav::NavState<T>& initial, const RawSample& first) {
    state_ = initial;
    state_.q_nb.normalize();
    const VecX s = compensate(front_end(first.counts), initial.w_b, initial.wdot_b);
    const VecX u = solve(s, to_x(initial.w_b));
    state_.wdot_b = u.head(3);
    state_.f_b = u.tail(3);
    state_.a_n = state_.q_nb * state_.f_b + gravity_.g_n(state_.r_n);
    v_sum_ = to_x(state_.v_n);
    v_carry_ = VecX::Zero(3);
    r_sum_ = to_x(state_.r_n);
    r_carry_ = VecX::Zero(3);
    last_seq_ = initial.seq;
  }

  /// Takes over another implementation's state after a step (baseline_equivalence_test.cpp
  /// compares one step at a time from the same state): attitude, ω, ω̇, f, a, v and r as given,
  /// the Kahan carries zero (the other side's carries are not part of NavState; the test's bound
  /// allows for them).
  void resync(const nav::NavState<T>& s) {
    state_ = s;
    v_sum_ = to_x(s.v_n);
    v_carry_ = VecX::Zero(3);
    r_sum_ = to_x(s.r_n);
    r_carry_ = VecX::Zero(3);
    last_seq_ = s.seq;
  }

  void step(const RawSample& sample) {
    const std::uint32_t seq = sample.seq;
    const T h = period_s_ * static_cast<T>(seq - last_seq_);
    last_seq_ = seq;
    const VecX s = compensate(front_end(sample.counts), state_.w_b, state_.wdot_b);
    const VecX w0 = to_x(state_.w_b);
    const VecX wdot0 = to_x(state_.wdot_b);
    // Heun: predictor with the full K product, then the trapezoid.
    const VecX w_pred = w0 + h * wdot0;
    const VecX u_pred = solve(s, w_pred);
    const VecX w1 = w0 + (h / T(2)) * (wdot0 + u_pred.head(3));
    const VecX u1 = solve(s, w1);
    // Attitude: two-sample rotation vector, exponential with sin/cos.
    const VecX phi = (h / T(2)) * (w0 + w1) + (h * h / T(12)) * cross(w0, w1);
    const T angle = phi.norm();
    nav::Quat<T> dq = nav::Quat<T>::Identity();
    if (angle > T(0)) {
      const T sc = std::sin(angle / T(2)) / angle;
      dq = nav::Quat<T>(std::cos(angle / T(2)), sc * phi(0), sc * phi(1), sc * phi(2));
    }
    const nav::Quat<T> q1 = (state_.q_nb * dq).normalized();
    const nav::Vec3<T> f1 = u1.tail(3);
    const VecX a0 = to_x(state_.a_n);
    const VecX a1 = to_x(q1 * f1 + gravity_.g_n(r_sum_));
    const VecX v0 = v_sum_;
    kahan_add(v_sum_, v_carry_, (h / T(2)) * (a0 + a1));
    kahan_add(r_sum_, r_carry_, h * v0 + (h * h / T(6)) * (T(2) * a0 + a1));
    state_.t_ns = sample.t_ns;
    state_.seq = seq;
    state_.q_nb = q1;
    state_.w_b = w1;
    state_.wdot_b = u1.head(3);
    state_.f_b = f1;
    state_.a_n = a1;
    state_.v_n = v_sum_;
    state_.r_n = r_sum_;
  }

  const nav::NavState<T>& state() const { return state_; }

 private:
  static VecX to_x(const nav::Vec3<T>& v) { return VecX(v); }

  static VecX cross(const VecX& a, const VecX& b) {
    VecX c(3);
    c << a(1) * b(2) - a(2) * b(1), a(2) * b(0) - a(0) * b(2), a(0) * b(1) - a(1) * b(0);
    return c;
  }

  static void kahan_add(VecX& sum, VecX& carry, const VecX& delta) {
    const VecX y = delta - carry;
    const VecX t = sum + y;
    carry = (t - sum) - y;
    sum = t;
  }

  // s**_j = counts_j · LSB_j · g / SF_j − b_j · g (paper eq. (21)).
  VecX front_end(const std::array<std::int32_t, 6>& counts) const {
    VecX c(6);
    for (int j = 0; j < 6; ++j) c(j) = static_cast<T>(counts[static_cast<std::size_t>(j)]);
    return gain_.cwiseProduct(c) - offset_;
  }

  // The paper's compensator set by set: location (eqs. (27)/(28)), then orientation ((29)/(30)).
  VecX compensate(const VecX& s_raw, const nav::Vec3<T>& w3, const nav::Vec3<T>& wdot3) const {
    if (kind_ != nav::CompensatorKind::kPaper) return s_raw;
    const VecX w = to_x(w3);
    const VecX wdot = to_x(wdot3);
    VecX s = s_raw;
    const auto one_set = [&](const std::array<int, 3>& set, const MatX& c, const MatX& c_inv) {
      VecX df_theta(3);
      VecX s2(3);
      for (int i = 0; i < 3; ++i) {
        const int j = set[static_cast<std::size_t>(i)];
        const VecX d = drho_.col(j);
        const VecX df = cross(w, cross(w, d)) + cross(wdot, d);  // eq. (22)
        df_theta(i) = theta_.col(j).dot(df);
        s2(i) = s_raw(j);
      }
      const VecX s_star = s2 - c * df_theta;
      const VecX s_ideal = c_inv * s_star;
      for (int i = 0; i < 3; ++i) s(set[static_cast<std::size_t>(i)]) = s_ideal(i);
    };
    one_set(nav::kSetBeta, c_beta_, c_beta_inv_);
    one_set(nav::kSetAlpha, c_alpha_, c_alpha_inv_);
    return s;
  }

  // [ω̇; f] = M s − K m(ω), eqs. (4)-(6), all six rows of both products.
  VecX solve(const VecX& s, const VecX& w) const {
    VecX m(6);
    m << w(0) * w(0), w(1) * w(1), w(2) * w(2), w(1) * w(2), w(0) * w(2), w(0) * w(1);
    return m_ * s - k_ * m;
  }

  nav::CompensatorKind kind_;
  nav::GravityModel<T> gravity_;
  VecX gain_;
  VecX offset_;
  MatX m_;
  MatX k_;
  MatX theta_;
  MatX drho_;
  MatX c_beta_;
  MatX c_alpha_;
  MatX c_beta_inv_;
  MatX c_alpha_inv_;
  T period_s_ = T(0.001);
  std::uint32_t last_seq_ = 0;
  nav::NavState<T> state_{};
  VecX v_sum_;
  VecX v_carry_;
  VecX r_sum_;
  VecX r_carry_;
};

}  // namespace gfins::bench
