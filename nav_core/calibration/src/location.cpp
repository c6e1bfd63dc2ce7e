// Location calibration (paper §4.2, eqs. (19)-(21)); the model, the observability argument and
// the gauge are explained in gfins/nav_core/calibration/location.hpp and docs/compensator.md.
#include "gfins/nav_core/calibration/location.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <cstddef>

namespace gfins::calib {
namespace {

// Unknowns: Δρ_1..Δρ_6 (3 each), then the table-axis offsets p_0..p_{M−1} (3 each), all in m.
constexpr int kNumDrho = 3 * nav::kNumSensors;
constexpr int kNumUnknowns = kNumDrho + 3 * kMaxLocationMountings;
using VecX = Eigen::Matrix<double, kNumUnknowns, 1>;
using MatX = Eigen::Matrix<double, kNumUnknowns, kNumUnknowns>;

constexpr int drho_index(int j) { return 3 * j; }
constexpr int offset_index(int m) { return kNumDrho + 3 * m; }

// Two spin directions count as the same table axis when they differ by less than this angle
// (rad): a fixture pose is repeatable to far better than 1 mrad, and the centripetal term is even
// in ω, so ω and −ω share an axis.
constexpr double kSameAxisTolerance = 1e-3;

// A sensor direction is reported unobservable when more than this fraction of it lies in the
// null space of the normal equations (the eigenvalue of the null-space projector's 3×3 block).
// Exactly estimable directions give 0 up to rounding (1e-12); a direction mixed into the null
// space at the 10 % amplitude level (fraction 0.01) already depends visibly on the zero-hold.
constexpr double kNullFractionThreshold = 1e-2;

struct Mounting {
  bool used = false;
  Eigen::Vector3d u_b = Eigen::Vector3d::Zero();  // unit spin axis of the first run
};

template <typename T>
Status validate_run(const LocationRun<T>& run, const LocationOptions& options) {
  if (!run.w_b.allFinite() || !run.g_b.allFinite() || !run.s_mean.allFinite() ||
      !run.sigma.allFinite()) {
    return Status(ErrorCode::kInvalidArgument,
                  "location calibration: a run has a non-finite rate, gravity, output or sigma");
  }
  if (run.mounting < 0 || run.mounting >= kMaxLocationMountings) {
    return Status(ErrorCode::kOutOfRange,
                  "location calibration: a run's mounting index is outside "
                  "0..kMaxLocationMountings-1");
  }
  if (!(static_cast<double>(run.w_b.norm()) >= options.min_rate_rad_s)) {
    return Status(ErrorCode::kInvalidArgument,
                  "location calibration: a run's table rate is zero or below min_rate_rad_s; it "
                  "carries no centripetal signal");
  }
  if (!(run.sigma.minCoeff() > T(0)) || run.count == 0) {
    return Status(ErrorCode::kInvalidArgument,
                  "location calibration: a run has sigma <= 0 or a sample count of 0");
  }
  return Status::ok();
}

// Checks every run and records each mounting's spin axis.
template <typename T>
Status validate_runs(std::span<const LocationRun<T>> runs, const LocationOptions& options,
                     std::array<Mounting, kMaxLocationMountings>& mountings) {
  if (runs.size() < 3) {
    return Status(ErrorCode::kInvalidArgument,
                  "location calibration: fewer than three runs; at least one run about each of "
                  "three axes is needed");
  }
  if (!std::isfinite(options.min_relative_information) ||
      !(options.min_relative_information > 0.0) || !(options.min_relative_information < 1.0) ||
      !std::isfinite(options.min_rate_rad_s)) {
    return Status(ErrorCode::kInvalidArgument,
                  "location calibration: min_relative_information must be in (0, 1) and "
                  "min_rate_rad_s finite");
  }
  for (const auto& run : runs) {
    const Status s = validate_run(run, options);
    if (!s.is_ok()) return s;
    Mounting& m = mountings[static_cast<std::size_t>(run.mounting)];
    const Eigen::Vector3d u = run.w_b.template cast<double>().normalized();
    if (!m.used) {
      m.used = true;
      m.u_b = u;
    } else if (options.axis_offset == AxisOffsetModel::kEstimatePerMounting &&
               m.u_b.cross(u).norm() > kSameAxisTolerance) {
      return Status(ErrorCode::kInvalidArgument,
                    "location calibration: runs of one mounting spin about different axes; a "
                    "mounting is one fixture pose on a single-axis table");
    }
  }
  return Status::ok();
}

struct NormalEquations {
  MatX n = MatX::Zero();  // Σ w rᵀr over all equations (data only)
  VecX b = VecX::Zero();  // Σ w r y
  int rows = 0;
};

// Row of sensor j in one run: y = aᵀ(Δρ_j − p_m), a = [ω×]²θ*_j; weight count/σ² (σ of the mean).
struct Equation {
  Eigen::Vector3d a;
  double y = 0.0;
  double weight = 0.0;
};

template <typename T>
Equation make_equation(const nav::ArrayGeometry<double, nav::kNumSensors>& g,
                       const LocationRun<T>& run, int j) {
  const auto js = static_cast<std::size_t>(j);
  const Eigen::Vector3d w = run.w_b.template cast<double>();
  const Eigen::Vector3d grav = run.g_b.template cast<double>();
  const Eigen::Vector3d& th = g.theta_b[js];
  // Output of sensor j at its nominal position, eqs. (20)/(21) with ω×(ω×ρ) (misprint fixed).
  const double s_nominal = th.dot(-grav + w.cross(w.cross(g.rho_b[js])));
  const double sigma = static_cast<double>(run.sigma(j));
  Equation e;
  e.a = location_design_row(th, w);
  e.y = static_cast<double>(run.s_mean(j)) - s_nominal;
  e.weight = static_cast<double>(run.count) / (sigma * sigma);
  return e;
}

template <typename T>
NormalEquations accumulate(const nav::ArrayGeometry<double, nav::kNumSensors>& g,
                           std::span<const LocationRun<T>> runs, bool estimate_offsets) {
  NormalEquations ne;
  for (const auto& run : runs) {
    const int p = offset_index(run.mounting);
    for (int j = 0; j < nav::kNumSensors; ++j) {
      const Equation e = make_equation(g, run, j);
      const int d = drho_index(j);
      const Eigen::Matrix3d aa = e.weight * e.a * e.a.transpose();
      ne.n.block<3, 3>(d, d) += aa;
      ne.b.segment<3>(d) += e.weight * e.y * e.a;
      if (estimate_offsets) {
        ne.n.block<3, 3>(p, p) += aa;
        ne.n.block<3, 3>(d, p) -= aa;
        ne.n.block<3, 3>(p, d) -= aa;
        ne.b.segment<3>(p) -= e.weight * e.y * e.a;
      }
      ++ne.rows;
    }
  }
  return ne;
}

// Minimal constraints that fix the directions no data can see by construction (unused offsets,
// the gauge, offsets along the spin axis), as CᵀC scaled to the data's largest eigenvalue so the
// eigenvalue test below treats them like well-determined directions. Returns their count.
int add_constraints(const std::array<Mounting, kMaxLocationMountings>& mountings,
                    bool estimate_offsets, const VecX& block_scale, double scale, MatX& n) {
  int count = 0;
  for (int m = 0; m < kMaxLocationMountings; ++m) {
    const Mounting& mt = mountings[static_cast<std::size_t>(m)];
    const int p = offset_index(m);
    if (!estimate_offsets || !mt.used) {
      n.block<3, 3>(p, p) += scale * Eigen::Matrix3d::Identity();  // p_m = 0
      count += 3;
    } else {
      n.block<3, 3>(p, p) += scale * mt.u_b * mt.u_b.transpose();  // u_m·p_m = 0
      count += 1;
    }
  }
  if (estimate_offsets) {
    // Gauge Σ_j Δρ_j = 0 per axis k; in the scaled unknowns z (Δρ_j = c_j z_j) the row is
    // Σ_j c_j e_{3j+k}, normalised.
    for (int k = 0; k < 3; ++k) {
      VecX row = VecX::Zero();
      for (int j = 0; j < nav::kNumSensors; ++j)
        row(drho_index(j) + k) = block_scale(drho_index(j));
      row.normalize();
      n += scale * row * row.transpose();
      count += 1;
    }
  }
  return count;
}

template <typename T>
double weighted_residual_sum(const nav::ArrayGeometry<double, nav::kNumSensors>& g,
                             std::span<const LocationRun<T>> runs, const VecX& x) {
  double chi2 = 0.0;
  for (const auto& run : runs) {
    const Eigen::Vector3d p = x.segment<3>(offset_index(run.mounting));
    for (int j = 0; j < nav::kNumSensors; ++j) {
      const Equation e = make_equation(g, run, j);
      const double r = e.y - e.a.dot(x.segment<3>(drho_index(j)) - p);
      chi2 += e.weight * r * r;
    }
  }
  return chi2;
}

// Right-hand side of the first-order change of the normal equations when sensor j's base
// calibration moves (paper §4.2, eqs. (20)/(21); docs/calibration.md, location σ). The solution
// satisfies Σ_r w_r a_r e_r = 0 (and its negative for the offset of the run's mounting), with
// e_r = y_r − a_rᵀ(Δρ_j − p_m), a_r = W_r θ*_j, W_r = [ω_r×]² (symmetric), y_r = s*_r − θ*_j·h_r
// and h_r = −g_b + W_r ρ_j. Differentiating: N dx = Σ_r w_r (a_r (dy_r − da_rᵀ(Δρ_j − p_m)) +
// da_r e_r), where
//   offset c:  dy_r = c,  da_r = 0;
//   gain k:    dy_r = k s*_r,  da_r = 0;
//   axis δθ:   dy_r = −h_rᵀ δθ,  da_r = W_r δθ.
// The weights w_r = count/σ_r² do not move: an SF error scales every σ_r of the sensor alike, which
// leaves the estimate unchanged with kThroughCentre (and changes it only by residual-sized terms
// otherwise, below first order in the base error times the noise). Columns: kBaseOffset,
// kBaseGain, kBaseAxis..+2.
using RhsX = Eigen::Matrix<double, kNumUnknowns, kNumBaseParams>;

template <typename T>
RhsX base_rhs(const nav::ArrayGeometry<double, nav::kNumSensors>& g,
              std::span<const LocationRun<T>> runs, bool estimate_offsets, const VecX& x, int j) {
  RhsX rhs = RhsX::Zero();
  const int d = drho_index(j);
  const Eigen::Vector3d rho = g.rho_b[static_cast<std::size_t>(j)];
  for (const auto& run : runs) {
    const Equation e = make_equation(g, run, j);
    const int p = offset_index(run.mounting);
    const Eigen::Vector3d rel = x.segment<3>(d) - x.segment<3>(p);  // Δρ_j − p_m
    const Eigen::Vector3d w = run.w_b.template cast<double>();
    const Eigen::Matrix3d big_w = w * w.transpose() - w.squaredNorm() * Eigen::Matrix3d::Identity();
    const Eigen::Vector3d h = -run.g_b.template cast<double>() + big_w * rho;
    const double residual = e.y - e.a.dot(rel);
    Eigen::Matrix<double, 3, kNumBaseParams> block;
    block.col(kBaseOffset) = e.weight * e.a;
    block.col(kBaseGain) = e.weight * static_cast<double>(run.s_mean(j)) * e.a;
    block.block<3, 3>(0, kBaseAxis) =
        e.weight * (residual * big_w - e.a * (h + big_w * rel).transpose());
    rhs.block<3, kNumBaseParams>(d, 0) += block;
    if (estimate_offsets) rhs.block<3, kNumBaseParams>(p, 0) -= block;
  }
  return rhs;
}

}  // namespace

template <typename T>
Result<LocationCalibration<T>> calibrate_location(
    const nav::ArrayGeometry<T, nav::kNumSensors>& calibrated, std::span<const LocationRun<T>> runs,
    const LocationOptions& options) {
  const nav::ArrayGeometry<double, nav::kNumSensors> g = calibrated.template cast<double>();
  for (int j = 0; j < nav::kNumSensors; ++j) {
    const auto js = static_cast<std::size_t>(j);
    if (!g.rho_b[js].allFinite() || !g.theta_b[js].allFinite() ||
        std::abs(g.theta_b[js].norm() - 1.0) > 0.1) {
      return Status(ErrorCode::kInvalidArgument,
                    "location calibration: a nominal position or calibrated axis is not finite, "
                    "or an axis is not near unit length");
    }
  }
  std::array<Mounting, kMaxLocationMountings> mountings{};
  const Status valid = validate_runs(runs, options, mountings);
  if (!valid.is_ok()) return valid;

  const bool estimate_offsets = options.axis_offset == AxisOffsetModel::kEstimatePerMounting;
  const NormalEquations ne = accumulate(g, runs, estimate_offsets);

  // Work in block-scaled unknowns z, x = S z, with S = c_b I on each 3-block and
  // c_b = 1/√(tr N_bb / 3): the offsets collect information from all six sensors and would
  // otherwise set the scale of the information floor for the positions. Within a block the scaling
  // is isotropic, so a sensor's weak direction stays weak relative to its strong ones.
  VecX block_scale = VecX::Ones();
  for (int i = 0; i < kNumUnknowns; i += 3) {
    const double tr = ne.n.block<3, 3>(i, i).trace() / 3.0;
    if (tr > 0.0 && std::isfinite(tr)) block_scale.segment<3>(i).setConstant(1.0 / std::sqrt(tr));
  }
  const MatX n_scaled = block_scale.asDiagonal() * ne.n * block_scale.asDiagonal();
  const VecX b_scaled = block_scale.cwiseProduct(ne.b);

  const Eigen::SelfAdjointEigenSolver<MatX> data_eig(n_scaled, Eigen::EigenvaluesOnly);
  const double lambda_max = data_eig.eigenvalues().maxCoeff();
  if (!(lambda_max > 0.0) || !std::isfinite(lambda_max)) {
    return Status(ErrorCode::kInvalidArgument,
                  "location calibration: the runs carry no information on the positions (every "
                  "axis parallel to every rate?)");
  }
  MatX n_constrained = n_scaled;
  const int num_constraints =
      add_constraints(mountings, estimate_offsets, block_scale, lambda_max, n_constrained);

  // Truncated eigen-inverse: directions below the information floor are held at zero (they are
  // the unobservable ones); the others are solved exactly. With minimal constraints this is the
  // constrained least-squares solution, and its covariance is N'⁺ N N'⁺ (N'⁺ b propagated).
  const Eigen::SelfAdjointEigenSolver<MatX> eig(n_constrained);
  const double floor = options.min_relative_information * lambda_max;
  MatX n_pinv = MatX::Zero();
  MatX null_projector = MatX::Zero();
  int num_determined = 0;
  for (int i = 0; i < kNumUnknowns; ++i) {
    const auto v = eig.eigenvectors().col(i);
    if (eig.eigenvalues()(i) > floor) {
      n_pinv += v * v.transpose() / eig.eigenvalues()(i);
      ++num_determined;
    } else {
      null_projector += v * v.transpose();
    }
  }
  const VecX x = block_scale.cwiseProduct(n_pinv * b_scaled);
  const MatX cov =
      block_scale.asDiagonal() * (n_pinv * n_scaled * n_pinv) * block_scale.asDiagonal();

  LocationCalibration<T> out;
  for (int j = 0; j < nav::kNumSensors; ++j) {
    const auto js = static_cast<std::size_t>(j);
    const int d = drho_index(j);
    out.drho_b[js] = x.segment<3>(d).template cast<T>();
    out.drho_cov_m2[js] = cov.block<3, 3>(d, d).template cast<T>();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> block_eig(
        null_projector.block<3, 3>(d, d));
    int dims = 0;
    for (int k = 0; k < 3; ++k) dims += block_eig.eigenvalues()(k) > kNullFractionThreshold;
    out.unobservable_dims[js] = dims;
    out.verdict[js] = dims > 0 ? Observability::kUnobservable : Observability::kObservable;
    // Eigenvalues ascend, so the last column is the sensor direction most inside the null space.
    const Eigen::Vector3d dir = block_eig.eigenvectors().col(2);
    out.unobservable_dir_b[js] = nav::Vec3<T>::Zero();
    if (dims > 0) out.unobservable_dir_b[js] = dir.template cast<T>();
  }
  for (int m = 0; m < kMaxLocationMountings; ++m) {
    const auto ms = static_cast<std::size_t>(m);
    if (mountings[ms].used) out.num_mountings = m + 1;
    out.axis_offset_b[ms] = x.segment<3>(offset_index(m)).template cast<T>();
    out.axis_offset_cov_m2[ms] =
        cov.block<3, 3>(offset_index(m), offset_index(m)).template cast<T>();
  }
  // Sensitivity to the base calibration: dx = S N'⁺ S · rhs (the same linear map that gives x
  // from the right-hand side b, so held-at-zero directions stay zero).
  for (int j = 0; j < nav::kNumSensors; ++j) {
    const RhsX rhs = base_rhs(g, runs, estimate_offsets, x, j);
    const RhsX scaled = block_scale.asDiagonal() * rhs;
    const RhsX dx = block_scale.asDiagonal() * (n_pinv * scaled);
    for (int i = 0; i < nav::kNumSensors; ++i) {
      out.base_jacobian[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)] =
          dx.block<3, kNumBaseParams>(drho_index(i), 0).template cast<T>();
    }
  }
  out.chi2 = weighted_residual_sum(g, runs, x);
  out.dof = ne.rows - (num_determined - num_constraints);
  return out;
}

template Result<LocationCalibration<float>> calibrate_location<float>(
    const nav::ArrayGeometry<float, nav::kNumSensors>&, std::span<const LocationRun<float>>,
    const LocationOptions&);
// GFINS_NAV_FLOAT_ONLY: the board's scalar only. Set by a build without GFINS_NAV_DOUBLE (the
// bare-metal one) and by clang-tidy (scripts/check-tidy.sh), which checks the template once: the
// double instantiation is the same source with T = double.
#ifndef GFINS_NAV_FLOAT_ONLY
template Result<LocationCalibration<double>> calibrate_location<double>(
    const nav::ArrayGeometry<double, nav::kNumSensors>&, std::span<const LocationRun<double>>,
    const LocationOptions&);
#endif

}  // namespace gfins::calib
