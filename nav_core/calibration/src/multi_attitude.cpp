// Multi-attitude static calibration: per-sensor affine least squares, then the decomposition of
// v_i = SF_i θ*_i on the set's nominal axes (see multi_attitude.hpp for the model and why it is
// identifiable). No heap: the designs are Eigen matrices with a fixed maximum row count.
#include "gfins/nav_core/calibration/multi_attitude.hpp"

#include <Eigen/Dense>
#include <cmath>

namespace gfins::calib {
namespace {

using nav::kSetAlpha;
using nav::kSetBeta;

template <typename T>
using Design =
    Eigen::Matrix<T, Eigen::Dynamic, 4, Eigen::ColMajor, static_cast<int>(kMaxAttitudes), 4>;
template <typename T>
using Column =
    Eigen::Matrix<T, Eigen::Dynamic, 1, Eigen::ColMajor, static_cast<int>(kMaxAttitudes), 1>;
template <typename T>
using Mat4 = Eigen::Matrix<T, 4, 4>;
template <typename T>
using Vec4 = Eigen::Matrix<T, 4, 1>;

// Messages name the sensor with the paper's 1-based number; Status wants literals.
constexpr std::array<const char*, 6> kTooFewMsg = {
    "multi-attitude: sensor 1 has fewer than four attitudes",
    "multi-attitude: sensor 2 has fewer than four attitudes",
    "multi-attitude: sensor 3 has fewer than four attitudes",
    "multi-attitude: sensor 4 has fewer than four attitudes",
    "multi-attitude: sensor 5 has fewer than four attitudes",
    "multi-attitude: sensor 6 has fewer than four attitudes"};
constexpr std::array<const char*, 6> kSaturatedMsg = {
    "multi-attitude: sensor 1 output saturated in some attitude",
    "multi-attitude: sensor 2 output saturated in some attitude",
    "multi-attitude: sensor 3 output saturated in some attitude",
    "multi-attitude: sensor 4 output saturated in some attitude",
    "multi-attitude: sensor 5 output saturated in some attitude",
    "multi-attitude: sensor 6 output saturated in some attitude"};
constexpr std::array<const char*, 6> kDeadMsg = {
    "multi-attitude: sensor 1 output did not change between attitudes (dead or disconnected)",
    "multi-attitude: sensor 2 output did not change between attitudes (dead or disconnected)",
    "multi-attitude: sensor 3 output did not change between attitudes (dead or disconnected)",
    "multi-attitude: sensor 4 output did not change between attitudes (dead or disconnected)",
    "multi-attitude: sensor 5 output did not change between attitudes (dead or disconnected)",
    "multi-attitude: sensor 6 output did not change between attitudes (dead or disconnected)"};
constexpr std::array<const char*, 6> kCoplanarMsg = {
    "multi-attitude: the attitudes of sensor 1 are coplanar (design ill-conditioned)",
    "multi-attitude: the attitudes of sensor 2 are coplanar (design ill-conditioned)",
    "multi-attitude: the attitudes of sensor 3 are coplanar (design ill-conditioned)",
    "multi-attitude: the attitudes of sensor 4 are coplanar (design ill-conditioned)",
    "multi-attitude: the attitudes of sensor 5 are coplanar (design ill-conditioned)",
    "multi-attitude: the attitudes of sensor 6 are coplanar (design ill-conditioned)"};
constexpr std::array<const char*, 6> kNonFiniteMsg = {
    "multi-attitude: a non-finite specific force, mean or sigma for sensor 1",
    "multi-attitude: a non-finite specific force, mean or sigma for sensor 2",
    "multi-attitude: a non-finite specific force, mean or sigma for sensor 3",
    "multi-attitude: a non-finite specific force, mean or sigma for sensor 4",
    "multi-attitude: a non-finite specific force, mean or sigma for sensor 5",
    "multi-attitude: a non-finite specific force, mean or sigma for sensor 6"};

// Where sensor i sits: its set (the three 0-based sensor indices) and its row in C.
struct SetPosition {
  const std::array<int, 3>* set;
  int row;
  bool is_alpha;
};

SetPosition set_position(int sensor) {
  for (int r = 0; r < 3; ++r) {
    if (kSetBeta[static_cast<std::size_t>(r)] == sensor) return {&kSetBeta, r, false};
    if (kSetAlpha[static_cast<std::size_t>(r)] == sensor) return {&kSetAlpha, r, true};
  }
  return {&kSetBeta, 0, false};  // unreachable for sensor in 0..5
}

// Row r of C (eq. (14)/(15)) holds the angles 2r and 2r+1 of the OrientationErrors order
// (xy, xz | yx, yz | zx, zy). angle_column/angle_sign say where and with which sign: C(r, col) =
// sign · angle. Derived from nav::set_matrix so the two cannot disagree.
template <typename T>
void angle_place(int angle, int& row, int& col, T& sign) {
  std::array<T, 6> d{};
  d[static_cast<std::size_t>(angle)] = T(1);
  const nav::Mat3<T> c = nav::set_matrix(d) - nav::Mat3<T>::Identity();
  for (int r = 0; r < 3; ++r) {
    for (int k = 0; k < 3; ++k) {
      if (c(r, k) != T(0)) {
        row = r;
        col = k;
        sign = c(r, k);
      }
    }
  }
}

template <typename T>
T& angle_ref(OrientationErrors<T>& o, bool is_alpha, int angle) {
  return is_alpha ? o.alpha[static_cast<std::size_t>(angle)]
                  : o.beta[static_cast<std::size_t>(angle)];
}

template <typename T>
bool all_finite(const std::array<T, 3>& v) {
  return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]);
}

