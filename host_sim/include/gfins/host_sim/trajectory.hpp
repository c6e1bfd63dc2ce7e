// Trajectories with analytic truth: attitude, rate, angular acceleration, position, velocity and
// kinematic acceleration of the array centre o_b at any instant, exact to floating-point rounding.
//
// Frames (docs/architecture.md): navigation frame NED fixed at the alignment point and treated as
// inertial; body frame FRD at the array centre o_b. q_nb rotates body vectors into the navigation
// frame.
//
// How the truth is made exact. Every trajectory is written once as a function of time over the
// jet scalar of jet.hpp: position r_n(t) as three jets and attitude q_nb(t) as a quaternion of
// four jets (JetQuat). One evaluation at the jet t = (t_s, 1, 0) yields r, ṙ, r̈ and q, q̇, q̈. Then
//
//   v_n = ṙ_n,  a_n = r̈_n                                    (definitions)
//   q̇ = ½ q ⊗ [0; ω_b]      ⇒  ω_b = 2 vec(q* ⊗ q̇)          (body-rate kinematics, |q| = 1)
//   ω̇_b = d/dt 2 vec(q* ⊗ q̇) = 2 vec(q̇* ⊗ q̇) + 2 vec(q* ⊗ q̈) = 2 vec(q* ⊗ q̈)
//
// because p* ⊗ p = |p|² is real for any quaternion p, so vec(q̇* ⊗ q̇) = 0. (The scalar part of
// q* ⊗ q̇ is q·q̇ = ½ d|q|²/dt = 0 for a unit q.) The attitudes below are products of unit
// quaternions [cos(φ/2); sin(φ/2) u], so |q| = 1 to rounding for every t, and nothing is
// differentiated numerically anywhere.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "gfins/host_sim/jet.hpp"
#include "gfins/nav_core/nav_state.hpp"

namespace gfins::sim {

using Vec3d = Eigen::Vector3d;
using Quatd = Eigen::Quaterniond;
using Vec6d = Eigen::Matrix<double, 6, 1>;
using JetD = Jet<double>;

/// Truth at one instant. NED navigation frame, FRD body frame at the array centre o_b.
struct TruthState {
  double t_s = 0;
  Quatd q_nb = Quatd::Identity();  // body-to-navigation rotation
  Vec3d w_b = Vec3d::Zero();       // ω_nb^b, rad/s
  Vec3d wdot_b = Vec3d::Zero();    // dω_b/dt, rad/s²
  Vec3d r_n = Vec3d::Zero();       // m
  Vec3d v_n = Vec3d::Zero();       // m/s
  Vec3d a_n = Vec3d::Zero();       // kinematic acceleration of o_b, m/s²
};

/// The one TruthState → NavState conversion (start_at with the truth, error against the truth):
/// attitude, rate, angular acceleration, acceleration, velocity and position, t_ns = t_s in ns
/// (rounded), seq as given. f_b stays zero: it depends on the gravity model, which the truth
/// does not carry, and nothing that starts from the truth reads it.
template <typename T>
nav::NavState<T> to_nav_state(const TruthState& x, std::uint32_t seq = 0) {
  nav::NavState<double> s;
  s.t_ns = static_cast<std::int64_t>(std::llround(x.t_s * 1e9));
  s.seq = seq;
  s.q_nb = x.q_nb;
  s.w_b = x.w_b;
  s.wdot_b = x.wdot_b;
  s.a_n = x.a_n;
  s.v_n = x.v_n;
  s.r_n = x.r_n;
  return s.template cast<T>();
}

class Trajectory {
 public:
  virtual ~Trajectory() = default;
  virtual TruthState at(double t_s) const = 0;
  virtual std::string name() const = 0;
};

/// A 3-vector of jets (x, y, z).
using JetVec3 = std::array<JetD, 3>;

/// A quaternion of jets, Hamilton convention (w, x, y, z) as Eigen's.
struct JetQuat {
  JetD w{1.0};
  JetD x{};
  JetD y{};
  JetD z{};

  /// A constant quaternion (zero derivatives).
  static JetQuat constant(const Quatd& q) {
    return {JetD(q.w()), JetD(q.x()), JetD(q.y()), JetD(q.z())};
  }
};

/// Hamilton product p ⊗ q.
JetQuat operator*(const JetQuat& p, const JetQuat& q);

/// exp(½ angle·u) = [cos(angle/2); sin(angle/2) u] for a unit axis u (not checked) and an angle
/// (rad) that is a function of time.
JetQuat jet_axis_angle(const Vec3d& unit_axis, const JetD& angle_rad);

/// The elementary rotations about the x, y and z axes by a jet angle (rad).
JetQuat jet_rot_x(const JetD& angle_rad);
JetQuat jet_rot_y(const JetD& angle_rad);
JetQuat jet_rot_z(const JetD& angle_rad);

/// The truth state at t_s from position and attitude jets evaluated at the jet (t_s, 1, 0), with
/// the formulas of the file comment. q_nb must be unit to rounding (ω_b and ω̇_b assume |q| = 1).
TruthState truth_from_jets(double t_s, const JetVec3& r_n, const JetQuat& q_nb);

/// Base of every trajectory here: derive, write pose() once over jets, and at() follows.
class JetTrajectory : public Trajectory {
 public:
  TruthState at(double t_s) const final;

