// The work of gfins-calibrate between reading its inputs and writing the calibration file:
// observations from mean outputs (paper Tables 4/5 layout, or any poses), the multi-attitude
// solver of gfins::nav_calib, the CalibrationData it yields and a printed report.
#pragma once

#include <limits>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "csv.hpp"
#include "gfins/calib_file/calibration_data.hpp"
#include "gfins/host_sim/error.hpp"
#include "gfins/nav_core/calibration/location.hpp"
#include "gfins/nav_core/calibration/multi_attitude.hpp"
#include "gfins/nav_core/calibration/static_detector.hpp"

namespace gfins::tools {

enum class Method : std::uint8_t {
  kPaper,    // SF from eqs. (17)/(18), then least squares (Tables 2/3 poses only)
  kGeneral,  // per-sensor least squares over any ≥ 4 non-coplanar poses (weighted if σ given)
};

struct CalibrationInputs {
  std::vector<MeanRow> means;
  std::optional<std::vector<Pose>> poses;  // absent: attitudes numbered as in Tables 2/3
  Method method = Method::kPaper;
};

struct CalibrationRun {
  calib::MultiAttitudeResult<double> result;
  std::vector<std::array<double, 3>> pose_f_b_g;  // per observation, for the report
  std::vector<std::string> pose_labels;           // "T2.1" (Table 2 pose 1), "P7" (poses file)
  std::vector<std::uint8_t> pose_used_mask;       // bit j: sensor j+1 recorded in that pose
  std::string method_text;
  std::vector<std::string> notes;  // printed before the parameters (e.g. static intervals found)
};

/// Builds the observations and runs the solver. Fails (kInvalidArgument) naming the file line or
/// the missing (sensor, attitude) pair when the means do not match the layout, and passes on the
/// solver's Status otherwise.
HostResult<CalibrationRun> run_calibration(const CalibrationInputs& in,
                                           const std::string& means_file);

/// A raw recording: the static detector (gfins::calib::StaticDetector) finds the poses, each
/// pose is matched to the nearest expected attitude (the poses file, or the twelve of Tables 2
/// and 3) using nominal scale factors, and the general solver runs on the interval means.
struct RecordingOptions {
  double rate_hz = 0.0;       // 0: take it from the recording (.gfr header)
  double still_std_v = 2e-3;  // largest std of a still channel, V (2-3× the noise)
  double window_s = 0.1;
  double min_still_s = 2.0;
  std::array<double, 6> nominal_scale_v_per_g{};  // to tell the poses apart (sign matters)
};
HostResult<CalibrationRun> run_recording_calibration(const Recording& rec,
                                                     const std::optional<std::vector<Pose>>& poses,
                                                     const RecordingOptions& options,
                                                     const std::string& recording_file);

/// What the calibration does not determine, taken from options or a previous file.
struct FileSettings {
  std::string device_id;
  std::string source;
  calib_file::GeometrySpec geometry{};
  std::array<double, 6> adc_lsb_v_per_count{};
  std::array<calib_file::SensorCalibration, 6> location{};  // only Δρ and its σ are used
  nav::CompensatorKind compensator = nav::CompensatorKind::kExact;
  double gravity_mps2 = 0.0;   // local gravity of the calibration site (m/s²)
  std::string gravity_source;  // how it was obtained, for the file and the report
};

/// The first setting outside the calibration file's domain (device id, ADC LSB, ρ, gravity),
/// found before anything is solved; message names the option.
HostStatus check_settings(const FileSettings& settings);

/// Location calibration (paper §4.2) from rate-table runs, given the orientation calibration
/// (SF, bias, angles, nominal geometry and local gravity of `cal`): Δρ_j and its 1σ per body
/// component, and which components the runs did not determine (held at 0; their σ is the
/// mechanical prior `prior_sigma_m`). sigma_m counts the runs' noise (solution.drho_cov_m2) and
/// the uncertainty of `cal`'s SF, bias and angles (base_cov_m2, first order, with `cal`'s
/// correlations; 0 correlation when cal.correlations_known is false).
struct LocationReport {
  calib::LocationCalibration<double> solution;
  std::array<nav::Mat3<double>, 6> base_cov_m2{};  // Δρ_j covariance from the base, m²
  std::array<std::array<double, 3>, 6> drho_m{};
  std::array<std::array<double, 3>, 6> sigma_m{};
  std::vector<std::string> lines;  // the report
};
HostResult<LocationReport> run_location_calibration(const std::vector<LocationRunRow>& runs,
                                                    const calib_file::CalibrationData& cal,
                                                    double prior_sigma_m,
                                                    const std::string& runs_file);

/// The calibration file's content: SF, bias, angles (rad → deg) and their 1σ from the run.
calib_file::CalibrationData make_calibration_data(const CalibrationRun& run,
                                                  const FileSettings& settings);

/// Human-readable report: parameters ± 1σ, residuals, condition numbers, verdict and flags.
void print_report(std::ostream& out, const CalibrationRun& run);

/// One line per problem the verdict flags, empty when the verdict is good.
std::vector<std::string> verdict_warnings(const calib::MultiAttitudeResult<double>& r);

/// Verification poses against an installed calibration: per pose and sensor the residual
/// P − SF (b + θ*·a) (eqs. (16)/(21), a in local g) and its z, the residual over its predicted σ:
/// the capture's noise (std_v/√count where given) and the file's covariance of the sensor's SF,
/// b and two angles (its σ and correlations; correlations taken as 0 when
/// cal.correlations_known is false), propagated to first order (docs/calibration.md §7). Poses
/// without a poses file are numbered as in Tables 2/3.
/// Two-sided tail probability of Student's t with `dof` > 0 degrees of freedom (non-integer
/// allowed): P(|T| ≥ |t|) = I_{ν/(ν+t²)}(ν/2, 1/2), the regularized incomplete beta function by
/// its continued fraction (modified Lentz). 2 Φ(−|t|) for an infinite dof.
double student_t_two_sided_p(double t, double dof);

struct VerifyRow {
  int attitude = 0;
  int sensor = 0;             // 1-based
  double residual_v = 0.0;    // P − SF (b + θ*·a), V
  double sigma_v = 0.0;       // predicted 1σ of the residual, V
  double sigma_mean_v = 0.0;  // the capture's part of it (std_v/√count), V
  double z = 0.0;             // residual / sigma
  /// Degrees of freedom of z: infinite (Gaussian) when every part of sigma is stated; finite
  /// when the file's σ of the sensor came from fit residuals (Welch–Satterthwaite of its part and
  /// the capture's stated noise).
  double dof = std::numeric_limits<double>::infinity();
  double z_gauss = 0.0;  // the Gaussian z with the same two-sided tail probability as z
};
struct VerifyReport {
  std::vector<std::string> lines;
  std::vector<VerifyRow> rows;  // one per row of the means, in their order
  double max_abs_z = 0.0;       // of z_gauss: the verdict's statistic
  int worst_sensor = 0;         // 1-based
  int worst_pose = 0;
};
HostResult<VerifyReport> verify_calibration(const std::vector<MeanRow>& means,
                                            const std::optional<std::vector<Pose>>& poses,
                                            const calib_file::CalibrationData& cal,
                                            const std::string& means_file);

}  // namespace gfins::tools
