// The paper's sensor axes written out for the calibration tests' oracles, independently of the
// code under test (nav_core's geometry and calibration): Table 1's nominal axes and the
// misalignment matrices C of eqs. (14)/(15).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <cstddef>

namespace gfins::tools::test_oracle {

// Table 1 of the paper: nominal sensitive axes θ_j of Chen's cube.
inline std::array<Eigen::Vector3d, 6> table1_theta() {
  const double k = 1.0 / std::sqrt(2.0);
  return {Eigen::Vector3d(k, k, 0),  Eigen::Vector3d(k, 0, k),  Eigen::Vector3d(0, k, k),
          Eigen::Vector3d(0, -k, k), Eigen::Vector3d(-k, 0, k), Eigen::Vector3d(-k, k, 0)};
}

// Sets of eqs. (14)/(15), 0-based sensors: β = {2, 3, 5}, α = {1, 4, 6}; the sensor at row r of
// its set senses along θ*_r = Σ_k C_rk θ_k, and row r of C holds the set's angles 2r and 2r+1
// (xy/xz, yx/yz, zx/zy, Table 6 order).
constexpr std::array<std::size_t, 3> kBeta{1, 2, 4};
constexpr std::array<std::size_t, 3> kAlpha{0, 3, 5};
struct Place {
  bool alpha;
  std::size_t row;
};
inline Place place_of(std::size_t j) {
  for (std::size_t r = 0; r < 3; ++r) {
    if (kAlpha[r] == j) return {true, r};
    if (kBeta[r] == j) return {false, r};
  }
  return {false, 3};
}

// C of eq. (14)/(15) from the angles (rad) in Table 6 order xy, xz, yx, yz, zx, zy.
inline Eigen::Matrix3d c_matrix(const std::array<double, 6>& a) {
  Eigen::Matrix3d c;
  c << 1.0, a[1], -a[0],  //
      -a[3], 1.0, a[2],   //
      a[5], -a[4], 1.0;
  return c;
}

// θ*_j of every sensor from the β and α sets' angles (rad).
inline std::array<Eigen::Vector3d, 6> axes_of(const std::array<double, 6>& beta_rad,
                                              const std::array<double, 6>& alpha_rad) {
  const auto nominal = table1_theta();
  std::array<Eigen::Vector3d, 6> th;
  for (const bool alpha : {false, true}) {
    const auto& set = alpha ? kAlpha : kBeta;
    const Eigen::Matrix3d c = c_matrix(alpha ? alpha_rad : beta_rad);
    for (std::size_t r = 0; r < 3; ++r) {
      Eigen::Vector3d v = Eigen::Vector3d::Zero();
      for (std::size_t k = 0; k < 3; ++k) {
        v += c(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(k)) * nominal[set[k]];
      }
      th[set[r]] = v;
    }
  }
  return th;
}

}  // namespace gfins::tools::test_oracle
