// The calibration poses of the paper's Tables 2/3 as a motion with analytic truth, so that a
// calibration run can be recorded like any other scenario (gfins-sim run --record) and the
// recording fed to gfins-calibrate (docs/simulation.md, "Recording a calibration").
//
// Pose j is held still for dwell_s, then the body turns to pose j + 1 in slew_s about one fixed
// body axis (the shortest rotation between the two attitudes) with the quintic time law
// s(τ) = 10τ³ − 15τ⁴ + 6τ⁵, τ ∈ [0, 1]: rate and angular acceleration are zero at both ends of a
// turn, so the truth (trajectory.hpp) is continuous in ω and ω̇. After the last pose the body
// stays in it.
//
// In pose j the body senses the specific force a_j g of the table (a_j a unit vector in the
// body frame, in g): the attitude q_nb rotates a_j onto the "up" direction of the navigation
// frame, −z of NED for gravity along +z (f_n = −g_n at rest).
#pragma once

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "gfins/host_sim/error.hpp"
#include "gfins/host_sim/trajectory.hpp"

namespace gfins::sim {

/// Time of each turn between two poses, s (long enough for a still-interval detector to see the
/// motion, short against the dwell).
inline constexpr double kPoseSlewS = 2.0;

/// The specific force of each pose (g, body frame): "table2" (Table 2, six poses), "table3"
/// (Table 3) or "both" (Table 2 then Table 3). kInvalidArgument for another name.
HostResult<std::vector<std::array<double, 3>>> calibration_pose_list(const std::string& which);

/// Time from the start to the end of the last dwell: n dwell_s + (n − 1) slew_s.
double pose_sequence_duration_s(std::size_t poses, double dwell_s, double slew_s = kPoseSlewS);

/// The motion described above. `up_n` is the unit vector of the navigation frame along −gravity
/// ((0, 0, −1) for NED with gravity down).
std::unique_ptr<Trajectory> make_pose_sequence(const std::vector<std::array<double, 3>>& f_b_g,
                                               double dwell_s, double slew_s = kPoseSlewS,
                                               const Vec3d& up_n = Vec3d(0.0, 0.0, -1.0));

}  // namespace gfins::sim
