// Trajectories with analytic truth (see trajectory.hpp for the derivation of ω and ω̇ from q, q̇,
// q̈). Each class writes its motion once, in pose(), over time jets.
#include "gfins/host_sim/trajectory.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace gfins::sim {

JetQuat operator*(const JetQuat& p, const JetQuat& q) {
  // [p0; p] ⊗ [q0; q] = [p0 q0 − p·q;  p0 q + q0 p + p × q]
  return {
      p.w * q.w - p.x * q.x - p.y * q.y - p.z * q.z, p.w * q.x + p.x * q.w + p.y * q.z - p.z * q.y,
      p.w * q.y - p.x * q.z + p.y * q.w + p.z * q.x, p.w * q.z + p.x * q.y - p.y * q.x + p.z * q.w};
}

JetQuat jet_axis_angle(const Vec3d& unit_axis, const JetD& angle_rad) {
  JetD s;
  JetD c;
  sin_cos(0.5 * angle_rad, s, c);
  return {c, unit_axis.x() * s, unit_axis.y() * s, unit_axis.z() * s};
}

JetQuat jet_rot_x(const JetD& angle_rad) {
  JetD s;
  JetD c;
  sin_cos(0.5 * angle_rad, s, c);
  return {c, s, JetD(), JetD()};
}

JetQuat jet_rot_y(const JetD& angle_rad) {
  JetD s;
  JetD c;
  sin_cos(0.5 * angle_rad, s, c);
  return {c, JetD(), s, JetD()};
}

JetQuat jet_rot_z(const JetD& angle_rad) {
  JetD s;
  JetD c;
  sin_cos(0.5 * angle_rad, s, c);
  return {c, JetD(), JetD(), s};
}

namespace {

// 2 vec(q* ⊗ p) for a plain quaternion q = (w, v) and p = (p0, pv): the vector part of
// q* ⊗ p is w pv − p0 v − v × pv.
Vec3d twice_vec_conj_product(double w, const Vec3d& v, double p0, const Vec3d& pv) {
  return 2.0 * (w * pv - p0 * v - v.cross(pv));
}

}  // namespace

TruthState truth_from_jets(double t_s, const JetVec3& r_n, const JetQuat& q_nb) {
  TruthState x;
  x.t_s = t_s;
  x.r_n = Vec3d(r_n[0].val, r_n[1].val, r_n[2].val);
  x.v_n = Vec3d(r_n[0].d1, r_n[1].d1, r_n[2].d1);
  x.a_n = Vec3d(r_n[0].d2, r_n[1].d2, r_n[2].d2);
  x.q_nb = Quatd(q_nb.w.val, q_nb.x.val, q_nb.y.val, q_nb.z.val);
  const Vec3d v = x.q_nb.vec();
  // ω_b = 2 vec(q* ⊗ q̇), ω̇_b = 2 vec(q* ⊗ q̈) (trajectory.hpp).
  x.w_b = twice_vec_conj_product(q_nb.w.val, v, q_nb.w.d1, Vec3d(q_nb.x.d1, q_nb.y.d1, q_nb.z.d1));
  x.wdot_b =
      twice_vec_conj_product(q_nb.w.val, v, q_nb.w.d2, Vec3d(q_nb.x.d2, q_nb.y.d2, q_nb.z.d2));
  return x;
}

TruthState JetTrajectory::at(double t_s) const {
  JetVec3 r_n{};
  JetQuat q_nb{};
  pose(JetD::variable(t_s), r_n, q_nb);
  return truth_from_jets(t_s, r_n, q_nb);
}

namespace {

JetVec3 constant_vec(const Vec3d& v) { return {JetD(v.x()), JetD(v.y()), JetD(v.z())}; }

class Rest final : public Trajectory {
 public:
  Rest(const Quatd& q_nb, const Vec3d& r_n) {
    state_.q_nb = q_nb;
    state_.r_n = r_n;
  }
  TruthState at(double t_s) const override {
    TruthState x = state_;
    x.t_s = t_s;
    return x;
  }
  std::string name() const override { return "rest"; }

 private:
  TruthState state_;
};

class ConstantAcceleration final : public JetTrajectory {
 public:
  ConstantAcceleration(const Vec3d& a_n, const Quatd& q_nb, const Vec3d& r0_n)
      : a_n_(a_n), q_nb_(JetQuat::constant(q_nb)), r0_n_(r0_n) {}
  void pose(const JetD& t, JetVec3& r_n, JetQuat& q_nb) const override {
    const JetD half_t2 = 0.5 * (t * t);
    for (int i = 0; i < 3; ++i) {
      r_n[static_cast<std::size_t>(i)] = r0_n_(i) + a_n_(i) * half_t2;
    }
    q_nb = q_nb_;
  }
  std::string name() const override { return "constant_acceleration"; }

