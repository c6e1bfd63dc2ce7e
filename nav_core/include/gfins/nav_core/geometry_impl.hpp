// Definitions of ArraySolver's out-of-line members. Included by nav_core/src/geometry.cpp for the
// float and double six-sensor instantiations; include it directly only to instantiate another N.
//
// The set-up runs in T, the scalar of the solver: on the Cortex-M4F (single-precision FPU) a
// double set-up would pull Eigen's double SVD and libgcc's soft-float double routines into the
// image (about 14 KB of 34 KB; docs/performance.md). Its float accuracy against a double
// reference is bounded by the condition number times float epsilon and checked in
// tests/nav_core/solver_setup_accuracy_test.cpp.
#pragma once

#include <cmath>
#include <limits>

#include "gfins/nav_core/geometry.hpp"

namespace gfins::nav {

namespace detail {

/// One-sided (Hestenes) Jacobi orthogonalisation (Golub & Van Loan, Matrix Computations, 4th ed.,
/// §8.6.3): rotates pairs of columns of `a` (N×6) until every pair is orthogonal to within
/// tol·‖a_p‖‖a_q‖, applying the same rotations to `v` (6×6, starts as the identity). On return
/// a = H V with orthogonal columns, i.e. a = U Σ: ‖a_i‖ are the singular values of H, and
/// pinv(H) = V Σ⁻¹ Uᵀ = V Σ⁻² aᵀ. Returns false when the sweeps did not converge (never seen:
/// Jacobi converges quadratically, about six sweeps for a 6×6 matrix).
template <typename T, int N>
bool jacobi_orthogonalize(Eigen::Matrix<T, N, 6>& a, Mat6<T>& v) {
  // Orthogonality target: N·ε relative, a few roundings of the N-term dot product.
  const T tol = T(N) * std::numeric_limits<T>::epsilon();
  constexpr int kMaxSweeps = 30;
  for (int sweep = 0; sweep < kMaxSweeps; ++sweep) {
    bool rotated = false;
    for (int p = 0; p < 5; ++p) {
      for (int q = p + 1; q < 6; ++q) {
        const T alpha = a.col(p).squaredNorm();
        const T beta = a.col(q).squaredNorm();
        const T gamma = a.col(p).dot(a.col(q));
        if (!(std::abs(gamma) > tol * std::sqrt(alpha * beta))) continue;
        rotated = true;
        // The rotation that diagonalises [[α, γ], [γ, β]] (symmetric Schur decomposition, G&VL
        // Algorithm 8.5.1), the smaller of the two angles so that it converges.
        const T zeta = (beta - alpha) / (T(2) * gamma);
        const T t = std::copysign(T(1), zeta) / (std::abs(zeta) + std::sqrt(T(1) + zeta * zeta));
        const T c = T(1) / std::sqrt(T(1) + t * t);
        const T s = c * t;
        for (int i = 0; i < N; ++i) {
          const T x = a(i, p);
          const T y = a(i, q);
          a(i, p) = c * x - s * y;
          a(i, q) = s * x + c * y;
        }
        for (int i = 0; i < 6; ++i) {
          const T x = v(i, p);
          const T y = v(i, q);
          v(i, p) = c * x - s * y;
          v(i, q) = s * x + c * y;
        }
      }
    }
    if (!rotated) return true;
  }
  return false;
}

/// Sets to zero the entries of `m` that are rounding noise of their own sum: an entry that is
/// zero in exact arithmetic comes out of a sum of `terms` products as at most
/// terms·u·Σ|products| (u = ε/2); `bound` holds Σ|products| per entry. Symmetric arrays must cancel
/// exactly (a level Table 1 array at rest gives ω̇ == 0 to the bit; the integrator skips K's top
/// rows only when they are exactly zero), and an entry this small is below its own rounding
/// error, so zeroing it costs no accuracy.
template <typename T, int R, int C>
void zero_rounding_noise(Eigen::Matrix<T, R, C>& m, const Eigen::Matrix<T, R, C>& bound,
                         int terms) {
  // Plain loops over the storage: Eigen's unrolled expressions cost hundreds of bytes on the
  // Cortex-M4F at -Os.
  const T factor = T(2 * terms) * std::numeric_limits<T>::epsilon() / T(2);
  T* x = m.data();
  const T* b = bound.data();
  for (int i = 0; i < R * C; ++i) {
    if (std::abs(x[i]) <= factor * b[i]) x[i] = T(0);
  }
}

}  // namespace detail

template <typename T, int N>
Result<ArraySolver<T, N>> ArraySolver<T, N>::create(const ArrayGeometry<T, N>& g, T max_condition) {
  using HMatrix = Eigen::Matrix<T, N, 6>;

  T lever_sum = T(0);
  for (int j = 0; j < N; ++j) {
    const Vec3<T>& rho = g.rho_b[static_cast<std::size_t>(j)];
    if (!std::isfinite(rho.squaredNorm())) {
      // Checked first: a NaN position made the mean lever arm NaN, reported as "no lever arm".
      return Status(ErrorCode::kInvalidArgument,
                    "array geometry: a sensor position is not a finite number");
    }
    lever_sum += rho.norm();
  }
  const T lever = lever_sum / T(N);
  if (!(lever > T(0)) || !std::isfinite(lever)) {
    return Status(ErrorCode::kInvalidArgument,
                  "array geometry: sensors have no lever arm (all positions at the centre), so "
                  "angular acceleration is unobservable");
  }

  HMatrix a;  // H with its ω̇ columns divided by the mean lever arm (dimensionless)
  HMatrix q;
  for (int j = 0; j < N; ++j) {
    const Vec3<T>& rho = g.rho_b[static_cast<std::size_t>(j)];
    const Vec3<T>& th = g.theta_b[static_cast<std::size_t>(j)];
    if (!(std::abs(th.norm() - T(1)) <= T(0.1))) {  // NaN fails the comparison too
      return Status(ErrorCode::kInvalidArgument,
                    "array geometry: a sensitive axis is not near unit length or not finite");
    }
    a.row(j) << rho.cross(th).transpose() / lever, th.transpose();
    const T tr = th.dot(rho);
    q.row(j) << th.x() * rho.x() - tr, th.y() * rho.y() - tr, th.z() * rho.z() - tr,
        th.y() * rho.z() + th.z() * rho.y(), th.x() * rho.z() + th.z() * rho.x(),
        th.x() * rho.y() + th.y() * rho.x();
  }

  Mat6<T> v = Mat6<T>::Identity();
  const bool converged = detail::jacobi_orthogonalize(a, v);
  const Vec6<T> sigma_sq = a.colwise().squaredNorm().transpose();
  const T smax = std::sqrt(sigma_sq.maxCoeff());
  const T smin = std::sqrt(sigma_sq.minCoeff());
  const T cond = smin > T(0) ? smax / smin : std::numeric_limits<T>::infinity();
  if (!converged || !(cond <= max_condition)) {
    return Status(ErrorCode::kSingular,
                  "array geometry: the map from outputs to [angular accel; specific force] is "
                  "singular or ill-conditioned (condition number above the limit); check that "
                  "positions and axes are not coplanar or repeated");
  }

  // pinv(H_s) = V Σ⁻² (H_s V)ᵀ. H_s = H D with D = diag(I₃/lever, I₃), so pinv(H) = D pinv(H_s):
  // the ω̇ rows of pinv(H_s) divided by the lever arm.
  const Vec6<T> inv_sigma_sq = sigma_sq.cwiseInverse();
  Eigen::Matrix<T, 6, N> m = v * inv_sigma_sq.asDiagonal() * a.transpose();
  detail::zero_rounding_noise<T, 6, N>(
      m, v.cwiseAbs() * inv_sigma_sq.asDiagonal() * a.cwiseAbs().transpose(), 6);
  m.template topRows<3>() /= lever;  // exact zeros stay zero
  Mat6<T> k = m * q;
  detail::zero_rounding_noise<T, 6, 6>(k, m.cwiseAbs() * q.cwiseAbs(), N);

  ArraySolver solver;
  solver.m_.template topRows<3>() = m.template topRows<3>();
  solver.m_.template middleRows<3>(kHalfRows) = m.template bottomRows<3>();
  solver.k_.template topRows<3>() = k.template topRows<3>();
  solver.k_.template middleRows<3>(kHalfRows) = k.template bottomRows<3>();
  solver.k_force_.template topRows<3>() = k.template bottomRows<3>();
  solver.condition_ = cond;
  solver.geometry_ = g;
  return solver;
}

// The masked set-up of create_subset(): create()'s steps with the rows of the sensors left out
// set to zero. Kept apart from create() (see geometry.hpp).
template <typename T, int N>
template <typename Mask>
Result<ArraySolver<T, N>> ArraySolver<T, N>::create_subset(const ArrayGeometry<T, N>& g,
                                                           T max_condition, Mask active_in) {
  const ChannelMask active = static_cast<ChannelMask>(active_in) & all_channels<N>();
  using HMatrix = Eigen::Matrix<T, N, 6>;

  if (channel_count(active) < 6) {
    return Status(ErrorCode::kInvalidArgument,
                  "array geometry: fewer than six active sensors cannot determine [angular "
                  "accel; specific force]");
  }
  const auto used = [active](int j) { return ((active >> static_cast<unsigned>(j)) & 1U) != 0U; };
  T lever_sum = T(0);
  for (int j = 0; j < N; ++j) {
    const Vec3<T>& rho = g.rho_b[static_cast<std::size_t>(j)];
    if (!std::isfinite(rho.squaredNorm())) {
      // Checked first: a NaN position made the mean lever arm NaN, reported as "no lever arm".
      return Status(ErrorCode::kInvalidArgument,
                    "array geometry: a sensor position is not a finite number");
    }
    if (used(j)) lever_sum += rho.norm();
  }
  const T lever = lever_sum / static_cast<T>(channel_count(active));
  if (!(lever > T(0)) || !std::isfinite(lever)) {
    return Status(ErrorCode::kInvalidArgument,
                  "array geometry: sensors have no lever arm (all positions at the centre), so "
                  "angular acceleration is unobservable");
  }

  HMatrix a;  // H with its ω̇ columns divided by the mean lever arm; rows of the sensors left
  HMatrix q;  // out are zero (zero columns of M = pinv(H))
  for (int j = 0; j < N; ++j) {
    const Vec3<T>& rho = g.rho_b[static_cast<std::size_t>(j)];
    const Vec3<T>& th = g.theta_b[static_cast<std::size_t>(j)];
    if (!(std::abs(th.norm() - T(1)) <= T(0.1))) {  // NaN fails the comparison too
      return Status(ErrorCode::kInvalidArgument,
                    "array geometry: a sensitive axis is not near unit length or not finite");
    }
    if (!used(j)) {
      // Row by row, not HMatrix::Zero() up front: Eigen unrolls a whole-matrix fill into one
      // store per element at -Os on the Cortex-M4F (docs/performance.md).
      a.row(j).setZero();
      q.row(j).setZero();
      continue;
    }
    a.row(j) << rho.cross(th).transpose() / lever, th.transpose();
    const T tr = th.dot(rho);
    q.row(j) << th.x() * rho.x() - tr, th.y() * rho.y() - tr, th.z() * rho.z() - tr,
        th.y() * rho.z() + th.z() * rho.y(), th.x() * rho.z() + th.z() * rho.x(),
        th.x() * rho.y() + th.y() * rho.x();
  }

  Mat6<T> v = Mat6<T>::Identity();
  const bool converged = detail::jacobi_orthogonalize(a, v);
  const Vec6<T> sigma_sq = a.colwise().squaredNorm().transpose();
  const T smax = std::sqrt(sigma_sq.maxCoeff());
  const T smin = std::sqrt(sigma_sq.minCoeff());
  const T cond = smin > T(0) ? smax / smin : std::numeric_limits<T>::infinity();
  if (!converged || !(cond <= max_condition)) {
    return Status(ErrorCode::kSingular,
                  "array geometry: the map from outputs to [angular accel; specific force] is "
                  "singular or ill-conditioned (condition number above the limit); check that "
                  "positions and axes are not coplanar or repeated");
  }

  // pinv(H_s) = V Σ⁻² (H_s V)ᵀ. H_s = H D with D = diag(I₃/lever, I₃), so pinv(H) = D pinv(H_s):
  // the ω̇ rows of pinv(H_s) divided by the lever arm.
  const Vec6<T> inv_sigma_sq = sigma_sq.cwiseInverse();
  Eigen::Matrix<T, 6, N> m = v * inv_sigma_sq.asDiagonal() * a.transpose();
  detail::zero_rounding_noise<T, 6, N>(
      m, v.cwiseAbs() * inv_sigma_sq.asDiagonal() * a.cwiseAbs().transpose(), 6);
  m.template topRows<3>() /= lever;  // exact zeros stay zero
  Mat6<T> k = m * q;
  detail::zero_rounding_noise<T, 6, 6>(k, m.cwiseAbs() * q.cwiseAbs(), N);

  ArraySolver solver;
  solver.m_.template topRows<3>() = m.template topRows<3>();
  solver.m_.template middleRows<3>(kHalfRows) = m.template bottomRows<3>();
  solver.k_.template topRows<3>() = k.template topRows<3>();
  solver.k_.template middleRows<3>(kHalfRows) = k.template bottomRows<3>();
  solver.k_force_.template topRows<3>() = k.template bottomRows<3>();
  solver.condition_ = cond;
  solver.geometry_ = g;
  return solver;
}

template <typename T, int N>
typename ArraySolver<T, N>::Outputs ArraySolver<T, N>::predict(const Vec3<T>& wdot_b,
                                                               const Vec3<T>& f_b,
                                                               const Vec3<T>& w) const {
  Outputs s;
  for (int j = 0; j < N; ++j) {
    const Vec3<T>& rho = geometry_.rho_b[static_cast<std::size_t>(j)];
    const Vec3<T>& th = geometry_.theta_b[static_cast<std::size_t>(j)];
    s(j) = th.dot(f_b + wdot_b.cross(rho) + w.cross(w.cross(rho)));
  }
  return s;
}

}  // namespace gfins::nav
