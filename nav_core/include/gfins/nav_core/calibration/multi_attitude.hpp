// Multi-attitude static calibration of the six accelerometers (paper §4.1, experiment §6).
//
// Model (paper eq. (16) with g = 1 and T = 1, because Tables 4/5 hold mean voltages, not
// integrals): in attitude j the array senses the specific force a_j (body axes, g) and sensor i
// outputs the mean voltage
//
//   P_ij = SF_i (b_i + θ*_i·a_j),   θ*_i = Σ_k C_ik θ_k   (k over the sensor's set)
//
// with SF_i in V/g, b_i in g and C the matrix of eq. (14) (set β = {2,3,5}) or (15) (set α =
// {1,4,6}), see misalignment.hpp. a_j is the specific force SENSED (at rest: minus gravity, i.e.
// "up"), exactly as printed in the paper's Tables 2/3; reading those vectors as gravity gives
// errors of about 130° (docs/calibration.md).
//
// Identifiability. Per sensor the model is affine in a_j: P_ij = u_i + v_i·a_j with
// u_i = SF_i b_i and v_i = SF_i θ*_i, four unknowns. Within the set the three nominal axes are a
// basis, so v_i = SF_i (θ_i + C_ik θ_k + C_il θ_l) decomposes uniquely into SF_i and the two
// angles of row i of C (each angle appears in exactly one sensor's row). Hence four attitudes
// whose vectors a_j are not coplanar (rank [1 a_jᵀ] = 4) determine every parameter; the paper's
// "at least six" (three antipodal pairs) determine SF and the angles exactly and put all the
// redundancy in the biases. Sensors never share an unknown, so each is solved on its own (4×4
// least squares) and their estimates are uncorrelated.
//
// No heap: at most kMaxAttitudes observations, everything in fixed-size arrays. Templates are
// instantiated for float (target) and double (host) in src/multi_attitude.cpp.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "gfins/nav_core/geometry.hpp"
#include "gfins/nav_core/misalignment.hpp"
#include "gfins/status/status.hpp"

