#include "gfins/host_sim/gnss_model.hpp"

#include <cmath>
#include <random>

namespace gfins::sim {

Vec3d antenna_position(const TruthState& x, const Vec3d& lever_arm_b_m) {
  return x.r_n + x.q_nb * lever_arm_b_m;
}

Vec3d antenna_velocity(const TruthState& x, const Vec3d& lever_arm_b_m) {
  // d/dt (C_nb l_b) = C_nb (ω_b × l_b) for a lever arm fixed in the body.
  return x.v_n + x.q_nb * x.w_b.cross(lever_arm_b_m);
}

GnssModel::GnssModel(const GnssSpec& spec, const Trajectory& trajectory, const Vec3d& origin_n_m)
    : spec_(spec), trajectory_(&trajectory), origin_n_m_(origin_n_m) {}

std::vector<GnssSample> GnssModel::fixes(double duration_s) const {
  std::vector<GnssSample> out;
  if (!(spec_.rate_hz > 0.0) || !(duration_s >= 0.0)) return out;
  // One generator for the whole run, six draws per fix time in a fixed order (N, E, D position,
  // then N, E, D velocity), also for the times inside an outage: the same seed gives the same
  // fixes, and a fix's noise does not depend on the outages before it.
  std::mt19937_64 rng(spec_.seed);
  std::normal_distribution<double> unit(0.0, 1.0);
  const auto n_fixes = static_cast<std::uint64_t>(std::floor(duration_s * spec_.rate_hz + 1e-9));
  std::uint32_t sent = 0;
  for (std::uint64_t k = 0; k <= n_fixes; ++k) {
    const double t = static_cast<double>(k) / spec_.rate_hz;
    const std::array<double, 6> noise{unit(rng), unit(rng), unit(rng),
                                      unit(rng), unit(rng), unit(rng)};
    bool in_outage = false;
    for (const auto& [start, end] : spec_.outages) in_outage = in_outage || (t >= start && t < end);
    if (in_outage) continue;
    const TruthState x = trajectory_->at(t);
    GnssSample s;
    s.index = sent++;
    s.t_valid_s = t;
    s.t_send_s = t + spec_.latency_s;
    s.r_true_n_m = antenna_position(x, spec_.lever_arm_b_m) - origin_n_m_;
    s.v_true_n_mps = antenna_velocity(x, spec_.lever_arm_b_m);
    s.r_n_m = s.r_true_n_m + Vec3d(spec_.sigma_pos_h_m * noise[0], spec_.sigma_pos_h_m * noise[1],
                                   spec_.sigma_pos_v_m * noise[2]);
    s.v_n_mps = s.v_true_n_mps + spec_.sigma_vel_mps * Vec3d(noise[3], noise[4], noise[5]);
    out.push_back(s);
  }
  return out;
}

}  // namespace gfins::sim
