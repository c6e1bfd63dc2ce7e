// gfins-sim montecarlo [NAME]: N seeds, error statistics over time and log-log growth slopes.
#include <cmath>

#include "commands.hpp"
#include "common.hpp"
#include "gfins/host_sim/montecarlo.hpp"
#include "run_options.hpp"

namespace gfins::sim::app {

int cmd_montecarlo(const std::string& name, std::size_t runs, std::uint64_t seed0, std::size_t jobs,
                   const OutputOptions& out) {
  auto loaded = load(name);
  if (!loaded.is_ok()) return fail(loaded.error(), kExitBadInput);
  const Scenario& s = loaded.value();
  const auto dir = output_dir(out, "sim-out/montecarlo-" + s.name);
  if (!dir.is_ok()) return fail(dir.error(), kExitBadInput);
  const auto scalar = nav_scalar(out.scalar);
  if (!scalar.is_ok()) return fail(scalar.error(), kExitBadInput);
  if (s.trajectory.kind == "calibration_poses") {
    return fail({ErrorCode::kInvalidArgument,
                 "scenario " + s.name + " is a calibration, not a navigation run"},
                kExitBadInput);
  }
  // Every run in flight holds its series, and finished runs wait for their turn: the estimate
  // counts the threads (montecarlo_memory_bytes).
  if (auto c = check_montecarlo_size(s, runs, jobs); !c.is_ok()) {
    return fail(c.error(), kExitBadInput);
  }
  const std::string& out_dir = dir.value();
  if (auto d = make_dir(out_dir, "gfins-sim", {"montecarlo.csv", "slopes.txt"}); !d.is_ok()) {
    return fail(d.error(), kExitError);
  }
  if (auto w = check_writable({out_dir + "/montecarlo.csv", out_dir + "/slopes.txt"}); !w.is_ok()) {
    return fail(w.error(), kExitError);
  }
  std::printf("gfins-sim montecarlo: %zu runs of %s\n  navigation: %s\n", runs, describe(s).c_str(),
              scalar_text(scalar.value()));
  print_estimate(sample_count(s), runs, static_cast<double>(montecarlo_memory_bytes(s, runs, jobs)),
                 montecarlo_seconds_estimate(s, runs, jobs),
                 "peak memory, an upper bound; limit " +
                     std::to_string(max_run_memory_bytes() / 1000000) + " MB");
  HostResult<MonteCarloResult> result = [&] {
    const StopSignals handlers;
    return run_montecarlo(s, runs, seed0,
                          log_progress("montecarlo", static_cast<double>(runs), "runs"),
                          scalar.value(), jobs, &g_stop_signal);
  }();
  const int stop_signal = g_stop_signal;
  if (!result.is_ok()) {
    if (stop_signal != 0) {
      std::fprintf(stderr, "gfins-sim: interrupted (signal %d): %s; nothing written\n", stop_signal,
                   result.error().message.c_str());
      return kExitInterrupted;
    }
    return fail(result.error(), kExitError);
  }
  const MonteCarloResult& r = result.value();

  if (auto w = write_montecarlo_csv(r, out_dir + "/montecarlo.csv"); !w.is_ok()) {
    return fail(w.error(), kExitError);
  }
  // Fit window: the last decade of the run, where the constant-residual terms dominate the noise
  // random walk (montecarlo.hpp).
  const double t_end = r.t_s.back();
  const double w_slope = loglog_slope(
      r.t_s, r.rms_norm[static_cast<std::size_t>(McQuantity::kRate)], 0.1 * t_end, t_end);
  const double a_slope = loglog_slope(
      r.t_s, r.rms_norm[static_cast<std::size_t>(McQuantity::kAttitude)], 0.1 * t_end, t_end);
  const std::string slopes_path = out_dir + "/slopes.txt";
  std::FILE* f = std::fopen(slopes_path.c_str(), "w");
  if (f == nullptr) return fail({ErrorCode::kIoError, "cannot write " + slopes_path}, kExitError);
  for (std::FILE* o : {stdout, f}) {
    if (r.runs < runs) {
      std::fprintf(o, "interrupted: statistics of the first %zu of %zu runs\n", r.runs, runs);
    }
    std::fprintf(o, "RMS calibration angle error over the runs: %.4f deg\n",
                 r.rms_calibration_angle_error_rad * 180.0 / M_PI);
    std::fprintf(o, "log-log slope of RMS |w error| over [%.3g, %.3g] s: %.3f (kinematics: 1)\n",
                 0.1 * t_end, t_end, w_slope);
    std::fprintf(
        o, "log-log slope of RMS |attitude error| over [%.3g, %.3g] s: %.3f (kinematics: 2)\n",
        0.1 * t_end, t_end, a_slope);
    std::fprintf(o, "final RMS: |w| %.4g rad/s, |att| %.4g deg, |v| %.4g m/s, |r| %.4g m\n",
                 r.rms_norm[0].back(), r.rms_norm[1].back() * 180.0 / M_PI, r.rms_norm[2].back(),
                 r.rms_norm[3].back());
  }
  if (auto c = close_output(f, slopes_path); !c.is_ok()) return fail(c.error(), kExitError);
  if (r.runs < runs) {
    std::fprintf(stderr, "gfins-sim: interrupted after %zu of %zu runs (%s/slopes.txt)\n", r.runs,
                 runs, out_dir.c_str());
    return kExitInterrupted;
  }
  if (!out.plot) return kExitOk;
  const std::string title = s.name + ", " + nav::to_string(s.compensator) + " compensator, " +
                            std::to_string(r.runs) + " runs, " +
                            (scalar.value() == NavScalar::kFloat ? "float32" : "double") + " core";
  if (const int rc = plot_step("gfins-sim", "plot_sim.py", {"montecarlo", out_dir, title});
      rc != kExitOk) {
    return rc;
  }
  return kExitOk;
}

}  // namespace gfins::sim::app
