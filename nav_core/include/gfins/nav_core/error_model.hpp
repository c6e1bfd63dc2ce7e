// Linear error-state model of the gyro-free strapdown (paper §3, eqs. (7)-(13)), generalised from
// the Table 1 cube to any array through the solver's maps M and K (geometry.hpp).
//
// Error state (docs/error-model.md derives every block):
//   x = [φ (3), δr_n (3), δv_n (3), δω_b (3), b (N)]
//   φ     attitude error, navigation frame, eq. (7): Ĉ_b^n = (I − [φ×]) C_b^n, rad
//   δr_n  r̂_n − r_n, m, NED;  δv_n  v̂_n − v_n, m/s, NED;  δω_b  ω̂_b − ω_b, rad/s, body FRD
//   b     per-sensor output bias (random constant and/or random walk), m/s²
// Continuous dynamics, with δs the error of the compensated outputs (m/s²) and
// δ[ω̇; f] = M δs − K J(ω) δω, J = ∂m/∂ω the Jacobian of the centripetal monomials:
//   φ̇   = −C_b^n δω                                             eq. (8)
//   δṙ  = δv                                                    eq. (10)
//   δv̇  = [(C_b^n f_b)×] φ + G_r δr + C_b^n (M_f δs − K_f J δω)   eq. (12), ρ misprint fixed
//   δω̇  = M_w δs − K_w J δω                                      eq. (13), δg term dropped
//   ḃ   = w_b (bias random walk)
// (M_w, K_w the top three rows, M_f, K_f the bottom three.) For Table 1, M_w = S/(2ρ) and
// K_w = 0, K_f J δω = −ρ δω² of eq. (11)/(12) with the ρ factor the paper drops. The δg term of
// (11)-(13) vanishes because the computed gravity projection cancels exactly in [ω̇; f]
// (S·Θᵀ = 0), and the navigation core adds gravity back in the n frame, where only its
// gradient G_r (∂g_n/∂r_n, the free-air term) enters.
//
// Discretisation over a step h between two truth points x0, x1: F̄ = (F(x0) + F(x1))/2,
// Φ = I + F̄ h + F̄² h²/2 (second order, matching the integrator's order), inputs by the
// trapezoid rule, and Q_d = Q_c h + (F̄ Q_c + Q_c F̄ᵀ) h²/2 + F̄ Q_c F̄ᵀ h³/3 (Van Loan's series
// to the same order). White noise of σ per sample at interval h is the PSD σ² h.
//
// No heap, no exceptions: every matrix is fixed-size (18×18 for six sensors, 2.6 kB in double).
#pragma once

#include <array>
#include <cstddef>

#include "gfins/nav_core/geometry.hpp"
#include "gfins/nav_core/gravity.hpp"
#include "gfins/nav_core/nav_state.hpp"
#include "gfins/status/status.hpp"

namespace gfins::nav {

/// Offsets of the blocks of the error state.
namespace err_idx {
inline constexpr int kPhi = 0;    // φ, rad, n frame
inline constexpr int kPos = 3;    // δr_n, m
inline constexpr int kVel = 6;    // δv_n, m/s
inline constexpr int kRate = 9;   // δω_b, rad/s
inline constexpr int kBias = 12;  // b_j, m/s², one per sensor
inline constexpr int kNav = 12;   // number of navigation error states
}  // namespace err_idx

/// Stochastic error sources of the outputs, per sensor (m/s² after the front end).
template <typename T, int N = kNumSensors>
struct SensorNoiseSpec {
  std::array<T, N> white_sigma_mps2{};     // white noise σ per sample
  std::array<T, N> bias_rw_mps2_sqrt_s{};  // bias random walk, m/s² per √s
  std::array<T, N> bias_sigma_mps2{};      // random-constant bias σ (initial covariance)
};

/// Jacobian J(ω) = ∂m/∂ω of m = [ωx², ωy², ωz², ωyωz, ωxωz, ωxωy] (geometry.hpp).
template <typename T>
Eigen::Matrix<T, 6, 3> centripetal_jacobian(const Vec3<T>& w) {
  Eigen::Matrix<T, 6, 3> j;
  j << T(2) * w.x(), T(0), T(0),  //
      T(0), T(2) * w.y(), T(0),   //
      T(0), T(0), T(2) * w.z(),   //
      T(0), w.z(), w.y(),         //
      w.z(), T(0), w.x(),         //
      w.y(), w.x(), T(0);
  return j;
}

/// φ of eq. (7) between a computed and a true attitude: Ĉ Cᵀ = exp(−[φ×]), so
/// φ = −rotvec(q̂_nb ⊗ q_nb⁻¹) (exact for any size; the linear model holds while |φ| ≪ 1).
template <typename T>
Vec3<T> attitude_error_n(const Quat<T>& q_nb_computed, const Quat<T>& q_nb_true) {
  return -rotation_vector_from_quat<T>(q_nb_computed * q_nb_true.conjugate());
}

template <typename T, int N = kNumSensors>
class ErrorModel {
 public:
  static constexpr int kStates = err_idx::kNav + N;
  using Solver = ArraySolver<T, N>;
  using Outputs = typename Solver::Outputs;
  using StateVec = Eigen::Matrix<T, kStates, 1>;
  using StateMat = Eigen::Matrix<T, kStates, kStates>;
  using InputMat = Eigen::Matrix<T, kStates, N>;
  using NavMat = Eigen::Matrix<T, err_idx::kNav, err_idx::kNav>;
  using NavInputMat = Eigen::Matrix<T, err_idx::kNav, 6>;

