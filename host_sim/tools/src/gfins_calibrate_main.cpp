// gfins-calibrate: multi-attitude calibration of the six-accelerometer array from static mean
// outputs (paper §4.1, Tables 2-6), written as a calibration file (docs/calibration-file.md).
//
// Exit status: 0 file written (or --dry-run done), 1 bad usage or input, 2 the solver failed,
// 3 the verdict is not good and --force was not given (nothing written), 4 the file could not
// be written.
#include <sys/stat.h>
#include <CLI/CLI.hpp>
#include <algorithm>
#include <array>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <limits>
#include <numbers>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "calibrate.hpp"
#include "csv.hpp"
#include "gfins/calib_file/calibration_file.hpp"
#include "gfins/drivers/lnx/output_paths.hpp"
#include "gfins/drivers/lnx/printable.hpp"
#include "gfins/nav_core/gravity.hpp"
#include "gfins/version/version.hpp"

namespace {

using namespace gfins;
using namespace gfins::tools;

constexpr int kExitOk = 0;
constexpr int kExitInput = 1;
constexpr int kExitSolver = 2;
constexpr int kExitVerdict = 3;
constexpr int kExitWrite = 4;

// Messages quote paths and file contents: printed with control characters escaped.
int fail(int code, const std::string& message) {
  std::cerr << "gfins-calibrate: error: " << drivers::lnx::printable_text(message) << "\n";
  return code;
}

/// Why the calibration file `output` could not be written, or "" when it can. The file is
/// replaced atomically (a temporary file in the same folder, then a rename), so what must be
/// writable is its folder, not the file: probed with a temporary file that is removed at once.
/// Checked before the work, so that a long solve does not end in "could not write".
std::string output_unwritable(const std::string& output) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::is_directory(output, ec)) return "it is a directory";
  // The rename would put a regular file in place of a device node, FIFO, socket or link (as
  // root, `-o /dev/full` would replace the machine's /dev/full): the save refuses them too.
  struct stat st {};
  if (::lstat(output.c_str(), &st) == 0) {
    if (const char* kind = gfins::drivers::lnx::non_regular_kind(st.st_mode)) {
      return std::string("it is ") + kind +
             ", which the atomic save would replace with a regular file (name a regular file)";
    }
  }
  fs::path dir = fs::path(output).parent_path();
  if (dir.empty()) dir = ".";
  if (!fs::is_directory(dir, ec)) return "its folder '" + dir.string() + "' does not exist";
  std::random_device rd;
  const fs::path probe = dir / (".gfins-calibrate-probe-" + std::to_string(rd()));
  std::FILE* f = std::fopen(probe.c_str(), "wbx");
  if (f == nullptr) {
    return "cannot create a file in its folder '" + dir.string() + "': " + std::strerror(errno);
  }
  static_cast<void>(std::fclose(f));
  (void)fs::remove(probe, ec);  // the probe's own file: best effort
  return {};
}

struct Options {
  std::string means;
  std::string recording;
  std::string location_runs;
  std::string verify;
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
  double gravity_mps2 = 0.0;
  std::optional<double> latitude_deg;  // given or not: NaN is a value to refuse, not "absent"
  double height_m = 0.0;
  double location_prior_m = 1e-3;
  bool force = false;
  bool dry_run = false;
};

// The shortest text that reads back as x: a refused value is shown as given, not rounded.
std::string num(double x) {
  std::array<char, 32> buf{};
  const auto r = std::to_chars(buf.data(), buf.data() + buf.size(), x);
  return std::string(buf.data(), r.ptr);
}