// Condition number of the unweighted design [1 a_jᵀ]: singular values of R from its QR.
template <typename T>
T design_condition(const Design<T>& a) {
  Eigen::HouseholderQR<Design<T>> qr(a);
  const Mat4<T> r = qr.matrixQR().template topRows<4>().template triangularView<Eigen::Upper>();
  const Eigen::JacobiSVD<Mat4<T>> svd(r);
  const Vec4<T>& s = svd.singularValues();
  if (!(s(3) > T(0))) return std::numeric_limits<T>::infinity();
  return s(0) / s(3);
}

template <typename T>
Status solve_sensor(int i, std::span<const AttitudeObservation<T>> obs,
                    const MultiAttitudeConfig<T>& cfg, MultiAttitudeResult<T>& out) {
  const auto si = static_cast<std::size_t>(i);
  const std::uint8_t bit = static_cast<std::uint8_t>(1u << i);

  // Gather this sensor's attitudes; validate them.
  std::array<std::size_t, kMaxAttitudes> idx{};
  std::size_t n = 0;
  bool sigma_stated = true;
  for (std::size_t j = 0; j < obs.size(); ++j) {
    const AttitudeObservation<T>& o = obs[j];
    if ((o.used_mask & bit) == 0) continue;
    const T p = o.mean_v[si];
    const T sd = o.sample_std_v[si];
    if (!all_finite(o.f_b_g) || !std::isfinite(p) || !std::isfinite(sd)) {
      return Status(ErrorCode::kDataLoss, kNonFiniteMsg[si]);
    }
    if (sd < T(0)) {
      return Status(ErrorCode::kInvalidArgument, "multi-attitude: a negative sample_std_v");
    }
    if ((o.saturated_mask & bit) != 0 ||
        (cfg.full_scale_v > T(0) && std::abs(p) >= cfg.full_scale_v)) {
      return Status(ErrorCode::kOutOfRange, kSaturatedMsg[si]);
    }
    if (!(sd > T(0)) || o.sample_count == 0) sigma_stated = false;
    idx[n++] = j;
  }
  if (n < kMinAttitudes) return Status(ErrorCode::kInvalidArgument, kTooFewMsg[si]);

  // Design [1 a_jᵀ] (unweighted for the geometry check, weighted by 1/σ for the fit).
  const auto rows = static_cast<Eigen::Index>(n);
  Design<T> a0(rows, 4);
  Design<T> a(rows, 4);
  Column<T> y(rows);
  Column<T> w(rows);
  T p_min = obs[idx[0]].mean_v[si];
  T p_max = p_min;
  for (std::size_t k = 0; k < n; ++k) {
    const AttitudeObservation<T>& o = obs[idx[k]];
    const auto r = static_cast<Eigen::Index>(k);
    a0(r, 0) = T(1);
    a0(r, 1) = o.f_b_g[0];
    a0(r, 2) = o.f_b_g[1];
    a0(r, 3) = o.f_b_g[2];
    w(r) = sigma_stated
               ? std::sqrt(static_cast<T>(o.sample_count)) / o.sample_std_v[si]  // 1/σ(mean)
               : T(1);
    // The fit is weighted by 1/σ unless the configuration asks for the unweighted estimator
    // (the paper's procedure); w keeps 1/σ for the χ² and the covariance either way.
    const T fit_w = cfg.weighted ? w(r) : T(1);
    a.row(r) = fit_w * a0.row(r);
    y(r) = fit_w * o.mean_v[si];
    p_min = std::min(p_min, o.mean_v[si]);
    p_max = std::max(p_max, o.mean_v[si]);
  }
  const T cond = design_condition(a0);
  out.condition_number[si] = cond;
  if (!(cond <= cfg.max_condition)) return Status(ErrorCode::kSingular, kCoplanarMsg[si]);
  if (!(p_max - p_min >= cfg.min_output_span_v)) {
    return Status(ErrorCode::kUnavailable, kDeadMsg[si]);
  }

  // x = (u, v) with P = u + v·a (u = SF b, v = SF θ*).
  const Eigen::HouseholderQR<Design<T>> qr(a);
  const Vec4<T> x = qr.solve(y);
  const Mat4<T> r = qr.matrixQR().template topRows<4>().template triangularView<Eigen::Upper>();
  const Mat4<T> r_inv = r.template triangularView<Eigen::Upper>().solve(Mat4<T>::Identity());
  Mat4<T> cov_x = r_inv * r_inv.transpose();  // (AᵀWA)⁻¹, or (AᵀA)⁻¹ unweighted
  if (sigma_stated && !cfg.weighted) {
    // Unweighted estimate x = (AᵀA)⁻¹Aᵀy with the stated Σ = diag(σ²) of y: its covariance is
    // the sandwich (AᵀA)⁻¹ AᵀΣA (AᵀA)⁻¹ (equal to (AᵀΣ⁻¹A)⁻¹ only when all σ are equal).
    Mat4<T> meat = Mat4<T>::Zero();
    for (std::size_t k = 0; k < n; ++k) {
      const auto rk = static_cast<Eigen::Index>(k);
      const Vec4<T> row = a0.row(rk).transpose();
      meat += (row * row.transpose()) / (w(rk) * w(rk));
    }
    cov_x = cov_x * meat * cov_x;
  }

  // Residuals (V, unweighted) and the weighted sum of squares.
  T ss_v = T(0);
  T ss_w = T(0);
  for (std::size_t k = 0; k < n; ++k) {
    const auto rk = static_cast<Eigen::Index>(k);
    const T res = obs[idx[k]].mean_v[si] - a0.row(rk).dot(x);
    out.residual_v[idx[k]][si] = res;
    ss_v += res * res;
    ss_w += (res * w(rk)) * (res * w(rk));
  }
  const std::size_t dof = n - kMinAttitudes;
  CovarianceSource source = CovarianceSource::kStatedSigma;
  if (!sigma_stated && !cfg.weighted) {
    ss_w = ss_v;  // w = 1: the residual variance in V², as the weighted branch with w = 1
  }
  if (!sigma_stated) {
    if (dof > 0) {
      source = CovarianceSource::kResiduals;
      cov_x *= ss_w / static_cast<T>(dof);
    } else {
      source = CovarianceSource::kNone;
      cov_x.setZero();
    }
  }

  // Decompose v on the set's nominal axes: w = Θ_set⁻¹ v, w_k = SF C_rk (C_rr = 1).
  const SetPosition pos = set_position(i);
  nav::Mat3<T> theta_set;
  for (int k = 0; k < 3; ++k) {
    theta_set.col(k) =
        cfg.theta_b[static_cast<std::size_t>((*pos.set)[static_cast<std::size_t>(k)])];
  }
  const nav::Mat3<T> b_inv = theta_set.inverse();
  const nav::Vec3<T> wv = b_inv * x.template tail<3>();
  const T sf = wv(pos.row);
  if (!std::isfinite(sf) || !(std::abs(sf) > T(0))) {
    return Status(ErrorCode::kUnavailable, kDeadMsg[si]);
  }
  const T u = x(0);
  out.scale_v_per_g[si] = sf;
  out.bias_g[si] = u / sf;

  // Jacobian of p = (SF, b, angle 2r, angle 2r+1) with respect to x = (u, v).
  Mat4<T> jac = Mat4<T>::Zero();
  jac.block(0, 1, 1, 3) = b_inv.row(pos.row);
  jac(1, 0) = T(1) / sf;
  jac.block(1, 1, 1, 3) = -u / (sf * sf) * b_inv.row(pos.row);
  T max_angle = T(0);
  for (int m = 0; m < 2; ++m) {
    const int angle = 2 * pos.row + m;
    int row = 0;
    int col = 0;
    T sign = T(0);
    angle_place<T>(angle, row, col, sign);
    const T value = sign * wv(col) / sf;  // C_rk = sign · angle
    angle_ref(out.orientation, pos.is_alpha, angle) = value;
    max_angle = std::max(max_angle, std::abs(value));
    jac.block(2 + m, 1, 1, 3) =
        sign * (b_inv.row(col) * sf - wv(col) * b_inv.row(pos.row)) / (sf * sf);
    out.covariance_angle[si][static_cast<std::size_t>(m)] = static_cast<std::uint8_t>(angle);
  }
  const Mat4<T> cov_p = jac * cov_x * jac.transpose();
  for (int rr = 0; rr < 4; ++rr) {
    for (int cc = 0; cc < 4; ++cc) {
      out.covariance[si][static_cast<std::size_t>(rr) * 4 + static_cast<std::size_t>(cc)] =
          cov_p(rr, cc);
    }
  }
  out.scale_std_v_per_g[si] = std::sqrt(cov_p(0, 0));
  out.bias_std_g[si] = std::sqrt(cov_p(1, 1));
  angle_ref(out.orientation_std, pos.is_alpha, 2 * pos.row) = std::sqrt(cov_p(2, 2));
  angle_ref(out.orientation_std, pos.is_alpha, 2 * pos.row + 1) = std::sqrt(cov_p(3, 3));
  out.covariance_source[si] = source;
  out.attitudes_used[si] = static_cast<std::uint8_t>(n);

  // Fit quality and verdict flags.
  out.rms_residual_g[si] = std::sqrt(ss_v / static_cast<T>(n)) / std::abs(sf);
  out.chi2_per_dof[si] = (sigma_stated && dof > 0) ? ss_w / static_cast<T>(dof) : T(0);
  std::uint8_t flags = 0;
  if (sf < T(0)) flags |= kFlagNegativeScaleFactor;
  if (max_angle > cfg.max_angle_rad) flags |= kFlagLargeAngle;
  // A residual beyond the limit says a pose was not still or its vector is wrong, unless the
  // stated σ explain it (χ²/dof within its limit): the means are then noisy, the residual is that
  // noise, and the covariance from the stated σ carries it already.
  const bool noise_explains =
      sigma_stated && dof > 0 && out.chi2_per_dof[si] <= cfg.max_chi2_per_dof;
  if (out.rms_residual_g[si] > cfg.max_rms_residual_g && !noise_explains) {
    flags |= kFlagHighResidual;
  }
  if (out.chi2_per_dof[si] > cfg.max_chi2_per_dof) flags |= kFlagResidualsExceedNoise;
  if (dof == 0) flags |= kFlagNoRedundancy;
  out.sensor_flags[si] = flags;
  return Status::ok();
}

