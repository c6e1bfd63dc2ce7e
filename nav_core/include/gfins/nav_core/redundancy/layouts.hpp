// Redundant array layouts (N > 6) used by the simulations and tests of the parity monitor
// (docs/redundancy.md gives their condition numbers and parity spaces).
//
//   table1_with_corners<T, N>(ρ), 7 ≤ N ≤ 14: the paper's Table 1 cube (six sensors at the face
//     centres, ±ρ on each axis) plus N − 6 sensors at the cube's corners ρ(±1, ±1, ±1), corner k
//     sensing along the tangent c_k × e_(k mod 3) (normalised), so that each extra sensor sees
//     angular acceleration as well as specific force.
//   four_triads<T>(ρ): twelve sensors, a triad (x, y, z axes) at each vertex of the regular
//     tetrahedron inscribed in the sphere of radius ρ, the twelve-accelerometer configuration of
//     the literature on angular rate from the centripetal terms.
//   three_triads<T>(ρ): nine sensors, the first three triads of four_triads. The angular rate is
//     observable from its centripetal terms except along the normal of the three vertices' plane,
//     ±(1, 1, −1)/√3 (three points are always coplanar: every nine-sensor layout of three triads
//     has such a direction). table1_with_corners carries no rate information: its Fisher
//     information about ω is singular at N = 9 and 10 (docs/redundancy.md).
#pragma once

#include <array>
#include <cmath>
#include <cstddef>

#include "gfins/nav_core/geometry.hpp"

namespace gfins::nav {

template <typename T, int N>
ArrayGeometry<T, N> table1_with_corners(T rho_m) {
  static_assert(N >= 7 && N <= 14, "Table 1 plus one to eight corners");
  const ArrayGeometry<T, 6> base = table1_geometry(rho_m);
  ArrayGeometry<T, N> g;
  for (std::size_t j = 0; j < 6; ++j) {
    g.rho_b[j] = base.rho_b[j];
    g.theta_b[j] = base.theta_b[j];
  }
  constexpr std::array<std::array<int, 3>, 8> kCorners = {{{1, 1, 1},
                                                           {-1, -1, 1},
                                                           {-1, 1, -1},
                                                           {1, -1, -1},
                                                           {1, 1, -1},
                                                           {-1, -1, -1},
                                                           {-1, 1, 1},
                                                           {1, -1, 1}}};
  for (std::size_t k = 0; k + 6 < static_cast<std::size_t>(N); ++k) {
    const Vec3<T> c(static_cast<T>(kCorners[k][0]), static_cast<T>(kCorners[k][1]),
                    static_cast<T>(kCorners[k][2]));
    g.rho_b[k + 6] = c * rho_m;
    g.theta_b[k + 6] = c.cross(Vec3<T>::Unit(static_cast<Eigen::Index>(k % 3))).normalized();
  }
  return g;
}

template <typename T>
ArrayGeometry<T, 12> four_triads(T rho_m) {
  const T k = rho_m / std::sqrt(T(3));
  const std::array<Vec3<T>, 4> vertices = {Vec3<T>(k, k, k), Vec3<T>(k, -k, -k), Vec3<T>(-k, k, -k),
                                           Vec3<T>(-k, -k, k)};
  ArrayGeometry<T, 12> g;
  for (std::size_t v = 0; v < 4; ++v) {
    for (std::size_t a = 0; a < 3; ++a) {
      g.rho_b[3 * v + a] = vertices[v];
      g.theta_b[3 * v + a] = Vec3<T>::Unit(static_cast<Eigen::Index>(a));
    }
  }
  return g;
}

template <typename T>
ArrayGeometry<T, 9> three_triads(T rho_m) {
  const ArrayGeometry<T, 12> four = four_triads<T>(rho_m);
  ArrayGeometry<T, 9> g;
  for (std::size_t j = 0; j < 9; ++j) {
    g.rho_b[j] = four.rho_b[j];
    g.theta_b[j] = four.theta_b[j];
  }
  return g;
}

}  // namespace gfins::nav
