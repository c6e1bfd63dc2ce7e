// The parity projector P = I − H M of a (redundant) array solver: what of the outputs no
// rigid-body motion explains (docs/redundancy.md). Rows and columns of the sensors the solver
// leaves out are zero.
#pragma once

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

}  // namespace gfins::nav