namespace gfins::calib {

using nav::OrientationErrors;
using nav::Vec3;

/// Largest number of attitudes one calibration accepts.
inline constexpr std::size_t kMaxAttitudes = 64;
/// Minimum number of non-coplanar attitudes per sensor (four unknowns per sensor).
inline constexpr std::size_t kMinAttitudes = 4;
/// Number of unknowns per sensor: SF, bias and the two angles of the sensor's row of C.
inline constexpr std::size_t kParamsPerSensor = 4;
/// Bit mask of all six sensors.
inline constexpr std::uint8_t kAllSensors = 0x3F;

/// One static pose: what the array sensed and what each sensor output.
template <typename T>
struct AttitudeObservation {
  std::array<T, 3> f_b_g{};   // specific force sensed, body axes, in g (paper Tables 2/3)
  std::array<T, 6> mean_v{};  // mean output per sensor, V (paper Tables 4/5)
  // Optional noise of each mean: the standard deviation of the samples (V) and their number.
  // σ(mean) = sample_std_v / √sample_count. When either is zero for a sensor in any of its
  // attitudes, that sensor's covariance comes from its residuals instead. To pass σ(mean)
  // directly (e.g. for correlated samples) set sample_count = 1.
  std::array<T, 6> sample_std_v{};
  std::uint32_t sample_count = 0;
  std::uint8_t used_mask = kAllSensors;  // bit i: sensor i (0-based) was recorded in this pose
  std::uint8_t saturated_mask = 0;       // bit i: the caller saw sensor i saturate in this pose
};

/// Thresholds of the solver. The defaults suit the QA-1100 board of the paper.
template <typename T>
struct MultiAttitudeConfig {
  /// Nominal unit sensitive axes (body), paper Table 1 by default.
  std::array<Vec3<T>, 6> theta_b = nav::table1_geometry<T>(T(1)).theta_b;
  /// |mean_v| at or beyond this is saturated (V); 0 disables the check.
  T full_scale_v = T(0);
  /// A sensor whose means span less than this over its attitudes is dead or disconnected (V).
  T min_output_span_v = T(1e-3);
  /// Condition number of the per-sensor design [1 a_jᵀ] above which the attitudes count as
  /// coplanar (kSingular). Six faces or a tetrahedron give √3, Tables 2/3 give 3.2; it grows as
  /// 1/tilt when the poses approach a plane (four poses 1° off a plane: 57). Noise on the means is
  /// amplified by up to this factor, hence the same limit as nav::kDefaultMaxCondition.
  T max_condition = T(100);
  // Verdict thresholds (they do not fail the call).
  T max_rms_residual_g = T(2e-3);  // RMS residual per sensor / SF (g); Tables 4/5: ≤ 0.5 mg
  T max_chi2_per_dof = T(9);       // weighted residuals vs the stated σ
  T max_angle_rad = T(0.0873);     // 5°: beyond, the small-angle model (14)/(15) is poor
  /// Weighted least squares by 1/σ(mean) when σ is stated (the best linear unbiased estimate);
  /// false: unweighted least squares, the paper's procedure, whose covariance with stated σ is
  /// then the sandwich (AᵀA)⁻¹AᵀΣA(AᵀA)⁻¹. Without stated σ both are the same estimator.
  bool weighted = true;
};

/// Where a sensor's parameter covariance comes from.
enum class CovarianceSource : std::uint8_t {
  kStatedSigma = 0,  // from the σ(mean) given with every observation (weighted LS)
  kResiduals,        // from the residual variance (unweighted LS, needs > 4 attitudes)
  kNone,             // exactly determined and no σ given: covariance unknown (all zeros)
};

/// Overall verdict, the first problem found in this order.
enum class Verdict : std::uint8_t {
  kGood = 0,
  kNegativeScaleFactor,   // a sensor reads opposite to its nominal axis (wiring, or gravity
                          // vectors given instead of specific force)
  kLargeAngle,            // an orientation error beyond max_angle_rad
  kHighResidual,          // RMS residual beyond max_rms_residual_g that stated σ do not explain
  kResidualsExceedNoise,  // weighted residuals beyond max_chi2_per_dof
  kNoRedundancy,          // exactly determined: nothing checks the fit
};

/// Per-sensor flag bits of MultiAttitudeResult::sensor_flags.
inline constexpr std::uint8_t kFlagNegativeScaleFactor = 1u << 0;
inline constexpr std::uint8_t kFlagLargeAngle = 1u << 1;
inline constexpr std::uint8_t kFlagHighResidual = 1u << 2;
inline constexpr std::uint8_t kFlagResidualsExceedNoise = 1u << 3;
inline constexpr std::uint8_t kFlagNoRedundancy = 1u << 4;

const char* to_string(Verdict v);
const char* to_string(CovarianceSource s);

/// The calibration, as plain arrays (sensors 0-based in Table 1 order; angles per set in the
/// order of nav::OrientationErrors / Table 6: xy, xz, yx, yz, zx, zy).
template <typename T>
struct MultiAttitudeResult {
  std::array<T, 6> scale_v_per_g{};    // SF_i, V/g
  std::array<T, 6> bias_g{};           // b_i, g
  OrientationErrors<T> orientation{};  // rad (Table 6 prints degrees)

  // 1σ of each parameter (square roots of the covariance diagonal).
  std::array<T, 6> scale_std_v_per_g{};
  std::array<T, 6> bias_std_g{};
  OrientationErrors<T> orientation_std{};  // rad

  // Full covariance per sensor, row-major 4×4 over (SF [V/g], b [g], angle A [rad],
  // angle B [rad]); angle A/B are indices 0..5 into the sensor's set (covariance_angle). Sensors
  // are independent: there is no covariance between sensors.
  std::array<std::array<T, kParamsPerSensor * kParamsPerSensor>, 6> covariance{};
  std::array<std::array<std::uint8_t, 2>, 6> covariance_angle{};
  std::array<CovarianceSource, 6> covariance_source{};

