// Simulated GNSS receiver: fixes of the antenna's position and velocity made from a trajectory's
// analytic truth, with the lever arm, white Gaussian noise of the stated σ, outages, and the
// latency between a fix's time of validity and its transmission. Feeds `gfins-can gnss`, which
// writes the fixes as the CAN interface's GNSS input frames (docs/can-interface.md).
//
// Geometry (frames of trajectory.hpp: n = NED at the alignment point, b = FRD at the array
// centre o_b; l_b = antenna position from o_b in body axes):
//   antenna position  r_a = r_n + C_nb l_b
//   antenna velocity  v_a = v_n + C_nb (ω_b × l_b)      (l_b is fixed in the body)
// both at the fix's time of validity t_v; the fix is sent at t_v + latency_s and says so
// (age_s = latency_s), so the board can place it at t_v.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "gfins/host_sim/trajectory.hpp"

namespace gfins::sim {

/// The `[gnss]` table of a scenario file (docs/simulation.md).
struct GnssSpec {
  double rate_hz = 10.0;                // fixes per second
  double sigma_pos_h_m = 1.0;           // 1σ of the position noise, north and east (each), m
  double sigma_pos_v_m = 2.0;           // 1σ, down, m
  double sigma_vel_mps = 0.05;          // 1σ per velocity axis, m/s
  double latency_s = 0.05;              // transmission time - time of validity
  Vec3d lever_arm_b_m = Vec3d::Zero();  // antenna from the array centre, body FRD, m
  std::vector<std::pair<double, double>> outages;  // [start_s, end_s): no fix valid in between
  std::uint64_t seed = 1;
};

/// One fix as the receiver sends it (noisy) and the truth behind it.
struct GnssSample {
  std::uint32_t index = 0;           // fixes sent before this one (the fix id is index mod 16)
  double t_valid_s = 0.0;            // time of validity, scenario time
  double t_send_s = 0.0;             // transmission time: t_valid_s + latency
  Vec3d r_n_m = Vec3d::Zero();       // measured antenna position, NED from the origin
  Vec3d v_n_mps = Vec3d::Zero();     // measured antenna velocity
  Vec3d r_true_n_m = Vec3d::Zero();  // the truth the noise was added to
  Vec3d v_true_n_mps = Vec3d::Zero();
};

/// Antenna position and velocity of a truth state with lever arm l_b (the formulas above).
Vec3d antenna_position(const TruthState& x, const Vec3d& lever_arm_b_m);
Vec3d antenna_velocity(const TruthState& x, const Vec3d& lever_arm_b_m);

class GnssModel {
 public:
  /// `origin_n_m`: the navigation origin (alignment point) in the trajectory's frame; positions
  /// are sent relative to it.
  GnssModel(const GnssSpec& spec, const Trajectory& trajectory,
            const Vec3d& origin_n_m = Vec3d::Zero());

  /// Every fix whose time of validity lies in [0, duration_s] and outside the outages, in
  /// order. The same spec and seed give the same fixes, bit for bit.
  std::vector<GnssSample> fixes(double duration_s) const;

  const GnssSpec& spec() const { return spec_; }

 private:
  GnssSpec spec_;
  const Trajectory* trajectory_;
  Vec3d origin_n_m_;
};

}  // namespace gfins::sim
