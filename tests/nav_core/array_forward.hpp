// The rigid-body forward model of an accelerometer array, written for the tests independently of
// ArraySolver::predict (paper eq. (22), with the misprint ω×ω̇×Δρ read as ω×(ω×Δρ); see
// docs/paper-errata.md): s_j = θ_j·(f + ω̇×ρ_j + ω×(ω×ρ_j)).
#pragma once

#include <cstddef>

#include "gfins/nav_core/geometry.hpp"

namespace gfins::nav::test {

template <int N>
Eigen::Matrix<double, N, 1> forward(const ArrayGeometry<double, N>& g, const Vec3<double>& wdot,
                                    const Vec3<double>& f, const Vec3<double>& w) {
  Eigen::Matrix<double, N, 1> s;
  for (int j = 0; j < N; ++j) {
    const auto& rho = g.rho_b[static_cast<std::size_t>(j)];
    s(j) = g.theta_b[static_cast<std::size_t>(j)].dot(f + wdot.cross(rho) + w.cross(w.cross(rho)));
  }
  return s;
}

}  // namespace gfins::nav::test