  // Fit quality.
  std::size_t num_attitudes = 0;
  std::array<std::uint8_t, 6> attitudes_used{};  // per sensor
  // Residual P_ij − model (V), [attitude][sensor]; zero where the sensor was not used.
  std::array<std::array<T, 6>, kMaxAttitudes> residual_v{};
  std::array<T, 6> rms_residual_g{};    // per sensor, RMS residual / SF
  std::array<T, 6> chi2_per_dof{};      // weighted residuals (stated σ only; else 0)
  std::array<T, 6> condition_number{};  // of each sensor's design [1 a_jᵀ]
  T max_condition_number = T(0);

  Verdict verdict = Verdict::kGood;
  std::array<std::uint8_t, 6> sensor_flags{};  // kFlag* bits
};

/// General solver: any ≥ 4 non-coplanar attitudes per sensor (weighted least squares when σ is
/// given). Fails with
///   kResourceExhausted  more than kMaxAttitudes observations,
///   kDataLoss           a non-finite f_b_g, mean or σ,
///   kInvalidArgument    fewer than four attitudes for some sensor, or a negative σ / bad config,
///   kOutOfRange         a saturated output (flagged, or |mean| ≥ full_scale_v),
///   kUnavailable        a sensor whose output did not change between attitudes (dead),
///   kSingular           coplanar attitudes (condition number beyond max_condition),
/// each with a message naming the sensor.
template <typename T>
Result<MultiAttitudeResult<T>> calibrate_multi_attitude(
    std::span<const AttitudeObservation<T>> observations,
    const MultiAttitudeConfig<T>& config = MultiAttitudeConfig<T>{});

/// Paper Tables 2 (set β) and 3 (set α): the six specific forces sensed, g.
template <typename T>
std::array<std::array<T, 3>, 6> table2_attitudes();
template <typename T>
std::array<std::array<T, 3>, 6> table3_attitudes();

/// Tables 4/5 in the paper's layout: mean_v[i][j] = P_a(i+1)(j+1), sensor i 0-based (Table 1
/// order), attitude j of Table 2 for the sensors of set β, of Table 3 for those of set α.
template <typename T>
struct PaperTableOutputs {
  std::array<std::array<T, 6>, 6> mean_v{};
  /// σ of each mean (V), same layout; all zero when not stated. When every mean of a sensor has
  /// σ > 0 its covariance comes from them (stated σ), else from the residuals (2 dof per sensor
  /// on Tables 2/3: a Student-t with 2 dof covers only 90 % within 3σ).
  std::array<std::array<T, 6>, 6> sigma_v{};
};

/// The twelve observations (Table 2 poses recording set β, then Table 3 poses recording set α)
/// that feed the general solver with the paper's data, with p.sigma_v as σ(mean) (count 1).
template <typename T>
std::array<AttitudeObservation<T>, 12> paper_observations(const PaperTableOutputs<T>& p);

/// The paper's own procedure: SF from the closed forms (17a-c)/(18a-c), then least squares for
/// the bias and the two angles of each sensor with SF fixed (the 18 output equations of each
/// set decouple per sensor). The estimates equal the unweighted general solver's
/// (docs/calibration.md); residuals, covariance (stated σ where p.sigma_v gives it: the
/// sandwich of the unweighted estimator), condition number and verdict are that solver's.
template <typename T>
Result<MultiAttitudeResult<T>> calibrate_paper_procedure(
    const PaperTableOutputs<T>& p, const MultiAttitudeConfig<T>& config = MultiAttitudeConfig<T>{});

extern template Result<MultiAttitudeResult<float>> calibrate_multi_attitude<float>(
    std::span<const AttitudeObservation<float>>, const MultiAttitudeConfig<float>&);
extern template Result<MultiAttitudeResult<double>> calibrate_multi_attitude<double>(
    std::span<const AttitudeObservation<double>>, const MultiAttitudeConfig<double>&);
extern template Result<MultiAttitudeResult<float>> calibrate_paper_procedure<float>(
    const PaperTableOutputs<float>&, const MultiAttitudeConfig<float>&);
extern template Result<MultiAttitudeResult<double>> calibrate_paper_procedure<double>(
    const PaperTableOutputs<double>&, const MultiAttitudeConfig<double>&);

}  // namespace gfins::calib
