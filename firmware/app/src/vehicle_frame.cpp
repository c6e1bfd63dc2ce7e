#include "gfins/app/vehicle_frame.hpp"

#include <numbers>

namespace gfins::app {

nav::Quat<float> mounting_rotation(const std::array<double, 3>& rpy_deg) {
  constexpr double kRadPerDeg = std::numbers::pi / 180.0;
  const nav::Quat<double> q = Eigen::AngleAxisd(rpy_deg[2] * kRadPerDeg, Eigen::Vector3d::UnitZ()) *
                              Eigen::AngleAxisd(rpy_deg[1] * kRadPerDeg, Eigen::Vector3d::UnitY()) *
                              Eigen::AngleAxisd(rpy_deg[0] * kRadPerDeg, Eigen::Vector3d::UnitX());
  return q.normalized().cast<float>();
}

void to_vehicle_frame(nav::NavState<float>& n, const nav::Quat<float>& q_vb) {
  n.q_nb = (n.q_nb * q_vb.conjugate()).normalized();
  n.w_b = q_vb * n.w_b;
  n.wdot_b = q_vb * n.wdot_b;
  n.f_b = q_vb * n.f_b;
}

}  // namespace gfins::app