template <typename T>
Verdict overall_verdict(const std::array<std::uint8_t, 6>& flags) {
  std::uint8_t all = 0;
  for (const std::uint8_t f : flags) all |= f;
  if (all & kFlagNegativeScaleFactor) return Verdict::kNegativeScaleFactor;
  if (all & kFlagLargeAngle) return Verdict::kLargeAngle;
  if (all & kFlagHighResidual) return Verdict::kHighResidual;
  if (all & kFlagResidualsExceedNoise) return Verdict::kResidualsExceedNoise;
  if (all & kFlagNoRedundancy) return Verdict::kNoRedundancy;
  return Verdict::kGood;
}

template <typename T>
Status check_config(const MultiAttitudeConfig<T>& cfg) {
  if (!(cfg.max_condition >= T(1)) || !(cfg.min_output_span_v >= T(0)) ||
      !(cfg.full_scale_v >= T(0))) {
    return Status(ErrorCode::kInvalidArgument,
                  "multi-attitude: config thresholds must be finite and non-negative");
  }
  for (const auto& beta_alpha : {kSetBeta, kSetAlpha}) {
    nav::Mat3<T> m;
    for (int k = 0; k < 3; ++k) {
      m.col(k) = cfg.theta_b[static_cast<std::size_t>(beta_alpha[static_cast<std::size_t>(k)])];
    }
    if (!(std::abs(m.determinant()) > T(1e-3))) {
      return Status(ErrorCode::kInvalidArgument,
                    "multi-attitude: the nominal axes of a set are not linearly independent");
    }
  }
  return Status::ok();
}

}  // namespace

