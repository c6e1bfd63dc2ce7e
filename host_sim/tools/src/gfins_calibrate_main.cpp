// gfins-calibrate: multi-attitude calibration of the six-accelerometer array from static mean
// outputs (paper §4.1, Tables 2-6), written as a calibration file (docs/calibration-file.md).
//
// Exit status: 0 file written (or --dry-run done), 1 bad usage or input, 2 the solver failed,
// 3 the verdict is not good and --force was not given (nothing written), 4 the file could not
// be written.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include "calibrate.hpp"
#include "csv.hpp"
#include "gfins/calib_file/calibration_file.hpp"

namespace {

using namespace gfins;
using namespace gfins::tools;

constexpr int kExitOk = 0;
constexpr int kExitInput = 1;
constexpr int kExitSolver = 2;
constexpr int kExitVerdict = 3;
constexpr int kExitWrite = 4;

int fail(int code, const std::string& message) {
  std::cerr << "gfins-calibrate: error: " << message << "\n";
  return code;
}

struct Options {
  std::string means;
  std::string recording;
  double rate_hz = 0.0;
  double still_std_v = 2e-3;
  std::vector<double> nominal_sf;
  std::string poses;
  std::string method = "auto";
  std::string output;
  std::string base;
  std::string device_id;
  std::string compensator;
  double rho_m = 0.1;
  double adc_lsb = 0.0;
  bool force = false;
  bool dry_run = false;
};

// The parts of the file the calibration does not determine: from --base, then the options.
int settings_from(const Options& o, FileSettings& s) {
  if (!o.base.empty()) {
    const auto base = calib_file::load_calibration_file(o.base);
    if (!base.is_ok()) return fail(kExitInput, base.status().message());
    const auto& b = base.value();
    s.device_id = b.device_id;
    s.geometry = b.geometry;
    s.compensator = b.compensator;
    for (std::size_t j = 0; j < 6; ++j) {
      s.adc_lsb_v_per_count[j] = b.sensors[j].adc_lsb_v_per_count;
      s.location[j] = b.sensors[j];
    }
  } else {
    if (o.adc_lsb <= 0.0) {
      return fail(kExitInput,
                  "--adc-lsb (V/count, Vref/(gain·2^23) for a 24-bit ADC) is required without "
                  "--base");
    }
    s.geometry.kind = calib_file::GeometryKind::kTable1;
    s.geometry.rho_m = o.rho_m;
    s.adc_lsb_v_per_count.fill(o.adc_lsb);
  }
  if (!o.device_id.empty()) s.device_id = o.device_id;
  if (s.device_id.empty()) return fail(kExitInput, "--device-id is required without --base");
  if (o.adc_lsb > 0.0) s.adc_lsb_v_per_count.fill(o.adc_lsb);
  if (o.compensator == "none") s.compensator = nav::CompensatorKind::kNone;
  if (o.compensator == "paper") s.compensator = nav::CompensatorKind::kPaper;
  if (o.compensator == "exact") s.compensator = nav::CompensatorKind::kExact;
  return kExitOk;
}

// Runs the solver on the chosen input; kExitOk or the exit status of the failure.
int calibrate(const Options& o, CalibrationInputs& in, FileResult<CalibrationRun>& out) {
  if (!o.poses.empty()) {
    const auto poses = read_poses(o.poses);
    if (!poses.is_ok()) return fail(kExitInput, poses.status().message());
    in.poses = poses.value();
  }
  if (!o.recording.empty()) {
    RecordingOptions ro;
    ro.rate_hz = o.rate_hz;
    ro.still_std_v = o.still_std_v;
    if (o.rate_hz <= 0.0) return fail(kExitInput, "--rate (Hz) is required with --recording");
    if (o.nominal_sf.size() == 1)
      ro.nominal_scale_v_per_g.fill(o.nominal_sf[0]);
    else if (o.nominal_sf.size() == 6)
      std::copy_n(o.nominal_sf.begin(), 6, ro.nominal_scale_v_per_g.begin());
    else
      return fail(kExitInput, "--nominal-sf takes 1 or 6 values (V/g) with --recording");
    const auto rec = read_recording(o.recording);
    if (!rec.is_ok()) return fail(kExitInput, rec.status().message());
    in.method = Method::kGeneral;
    out = run_recording_calibration(rec.value(), in.poses, ro, o.recording);
    return kExitOk;
  }
  const auto means = read_means(o.means);
  if (!means.is_ok()) return fail(kExitInput, means.status().message());
  in.means = means.value();
  in.method = o.method == "paper"                 ? Method::kPaper
              : o.method == "general" || in.poses ? Method::kGeneral
                                                  : Method::kPaper;
  out = run_calibration(in, o.means);
  return kExitOk;
}

int run(const Options& o) {
  FileSettings settings;
  if (const int rc = settings_from(o, settings); rc != kExitOk) return rc;
  CalibrationInputs in;
  FileResult<CalibrationRun> calibrated(FileStatus(ErrorCode::kUnimplemented, "not run"));
  if (const int rc = calibrate(o, in, calibrated); rc != kExitOk) return rc;
  const std::string input = o.recording.empty() ? o.means : o.recording;
  settings.source = "gfins-calibrate " +
                    std::string(in.method == Method::kPaper ? "paper" : "general") + " from " +
                    std::filesystem::path(input).filename().string();
  if (!calibrated.is_ok()) {
    const auto& st = calibrated.status();
    return fail(st.code() == ErrorCode::kInvalidArgument &&
                        st.message().find("calibration failed") == std::string::npos
                    ? kExitInput
                    : kExitSolver,
                st.message());
  }
  const CalibrationRun& cal = calibrated.value();
  print_report(std::cout, cal);
  if (settings.location[0].location_error_m == std::array<double, 3>{} && o.base.empty()) {
    std::cout << "  note: location errors are not part of this calibration: Δρ = 0 written "
                 "(use --base to keep a previous location calibration)\n";
  }

  const calib_file::CalibrationData data = make_calibration_data(cal, settings);
  if (o.dry_run) {
    std::cout << "\ndry run: nothing written\n";
    return kExitOk;
  }
  if (cal.result.verdict != calib::Verdict::kGood && !o.force) {
    return fail(kExitVerdict, std::string("verdict \"") + calib::to_string(cal.result.verdict) +
                                  "\": no file written (--force writes it anyway)");
  }
  const auto saved = calib_file::save_calibration_file(o.output, data);
  if (!saved.is_ok()) return fail(kExitWrite, saved.message());
  char sum[32];
  std::snprintf(sum, sizeof sum, "fnv1a64:%016llx",
                static_cast<unsigned long long>(calib_file::checksum(data)));
  std::cout << "\nwrote " << o.output << " (device " << data.device_id << ", " << sum << ")\n";
  return kExitOk;
}

// The program. main turns an exception from anywhere in it (CLI11 setup, the solver, file
// writing) into a message and kExitInput.
int calibrate_main(int argc, char** argv) {
  CLI::App app{
      "Multi-attitude calibration of the six-accelerometer array (Hung, Fang & Lee 2007, §4.1).\n"
      "Reads mean outputs per sensor and pose, solves scale factors, biases and orientation\n"
      "errors, prints a report and writes the calibration file (docs/calibration-file.md).",
      "gfins-calibrate"};
  Options o;
  auto* means = app.add_option("--means", o.means,
                               "CSV of mean outputs: sensor,attitude,mean_v[,std_v,count] (paper "
                               "Tables 4/5; attitudes as in Tables 2/3 unless --poses)")
                    ->check(CLI::ExistingFile);
  auto* recording =
      app.add_option("--recording", o.recording,
                     "CSV of raw samples with columns v1..v6 (V); static poses found by the "
                     "static detector, matched to --poses or to the 12 poses of Tables 2/3")
          ->check(CLI::ExistingFile)
          ->excludes(means);
  means->excludes(recording);
  app.add_option("--rate", o.rate_hz, "sample rate of --recording (Hz)")
      ->check(CLI::PositiveNumber);
  app.add_option("--still-std-v", o.still_std_v,
                 "largest standard deviation of a still channel (V), 2-3x the noise "
                 "(--recording; default 2e-3)")
      ->check(CLI::PositiveNumber);
  app.add_option("--nominal-sf", o.nominal_sf,
                 "nominal scale factor(s) in V/g, 1 or 6 values, to recognise the poses of a "
                 "--recording");
  app.add_option("--poses", o.poses,
                 "CSV attitude,fx_g,fy_g,fz_g: specific force sensed in each pose (g, body)")
      ->check(CLI::ExistingFile);
  app.add_option("--method", o.method,
                 "paper (eqs. 17/18 + LS, Table 2/3 poses) or general (any >= 4 poses); "
                 "default: paper without --poses, general with")
      ->check(CLI::IsMember({"auto", "paper", "general"}));
  app.add_option("-o,--output", o.output, "calibration file to write (atomically)");
  app.add_option("--base", o.base,
                 "previous calibration file: keeps its device id, geometry, ADC LSB, location "
                 "errors and compensator unless given here")
      ->check(CLI::ExistingFile);
  app.add_option("--device-id", o.device_id, "board identifier [A-Za-z0-9._-]");
  app.add_option("--rho", o.rho_m, "cube half-size rho (m), Table 1 geometry")
      ->check(CLI::PositiveNumber);
  app.add_option("--adc-lsb", o.adc_lsb, "ADC LSB (V/count) of every channel")
      ->check(CLI::PositiveNumber);
  app.add_option("--compensator", o.compensator, "none | paper | exact (default exact)")
      ->check(CLI::IsMember({"none", "paper", "exact"}));
  app.add_flag("--force", o.force, "write the file even when the verdict is not good");
  app.add_flag("--dry-run", o.dry_run, "report only, write nothing");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? kExitOk : kExitInput;
  }
  if (o.means.empty() == o.recording.empty()) {
    return fail(kExitInput, "give one input: --means FILE or --recording FILE");
  }
  if (o.output.empty() && !o.dry_run) {
    return fail(kExitInput, "--output is required (or --dry-run)");
  }
  return run(o);
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return calibrate_main(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "gfins-calibrate: error: unexpected: %s\n", e.what());
    return kExitInput;
  }
}