// Numeric options checked before anything is read or solved, with their bounds as plain numbers.
int check_numbers(const Options& o) {
  const auto outside = [](double x, double lo, double hi) {
    return !std::isfinite(x) || x < lo || x > hi;
  };
  if (outside(o.rho_m, 1e-3, calib_file::kMaxRhoM)) {
    return fail(kExitInput, "--rho " + num(o.rho_m) + ": the cube half-size must be between " +
                                "0.001 and " + num(calib_file::kMaxRhoM) + " m");
  }
  if (o.adc_lsb != 0.0 && outside(o.adc_lsb, 1e-12, calib_file::kMaxAdcLsbV)) {
    return fail(kExitInput, "--adc-lsb " + num(o.adc_lsb) +
                                ": the ADC LSB must be a positive number of volts per count, at "
                                "most 1 (a 24-bit ADC with a 2.5 V reference: 2.98e-07)");
  }
  if (o.gravity_mps2 != 0.0 &&
      outside(o.gravity_mps2, calib_file::kMinGravityMps2, calib_file::kMaxGravityMps2)) {
    return fail(kExitInput, "--gravity " + num(o.gravity_mps2) +
                                ": the local gravity must be between 9.7 and 9.9 m/s² (give "
                                "m/s², not g or Gal)");
  }
  for (const double sf : o.nominal_sf) {
    if (outside(sf, calib_file::kMinScaleVPerG, calib_file::kMaxScaleVPerG)) {
      return fail(kExitInput, "--nominal-sf " + num(sf) +
                                  ": a nominal scale factor must be between 1e-06 and 1e+06 V/g");
    }
  }
  if (o.latitude_deg && outside(*o.latitude_deg, -90.0, 90.0)) {
    return fail(kExitInput, "--latitude " + num(*o.latitude_deg) +
                                ": the geodetic latitude must be between -90 and 90 degrees");
  }
  if (outside(o.height_m, -500.0, 9000.0)) {
    return fail(kExitInput, "--height " + num(o.height_m) +
                                ": the ellipsoidal height of the site must be between -500 and "
                                "9000 m");
  }
  if (o.rate_hz != 0.0 && outside(o.rate_hz, 1.0, 1e6)) {
    return fail(kExitInput, "--rate " + num(o.rate_hz) + ": must be between 1 and 1000000 Hz");
  }
  if (outside(o.still_std_v, 1e-9, 10.0)) {
    return fail(kExitInput, "--still-std-v " + num(o.still_std_v) +
                                ": must be between 1e-09 and 10 V (2-3x the sensor noise)");
  }
  if (outside(o.location_prior_m, 0.0, 0.05)) {
    return fail(kExitInput,
                "--location-prior " + num(o.location_prior_m) + ": must be between 0 and 0.05 m");
  }
  if (o.gravity_mps2 != 0.0 && o.latitude_deg) {
    return fail(kExitInput, "give the local gravity once: --gravity or --latitude, not both");
  }
  return kExitOk;
}

// Local gravity of the calibration site from the options (--gravity, or --latitude/--height
// through the WGS-84 normal gravity model of nav_core/gravity.hpp); false when neither is given.
bool gravity_from_options(const Options& o, FileSettings& s) {
  if (o.gravity_mps2 != 0.0) {
    s.gravity_mps2 = o.gravity_mps2;
    s.gravity_source = "given (--gravity)";
    return true;
  }
  if (o.latitude_deg) {
    s.gravity_mps2 = static_cast<double>(
        nav::GravityModel<double>::normal(*o.latitude_deg * std::numbers::pi / 180.0, o.height_m)
            .magnitude_at_origin());
    s.gravity_source = "WGS-84 normal gravity at latitude " + num(*o.latitude_deg) +
                       " deg, height " + num(o.height_m) + " m";
    return true;
  }
  return false;
}

