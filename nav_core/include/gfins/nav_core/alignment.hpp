// Static alignment: roll and pitch from the specific force averaged at rest; heading and
// position are given (nothing on a gyro-free board senses heading), ω = 0 at rest.
#pragma once

#include <cstdint>

#include "gfins/nav_core/geometry.hpp"
#include "gfins/nav_core/nav_state.hpp"
#include "gfins/status/status.hpp"

namespace gfins::nav {

template <typename T>
struct AlignmentResult {
  T roll_rad = T(0);
  T pitch_rad = T(0);
  T gravity_mps2 = T(0);   // |mean f|: a check against the gravity model
  T f_noise_mps2 = T(0);   // RMS deviation of f from its mean (motion / noise indicator)
  T wdot_rms_rps2 = T(0);  // RMS angular acceleration seen while "at rest"
  std::uint32_t samples = 0;
};

/// Accumulates the array's specific force at o_b (ω = 0) over a window at rest. The mean is
/// computed with a shifted sum (first sample as reference) so float32 keeps its precision over
/// long windows. The aligner holds no solver of its own: the caller passes the one it navigates
/// with, so a new calibration cannot leave alignment and navigation on different geometries.
template <typename T, int N = kNumSensors>
class StaticAligner {
 public:
  using Solver = ArraySolver<T, N>;

  void reset() { *this = StaticAligner(); }

  /// One sample at rest: compensated outputs s, mapped to [ω̇; f] by `solver` with ω = 0.
  void add(const Solver& solver, const typename Solver::Outputs& s) {
    Vec3<T> wdot;
    Vec3<T> f;
    solver.solve(s, Vec3<T>::Zero(), wdot, f);
    if (count_ == 0) ref_ = f;
    const Vec3<T> d = f - ref_;
    sum_ += d;
    sum_sq_ += d.squaredNorm();
    wdot_sq_ += wdot.squaredNorm();
    ++count_;
  }

  std::uint32_t count() const { return count_; }

  /// Roll and pitch (NED navigation frame, FRD body) from the mean specific force. Fails when
  /// fewer than min_samples were added or the mean is far from a gravity vector (|f| < 1 m/s²).
  Result<AlignmentResult<T>> finish(std::uint32_t min_samples = 1) const {
    if (count_ < min_samples || count_ == 0) {
      return Status(ErrorCode::kFailedPrecondition,
                    "alignment: not enough samples at rest were collected");
    }
    const T n = static_cast<T>(count_);
    const Vec3<T> mean_d = sum_ / n;
    const Vec3<T> f = ref_ + mean_d;
    AlignmentResult<T> r;
    r.gravity_mps2 = f.norm();
    if (!(r.gravity_mps2 > T(1))) {
      return Status(ErrorCode::kInvalidArgument,
                    "alignment: mean specific force is not a gravity vector (|f| < 1 m/s^2); the "
                    "board was not at rest or the outputs are not in m/s^2");
    }
    // At rest f_b = −C_n^b g_n = g [sin θ, −sin φ cos θ, −cos φ cos θ].
    r.roll_rad = std::atan2(-f.y(), -f.z());
    r.pitch_rad = std::atan2(f.x(), std::sqrt(f.y() * f.y() + f.z() * f.z()));
    const T var = sum_sq_ / n - mean_d.squaredNorm();
    r.f_noise_mps2 = std::sqrt(var > T(0) ? var : T(0));
    r.wdot_rms_rps2 = std::sqrt(wdot_sq_ / n);
    r.samples = count_;
    return r;
  }

  /// The initial state at t_ns for a given heading (rad, from north) and position (m, NED).
  static NavState<T> initial_state(const AlignmentResult<T>& a, T heading_rad, const Vec3<T>& r_n,
                                   std::int64_t t_ns) {
    NavState<T> s;
    s.t_ns = t_ns;
    s.q_nb = quat_from_euler(a.roll_rad, a.pitch_rad, heading_rad);
    s.r_n = r_n;
    s.status = nav_status::kAligned;
    return s;
  }

 private:
  Vec3<T> ref_ = Vec3<T>::Zero();
  Vec3<T> sum_ = Vec3<T>::Zero();
  T sum_sq_ = T(0);
  T wdot_sq_ = T(0);
  std::uint32_t count_ = 0;
};

}  // namespace gfins::nav
