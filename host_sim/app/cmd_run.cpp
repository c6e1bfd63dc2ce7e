// gfins-sim run FILE|NAME: a scenario through the navigation core without and with
// compensation: summary, CSV and PNG figures; with --record the raw-sample recording of exactly
// the samples the runs navigated (docs/recording-format.md), which gfins-replay navigates again
// and gfins-calibrate reads.
#include "commands.hpp"
#include "common.hpp"
#include "gfins/drivers/lnx/output_paths.hpp"
#include "run_options.hpp"

#include <cmath>
#include <filesystem>

namespace gfins::sim::app {
namespace {

/// Refuses a run whose files would not fit on their file system (std::filesystem::space), with
/// the numbers: better than a disk full after minutes of work.
HostStatus check_disk_space(const Scenario& s, const std::string& dir, std::uint64_t need,
                            const char* what, const char* hint) {
  // The folder may not exist yet (it is made after the checks): its nearest existing ancestor.
  std::error_code ec;
  std::filesystem::path p = std::filesystem::absolute(dir, ec);
  while (!ec && !std::filesystem::exists(p, ec) && p.has_parent_path() && p != p.parent_path()) {
    p = p.parent_path();
  }
  const auto sp = std::filesystem::space(p, ec);
  if (ec || need <= sp.available) return Done{};  // unknown free space: try, write errors report
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "scenario %s: %.4g samples (duration_s %g x rate_hz %g): %s would need about "
                "%.3g MB in %s, which has %.3g MB free: free some space, %s",
                s.name.c_str(), static_cast<double>(sample_count(s)), s.duration_s, s.rate_hz, what,
                static_cast<double>(need) / 1e6, dir.c_str(),
                static_cast<double>(sp.available) / 1e6, hint);
  return HostError{ErrorCode::kResourceExhausted, buf};
}

/// Measured cost of one sample of `run` (both runs through the float32 core, two CSV rows): 60 s
/// of `rest` at 1 kHz took 3.16 s on the 2-core development machine (`drive` 3.13 s): 53 µs.
constexpr double kRunSecondsPerSample = 53e-6;

std::string parent_dir(const std::string& file) {
  const std::filesystem::path p = std::filesystem::path(file).parent_path();
  return p.empty() ? std::string(".") : p.string();
}

/// A run that stops on an error keeps no partial table (a CSV cut short reads like a complete
/// run) and says in summary.txt what happened; the recording, closed by the run even after an
/// error, stays a valid file of the samples written before it.
int fail_after_start(const std::string& out_dir, const StreamTargets& t, const HostError& e) {
  std::error_code ec;
  for (const std::string* csv : {&t.uncompensated_csv, &t.compensated_csv}) {
    if (!csv->empty()) (void)std::filesystem::remove(*csv, ec);  // best effort: failing already
  }
  // Figures of an earlier run in the folder would now sit beside this run's summary.
  for (const char* png : {"accel_errors.png", "nav_errors.png"}) {
    (void)std::filesystem::remove(std::filesystem::path(out_dir) / png, ec);
  }
  const std::string summary_path = out_dir + "/summary.txt";
  if (std::FILE* f = std::fopen(summary_path.c_str(), "w"); f != nullptr) {
    std::fprintf(
        f, "failed: %s\nno table kept (a run stopped by an error leaves no partial CSV)%s\n",
        e.message.c_str(),
        t.recording.empty() ? "" : "; the recording holds the samples written before the error");
    if (auto c = close_output(f, summary_path); !c.is_ok()) fail(c.error(), kExitError);
  }
  std::fprintf(stderr, "gfins-sim: %s (%s)\n", e.message.c_str(), summary_path.c_str());
  return kExitError;
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
  // The series are streamed to the files, never held: only the sample count is checked.
  if (auto c = check_run_size(s, true, /*in_memory=*/false); !c.is_ok()) {
    return fail(c.error(), kExitBadInput);
  }
  if (!out.record.empty() && !s.adc) {
    return fail({ErrorCode::kInvalidArgument,
                 "--record: scenario " + s.name +
                     " has no converter (sensors.adc = false, the paper's §6.3 in m/s²); a "
                     "recording holds ADC counts"},
                kExitBadInput);
  }
  const std::string& out_dir = dir.value();
  const bool navigation = s.trajectory.kind != "calibration_poses";
  // The recording must not be one of the files the run writes into its folder.
  const gfins::drivers::lnx::NamedOutput outputs[] = {
      {"--record", out.record},
      {"the run's uncompensated.csv", navigation ? out_dir + "/uncompensated.csv" : ""},
      {"the run's compensated.csv", navigation ? out_dir + "/compensated.csv" : ""},
      {"the run's summary.txt", out_dir + "/summary.txt"},
  };
  if (auto clash = gfins::drivers::lnx::output_clash(outputs)) {
    return fail({ErrorCode::kInvalidArgument, *clash}, kExitBadInput);
  }
  if (auto c = check_disk_space(s, out_dir, run_disk_bytes(s, out.decimate, false), "the CSV files",
                                "use --decimate N or a shorter run");
      !c.is_ok()) {
    return fail(c.error(), kExitBadInput);
  }
  if (!out.record.empty()) {
    const std::uint64_t need =
        run_disk_bytes(s, out.decimate, true) - run_disk_bytes(s, out.decimate, false);
    if (auto c = check_disk_space(s, parent_dir(out.record), need, "the recording",
                                  "record a shorter run");
        !c.is_ok()) {
      return fail(c.error(), kExitBadInput);
    }
  }
  if (auto d = make_dir(out_dir, "gfins-sim",
                        {"summary.txt", "uncompensated.csv", "compensated.csv", "accel_errors.png",
                         "nav_errors.png"});
      !d.is_ok()) {
    return fail(d.error(), kExitError);
  }
  std::printf("gfins-sim run %s\n  navigation: %s\n", describe(s).c_str(),
              scalar_text(scalar.value()));
  print_estimate(
      sample_count(s), 1, static_cast<double>(kProcessBaseBytes),
      static_cast<double>(sample_count(s)) * kRunSecondsPerSample,
      "streamed: the memory does not grow with the duration; files about " +
          std::to_string(run_disk_bytes(s, out.decimate, !out.record.empty()) / 1000000) + " MB");
  StreamTargets targets;
  if (navigation) {
    targets.uncompensated_csv = out_dir + "/uncompensated.csv";
    targets.compensated_csv = out_dir + "/compensated.csv";
  }
  targets.decimate = out.decimate;
  targets.recording = out.record;
  targets.stop = &g_stop_signal;
  HostResult<StreamedOutcome> outcome = [&] {
    const StopSignals handlers;
    return run_scenario_streamed(s, targets, run_progress(s.name, s.duration_s), scalar.value());
  }();
  if (!outcome.is_ok()) return fail_after_start(out_dir, targets, outcome.error());
  const StreamedOutcome& o = outcome.value();
  if (!out.record.empty()) {
    std::printf("recorded: %s (%llu samples at %g Hz, %s)\n", out.record.c_str(),
                static_cast<unsigned long long>(o.recorded), s.rate_hz,
                navigation ? "navigation run" : "calibration poses");
  }
  const std::string summary_path = out_dir + "/summary.txt";
  std::FILE* summary = std::fopen(summary_path.c_str(), "w");
  if (summary == nullptr) return fail({ErrorCode::kIoError, "cannot write " + summary_path}, 1);
  for (std::FILE* f : {stdout, summary}) {
    if (f == summary)
      std::fprintf(f, "%s\n  navigation: %s\n", describe(s).c_str(), scalar_text(scalar.value()));
    if (o.calibration.ran) print_calibration(f, s, o.calibration);
    if (o.compensated.samples != 0) print_run_table(f, o.uncompensated, o.compensated);
    if (o.interrupted) {
      std::fprintf(f,
                   "interrupted (signal %d) at t = %.6f s, after %llu of %llu samples: the files "
                   "hold the samples up to there\n",
                   static_cast<int>(g_stop_signal), o.t_stop_s,
                   static_cast<unsigned long long>(o.samples_done),
                   static_cast<unsigned long long>(o.samples_planned));
    }
  }
  if (auto c = close_output(summary, summary_path); !c.is_ok()) return fail(c.error(), kExitError);
  if (o.interrupted) {
    std::fprintf(stderr, "gfins-sim: interrupted at t = %.6f s (%s/summary.txt)\n", o.t_stop_s,
                 out_dir.c_str());
    return kExitInterrupted;
  }
  if (!navigation) return kExitOk;
  std::printf(
      "written: %s/{uncompensated,compensated}.csv, summary.txt%s\n", out_dir.c_str(),
      out.decimate > 1 ? (" (every " + std::to_string(out.decimate) + "th sample)").c_str() : "");
  if (!out.plot) return kExitOk;
  const std::string title = s.name + ", " + nav::to_string(s.compensator) + " compensator, " +
                            (scalar.value() == NavScalar::kFloat ? "float32" : "double") + " core";
  if (const int rc = plot_step("gfins-sim", "plot_sim.py", {"run", out_dir, title});
      rc != kExitOk) {
    return rc;
  }
  std::printf("figures: %s/*.png\n", out_dir.c_str());
  return kExitOk;
}

}  // namespace gfins::sim::app