// The parts of the file the calibration does not determine: from --base, then the options.
// A dry run writes nothing, so it needs none of them.
int settings_from(const Options& o, const Recording* rec, FileSettings& s) {
  if (!o.base.empty()) {
    const auto base = calib_file::load_calibration_file(o.base);
    if (!base.is_ok()) return fail(kExitInput, base.status().message());
    const auto& b = base.value();
    s.device_id = b.device_id;
    s.geometry = b.geometry;
    s.compensator = b.compensator;
    s.gravity_mps2 = b.gravity_mps2;
    s.gravity_source = b.gravity_source;
    for (std::size_t j = 0; j < 6; ++j) {
      s.adc_lsb_v_per_count[j] = b.sensors[j].adc_lsb_v_per_count;
      s.location[j] = b.sensors[j];
    }
  } else {
    s.geometry.kind = calib_file::GeometryKind::kTable1;
    s.geometry.rho_m = o.rho_m;
    if (rec != nullptr && rec->from_gfr) s.adc_lsb_v_per_count = rec->volts_per_count;
  }
  if (!o.device_id.empty()) s.device_id = o.device_id;
  if (o.adc_lsb > 0.0) s.adc_lsb_v_per_count.fill(o.adc_lsb);
  const bool have_gravity = gravity_from_options(o, s) || !o.base.empty();
  if (o.compensator == "none") s.compensator = nav::CompensatorKind::kNone;
  if (o.compensator == "paper") s.compensator = nav::CompensatorKind::kPaper;
  if (o.compensator == "exact") s.compensator = nav::CompensatorKind::kExact;
  if (o.dry_run) {
    // Placeholders so the report can be made; nothing is written.
    if (!have_gravity) {
      s.gravity_mps2 = nav::kStandardGravity;
      s.gravity_source = "dry run: not given";
    }
    return kExitOk;
  }
  if (s.adc_lsb_v_per_count[0] <= 0.0) {
    return fail(kExitInput,
                "--adc-lsb (V/count, Vref/(gain·2^23) for a 24-bit ADC) is required without "
                "--base (a .gfr recording carries it)");
  }
  if (s.device_id.empty()) return fail(kExitInput, "--device-id is required without --base");
  if (!have_gravity) {
    return fail(kExitInput,
                "the local gravity of the calibration site is required without --base: "
                "--gravity M/S2, or --latitude DEG [--height M] (WGS-84 normal gravity); the "
                "poses sense 1 local g, which is the g of every V/g in the file");
  }
  if (const HostStatus st = check_settings(s); !st.is_ok()) {
    return fail(kExitInput, st.error().message);
  }
  return kExitOk;
}

// Runs the solver on the chosen input; kExitOk or the exit status of the failure.
int calibrate(const Options& o, const std::optional<Recording>& rec, CalibrationInputs& in,
              HostResult<CalibrationRun>& out) {
  if (!o.poses.empty()) {
    const auto poses = read_poses(o.poses);
    if (!poses.is_ok()) return fail(kExitInput, poses.error().message);
    in.poses = poses.value();
  }
  if (rec) {
    RecordingOptions ro;
    ro.rate_hz = o.rate_hz;
    ro.still_std_v = o.still_std_v;
    if (o.rate_hz <= 0.0 && !rec->from_gfr) {
      return fail(kExitInput, "--rate (Hz) is required with a CSV --recording");
    }
    if (o.nominal_sf.size() == 1)
      ro.nominal_scale_v_per_g.fill(o.nominal_sf[0]);
    else if (o.nominal_sf.size() == 6)
      std::copy_n(o.nominal_sf.begin(), 6, ro.nominal_scale_v_per_g.begin());
    else
      return fail(kExitInput, "--nominal-sf takes 1 or 6 values (V/g) with --recording");
    in.method = Method::kGeneral;
    out = run_recording_calibration(*rec, in.poses, ro, o.recording);
    return kExitOk;
  }
  const auto means = read_means(o.means);
  if (!means.is_ok()) return fail(kExitInput, means.error().message);
  in.means = means.value();
  in.method = o.method == "paper"                 ? Method::kPaper
              : o.method == "general" || in.poses ? Method::kGeneral
                                                  : Method::kPaper;
  out = run_calibration(in, o.means);
  return kExitOk;
}