  ErrorModel() = default;
  /// `solver` is the one the navigation uses (nominal or calibrated geometry); `gravity` gives
  /// the gradient G_r.
  ErrorModel(const Solver& solver, const GravityModel<T>& gravity)
      : solver_(solver),
        dgz_drz_(gravity.g_n(Vec3<T>(T(0), T(0), T(1))).z() - gravity.g_n(Vec3<T>::Zero()).z()) {}

  const Solver& solver() const { return solver_; }

  /// ∂ẋ/∂δs: how an output error drives the state (δv and δω rows; eqs. (12)/(13)).
  InputMat input_matrix(const NavState<T>& x) const {
    InputMat g = InputMat::Zero();
    const Mat3<T> c_nb = x.q_nb.toRotationMatrix();
    g.template block<3, N>(err_idx::kVel, 0) = c_nb * solver_.m().template bottomRows<3>();
    g.template block<3, N>(err_idx::kRate, 0) = solver_.m().template topRows<3>();
    return g;
  }

  /// ∂ẋ_nav/∂δ[ω̇; f]: how an error of the array's solution [ω̇; f] (rad/s², m/s², body) drives
  /// the twelve navigation errors; input_matrix() is this times M (δ[ω̇; f] = M δs).
  NavInputMat array_input_matrix(const NavState<T>& x) const {
    NavInputMat g = NavInputMat::Zero();
    g.template block<3, 3>(err_idx::kVel, 3) = x.q_nb.toRotationMatrix();  // eq. (12): C_b^n δf
    g.template block<3, 3>(err_idx::kRate, 0) = Mat3<T>::Identity();       // eq. (13): δω̇
    return g;
  }

  /// The navigation block of F (12×12: φ, δr, δv, δω) at the point x.
  NavMat navigation_continuous(const NavState<T>& x) const {
    using namespace err_idx;
    NavMat f = NavMat::Zero();
    const Mat3<T> c_nb = x.q_nb.toRotationMatrix();
    const Eigen::Matrix<T, 6, 3> kj = solver_.k() * centripetal_jacobian(x.w_b);
    f.template block<3, 3>(kPhi, kRate) = -c_nb;                                // eq. (8)
    f.template block<3, 3>(kPos, kVel) = Mat3<T>::Identity();                   // eq. (10)
    f.template block<3, 3>(kVel, kPhi) = skew<T>(c_nb * x.f_b);                 // eq. (12)
    f(kVel + 2, kPos + 2) = dgz_drz_;                                           // gravity gradient
    f.template block<3, 3>(kVel, kRate) = -c_nb * kj.template bottomRows<3>();  // eq. (12) ρδω²
    f.template block<3, 3>(kRate, kRate) = -kj.template topRows<3>();           // eq. (13)
    return f;
  }