  /// Position (m, NED) and attitude q_nb as functions of the time jet t (s).
  virtual void pose(const JetD& t, JetVec3& r_n, JetQuat& q_nb) const = 0;
};

std::unique_ptr<Trajectory> make_rest(const Quatd& q_nb, const Vec3d& r_n = Vec3d::Zero());

/// Paper §6.3: constant kinematic acceleration a_n from rest at r0 (paper: [g 0 0]), fixed
/// attitude. r_n(t) = r0 + a t²/2, v_n = a t for every t (at rest at t = 0).
std::unique_ptr<Trajectory> make_constant_acceleration(const Vec3d& a_n, const Quatd& q_nb,
                                                       const Vec3d& r0_n = Vec3d::Zero());

/// Constant angular rate about a fixed body axis (any direction), centre fixed at r0:
/// q_nb(t) = q0 ⊗ exp(½ rate t u), u = axis_b/|axis_b|, so ω_b = rate·u and ω̇_b = 0.
/// Throws std::invalid_argument when axis_b is zero or not finite.
std::unique_ptr<Trajectory> make_spin(const Vec3d& axis_b, double rate_rps, const Quatd& q0_nb,
                                      const Vec3d& r0_n = Vec3d::Zero());

/// Classical coning: the body z axis describes a cone of half-angle half_angle_rad at
/// cone_rate_rps (non-commutative rotation, ω rotating in the body x-y plane).
/// q_nb(t) = q0 ⊗ [cos(β/2); sin(β/2) cos Ωt; sin(β/2) sin Ωt; 0] (β the half-angle, Ω the cone
/// rate): a rotation by β about an axis turning in the x-y plane. Its body rate is the textbook
///   ω_b = [−Ω sin β sin Ωt;  Ω sin β cos Ωt;  −Ω (1 − cos β)],
/// centre fixed at the origin.
std::unique_ptr<Trajectory> make_coning(double half_angle_rad, double cone_rate_rps,
                                        const Quatd& q0_nb = Quatd::Identity());

/// A smooth 6-DoF manoeuvre (sums of sinusoids/ramps in position and in the three Euler angles),
/// amplitude scaled by `scale` (1 = a vehicle-like motion: metres, tens of degrees, ~1 rad/s).
/// At scale 1: r_n(0) = 0; peaks over the first minute |ω_b| 0.97 rad/s, |ω̇_b| 2.5 rad/s²,
/// |a_n| 3.8 m/s², roll up to 26°, pitch up to 18°, a 2 m/s northward cruise (the exact formulas
/// are in trajectory.cpp). Meant for t ≥ 0 (the cruise ramp uses exp(−t/τ), which grows without
/// bound for large negative t).
///
/// Cost of at(), -O2 on the development machine: about 0.1 µs (constant acceleration), 0.3 µs
/// (spin, coning) and 0.7 µs (manoeuvre: 17 sin/cos pairs and one exp).
std::unique_ptr<Trajectory> make_maneuver(double scale = 1.0);

/// A vehicle (or walker) stopping and going along a weaving road (stop_and_go.cpp gives the
/// formulas): after initial_stop_s at rest, cycles of stop_s at rest, a minimum-jerk speed-up to
/// speed_mps over accel_s, cruise_s at that speed and a slow-down over accel_s; the road is
/// y = A (1 − cos 2πx/L) (A = weave_amplitude_m, L = weave_length_m, NED), heading along it,
/// banked as a coordinated turn. speed_mps is the progress north (ẋ); the ground speed along the
/// road is ẋ √(1 + (2πA/L · sin 2πx/L)²), up to √(1 + (2πA/L)²) times more. Starts at the origin
/// heading north.
struct StopAndGoSpec {
  double speed_mps = 10.0;
  double accel_s = 5.0;
  double cruise_s = 20.0;
  double stop_s = 10.0;
  double initial_stop_s = 10.0;
  double weave_amplitude_m = 20.0;
  double weave_length_m = 300.0;
};
std::unique_ptr<Trajectory> make_stop_and_go(const StopAndGoSpec& spec);

/// The attitude q_nb of a board at rest that senses the specific force f_b (body axes, any
/// length; at rest f = −g, i.e. "up": (0, 0, −1) g is the face "z down"). Heading: that of the
/// shortest rotation taking f̂_b to −ẑ_n (fixed, otherwise arbitrary).
Quatd attitude_sensing(const Vec3d& f_b);

/// A calibration session on an index table: the board rests in each pose k (sensing f_b[k]) for
/// dwell_s, then turns to the next about the array centre in transition_s along the shortest
/// rotation with a minimum-jerk profile (ω = ω̇ = 0 at both ends). Pose k is held over
/// [k·(dwell + transition), k·(dwell + transition) + dwell]; the last pose is held for ever.
/// Throws std::invalid_argument for no poses, a zero vector or a non-positive time.
std::unique_ptr<Trajectory> make_pose_sequence(const std::vector<Vec3d>& f_b, double dwell_s,
                                               double transition_s);

}  // namespace gfins::sim