const char* to_string(Verdict v) {
  switch (v) {
    case Verdict::kGood:
      return "good: every sensor fits its attitudes within the thresholds";
    case Verdict::kNegativeScaleFactor:
      return "a scale factor is negative: sensor wired reversed, or gravity given instead of "
             "specific force";
    case Verdict::kLargeAngle:
      return "an orientation error exceeds the small-angle limit of eqs. (14)/(15)";
    case Verdict::kHighResidual:
      return "residuals exceed max_rms_residual_g: poses not still, wrong attitudes or a bad "
             "sensor";
    case Verdict::kResidualsExceedNoise:
      return "residuals exceed the stated noise: model or attitude errors dominate";
    case Verdict::kNoRedundancy:
      return "exactly determined (four attitudes): nothing checks the fit";
  }
  return "unknown verdict";
}

const char* to_string(CovarianceSource s) {
  switch (s) {
    case CovarianceSource::kStatedSigma:
      return "stated sigma of the means";
    case CovarianceSource::kResiduals:
      return "residuals of the fit";
    case CovarianceSource::kNone:
      return "none (exactly determined, no sigma given)";
  }
  return "unknown";
}

template <typename T>
Result<MultiAttitudeResult<T>> calibrate_multi_attitude(
    std::span<const AttitudeObservation<T>> observations, const MultiAttitudeConfig<T>& config) {
  if (observations.size() > kMaxAttitudes) {
    return Status(ErrorCode::kResourceExhausted, "multi-attitude: more than 64 attitudes");
  }
  if (const Status s = check_config(config); !s.is_ok()) return s;
  MultiAttitudeResult<T> out;
  out.num_attitudes = observations.size();
  for (int i = 0; i < nav::kNumSensors; ++i) {
    if (const Status s = solve_sensor(i, observations, config, out); !s.is_ok()) return s;
    out.max_condition_number =
        std::max(out.max_condition_number, out.condition_number[static_cast<std::size_t>(i)]);
  }
  out.verdict = overall_verdict<T>(out.sensor_flags);
  return out;
}

