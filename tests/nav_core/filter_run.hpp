// Test support: the aided strapdown (Strapdown + ErrorStateFilter) driven by the forward physics
// of filter_truth.hpp, with the errors against the truth recorded once per second.
#pragma once

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <functional>
#include <vector>

#include "gfins/nav_core/error_model.hpp"
#include "gfins/nav_core/filter/error_state_filter.hpp"
#include "nav_core/filter_truth.hpp"

namespace gfins::nav::testing {

struct RunSpec {
  double rate_hz = 200;
  int decimation = 10;  // propagation at 20 Hz
  double duration_s = 60;
  double noise = 3e-4;       // per-sensor white σ per sample, m/s²
  double bias_sigma = 3e-4;  // per-sensor random-constant bias σ, m/s²
  unsigned seed = 1;
  std::function<Truth(double)> truth = [](double) { return rest(Quat<double>::Identity()); };
  bool aided = true;
  bool standstill = false;  // ZUPT + ZARU at every propagation
  bool gnss = false;        // position + velocity at gnss_rate_hz
  double gnss_rate_hz = 5;
  double pos_sigma = 1.5;
  double vel_sigma = 0.1;
  double outlier_m = 0;  // added to the north position of the fix at outlier_t_s
  double outlier_t_s = -1;
  Vec3<double> lever_true_b = Vec3<double>::Zero();
  Vec3<double> lever_filter_b = Vec3<double>::Zero();
  double latency_s = 0;       // fix valid this long before it is delivered
  bool latency_known = true;  // false: the fix is stamped with its delivery time
  bool initial_error = true;  // navigation starts with an error drawn from P0
  double init_tilt = 2e-3, init_heading = 1e-2, init_pos = 1.0, init_vel = 0.05, init_rate = 1e-4;
};

struct Epoch {
  double t = 0;
  Eigen::Matrix<double, 18, 1> err = Eigen::Matrix<double, 18, 1>::Zero();  // x = est − truth*
  Eigen::Matrix<double, 18, 18> p = Eigen::Matrix<double, 18, 18>::Zero();
};
// *bias block: β − β̂, the filter's own convention (measurement.hpp).

template <typename T>
struct RunResult {
  std::vector<Epoch> epochs;
  FilterCounters counters;
  std::vector<UpdateOutcome> gnss_position_outcomes;
  bool finite = true;
  Eigen::Matrix<double, 6, 1> beta_true = Eigen::Matrix<double, 6, 1>::Zero();
  Eigen::Matrix<double, 6, 1> beta_est = Eigen::Matrix<double, 6, 1>::Zero();
  double max_asymmetry = 0;    // max |P − Pᵀ| over the run (relative to max |P|)
  double min_eigen_ratio = 1;  // min over epochs of λ_min / λ_max of D^-1/2 P D^-1/2
};

inline FilterConfig<double> filter_config(const RunSpec& spec) {
  FilterConfig<double> c;
  c.sample_rate_hz = spec.rate_hz;
  c.noise.white_sigma_mps2.fill(spec.noise);
  c.noise.bias_sigma_mps2.fill(spec.bias_sigma);
  c.init_sigma_tilt_rad = spec.init_tilt;
  c.init_sigma_heading_rad = spec.init_heading;
  c.init_sigma_pos_m = spec.init_pos;
  c.init_sigma_vel_mps = spec.init_vel;
  c.init_sigma_rate_rps = spec.init_rate;
  c.gnss_lever_arm_b = spec.lever_filter_b;
  return c;
}

template <typename T>
FilterConfig<T> cast_config(const FilterConfig<double>& d) {
  FilterConfig<T> c;
  c.sample_rate_hz = static_cast<T>(d.sample_rate_hz);
  for (std::size_t j = 0; j < 6; ++j) {
    c.noise.white_sigma_mps2[j] = static_cast<T>(d.noise.white_sigma_mps2[j]);
    c.noise.bias_sigma_mps2[j] = static_cast<T>(d.noise.bias_sigma_mps2[j]);
    c.noise.bias_rw_mps2_sqrt_s[j] = static_cast<T>(d.noise.bias_rw_mps2_sqrt_s[j]);
  }
  c.init_sigma_tilt_rad = static_cast<T>(d.init_sigma_tilt_rad);
  c.init_sigma_heading_rad = static_cast<T>(d.init_sigma_heading_rad);
  c.heading_known = d.heading_known;
  c.init_sigma_pos_m = static_cast<T>(d.init_sigma_pos_m);
  c.init_sigma_vel_mps = static_cast<T>(d.init_sigma_vel_mps);
  c.init_sigma_rate_rps = static_cast<T>(d.init_sigma_rate_rps);
  c.gate_probability = static_cast<T>(d.gate_probability);
  c.innovation_gate = d.innovation_gate;
  c.zupt_sigma_mps = static_cast<T>(d.zupt_sigma_mps);
  c.zaru_sigma_rps = static_cast<T>(d.zaru_sigma_rps);
  c.gnss_lever_arm_b = d.gnss_lever_arm_b.template cast<T>();
  c.track_min_speed_mps = static_cast<T>(d.track_min_speed_mps);
  return c;
}

template <typename T>
RunResult<T> run_aided(const RunSpec& spec, const FilterConfig<double>& config_d) {
  using Filter = ErrorStateFilter<T>;
  static Filter filter;  // static: 18×18 matrices and the history stay off the test's stack
  const auto geometry = table1_geometry<double>(0.1);
  const auto solver = ArraySolver<T>::create(geometry.template cast<T>()).value();
  const auto gravity = GravityModel<T>::constant(static_cast<T>(kG));
  Strapdown<T> nav(solver, gravity);
  SensorErrors errors(spec.bias_sigma, spec.noise, spec.seed);
  const auto solver_d = ArraySolver<double>::create(geometry).value();
  RunResult<T> out;
  out.beta_true = solver_d.m() * errors.bias();

  // Initial navigation error drawn from P0 (so the filter is consistent from the start).
  const Truth x0 = spec.truth(0.0);
  NavState<double> init = nav_state_of<double>(x0);
  if (spec.initial_error) {
    const Vec3<double> phi(spec.init_tilt * errors.normal(), spec.init_tilt * errors.normal(),
                           spec.init_heading * errors.normal());
    init.q_nb = quat_from_rotation_vector<double>(-phi) * x0.q_nb;  // Ĉ = exp(−[φ×]) C
    for (int i = 0; i < 3; ++i) {
      init.r_n(i) += spec.init_pos * errors.normal();
      init.v_n(i) += spec.init_vel * errors.normal();
      init.w_b(i) += spec.init_rate * errors.normal();
    }
  }
  const double h = 1.0 / spec.rate_hz;
  const auto outputs = [&](double t) {
    return Vec6<T>(errors.apply(ideal_outputs(geometry, spec.truth(t))).template cast<T>());
  };
  nav.initialize(init.template cast<T>(), outputs(0.0));
  if (!filter.configure(cast_config<T>(config_d)).is_ok()) return out;
  filter.start(nav);

  const long steps = std::lround(spec.duration_s * spec.rate_hz);
  const long gnss_every = std::lround(spec.rate_hz / spec.gnss_rate_hz);
  const long record_every = std::lround(spec.rate_hz);
  for (long k = 1; k <= steps; ++k) {
    const double t = static_cast<double>(k) * h;
    const auto t_ns = static_cast<std::int64_t>(std::llround(t * 1e9));
    nav.step(outputs(t), static_cast<T>(h), t_ns, static_cast<std::uint32_t>(k));
    if (!spec.aided) {
      if (k % record_every != 0) continue;
    } else if (k % spec.decimation == 0) {
      (void)filter.propagate(nav, static_cast<T>(h * spec.decimation));
      if (spec.standstill) {
        (void)filter.update_zupt(nav);
        (void)filter.update_zaru(nav);
      }
      if (spec.gnss && k % gnss_every == 0) {
        const double tv = t - spec.latency_s;
        const Truth xv = spec.truth(tv);
        GnssFix<T> pos;
        GnssFix<T> vel;
        pos.t_valid_ns =
            spec.latency_known ? static_cast<std::int64_t>(std::llround(tv * 1e9)) : t_ns;
        vel.t_valid_ns = pos.t_valid_ns;
        Vec3<double> rp = xv.r_n + xv.q_nb * spec.lever_true_b;
        Vec3<double> vp = xv.v_n + xv.q_nb * xv.w_b.cross(spec.lever_true_b);
        for (int i = 0; i < 3; ++i) {
          rp(i) += spec.pos_sigma * errors.normal();
          vp(i) += spec.vel_sigma * errors.normal();
        }
        if (spec.outlier_t_s >= 0 && std::abs(t - spec.outlier_t_s) < 0.5 * h) {
          rp.x() += spec.outlier_m;
        }
        pos.value_n = rp.template cast<T>();
        pos.sigma = Vec3<T>::Constant(static_cast<T>(spec.pos_sigma));
        vel.value_n = vp.template cast<T>();
        vel.sigma = Vec3<T>::Constant(static_cast<T>(spec.vel_sigma));
        out.gnss_position_outcomes.push_back(filter.update_gnss_position(nav, pos));
        (void)filter.update_gnss_velocity(nav, vel);
      }
    }
    if (k % record_every != 0) continue;
    const Truth x = spec.truth(t);
    const NavState<double> s = nav.state().template cast<double>();
    Epoch e;
    e.t = t;
    e.err.segment<3>(0) = attitude_error_n(s.q_nb, x.q_nb);
    e.err.segment<3>(3) = s.r_n - x.r_n;
    e.err.segment<3>(6) = s.v_n - x.v_n;
    e.err.segment<3>(9) = s.w_b - x.w_b;
    e.err.segment<3>(12) =
        out.beta_true.template head<3>() - nav.bias_wdot().template cast<double>();
    e.err.segment<3>(15) = out.beta_true.template tail<3>() - nav.bias_f().template cast<double>();
    e.p = filter.covariance().template cast<double>();
    out.finite = out.finite && e.err.allFinite() && e.p.allFinite();
    const double scale = e.p.cwiseAbs().maxCoeff();
    out.max_asymmetry = std::max(
        out.max_asymmetry, (e.p - e.p.transpose()).cwiseAbs().maxCoeff() / (scale > 0 ? scale : 1));
    const Eigen::Matrix<double, 18, 1> d = e.p.diagonal().cwiseSqrt().cwiseInverse();
    const Eigen::Matrix<double, 18, 18> corr = d.asDiagonal() * e.p * d.asDiagonal();
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 18, 18>> eig(corr);
    out.min_eigen_ratio =
        std::min(out.min_eigen_ratio, eig.eigenvalues().minCoeff() / eig.eigenvalues().maxCoeff());
    out.epochs.push_back(e);
  }
  out.counters = filter.counters();
  out.beta_est << nav.bias_wdot().template cast<double>(), nav.bias_f().template cast<double>();
  return out;
}

/// The largest |error| / bound of a block over the epochs after t0.
inline double max_abs(const std::vector<Epoch>& e, int first, int n, double t0 = 0) {
  double m = 0;
  for (const Epoch& x : e) {
    if (x.t < t0) continue;
    m = std::max(m, x.err.segment(first, n).cwiseAbs().maxCoeff());
  }
  return m;
}

/// Fraction of (epoch, axis) pairs after t0 whose |error| is within k σ of the filter.
inline double fraction_within(const std::vector<Epoch>& e, int first, int n, double k, double t0) {
  int in = 0, all = 0;
  for (const Epoch& x : e) {
    if (x.t < t0) continue;
    for (int i = first; i < first + n; ++i) {
      ++all;
      if (std::abs(x.err(i)) <= k * std::sqrt(x.p(i, i))) ++in;
    }
  }
  return all > 0 ? static_cast<double>(in) / all : 0.0;
}

}  // namespace gfins::nav::testing
