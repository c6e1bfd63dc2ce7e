// Definitions of ArraySolver's out-of-line members. Included by nav_core/src/geometry.cpp for the
// float and double six-sensor instantiations; include it directly only to instantiate another N.
#pragma once

#include <Eigen/SVD>
#include <cmath>
#include <limits>

#include "gfins/nav_core/geometry.hpp"

namespace gfins::nav {

template <typename T, int N>
Result<ArraySolver<T, N>> ArraySolver<T, N>::create(const ArrayGeometry<T, N>& geometry,
                                                    double max_condition) {
  using HMatrix = Eigen::Matrix<double, N, 6>;
  using QMatrix = Eigen::Matrix<double, N, 6>;
  const auto g = geometry.template cast<double>();

  double lever_sum = 0.0;
  for (int j = 0; j < N; ++j) lever_sum += g.rho_b[static_cast<std::size_t>(j)].norm();
  const double lever = lever_sum / N;
  if (!(lever > 0.0) || !std::isfinite(lever)) {
    return Status(ErrorCode::kInvalidArgument,
                  "array geometry: sensors have no lever arm (all positions at the centre), so "
                  "angular acceleration is unobservable");
  }

  HMatrix h_scaled;  // H with its ω̇ columns multiplied by the mean lever arm (dimensionless)
  QMatrix q;
  for (int j = 0; j < N; ++j) {
    const Eigen::Vector3d& rho = g.rho_b[static_cast<std::size_t>(j)];
    const Eigen::Vector3d& th = g.theta_b[static_cast<std::size_t>(j)];
    if (!std::isfinite(rho.squaredNorm()) || std::abs(th.norm() - 1.0) > 0.1) {
      return Status(ErrorCode::kInvalidArgument,
                    "array geometry: a sensitive axis is not near unit length or a value is not "
                    "finite");
    }
    h_scaled.row(j) << rho.cross(th).transpose() / lever, th.transpose();
    const double tr = th.dot(rho);
    q.row(j) << th.x() * rho.x() - tr, th.y() * rho.y() - tr, th.z() * rho.z() - tr,
        th.y() * rho.z() + th.z() * rho.y(), th.x() * rho.z() + th.z() * rho.x(),
        th.x() * rho.y() + th.y() * rho.x();
  }

  const Eigen::JacobiSVD<HMatrix> svd(h_scaled, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const auto& sv = svd.singularValues();
  const double smax = sv(0);
  const double smin = sv(5);
  const double cond = smin > 0.0 ? smax / smin : std::numeric_limits<double>::infinity();
  if (!(cond <= max_condition)) {
    return Status(ErrorCode::kSingular,
                  "array geometry: the map from outputs to [angular accel; specific force] is "
                  "singular or ill-conditioned (condition number above the limit); check that "
                  "positions and axes are not coplanar or repeated");
  }

  // pinv(H_s) = V Σ⁻¹ Uᵀ (first six columns of U); H = H_s D⁻¹ so pinv(H) = D pinv(H_s).
  Eigen::Matrix<double, 6, N> m = svd.matrixV() * sv.cwiseInverse().asDiagonal() *
                                  svd.matrixU().template leftCols<6>().transpose();
  m.template topRows<3>() /= lever;
  // Entries that are zero in exact arithmetic come out near 1e-17; zero them so that symmetric
  // inputs cancel exactly in float (a level array at rest then gives ω̇ == 0 to the bit).
  const double tiny = 1e-13 * m.cwiseAbs().maxCoeff();
  m = m.unaryExpr([tiny](double x) { return std::abs(x) < tiny ? 0.0 : x; });
  Mat6<double> k = m * q;
  const double ktiny = 1e-13 * (k.cwiseAbs().maxCoeff() + 1e-300);
  k = k.unaryExpr([ktiny](double x) { return std::abs(x) < ktiny ? 0.0 : x; });

  ArraySolver solver;
  solver.m_.template topRows<6>() = m.template cast<T>();
  solver.k_.template topRows<6>() = k.template cast<T>();
  solver.k_force_.template topRows<3>() = k.template bottomRows<3>().template cast<T>();
  solver.condition_ = cond;
  solver.geometry_ = geometry;
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