template <typename T>
std::array<std::array<T, 3>, 6> table2_attitudes() {
  const T k = T(1) / std::sqrt(T(2));
  // Table 2, g = 1: a1 = [-1 0 1]/√2, a2 = -a1, a3 = [1 0 1]/√2, a4 = -a3, a5 = [0 1 1]/√2, a6 =
  // -a5.
  return {
      {{-k, T(0), k}, {k, T(0), -k}, {k, T(0), k}, {-k, T(0), -k}, {T(0), k, k}, {T(0), -k, -k}}};
}

template <typename T>
std::array<std::array<T, 3>, 6> table3_attitudes() {
  const T k = T(1) / std::sqrt(T(2));
  // Table 3, g = 1: a1 = [0 -1 1]/√2, a2 = -a1, a3 = [1 1 0]/√2, a4 = -a3, a5 = [-1 1 0]/√2, a6 =
  // -a5.
  return {
      {{T(0), -k, k}, {T(0), k, -k}, {k, k, T(0)}, {-k, -k, T(0)}, {-k, k, T(0)}, {k, -k, T(0)}}};
}

template <typename T>
std::array<AttitudeObservation<T>, 12> paper_observations(const PaperTableOutputs<T>& p) {
  std::array<AttitudeObservation<T>, 12> obs{};
  const auto t2 = table2_attitudes<T>();
  const auto t3 = table3_attitudes<T>();
  const auto fill = [&](std::size_t offset, const std::array<std::array<T, 3>, 6>& att,
                        const std::array<int, 3>& set) {
    for (std::size_t j = 0; j < 6; ++j) {
      AttitudeObservation<T>& o = obs[offset + j];
      o.f_b_g = att[j];
      o.used_mask = 0;
      o.sample_count = 1;  // sigma_v is already the σ of the mean
      for (const int s : set) {
        o.mean_v[static_cast<std::size_t>(s)] = p.mean_v[static_cast<std::size_t>(s)][j];
        o.sample_std_v[static_cast<std::size_t>(s)] = p.sigma_v[static_cast<std::size_t>(s)][j];
        o.used_mask = static_cast<std::uint8_t>(o.used_mask | (1u << s));
      }
    }
  };
  fill(0, t2, kSetBeta);
  fill(6, t3, kSetAlpha);
  return obs;
}