  /// Covariance (per second of PSD) of the white output noise seen through the array's solve:
  /// Cov(M n) = M diag(σ_j²) Mᵀ for independent per-sensor noise n_j of σ_j. 6×6 and correlated
  /// in general; with `scale` = h (the sample interval) it is the PSD σ² h of continuous_noise.
  Mat6<T> array_noise(const std::array<T, N>& sigma, T scale) const {
    Outputs q;
    for (int j = 0; j < N; ++j) {
      const T s = sigma[static_cast<std::size_t>(j)];
      q(j) = s * s * scale;
    }
    const typename Solver::MapMatrix m = solver_.m();
    return m * q.asDiagonal() * m.transpose();
  }

  /// Continuous F at the point x (the truth, or the navigation solution in a filter).
  StateMat continuous(const NavState<T>& x) const {
    StateMat f = StateMat::Zero();
    f.template topLeftCorner<err_idx::kNav, err_idx::kNav>() = navigation_continuous(x);
    f.template block<kStates, N>(0, err_idx::kBias) = input_matrix(x);  // δs = b
    return f;
  }

  /// Φ over one step from x0 to x1 (h = dt_s > 0), second order in h.
  Result<StateMat> transition(const NavState<T>& x0, const NavState<T>& x1, T dt_s) const {
    if (!(dt_s > T(0))) {
      return Status(ErrorCode::kInvalidArgument, "error model: step dt_s must be positive");
    }
    const StateMat fh = (continuous(x0) + continuous(x1)) * (dt_s / T(2));
    return StateMat(StateMat::Identity() + fh + fh * fh / T(2));
  }

  /// One deterministic step: x ← Φ x + h/2 (Φ G(x0) δs0 + G(x1) δs1), the trapezoid rule for an
  /// output error δs known at both samples (a scale-factor or misalignment residual).
  Status propagate(const NavState<T>& x0, const NavState<T>& x1, T dt_s, const Outputs& ds0,
                   const Outputs& ds1, StateVec& x) const {
    const Result<StateMat> phi = transition(x0, x1, dt_s);
    if (!phi.is_ok()) return phi.status();
    propagate(phi.value(), x0, x1, dt_s, ds0, ds1, x);
    return Status::ok();
  }

  /// The same step with Φ = transition(x0, x1, dt_s) computed by the caller, who shares one Φ
  /// between the many error sources propagated along the same step (bit for bit the same x).
  void propagate(const StateMat& phi, const NavState<T>& x0, const NavState<T>& x1, T dt_s,
                 const Outputs& ds0, const Outputs& ds1, StateVec& x) const {
    const StateVec u0 = input_matrix(x0) * ds0;
    const StateVec u1 = input_matrix(x1) * ds1;
    x = phi * x + (dt_s / T(2)) * (phi * u0 + u1);
  }

  /// Q_c: white output noise as the PSD σ² h (per-sample σ at interval h) and bias random walk.
  StateMat continuous_noise(const NavState<T>& x, const SensorNoiseSpec<T, N>& spec, T dt_s) const {
    Outputs q = Outputs::Zero();
    for (int j = 0; j < N; ++j) {
      const T s = spec.white_sigma_mps2[static_cast<std::size_t>(j)];
      q(j) = s * s * dt_s;
    }
    const InputMat g = input_matrix(x);
    StateMat qc = g * q.asDiagonal() * g.transpose();
    for (int j = 0; j < N; ++j) {
      const T rw = spec.bias_rw_mps2_sqrt_s[static_cast<std::size_t>(j)];
      qc(err_idx::kBias + j, err_idx::kBias + j) += rw * rw;
    }
    return qc;
  }

  /// Q_d over one step (Van Loan's series to h³, see the file comment).
  Result<StateMat> process_noise(const NavState<T>& x0, const NavState<T>& x1,
                                 const SensorNoiseSpec<T, N>& spec, T dt_s) const {
    if (!(dt_s > T(0))) {
      return Status(ErrorCode::kInvalidArgument, "error model: step dt_s must be positive");
    }
    const StateMat qc =
        (continuous_noise(x0, spec, dt_s) + continuous_noise(x1, spec, dt_s)) / T(2);
    const StateMat f = (continuous(x0) + continuous(x1)) / T(2);
    const T h = dt_s;
    const StateMat fq = f * qc;
    return StateMat(qc * h + (fq + fq.transpose()) * (h * h / T(2)) +
                    f * qc * f.transpose() * (h * h * h / T(3)));
  }

