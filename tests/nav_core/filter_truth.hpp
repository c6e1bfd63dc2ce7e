// Test support for the aided filter: analytic trajectories and the array's forward physics,
// written here independently of the code under test.
//
// Sensor j at ρ_j with axis θ_j reads s_j = θ_j·(f + ω̇×ρ_j + ω×(ω×ρ_j)) + b_j + n_j with
// f = C_n^b (a_n − g_n), the rigid-body kinematics of docs/math.md, eq. (22) read correctly.
#pragma once

#include <array>
#include <cmath>
#include <random>

#include "gfins/nav_core/geometry.hpp"
#include "gfins/nav_core/nav_state.hpp"

namespace gfins::nav::testing {

struct Truth {
  Quat<double> q_nb = Quat<double>::Identity();
  Vec3<double> w_b = Vec3<double>::Zero();
  Vec3<double> wdot_b = Vec3<double>::Zero();
  Vec3<double> a_n = Vec3<double>::Zero();
  Vec3<double> v_n = Vec3<double>::Zero();
  Vec3<double> r_n = Vec3<double>::Zero();
};

inline constexpr double kG = 9.80665;  // constant gravity of the tests, m/s², down

/// At rest with attitude q.
inline Truth rest(const Quat<double>& q) {
  Truth t;
  t.q_nb = q;
  return t;
}

/// Level figure eight r = [R sin Ωt, (R/2) sin 2Ωt, 0], heading along the track (ψ =
/// atan2(v_E, v_N), roll = pitch = 0), so ω = [0, 0, ψ̇] and ω̇ = [0, 0, ψ̈] in closed form.
/// The speed never falls below 0.66 RΩ; turns both ways with centripetal accelerations ~RΩ².
inline Truth figure_eight(double t, double radius_m, double omega_rps) {
  const double r = radius_m;
  const double w = omega_rps;
  const double s1 = std::sin(w * t), c1 = std::cos(w * t);
  const double s2 = std::sin(2 * w * t), c2 = std::cos(2 * w * t);
  Truth x;
  x.r_n = Vec3<double>(r * s1, 0.5 * r * s2, 0);
  x.v_n = Vec3<double>(r * w * c1, r * w * c2, 0);
  x.a_n = Vec3<double>(-r * w * w * s1, -2 * r * w * w * s2, 0);
  const Vec3<double> j(-r * w * w * w * c1, -4 * r * w * w * w * c2, 0);  // jerk
  const double vn = x.v_n.x(), ve = x.v_n.y(), an = x.a_n.x(), ae = x.a_n.y();
  const double v2 = vn * vn + ve * ve;
  const double num = vn * ae - ve * an;  // ψ̇ = num / v²
  const double dnum = vn * j.y() - ve * j.x();
  const double dv2 = 2 * (vn * an + ve * ae);
  x.q_nb = Quat<double>(Eigen::AngleAxisd(std::atan2(ve, vn), Vec3<double>::UnitZ()));
  x.w_b = Vec3<double>(0, 0, num / v2);
  x.wdot_b = Vec3<double>(0, 0, (dnum * v2 - num * dv2) / (v2 * v2));
  return x;
}

/// The six outputs of an ideal array (no bias, no noise) for the truth x.
inline Vec6<double> ideal_outputs(const ArrayGeometry<double, 6>& g, const Truth& x) {
  const Vec3<double> f_b = x.q_nb.conjugate() * (x.a_n - Vec3<double>(0, 0, kG));
  Vec6<double> s;
  for (std::size_t j = 0; j < 6; ++j) {
    const Vec3<double>& rho = g.rho_b[j];
    s(static_cast<int>(j)) =
        g.theta_b[j].dot(f_b + x.wdot_b.cross(rho) + x.w_b.cross(x.w_b.cross(rho)));
  }
  return s;
}

/// Sensor errors: a random-constant bias per sensor and white noise per sample.
class SensorErrors {
 public:
  SensorErrors(double bias_sigma, double noise_sigma, unsigned seed)
      : rng_(seed), noise_sigma_(noise_sigma) {
    for (int j = 0; j < 6; ++j) bias_(j) = bias_sigma * unit_(rng_);
  }
  Vec6<double> apply(const Vec6<double>& s) {
    Vec6<double> out = s + bias_;
    for (int j = 0; j < 6; ++j) out(j) += noise_sigma_ * unit_(rng_);
    return out;
  }
  const Vec6<double>& bias() const { return bias_; }
  void set_bias(const Vec6<double>& b) { bias_ = b; }
  double normal() { return unit_(rng_); }

 private:
  std::mt19937_64 rng_;
  std::normal_distribution<double> unit_{0.0, 1.0};
  double noise_sigma_;
  Vec6<double> bias_ = Vec6<double>::Zero();
};

template <typename T>
NavState<T> nav_state_of(const Truth& x) {
  NavState<double> s;
  s.q_nb = x.q_nb;
  s.w_b = x.w_b;
  s.wdot_b = x.wdot_b;
  s.v_n = x.v_n;
  s.r_n = x.r_n;
  s.a_n = x.a_n;
  return s.template cast<T>();
}

}  // namespace gfins::nav::testing
