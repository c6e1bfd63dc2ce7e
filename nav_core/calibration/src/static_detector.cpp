// Static-interval helpers: rejection names and the interval → solver-observation assignment.
#include "gfins/nav_core/calibration/static_detector.hpp"

#include <Eigen/Dense>

namespace gfins::calib {

const char* to_string(PoseRejection r) {
  switch (r) {
    case PoseRejection::kTooShort:
      return "too short: still for less than min_still_s";
    case PoseRejection::kTooNoisy:
      return "too noisy: a channel's standard deviation exceeds max_std_v";
  }
  return "unknown rejection";
}

template <typename T>
Vec3<T> specific_force_estimate(const StaticInterval<T>& interval,
                                const PoseAssignmentConfig<T>& cfg) {
  Eigen::Matrix<T, 6, 3> theta;
  Eigen::Matrix<T, 6, 1> s;
  for (int j = 0; j < 6; ++j) {
    const auto sj = static_cast<std::size_t>(j);
    theta.row(j) = cfg.theta_b[sj].transpose();
    s(j) = interval.mean_v[sj] / cfg.nominal_scale_v_per_g[sj] - cfg.nominal_bias_g[sj];
  }
  // Normal equations are fine here: ΘᵀΘ = 2I for Table 1 and any usable array is well
  // conditioned (the navigation solver refuses the others).
  const Eigen::Matrix<T, 3, 3> n = theta.transpose() * theta;
  return n.ldlt().solve(theta.transpose() * s);
}

template <typename T>
Result<std::size_t> intervals_to_observations(std::span<const StaticInterval<T>> intervals,
                                              std::span<const std::array<T, 3>> expected_f_b_g,
                                              const PoseAssignmentConfig<T>& cfg,
                                              std::span<AttitudeObservation<T>> out,
                                              std::span<int> attitude_of_interval) {
  for (const T sf : cfg.nominal_scale_v_per_g) {
    if (!std::isfinite(sf) || sf == T(0)) {
      return Status(ErrorCode::kInvalidArgument,
                    "pose assignment: a nominal scale factor is zero or not finite");
    }
  }
  if (attitude_of_interval.size() < intervals.size()) {
    return Status(ErrorCode::kInvalidArgument,
                  "pose assignment: attitude_of_interval shorter than the interval list");
  }
  const T min_cos = std::cos(cfg.max_angle_rad);
  std::size_t n = 0;
  for (std::size_t k = 0; k < intervals.size(); ++k) {
    const StaticInterval<T>& it = intervals[k];
    const Vec3<T> f = specific_force_estimate(it, cfg);
    const T norm = f.norm();
    attitude_of_interval[k] = -1;
    std::array<T, 3> f_b_g{};
    if (expected_f_b_g.empty()) {
      if (!(norm > T(0))) continue;  // no usable direction (all outputs at the bias)
      const Vec3<T> u = f / norm;
      f_b_g = {u.x(), u.y(), u.z()};
    } else {
      T best = T(-2);
      int best_j = -1;
      for (std::size_t j = 0; j < expected_f_b_g.size(); ++j) {
        const Vec3<T> e(expected_f_b_g[j][0], expected_f_b_g[j][1], expected_f_b_g[j][2]);
        const T en = e.norm();
        if (!(en > T(0)) || !(norm > T(0))) continue;
        const T c = e.dot(f) / (en * norm);
        if (c > best) {
          best = c;
          best_j = static_cast<int>(j);
        }
      }
      if (best_j < 0 || best < min_cos) continue;
      attitude_of_interval[k] = best_j;
      f_b_g = expected_f_b_g[static_cast<std::size_t>(best_j)];
    }
    if (n == out.size()) {
      return Status(ErrorCode::kResourceExhausted,
                    "pose assignment: more intervals than observation slots");
    }
    AttitudeObservation<T>& o = out[n++];
    o = AttitudeObservation<T>{};
    o.f_b_g = f_b_g;
    o.mean_v = it.mean_v;
    o.sample_std_v = it.std_v;
    o.sample_count = it.count;
    if (expected_f_b_g.empty()) attitude_of_interval[k] = static_cast<int>(n - 1);
  }
  return n;
}

template Vec3<float> specific_force_estimate<float>(const StaticInterval<float>&,
                                                    const PoseAssignmentConfig<float>&);
template Result<std::size_t> intervals_to_observations<float>(
    std::span<const StaticInterval<float>>, std::span<const std::array<float, 3>>,
    const PoseAssignmentConfig<float>&, std::span<AttitudeObservation<float>>, std::span<int>);
// GFINS_NAV_FLOAT_ONLY: the board's scalar only (a build without GFINS_NAV_DOUBLE; clang-tidy).
#ifndef GFINS_NAV_FLOAT_ONLY
template Vec3<double> specific_force_estimate<double>(const StaticInterval<double>&,
                                                      const PoseAssignmentConfig<double>&);
template Result<std::size_t> intervals_to_observations<double>(
    std::span<const StaticInterval<double>>, std::span<const std::array<double, 3>>,
    const PoseAssignmentConfig<double>&, std::span<AttitudeObservation<double>>, std::span<int>);
#endif

}  // namespace gfins::calib
