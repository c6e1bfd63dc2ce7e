// The arrays and the samples the parity and centripetal-rate benchmarks run on (parity_bench.cpp,
// centripetal_rate_bench.cpp: one executable, two files, so that the build compiles their
// template instances on two cores).
#pragma once

#include <random>
#include <vector>

#include "gfins/nav_core/geometry.hpp"
#include "gfins/nav_core/geometry_impl.hpp"  // ArraySolver for any N
#include "gfins/nav_core/redundancy/layouts.hpp"

namespace gfins::bench {

template <typename T, int N>
inline nav::ArrayGeometry<T, N> layout() {
  if constexpr (N == 12) {
    return nav::four_triads<T>(T(0.1));
  } else {
    return nav::table1_with_corners<T, N>(T(0.1));
  }
}

/// 1000 noisy samples of a spinning array (so the centripetal term is not zero), made before the
/// timed loop and cycled through.
template <typename T, int N>
inline std::vector<Eigen::Matrix<T, N, 1>> samples(const nav::ArraySolver<T, N>& solver,
                                                   const nav::Vec3<T>& w) {
  std::mt19937_64 rng(1);
  std::normal_distribution<double> noise(0.0, 5e-4);
  const auto clean =
      solver.predict(nav::Vec3<T>::Zero(), nav::Vec3<T>(T(0.3), T(-0.2), T(-9.8)), w);
  std::vector<Eigen::Matrix<T, N, 1>> out(1000, clean);
  for (auto& s : out) {
    for (int j = 0; j < N; ++j) s(j) += static_cast<T>(noise(rng));
  }
  return out;
}

}  // namespace gfins::bench
