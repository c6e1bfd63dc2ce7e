// gfins-calibrate: multi-attitude calibration of the six-accelerometer array from static mean
// outputs (paper §4.1, Tables 2-6), written as a calibration file (docs/calibration-file.md).
//
// Exit status: 0 file written (or --dry-run done), 1 bad usage or input, 2 the solver failed,
// 3 the verdict is not good and --force was not given (nothing written), 4 the file could not
// be written.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <iostream>
#include <optional>
#include <string>

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

int run(const Options& o) {
  CalibrationInputs in;
  const auto means = read_means(o.means);
  if (!means.is_ok()) return fail(kExitInput, means.status().message());
  in.means = means.value();
  if (!o.poses.empty()) {
    const auto poses = read_poses(o.poses);
    if (!poses.is_ok()) return fail(kExitInput, poses.status().message());
    in.poses = poses.value();
  }
  in.method = o.method == "paper"                 ? Method::kPaper
              : o.method == "general" || in.poses ? Method::kGeneral
                                                  : Method::kPaper;
  FileSettings settings;
  if (const int rc = settings_from(o, settings); rc != kExitOk) return rc;
  settings.source = "gfins-calibrate " +
                    std::string(in.method == Method::kPaper ? "paper" : "general") + " from " +
                    std::filesystem::path(o.means).filename().string();

  const auto calibrated = run_calibration(in, o.means);
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

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Multi-attitude calibration of the six-accelerometer array (Hung, Fang & Lee 2007, §4.1).\n"
      "Reads mean outputs per sensor and pose, solves scale factors, biases and orientation\n"
      "errors, prints a report and writes the calibration file (docs/calibration-file.md).",
      "gfins-calibrate"};
  Options o;
  app.add_option("--means", o.means,
                 "CSV of mean outputs: sensor,attitude,mean_v[,std_v,count] (paper Tables 4/5; "
                 "attitudes as in Tables 2/3 unless --poses)")
      ->required()
      ->check(CLI::ExistingFile);
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
  if (o.output.empty() && !o.dry_run) {
    return fail(kExitInput, "--output is required (or --dry-run)");
  }
  try {
    return run(o);
  } catch (const std::exception& e) {
    return fail(kExitInput, std::string("unexpected: ") + e.what());
  }
}
