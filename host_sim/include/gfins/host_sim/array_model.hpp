// The ideal accelerometer array: exact outputs of N accelerometers for a truth state, with no
// noise, bias, scale-factor or quantisation error (those belong to the sensor and ADC models).
//
// Sensor j at rho_b[j] (m, body, from the centre o_b) with sensitive axis θ_j senses the specific
// force of its own location projected on θ_j. For a rigid body the acceleration of that point is
// the one of o_b plus the tangential and centripetal terms, so (paper eq. (22), with its misprint
// ω×ω̇×Δρ read as ω×(ω×Δρ), see the paper notes):
//
//   f_b = C_n^b (a_n − g_n(r_n))                              specific force at o_b, m/s²
//   s_j = θ_j·(f_b + ω̇×ρ_j + ω×(ω×ρ_j))                       m/s²
//
// θ_j is used as given: a misaligned geometry (nav::misaligned_geometry) has axes that are not
// exactly unit, and their length then acts as a gain, as it does on the real array (eq. (23)).
// The gravity is evaluated at the centre; its gradient across the array (≈ 3e-6 s⁻² × ρ) is
// neglected, like in the navigation core.
#pragma once

#include <cstddef>

#include "gfins/host_sim/trajectory.hpp"
#include "gfins/nav_core/geometry.hpp"
#include "gfins/nav_core/gravity.hpp"

namespace gfins::sim {

/// Ideal array: exact outputs of N accelerometers of a given geometry (which may be a
/// misaligned one, non-unit axes allowed) for a truth state.
template <int N = 6>
class IdealArrayModel {
 public:
  using Outputs = Eigen::Matrix<double, N, 1>;

  IdealArrayModel(const nav::ArrayGeometry<double, N>& geometry,
                  const nav::GravityModel<double>& gravity)
      : geometry_(geometry), gravity_(gravity) {}

  /// f_b = C_n^b (a_n − g_n(r_n)): specific force at o_b.
  Vec3d specific_force(const TruthState& x) const {
    return x.q_nb.conjugate() * (x.a_n - gravity_.g_n(x.r_n));
  }

  /// s_j = θ_j·(f_b + ω̇×ρ_j + ω×(ω×ρ_j)), m/s².
  Outputs outputs(const TruthState& x) const {
    const Vec3d f_b = specific_force(x);
    Outputs s;
    for (std::size_t j = 0; j < static_cast<std::size_t>(N); ++j) {
      const Vec3d& rho = geometry_.rho_b[j];
      const Vec3d a_point = f_b + x.wdot_b.cross(rho) + x.w_b.cross(x.w_b.cross(rho));
      s(static_cast<Eigen::Index>(j)) = geometry_.theta_b[j].dot(a_point);
    }
    return s;
  }

  const nav::ArrayGeometry<double, N>& geometry() const { return geometry_; }
  const nav::GravityModel<double>& gravity() const { return gravity_; }

 private:
  nav::ArrayGeometry<double, N> geometry_;
  nav::GravityModel<double> gravity_;
};

}  // namespace gfins::sim
