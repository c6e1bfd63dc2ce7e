// The work of gfins-calibrate between reading its inputs and writing the calibration file:
// observations from mean outputs (paper Tables 4/5 layout, or any poses), the multi-attitude
// solver of gfins::nav_calib, the CalibrationData it yields and a printed report.
#pragma once

#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "csv.hpp"
#include "gfins/calib_file/calibration_data.hpp"
#include "gfins/nav_core/calibration/multi_attitude.hpp"

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
};

/// Builds the observations and runs the solver. Fails (kInvalidArgument) naming the file line or
/// the missing (sensor, attitude) pair when the means do not match the layout, and passes on the
/// solver's Status otherwise.
FileResult<CalibrationRun> run_calibration(const CalibrationInputs& in,
                                           const std::string& means_file);

/// What the calibration does not determine, taken from options or a previous file.
struct FileSettings {
  std::string device_id;
  std::string source;
  calib_file::GeometrySpec geometry{};
  std::array<double, 6> adc_lsb_v_per_count{};
  std::array<calib_file::SensorCalibration, 6> location{};  // only Δρ and its σ are used
  nav::CompensatorKind compensator = nav::CompensatorKind::kExact;
};

/// The calibration file's content: SF, bias, angles (rad → deg) and their 1σ from the run.
calib_file::CalibrationData make_calibration_data(const CalibrationRun& run,
                                                  const FileSettings& settings);

/// Human-readable report: parameters ± 1σ, residuals, condition numbers, verdict and flags.
void print_report(std::ostream& out, const CalibrationRun& run);

/// One line per problem the verdict flags, empty when the verdict is good.
std::vector<std::string> verdict_warnings(const calib::MultiAttitudeResult<double>& r);

}  // namespace gfins::tools
