// Angular rate from the centripetal terms of a redundant array (N ≥ 9), without integrating ω̇
// (docs/redundancy.md, "Angular rate from the centripetal terms").
//
// The outputs are s = H u + Q m(ω) + n, u = [ω̇; f], m(ω) = [ωx², ωy², ωz², ωyωz, ωxωz, ωxωy]
// (geometry.hpp). u enters linearly, so for a given ω its least-squares value is M (s − Q m(ω))
// and what is left is the parity residual r(ω) = P (s − Q m(ω)), P = I − H M (parity_monitor.hpp).
// ω is the minimiser of ‖r(ω)‖² (variable projection, Golub & Pereyra 1973): three unknowns
// against d = N − 6 parity equations, so N ≥ 9; at N = 9 (d = 3) other rates than ±ω can fit
// exactly, so an estimate is only called informative from N = 10 on. Gauss–Newton from a seed ω₀
// (the integrator's rate):
//   J(ω) = −P Q D(ω),  D = ∂m/∂ω (6×3, linear in ω),   ω ← ω − (JᵀJ)⁻¹ Jᵀ r(ω).
// m(−ω) = m(ω): −ω fits as well as ω, and the seed picks the sign (the solution is turned to the
// seed's side when ω·ω₀ < 0).
//
// Accuracy. With white noise of σ per sensor, the Fisher information about ω, u being unknown
// too, is JᵀJ / σ² (the Schur complement of the full information [H, Q D] of (u, ω) is exactly
// this, since P projects out the columns of H), so the Cramér–Rao bound is σ² (JᵀJ)⁻¹. D grows
// with ω, so the information grows with |ω|² (Skog, Nilsson, Händel, Nehorai, IEEE TSP 2016): at
// rest there is none, and an estimate is refused (informative = false) while the bound's total
// standard deviation √trace exceeds `max_relative_sigma` · |ω| (the linearisation behind
// Gauss–Newton and the bound is then no longer small against the rate itself).
//
// Static storage, no heap: P Q (N×6) is formed once from the solver; an estimate is a few
// 3×3 solves.
#pragma once

#include <Eigen/Cholesky>
#include <cmath>
#include <cstdint>

#include "gfins/nav_core/geometry.hpp"
#include "gfins/nav_core/geometry_impl.hpp"  // ArraySolver for any N
#include "gfins/nav_core/redundancy/parity_projector.hpp"
#include "gfins/status/status.hpp"

namespace gfins::nav {

template <typename T>
struct CentripetalRate {
  Vec3<T> w_b = Vec3<T>::Zero();         // rad/s, body
  Mat3<T> covariance = Mat3<T>::Zero();  // rad²/s², the Cramér–Rao bound at w_b for the stated σ
  int iterations = 0;
  bool converged = false;
  bool informative = false;  // the bound is small against |ω| (see above); w_b valid only then
};

template <typename T, int N>
class CentripetalRateEstimator {
 public:
  using Solver = ArraySolver<T, N>;
  using Outputs = typename Solver::Outputs;

  /// Forms P Q from the solver's geometry and active sensors (at least nine).
  [[nodiscard]] Status configure(const Solver& solver, T white_sigma_mps2,
                                 T max_relative_sigma = T(0.1)) {
    if (channel_count(solver.active()) < 9) {
      return Status(ErrorCode::kInvalidArgument,
                    "centripetal rate: nine active sensors needed (three unknowns against N − 6 "
                    "parity equations)");
    }
    if (!(white_sigma_mps2 > T(0)) || !std::isfinite(white_sigma_mps2) ||
        !(max_relative_sigma > T(0)) || !std::isfinite(max_relative_sigma)) {
      return Status(ErrorCode::kInvalidArgument,
                    "centripetal rate: positive finite sigma and relative limit required");
    }
    const Eigen::Matrix<T, N, N> p = parity_projector(solver);
    p_ = p;
    pq_ = p * centripetal_matrix(solver);
    dof_ = channel_count(solver.active()) - 6;
    sigma2_ = white_sigma_mps2 * white_sigma_mps2;
    max_relative_sigma_ = max_relative_sigma;
    return Status::ok();
  }

  /// ω from one sample's outputs s (m/s²), Gauss–Newton from `seed` (rad/s; its sign decides
  /// between ω and −ω). At most `max_iterations`; converged when a step is below 1e-6 rad/s
  /// relative to |ω|.
  CentripetalRate<T> estimate(const Outputs& s, const Vec3<T>& seed,
                              int max_iterations = 10) const {
    CentripetalRate<T> out;
    const Outputs ps = p_ * s;
    Vec3<T> w = seed;
    Mat3<T> jtj = Mat3<T>::Zero();
    for (int it = 0; it < max_iterations; ++it) {
      const Eigen::Matrix<T, N, 3> j = -pq_ * monomial_jacobian(w);
      const Outputs r = ps - pq_ * centripetal_monomials(w);
      jtj = j.transpose() * j;
      const Eigen::LDLT<Mat3<T>> ldlt(jtj);
      if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > T(0))) break;
      const Vec3<T> step = ldlt.solve(j.transpose() * r);
      w -= step;
      out.iterations = it + 1;
      if (!std::isfinite(w.squaredNorm())) break;
      if (step.norm() <= T(1e-6) * (w.norm() + T(1e-3))) {
        out.converged = true;
        break;
      }
    }
    if (w.dot(seed) < T(0)) w = -w;  // m(−ω) = m(ω): the seed's side
    out.w_b = w;
    // The bound at the solution.
    const Eigen::Matrix<T, N, 3> j = -pq_ * monomial_jacobian(w);
    jtj = j.transpose() * j;
    const Eigen::LDLT<Mat3<T>> ldlt(jtj);
    if (out.converged && ldlt.info() == Eigen::Success && ldlt.vectorD().minCoeff() > T(0)) {
      out.covariance = ldlt.solve(Mat3<T>::Identity()) * sigma2_;
      // The trace bounds the largest eigenvalue from above (by at most 3×): conservative.
      // Nine sensors (d = 3) give as many equations as unknowns: besides ±ω, other rates fit
      // the outputs exactly, and Gauss–Newton lands on one of them for a few per cent of seeds
      // (a zero residual does not tell). From ten on, the extra equations reject them.
      out.informative =
          dof_ >= 4 && std::sqrt(out.covariance.trace()) <= max_relative_sigma_ * w.norm();
    }
    return out;
  }

  /// The Cramér–Rao bound of ω at a given rate (rad²/s²; zero matrix where singular, e.g. at
  /// rest): σ² (JᵀJ)⁻¹ with J = −P Q D(ω).
  Mat3<T> bound(const Vec3<T>& w) const {
    const Eigen::Matrix<T, N, 3> j = -pq_ * monomial_jacobian(w);
    const Mat3<T> jtj = j.transpose() * j;
    const Eigen::LDLT<Mat3<T>> ldlt(jtj);
    if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > T(0))) {
      return Mat3<T>::Zero();
    }
    return ldlt.solve(Mat3<T>::Identity()) * sigma2_;
  }

 private:
  static Eigen::Matrix<T, 6, 3> monomial_jacobian(const Vec3<T>& w) {
    return centripetal_jacobian(w);
  }

  Eigen::Matrix<T, N, N> p_ = Eigen::Matrix<T, N, N>::Zero();
  Eigen::Matrix<T, N, 6> pq_ = Eigen::Matrix<T, N, 6>::Zero();
  T sigma2_ = T(1);
  T max_relative_sigma_ = T(0.1);
  int dof_ = 0;
};

}  // namespace gfins::nav