// Verification poses against an installed file: residuals and z, exit 3 beyond kVerifyMaxZ.
// 5σ: a correct calibration exceeds it on one of 36 residuals with probability 2e-5 (Gaussian; a
// z from residual-based σ, a Student-t, is first mapped to the Gaussian z of its tail
// probability, so the same holds for it).
constexpr double kVerifyMaxZ = 5.0;
int verify(const Options& o) {
  const auto cal = calib_file::load_calibration_file(o.verify);
  if (!cal.is_ok()) return fail(kExitInput, cal.status().message());
  std::optional<std::vector<Pose>> poses;
  if (!o.poses.empty()) {
    const auto p = read_poses(o.poses);
    if (!p.is_ok()) return fail(kExitInput, p.error().message);
    poses = p.value();
  }
  const auto means = read_means(o.means);
  if (!means.is_ok()) return fail(kExitInput, means.error().message);
  const auto rep = verify_calibration(means.value(), poses, cal.value(), o.means);
  if (!rep.is_ok()) return fail(kExitInput, rep.error().message);
  for (const auto& line : rep.value().lines) std::cout << line << "\n";
  if (rep.value().max_abs_z > kVerifyMaxZ) {
    return fail(kExitVerdict, "verification failed: sensor a" +
                                  std::to_string(rep.value().worst_sensor) + " in pose " +
                                  std::to_string(rep.value().worst_pose) + " is " +
                                  num(rep.value().max_abs_z) +
                                  " sigma (Gaussian-equivalent) from the calibration (limit 5): "
                                  "the pose, the jig or "
                                  "the file is not what it should be");
  }
  std::cout << "verification passed: largest |z| " << num(rep.value().max_abs_z)
            << " (Gaussian-equivalent; limit 5)\n";
  return kExitOk;
}

