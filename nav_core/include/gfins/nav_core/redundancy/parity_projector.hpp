// The parity projector P = I − H M of a (redundant) array solver: what of the outputs no
// rigid-body motion explains (docs/redundancy.md). Rows and columns of the sensors the solver
// leaves out are zero.
#pragma once

#include "gfins/nav_core/error_model.hpp"  // centripetal_jacobian, D(ω) = ∂m/∂ω
#include "gfins/nav_core/geometry.hpp"

namespace gfins::nav {

/// P column by column: column j is e_j minus the solver's own fit of a unit output on sensor j,
/// H (M e_j), evaluated with its forward model at ω = 0, so no second copy of the design is
/// needed. Symmetrised against rounding.
template <typename T, int N>
Eigen::Matrix<T, N, N> parity_projector(const ArraySolver<T, N>& solver) {
  const ChannelMask active = solver.active();
  const auto used = [active](int j) { return ((active >> static_cast<unsigned>(j)) & 1U) != 0U; };
  Eigen::Matrix<T, N, N> p = Eigen::Matrix<T, N, N>::Zero();
  for (int j = 0; j < N; ++j) {
    if (!used(j)) continue;
    typename ArraySolver<T, N>::Outputs e = ArraySolver<T, N>::Outputs::Zero();
    e(j) = T(1);
    Vec3<T> wdot;
    Vec3<T> f;
    solver.solve(e, Vec3<T>::Zero(), wdot, f);
    p.col(j) = e - solver.predict(wdot, f, Vec3<T>::Zero());
  }
  for (int i = 0; i < N; ++i) {
    if (!used(i)) p.row(i).setZero();
  }
  return (p + p.transpose()) / T(2);
}

/// Q (N×6) of the centripetal term c(ω) = Q m(ω), m = [ωx², ωy², ωz², ωyωz, ωxωz, ωxωy]
/// (geometry.hpp), from the solver's forward model: c(ω) = predict(0, 0, ω), so ω = e_i gives
/// the squares and ω = e_i + e_k the cross term once the squares are taken off.
template <typename T, int N>
Eigen::Matrix<T, N, 6> centripetal_matrix(const ArraySolver<T, N>& solver) {
  const auto c = [&solver](const Vec3<T>& w) {
    return solver.predict(Vec3<T>::Zero(), Vec3<T>::Zero(), w);
  };
  const Vec3<T> ex = Vec3<T>::UnitX();
  const Vec3<T> ey = Vec3<T>::UnitY();
  const Vec3<T> ez = Vec3<T>::UnitZ();
  Eigen::Matrix<T, N, 6> q;
  q.col(0) = c(ex);
  q.col(1) = c(ey);
  q.col(2) = c(ez);
  q.col(3) = c(ey + ez) - q.col(1) - q.col(2);
  q.col(4) = c(ex + ez) - q.col(0) - q.col(2);
  q.col(5) = c(ex + ey) - q.col(0) - q.col(1);
  return q;
}

}  // namespace gfins::nav
