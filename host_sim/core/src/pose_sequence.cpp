#include "gfins/host_sim/pose_sequence.hpp"

#include <algorithm>
#include <cmath>

#include "gfins/nav_core/calibration/multi_attitude.hpp"

namespace gfins::sim {
namespace {

/// Quintic time law s(τ) = 10τ³ − 15τ⁴ + 6τ⁵ over a jet τ: s(0) = 0, s(1) = 1, ṡ and s̈ zero at
/// both ends.
JetD quintic(const JetD& tau) {
  const JetD t3 = tau * tau * tau;
  return t3 * (10.0 - 15.0 * tau + 6.0 * tau * tau);
}

class PoseSequence final : public JetTrajectory {
 public:
  PoseSequence(std::vector<Quatd> q, double dwell_s, double slew_s)
      : q_(std::move(q)), dwell_s_(dwell_s), slew_s_(slew_s) {
    // The turn from pose j to j + 1: q_{j+1} = q_j ⊗ exp(½ θ u), u and θ in the body frame of
    // pose j, the shortest way (w ≥ 0).
    for (std::size_t j = 0; j + 1 < q_.size(); ++j) {
      Quatd dq = q_[j].conjugate() * q_[j + 1];
      if (dq.w() < 0) dq.coeffs() *= -1.0;
      const double s = dq.vec().norm();
      axis_.push_back(s > 0 ? Vec3d(dq.vec() / s) : Vec3d::UnitZ());
      angle_.push_back(2.0 * std::atan2(s, dq.w()));
    }
  }

  void pose(const JetD& t, JetVec3& r_n, JetQuat& q_nb) const override {
    r_n = {JetD(0.0), JetD(0.0), JetD(0.0)};
    const double period = dwell_s_ + slew_s_;
    const double k = std::floor(t.val / period);
    const auto last = static_cast<double>(q_.size() - 1);
    if (t.val < 0 || k >= last) {
      q_nb = JetQuat::constant(t.val < 0 ? q_.front() : q_.back());
      return;
    }
    const auto j = static_cast<std::size_t>(k);
    const JetD in_period = t - k * period;
    if (in_period.val <= dwell_s_) {
      q_nb = JetQuat::constant(q_[j]);
      return;
    }
    const JetD tau = (in_period - JetD(dwell_s_)) / slew_s_;
    q_nb = JetQuat::constant(q_[j]) * jet_axis_angle(axis_[j], angle_[j] * quintic(tau));
  }
  std::string name() const override { return "calibration_poses"; }

 private:
  std::vector<Quatd> q_;
  std::vector<Vec3d> axis_;
  std::vector<double> angle_;
  double dwell_s_;
  double slew_s_;
};

}  // namespace

HostResult<std::vector<std::array<double, 3>>> calibration_pose_list(const std::string& which) {
  if (which != "table2" && which != "table3" && which != "both") {
    return HostError{ErrorCode::kInvalidArgument,
                     "calibration poses '" + which + "': expected table2, table3 or both"};
  }
  std::vector<std::array<double, 3>> out;
  if (which != "table3") {
    for (const auto& a : calib::table2_attitudes<double>()) out.push_back(a);
  }
  if (which != "table2") {
    for (const auto& a : calib::table3_attitudes<double>()) out.push_back(a);
  }
  return out;
}

double pose_sequence_duration_s(std::size_t poses, double dwell_s, double slew_s) {
  if (poses == 0) return 0.0;
  return static_cast<double>(poses) * dwell_s + static_cast<double>(poses - 1) * slew_s;
}

std::unique_ptr<Trajectory> make_pose_sequence(const std::vector<std::array<double, 3>>& f_b_g,
                                               double dwell_s, double slew_s, const Vec3d& up_n) {
  std::vector<Quatd> q;
  q.reserve(f_b_g.size() + 1);
  for (const auto& a : f_b_g) {
    // q_nb a_j = up_n: the sensed specific force of the pose points up in the navigation frame.
    q.push_back(Quatd::FromTwoVectors(Vec3d(a[0], a[1], a[2]).normalized(), up_n.normalized()));
  }
  if (q.empty()) q.push_back(Quatd::Identity());
  return std::make_unique<PoseSequence>(std::move(q), dwell_s, std::max(slew_s, 1e-3));
}

}  // namespace gfins::sim