 private:
  Vec3d a_n_;
  JetQuat q_nb_;
  Vec3d r0_n_;
};

class Spin final : public JetTrajectory {
 public:
  Spin(const Vec3d& unit_axis_b, double rate_rps, const Quatd& q0_nb, const Vec3d& r0_n)
      : axis_b_(unit_axis_b), rate_rps_(rate_rps), q0_nb_(JetQuat::constant(q0_nb)), r0_n_(r0_n) {}
  void pose(const JetD& t, JetVec3& r_n, JetQuat& q_nb) const override {
    // A body-fixed axis: the incremental rotation multiplies on the right (body side).
    q_nb = q0_nb_ * jet_axis_angle(axis_b_, rate_rps_ * t);
    r_n = constant_vec(r0_n_);
  }
  std::string name() const override { return "spin"; }

 private:
  Vec3d axis_b_;
  double rate_rps_;
  JetQuat q0_nb_;
  Vec3d r0_n_;
};

class Coning final : public JetTrajectory {
 public:
  Coning(double half_angle_rad, double cone_rate_rps, const Quatd& q0_nb)
      : sin_half_(std::sin(0.5 * half_angle_rad)),
        cos_half_(std::cos(0.5 * half_angle_rad)),
        rate_rps_(cone_rate_rps),
        q0_nb_(JetQuat::constant(q0_nb)) {}
  void pose(const JetD& t, JetVec3& r_n, JetQuat& q_nb) const override {
    // Rotation by the fixed angle β about the axis (cos Ωt, sin Ωt, 0) of the x-y plane. That axis
    // is perpendicular to z, so the body z axis stays at β from the cone axis (q0's z axis) and
    // its azimuth turns at Ω.
    JetD s;
    JetD c;
    sin_cos(rate_rps_ * t, s, c);
    q_nb = q0_nb_ * JetQuat{JetD(cos_half_), sin_half_ * c, sin_half_ * s, JetD()};
    r_n = JetVec3{};
  }
  std::string name() const override { return "coning"; }

 private:
  double sin_half_;
  double cos_half_;
  double rate_rps_;
  JetQuat q0_nb_;
};

// amplitude · sin(omega t + phase): one term of the manoeuvre's sums.
JetD sinusoid(const JetD& t, double amplitude, double omega_rps, double phase_rad) {
  return amplitude * sin(omega_rps * t + phase_rad);
}

class Maneuver final : public JetTrajectory {
 public:
  explicit Maneuver(double scale) : scale_(scale) {}
  void pose(const JetD& t, JetVec3& r_n, JetQuat& q_nb) const override {
    const double k = scale_;
    // North: a cruise ramp that starts from rest, v(t) = v_c (1 − exp(−t/τ)), plus a weave.
    constexpr double kCruiseMps = 2.0;
    constexpr double kTauS = 2.0;
    const JetD ramp = kCruiseMps * (t - kTauS * (1.0 - exp(-t / kTauS)));
    r_n[0] = k * (ramp + sinusoid(t, 3.0, 0.5, 0.0));
    r_n[1] = k * (sinusoid(t, 4.0, 0.3, 0.0) + sinusoid(t, 0.5, 2.1, 0.0));
    r_n[2] = k * (sinusoid(t, -1.5, 0.8, 0.0) + sinusoid(t, 0.2, 3.3, 0.0));
    // Euler angles (rad), Z-Y-X: |roll| ≤ 26°, |pitch| ≤ 18°, yaw drifting at 0.1 rad/s with a
    // swing.
    const JetD roll = k * (sinusoid(t, 0.35, 1.3, 0.2) + sinusoid(t, 0.10, 4.1, 0.3));
    const JetD pitch = k * (sinusoid(t, 0.25, 0.9, 0.5) + sinusoid(t, 0.05, 3.7, 0.0));
    const JetD yaw = k * (0.1 * t + sinusoid(t, 0.5, 0.6, 1.0));
    q_nb = jet_rot_z(yaw) * jet_rot_y(pitch) * jet_rot_x(roll);
  }
  std::string name() const override { return "maneuver"; }