  /// Initial covariance: zero navigation errors, random-constant biases of spec.bias_sigma.
  static StateMat initial_covariance(const SensorNoiseSpec<T, N>& spec) {
    StateMat p = StateMat::Zero();
    for (int j = 0; j < N; ++j) {
      const T s = spec.bias_sigma_mps2[static_cast<std::size_t>(j)];
      p(err_idx::kBias + j, err_idx::kBias + j) = s * s;
    }
    return p;
  }

  /// One covariance step P ← Φ P Φᵀ + Q_d.
  Status propagate_covariance(const NavState<T>& x0, const NavState<T>& x1,
                              const SensorNoiseSpec<T, N>& spec, T dt_s, StateMat& p) const {
    const Result<StateMat> phi = transition(x0, x1, dt_s);
    if (!phi.is_ok()) return phi.status();
    return propagate_covariance(phi.value(), x0, x1, spec, dt_s, p);
  }

  /// The same step with Φ = transition(x0, x1, dt_s) computed by the caller.
  Status propagate_covariance(const StateMat& phi, const NavState<T>& x0, const NavState<T>& x1,
                              const SensorNoiseSpec<T, N>& spec, T dt_s, StateMat& p) const {
    const Result<StateMat> qd = process_noise(x0, x1, spec, dt_s);
    if (!qd.is_ok()) return qd.status();
    p = phi * p * phi.transpose() + qd.value();
    p = (p + p.transpose()) / T(2);  // keep it symmetric against rounding
    return Status::ok();
  }

 private:
  Solver solver_{};
  T dgz_drz_ = T(0);  // ∂g_z/∂r_z, s⁻² (positive: gravity grows going down)
};

// Equivalent output errors δs (m/s²) of deterministic sensor errors at the point x, for the
// nominal geometry `g` the navigation uses. Each is exact to first order in the error.

/// Relative scale-factor error ε_j of sensor j: the output is (1 + ε_j) s_j, so δs_j = ε_j s_j.
template <typename T, int N>
Eigen::Matrix<T, N, 1> scale_factor_ds(const NavState<T>& x, const ArrayGeometry<T, N>& g, int j,
                                       T epsilon) {
  Eigen::Matrix<T, N, 1> ds = Eigen::Matrix<T, N, 1>::Zero();
  const auto sj = static_cast<std::size_t>(j);
  const Vec3<T>& rho = g.rho_b[sj];
  const Vec3<T> a = x.f_b + x.wdot_b.cross(rho) + x.w_b.cross(x.w_b.cross(rho));
  ds(j) = epsilon * g.theta_b[sj].dot(a);
  return ds;
}

/// Residual orientation error: sensor j senses along θ_j + dtheta (rad, ⊥ θ_j to first order),
/// so δs_j = dtheta · a_j with a_j the acceleration at its location (eqs. (14)/(15), (23)).
template <typename T, int N>
Eigen::Matrix<T, N, 1> orientation_ds(const NavState<T>& x, const ArrayGeometry<T, N>& g, int j,
                                      const Vec3<T>& dtheta) {
  Eigen::Matrix<T, N, 1> ds = Eigen::Matrix<T, N, 1>::Zero();
  const Vec3<T>& rho = g.rho_b[static_cast<std::size_t>(j)];
  const Vec3<T> a = x.f_b + x.wdot_b.cross(rho) + x.w_b.cross(x.w_b.cross(rho));
  ds(j) = dtheta.dot(a);
  return ds;
}

/// Residual location error: sensor j sits at ρ_j + drho (m), so
/// δs_j = θ_j · (ω̇ × Δρ + ω × (ω × Δρ)) (eq. (22) with its misprint fixed).
template <typename T, int N>
Eigen::Matrix<T, N, 1> location_ds(const NavState<T>& x, const ArrayGeometry<T, N>& g, int j,
                                   const Vec3<T>& drho) {
  Eigen::Matrix<T, N, 1> ds = Eigen::Matrix<T, N, 1>::Zero();
  const Vec3<T> a = x.wdot_b.cross(drho) + x.w_b.cross(x.w_b.cross(drho));
  ds(j) = g.theta_b[static_cast<std::size_t>(j)].dot(a);
  return ds;
}

}  // namespace gfins::nav