int run(const Options& o) {
  std::optional<Recording> rec;
  if (!o.recording.empty()) {
    auto r = read_recording(o.recording);
    if (!r.is_ok()) return fail(kExitInput, r.error().message);
    rec = std::move(r).value();
  }
  FileSettings settings;
  if (const int rc = settings_from(o, rec ? &*rec : nullptr, settings); rc != kExitOk) return rc;
  std::optional<std::vector<LocationRunRow>> location_rows;
  if (!o.location_runs.empty()) {
    auto rows = read_location_runs(o.location_runs);
    if (!rows.is_ok()) return fail(kExitInput, rows.error().message);
    location_rows = std::move(rows).value();
  }

  calib_file::CalibrationData data;
  bool verdict_good = true;
  std::string verdict_text;
  const bool orientation = !o.means.empty() || rec.has_value();
  if (orientation) {
    CalibrationInputs in;
    HostResult<CalibrationRun> calibrated(HostError{ErrorCode::kUnimplemented, "not run", 0});
    if (const int rc = calibrate(o, rec, in, calibrated); rc != kExitOk) return rc;
    const std::string input = o.recording.empty() ? o.means : o.recording;
    settings.source = "gfins-calibrate " +
                      std::string(in.method == Method::kPaper ? "paper" : "general") + " from " +
                      std::filesystem::path(input).filename().string();
    if (!calibrated.is_ok()) {
      const HostError& e = calibrated.error();
      return fail(e.code == ErrorCode::kInvalidArgument &&
                          e.message.find("calibration failed") == std::string::npos
                      ? kExitInput
                      : kExitSolver,
                  e.message);
    }
    const CalibrationRun& cal = calibrated.value();
    print_report(std::cout, cal);
    std::cout << "local gravity of the calibration site: " << num(settings.gravity_mps2)
              << " m/s² (" << settings.gravity_source << "): the g of every V/g and bias\n";
    data = make_calibration_data(cal, settings);
    verdict_good = cal.result.verdict == calib::Verdict::kGood;
    verdict_text = calib::to_string(cal.result.verdict);
  } else {
    // Location only: the orientation calibration (and its gravity) comes from --base.
    const auto base = calib_file::load_calibration_file(o.base);
    if (!base.is_ok()) return fail(kExitInput, base.status().message());
    data = base.value();
    data.device_id = settings.device_id;
    data.compensator = settings.compensator;
    data.created_utc = calib_file::utc_now_iso8601();
    data.source = "gfins-calibrate location from " +
                  std::filesystem::path(o.location_runs).filename().string() + " on " +
                  std::filesystem::path(o.base).filename().string();
    if (o.gravity_mps2 != 0.0 || o.latitude_deg) {
      std::cout << "note: --gravity/--latitude ignored: the scale factors of --base are in units "
                   "of its own local gravity, "
                << num(data.gravity_mps2) << " m/s²\n";
    }
  }
  if (location_rows) {
    const auto loc =
        run_location_calibration(*location_rows, data, o.location_prior_m, o.location_runs);
    if (!loc.is_ok()) {
      return fail(loc.error().code == ErrorCode::kInvalidArgument ? kExitInput : kExitSolver,
                  loc.error().message);
    }
    std::cout << "\n";
    for (const auto& line : loc.value().lines) std::cout << line << "\n";
    for (std::size_t j = 0; j < 6; ++j) {
      data.sensors[j].location_error_m = loc.value().drho_m[j];
      data.sensors[j].location_error_sigma_m = loc.value().sigma_m[j];
    }
  } else if (o.base.empty()) {
    // Not calibrated is not known exactly: Δρ = 0 (the nominal geometry) with the mechanical
    // prior as its σ, as the location solver writes for a direction its runs cannot observe.
    for (std::size_t j = 0; j < 6; ++j)
      data.sensors[j].location_error_sigma_m.fill(o.location_prior_m);
    std::cout << "  note: location errors are not part of this calibration: Δρ = 0 written with "
                 "σ = the mechanical prior, "
              << num(o.location_prior_m * 1e3)
              << " mm per component (--location-prior; give --location-runs, or --base to keep "
                 "a previous location calibration)\n";
  }

  if (o.dry_run) {
    std::cout << "\ndry run: nothing written\n";
    return kExitOk;
  }
  if (!verdict_good && !o.force) {
    return fail(kExitVerdict, std::string("verdict \"") + verdict_text +
                                  "\": no file written (--force writes it anyway)");
  }
  const auto saved = calib_file::save_calibration_file(o.output, data);
  if (!saved.is_ok()) return fail(kExitWrite, saved.message());
  char sum[64];
  std::snprintf(sum, sizeof sum, "fnv1a64:%016llx, calibration id 0x%08x",
                static_cast<unsigned long long>(calib_file::checksum(data)),
                static_cast<unsigned>(calib_file::cal_id_of(data)));
  std::cout << "\nwrote " << o.output << " (device " << data.device_id << ", " << sum << ")\n";
  return kExitOk;
}