 private:
  double scale_;
};

// Static poses joined by smooth rotations about the array centre (calibration_poses). Pose k is
// held over [k·(D + T), k·(D + T) + D] (D dwell, T transition); the transition from q_k to
// q_k+1 is q_k ⊗ exp(½ φ s(τ) u) with u, φ the axis and angle of q_k* ⊗ q_k+1 (shortest way,
// body axes) and s(τ) = 10τ³ − 15τ⁴ + 6τ⁵ (minimum jerk), τ = (t − start)/T, so ω and ω̇ are zero
// at both ends and the board is exactly still within each dwell.
class PoseSequence final : public JetTrajectory {
 public:
  PoseSequence(std::vector<Quatd> q_nb, double dwell_s, double transition_s)
      : q_(std::move(q_nb)), dwell_s_(dwell_s), transition_s_(transition_s) {
    for (std::size_t k = 0; k + 1 < q_.size(); ++k) {
      Quatd dq = q_[k].conjugate() * q_[k + 1];
      if (dq.w() < 0) dq.coeffs() *= -1.0;
      const double n = dq.vec().norm();
      axis_.push_back(n > 0 ? Vec3d(dq.vec() / n) : Vec3d::UnitX());
      angle_.push_back(2.0 * std::atan2(n, dq.w()));
    }
  }
  void pose(const JetD& t, JetVec3& r_n, JetQuat& q_nb) const override {
    r_n = JetVec3{};
    const double period = dwell_s_ + transition_s_;
    const double k_real = std::floor(std::max(t.val, 0.0) / period);
    const auto k = static_cast<std::size_t>(std::min(k_real, static_cast<double>(q_.size() - 1)));
    const double in_dwell_until = static_cast<double>(k) * period + dwell_s_;
    if (k + 1 >= q_.size() || t.val <= in_dwell_until) {
      q_nb = JetQuat::constant(q_[k]);
      return;
    }
    const JetD tau = (t - in_dwell_until) / transition_s_;
    const JetD tau3 = tau * tau * tau;
    const JetD s = tau3 * (10.0 - 15.0 * tau + 6.0 * (tau * tau));
    q_nb = JetQuat::constant(q_[k]) * jet_axis_angle(axis_[k], angle_[k] * s);
  }
  std::string name() const override { return "calibration_poses"; }

 private:
  std::vector<Quatd> q_;
  std::vector<Vec3d> axis_;
  std::vector<double> angle_;
  double dwell_s_;
  double transition_s_;
};

}  // namespace

std::unique_ptr<Trajectory> make_rest(const Quatd& q_nb, const Vec3d& r_n) {
  return std::make_unique<Rest>(q_nb, r_n);
}

std::unique_ptr<Trajectory> make_constant_acceleration(const Vec3d& a_n, const Quatd& q_nb,
                                                       const Vec3d& r0_n) {
  return std::make_unique<ConstantAcceleration>(a_n, q_nb, r0_n);
}

std::unique_ptr<Trajectory> make_spin(const Vec3d& axis_b, double rate_rps, const Quatd& q0_nb,
                                      const Vec3d& r0_n) {
  const double n = axis_b.norm();
  if (!(n > 0.0) || !std::isfinite(n)) {
    throw std::invalid_argument("make_spin: the spin axis must be a finite non-zero vector");
  }
  return std::make_unique<Spin>(axis_b / n, rate_rps, q0_nb, r0_n);
}

std::unique_ptr<Trajectory> make_coning(double half_angle_rad, double cone_rate_rps,
                                        const Quatd& q0_nb) {
  return std::make_unique<Coning>(half_angle_rad, cone_rate_rps, q0_nb);
}

std::unique_ptr<Trajectory> make_maneuver(double scale) {
  return std::make_unique<Maneuver>(scale);
}

Quatd attitude_sensing(const Vec3d& f_b) {
  // At rest the specific force is −g: along −z of NED ("up"). FromTwoVectors gives the rotation
  // R with R·f̂_b = −ẑ_n, i.e. q_nb (heading: the shortest rotation's, arbitrary but fixed).
  return Quatd::FromTwoVectors(f_b.normalized(), Vec3d(0.0, 0.0, -1.0));
}

std::unique_ptr<Trajectory> make_pose_sequence(const std::vector<Vec3d>& f_b, double dwell_s,
                                               double transition_s) {
  if (f_b.empty() || !(dwell_s > 0.0) || !(transition_s > 0.0)) {
    throw std::invalid_argument(
        "make_pose_sequence: needs at least one pose, a positive dwell and transition");
  }
  std::vector<Quatd> q;
  for (const Vec3d& f : f_b) {
    if (!(f.norm() > 0.0) || !std::isfinite(f.norm())) {
      throw std::invalid_argument("make_pose_sequence: a pose's specific force must be non-zero");
    }
    q.push_back(attitude_sensing(f));
  }
  return std::make_unique<PoseSequence>(std::move(q), dwell_s, transition_s);
}

}  // namespace gfins::sim