template <typename T>
Result<MultiAttitudeResult<T>> calibrate_paper_procedure(const PaperTableOutputs<T>& p,
                                                         const MultiAttitudeConfig<T>& config) {
  const auto obs = paper_observations(p);
  // The paper's procedure is the unweighted estimator: its covariance with stated σ is the
  // sandwich, which the general solver gives with weighted = false.
  MultiAttitudeConfig<T> unweighted = config;
  unweighted.weighted = false;
  Result<MultiAttitudeResult<T>> general =
      calibrate_multi_attitude<T>(std::span<const AttitudeObservation<T>>(obs), unweighted);
  if (!general.is_ok()) return general;
  MultiAttitudeResult<T> out = general.value();

  // Eqs. (17a-c) and (18a-c) with g = T = 1: SF_i = Σ_q c_q (P_i,2q−1 − P_i,2q) / den, q = 1..3.
  struct ClosedForm {
    int sensor;
    std::array<T, 3> c;
    T den;
  };
  const std::array<ClosedForm, 6> forms = {{
      {1, {T(1), T(3), T(-2)}, T(4)},   // (17a) SF_a2
      {2, {T(-1), T(-1), T(2)}, T(2)},  // (17b) SF_a3
      {4, {T(3), T(1), T(-2)}, T(4)},   // (17c) SF_a5
      {0, {T(2), T(3), T(1)}, T(4)},    // (18a) SF_a1
      {3, {T(2), T(1), T(1)}, T(2)},    // (18b) SF_a4
      {5, {T(2), T(1), T(3)}, T(4)},    // (18c) SF_a6
  }};
  for (const ClosedForm& f : forms) {
    const auto si = static_cast<std::size_t>(f.sensor);
    const auto& pi = p.mean_v[si];
    T sf = T(0);
    for (std::size_t q = 0; q < 3; ++q) sf += f.c[q] * (pi[2 * q] - pi[2 * q + 1]);
    sf /= f.den;

    // With SF fixed the sensor's six equations P/SF − θ_i·a = b + C_rk θ_k·a + C_rl θ_l·a are
    // linear in (b, angle 2r, angle 2r+1): least squares, as the paper does per set (the set's
    // 18 equations decouple per sensor because each angle appears in one row only).
    const SetPosition pos = set_position(f.sensor);
    const auto& att = pos.is_alpha ? table3_attitudes<T>() : table2_attitudes<T>();
    Eigen::Matrix<T, 6, 3> a;
    Eigen::Matrix<T, 6, 1> y;
    std::array<int, 2> cols{};
    std::array<T, 2> signs{};
    for (int m = 0; m < 2; ++m) {
      int row = 0;
      angle_place<T>(2 * pos.row + m, row, cols[static_cast<std::size_t>(m)],
                     signs[static_cast<std::size_t>(m)]);
    }
    std::array<nav::Vec3<T>, 3> axis;  // nominal axes of the set, in the order of C's columns
    for (std::size_t k = 0; k < 3; ++k) {
      axis[k] = config.theta_b[static_cast<std::size_t>((*pos.set)[k])];
    }
    for (int j = 0; j < 6; ++j) {
      const auto sj = static_cast<std::size_t>(j);
      const nav::Vec3<T> aj(att[sj][0], att[sj][1], att[sj][2]);
      a(j, 0) = T(1);
      for (int m = 0; m < 2; ++m) {
        const auto sm = static_cast<std::size_t>(m);
        a(j, 1 + m) = signs[sm] * axis[static_cast<std::size_t>(cols[sm])].dot(aj);
      }
      y(j) = pi[sj] / sf - axis[static_cast<std::size_t>(pos.row)].dot(aj);
    }
    const Vec3<T> x = a.colPivHouseholderQr().solve(y);
    out.scale_v_per_g[si] = sf;
    out.bias_g[si] = x(0);
    for (int m = 0; m < 2; ++m) {
      angle_ref(out.orientation, pos.is_alpha, 2 * pos.row + m) = x(1 + m);
    }
    // Residuals of the final parameters under model (16).
    OrientationErrors<T> o = out.orientation;
    nav::Mat3<T> c = nav::set_matrix(pos.is_alpha ? o.alpha : o.beta);
    nav::Vec3<T> theta_star = nav::Vec3<T>::Zero();
    for (int k = 0; k < 3; ++k) {
      theta_star +=
          c(pos.row, k) *
          config.theta_b[static_cast<std::size_t>((*pos.set)[static_cast<std::size_t>(k)])];
    }
    T ss = T(0);
    for (int j = 0; j < 6; ++j) {
      const auto sj = static_cast<std::size_t>(j);
      const nav::Vec3<T> aj(att[sj][0], att[sj][1], att[sj][2]);
      const T res = pi[sj] - sf * (x(0) + theta_star.dot(aj));
      out.residual_v[(pos.is_alpha ? 6 : 0) + sj][si] = res;
      ss += res * res;
    }
    out.rms_residual_g[si] = std::sqrt(ss / T(6)) / std::abs(sf);
  }
  return out;
}

