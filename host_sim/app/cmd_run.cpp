// gfins-sim run FILE|NAME: a scenario through the navigation core without and with
// compensation: summary, CSV and PNG figures; with --record the raw-sample recording of exactly
// the samples the runs navigated (docs/recording-format.md), which gfins-replay navigates again
// and gfins-calibrate reads.
#include "commands.hpp"
#include "common.hpp"
#include "run_options.hpp"

namespace gfins::sim::app {
namespace {

int record(const Scenario& s, const ScenarioOutcome& o, const std::string& path) {
  if (auto w = write_run_recording(s, o, path); !w.is_ok()) return fail(w.error(), kExitError);
  std::printf("recorded: %s (%zu samples at %g Hz, %s)\n", path.c_str(), o.raw.size(), s.rate_hz,
              s.trajectory.kind == "calibration_poses" ? "calibration poses" : "navigation run");
  return kExitOk;
}

}  // namespace

int cmd_run(const std::string& name, const OutputOptions& out) {
  auto loaded = load(name);
  if (!loaded.is_ok()) return fail(loaded.error(), kExitBadInput);
  const Scenario& s = loaded.value();
  const auto dir = output_dir(out, "sim-out/" + s.name);
  if (!dir.is_ok()) return fail(dir.error(), kExitBadInput);
  const auto scalar = nav_scalar(out.scalar);
  if (!scalar.is_ok()) return fail(scalar.error(), kExitBadInput);
  if (auto c = check_run_size(s); !c.is_ok()) return fail(c.error(), kExitBadInput);
  if (!out.record.empty() && !s.adc) {
    return fail({ErrorCode::kInvalidArgument,
                 "--record: scenario " + s.name +
                     " has no converter (sensors.adc = false, the paper's §6.3 in m/s²); a "
                     "recording holds ADC counts"},
                kExitBadInput);
  }
  const std::string& out_dir = dir.value();
  if (auto d = make_dir(out_dir); !d.is_ok()) return fail(d.error(), kExitError);
  std::printf("gfins-sim run %s\n  navigation: %s\n", describe(s).c_str(),
              scalar_text(scalar.value()));
  const auto outcome = run_scenario(s, tty_progress(s.name), true, scalar.value());
  if (!outcome.is_ok()) return fail(outcome.error(), kExitError);
  const ScenarioOutcome& o = outcome.value();
  if (!out.record.empty()) {
    if (const int rc = record(s, o, out.record); rc != kExitOk) return rc;
  }
  const std::string summary_path = out_dir + "/summary.txt";
  std::FILE* summary = std::fopen(summary_path.c_str(), "w");
  if (summary == nullptr) return fail({ErrorCode::kIoError, "cannot write " + summary_path}, 1);
  for (std::FILE* f : {stdout, summary}) {
    if (f == summary)
      std::fprintf(f, "%s\n  navigation: %s\n", describe(s).c_str(), scalar_text(scalar.value()));
    if (o.calibration.ran) print_calibration(f, s, o.calibration);
    if (!o.compensated.samples.empty()) print_run_table(f, o);
  }
  if (auto c = close_output(summary, summary_path); !c.is_ok()) return fail(c.error(), kExitError);
  if (o.compensated.samples.empty()) return kExitOk;
  for (const auto& [series, file] : {std::pair{&o.uncompensated, "/uncompensated.csv"},
                                     std::pair{&o.compensated, "/compensated.csv"}}) {
    if (auto w = write_series_csv(*series, out_dir + file, out.decimate); !w.is_ok()) {
      return fail(w.error(), kExitError);
    }
  }
  std::printf(
      "written: %s/{uncompensated,compensated}.csv, summary.txt%s\n", out_dir.c_str(),
      out.decimate > 1 ? (" (every " + std::to_string(out.decimate) + "th sample)").c_str() : "");
  if (!out.plot) return kExitOk;
  const std::string title = s.name + ", " + nav::to_string(s.compensator) + " compensator, " +
                            (scalar.value() == NavScalar::kFloat ? "float32" : "double") + " core";
  if (auto p = plot("plot_sim.py", {"run", out_dir, title}); !p.is_ok()) {
    return fail(p.error(), kExitPlotFailed);
  }
  std::printf("figures: %s/*.png\n", out_dir.c_str());
  return kExitOk;
}

}  // namespace gfins::sim::app