// The program. main turns an exception from anywhere in it (CLI11 setup, the solver, file
// writing) into a message and kExitInput.
int calibrate_main(int argc, char** argv) {
  CLI::App app{
      "Calibration of the six-accelerometer array (Hung, Fang & Lee 2007, §4).\n"
      "Orientation poses (--means or --recording): scale factors, biases and orientation errors;\n"
      "rate-table runs (--location-runs): location errors. Prints a report and writes the\n"
      "calibration file (docs/calibration.md, docs/calibration-file.md).",
      "gfins-calibrate"};
  Options o;
  auto* means = app.add_option("--means", o.means,
                               "CSV of mean outputs: sensor,attitude,mean_v[,std_v,count] (paper "
                               "Tables 4/5; attitudes as in Tables 2/3 unless --poses)")
                    ->check(CLI::ExistingFile);
  auto* recording =
      app.add_option("--recording", o.recording,
                     "raw recording: a .gfr file (docs/recording-format.md) or a CSV with "
                     "columns v1..v6 (V); still poses found by the static detector, matched to "
                     "--poses or to the 12 poses of Tables 2/3")
          ->check(CLI::ExistingFile)
          ->excludes(means);
  means->excludes(recording);
  app.add_option("--location-runs", o.location_runs,
                 "CSV of rate-table runs: mounting,axis_x,axis_y,axis_z,rate_rad_s,"
                 "mean_v1..mean_v6,std_v1..std_v6,count (location errors, paper §4.2)")
      ->check(CLI::ExistingFile);
  app.add_option("--location-prior", o.location_prior_m,
                 "1-sigma (m) written for location components the runs cannot observe "
                 "(default 0.001, the mechanical tolerance)");
  app.add_option("--rate", o.rate_hz, "sample rate of a CSV --recording (Hz)");
  app.add_option("--still-std-v", o.still_std_v,
                 "largest standard deviation of a still channel (V), 2-3x the noise "
                 "(--recording; default 0.002)");
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
  app.add_option("--gravity", o.gravity_mps2,
                 "local gravity of the calibration site, m/s² (e.g. 9.7894)");
  app.add_option("--latitude", o.latitude_deg,
                 "geodetic latitude of the calibration site, degrees: local gravity from the "
                 "WGS-84 normal gravity model");
  app.add_option("--height", o.height_m, "ellipsoidal height of the site, m (with --latitude)");
  app.add_option("-o,--output", o.output, "calibration file to write (atomically)");
  app.add_option("--base", o.base,
                 "previous calibration file: keeps its device id, geometry, ADC LSB, local "
                 "gravity, location errors and compensator unless given here")
      ->check(CLI::ExistingFile);
  app.add_option("--device-id", o.device_id, "board identifier [A-Za-z0-9._-]");
  app.add_option("--rho", o.rho_m, "cube half-size rho (m), Table 1 geometry (default 0.1)");
  app.add_option("--adc-lsb", o.adc_lsb, "ADC LSB (V/count) of every channel");
  app.add_option("--compensator", o.compensator, "none | paper | exact (default exact)")
      ->check(CLI::IsMember({"none", "paper", "exact"}));
  app.add_flag("--force", o.force, "write the file even when the verdict is not good");
  app.add_flag("--dry-run", o.dry_run, "report only, write nothing");
  app.add_option("--verify", o.verify,
                 "check verification poses (--means, --poses) against this installed calibration "
                 "file: residuals and z per pose and sensor; exit 3 beyond 5 sigma")
      ->check(CLI::ExistingFile);
  app.footer(
      "Exit codes: 0 file written (or --dry-run / --verify done); 1 bad usage or input; 2 the "
      "solver failed; 3 the verdict is not good and --force was not given (nothing written), or "
      "--verify found a pose beyond 5 sigma; 4 the file could not be written.");
  app.set_version_flag("--version", gfins::version::version_line("gfins-calibrate"));
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? kExitOk : kExitInput;
  }
  if (!o.verify.empty()) {
    if (o.means.empty()) return fail(kExitInput, "--verify needs --means (and --poses)");
    return verify(o);
  }
  if (!o.means.empty() && !o.recording.empty()) {
    return fail(kExitInput, "give one orientation input: --means FILE or --recording FILE");
  }
  if (o.means.empty() && o.recording.empty() && o.location_runs.empty()) {
    return fail(kExitInput,
                "give an input: --means FILE or --recording FILE (orientation), and/or "
                "--location-runs FILE (location)");
  }
  if (o.means.empty() && o.recording.empty() && o.base.empty()) {
    return fail(kExitInput,
                "--location-runs alone needs --base: the location solution uses the scale "
                "factors, biases and orientation errors of a previous calibration");
  }
  if (o.output.empty() && !o.dry_run) {
    return fail(kExitInput, "--output is required (or --dry-run)");
  }
  if (const int rc = check_numbers(o); rc != kExitOk) return rc;
  if (!o.dry_run) {
    if (const std::string why = output_unwritable(o.output); !why.empty()) {
      return fail(kExitWrite, "--output " + o.output + ": " + why + " (checked before solving)");
    }
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