template Result<MultiAttitudeResult<float>> calibrate_multi_attitude<float>(
    std::span<const AttitudeObservation<float>>, const MultiAttitudeConfig<float>&);
template Result<MultiAttitudeResult<float>> calibrate_paper_procedure<float>(
    const PaperTableOutputs<float>&, const MultiAttitudeConfig<float>&);
template std::array<std::array<float, 3>, 6> table2_attitudes<float>();
template std::array<std::array<float, 3>, 6> table3_attitudes<float>();
template std::array<AttitudeObservation<float>, 12> paper_observations<float>(
    const PaperTableOutputs<float>&);
// GFINS_NAV_FLOAT_ONLY: the board's scalar only. Set by a build without GFINS_NAV_DOUBLE (the
// bare-metal one) and by clang-tidy (scripts/check-tidy.sh), which checks the template once: the
// double instantiation is the same source with T = double.
#ifndef GFINS_NAV_FLOAT_ONLY
template Result<MultiAttitudeResult<double>> calibrate_multi_attitude<double>(
    std::span<const AttitudeObservation<double>>, const MultiAttitudeConfig<double>&);
template Result<MultiAttitudeResult<double>> calibrate_paper_procedure<double>(
    const PaperTableOutputs<double>&, const MultiAttitudeConfig<double>&);
template std::array<std::array<double, 3>, 6> table2_attitudes<double>();
template std::array<std::array<double, 3>, 6> table3_attitudes<double>();
template std::array<AttitudeObservation<double>, 12> paper_observations<double>(
    const PaperTableOutputs<double>&);
#endif

}  // namespace gfins::calib
