// gfins-sim covariance [NAME] (docs/error-model.md): predicted 1σ envelopes of the twelve
// navigation errors along the scenario's truth, and the error budget at chosen times. The
// scenario gives trajectory, duration, rate, ρ, gravity and white noise (QA-1100 noise and bias
// random walk with model = "qa1100"); the constant-error σ come from the options.
#include <algorithm>
#include <cmath>

#include "commands.hpp"
#include "common.hpp"
#include "gfins/host_sim/covariance.hpp"
#include "gfins/host_sim/montecarlo.hpp"
#include "gfins/host_sim/sensor_model.hpp"
#include "run_options.hpp"

namespace gfins::sim::app {

namespace {

/// The options a user gives in physical units: a negative σ or a time outside the run is refused
/// (not clamped), with the option, the value and what is allowed.
HostStatus check_options(const Scenario& s, const CovarianceOptions& c) {
  const std::pair<const char*, double> sigmas[] = {{"--bias-ug", c.bias_ug},
                                                   {"--bias-rw", c.bias_rw_ug_sqrt_s},
                                                   {"--scale-ppm", c.scale_ppm},
                                                   {"--orientation-urad", c.orientation_urad},
                                                   {"--location-mm", c.location_mm}};
  char buf[256];
  for (const auto& [opt, v] : sigmas) {
    if (!std::isfinite(v) || v < 0) {
      std::snprintf(buf, sizeof buf, "%s %g: a 1-sigma must be a number >= 0", opt, v);
      return HostError{ErrorCode::kInvalidArgument, buf};
    }
  }
  // The run covers whole sample periods (sample_count): a time past its last sample is outside.
  const double covered = covered_duration_s(s);
  for (double t : c.times_s) {
    if (!std::isfinite(t) || t <= 0 || t > covered * (1.0 + 1e-12)) {
      std::snprintf(buf, sizeof buf,
                    "--at %g: outside the run of scenario %s: a budget time must be in (0, %g] s "
                    "(its last sample)",
                    t, s.name.c_str(), covered);
      return HostError{ErrorCode::kOutOfRange, buf};
    }
  }
  return Done{};
}

}  // namespace

int cmd_covariance(const std::string& name, const CovarianceOptions& c, const OutputOptions& out) {
  namespace nav = gfins::nav;
  auto loaded = load(name);
  if (!loaded.is_ok()) return fail(loaded.error(), kExitBadInput);
  const Scenario& s = loaded.value();
  const auto dir = output_dir(out, "sim-out/covariance-" + s.name);
  if (!dir.is_ok()) return fail(dir.error(), kExitBadInput);
  const auto scalar = nav_scalar(out.scalar);
  if (!scalar.is_ok()) return fail(scalar.error(), kExitBadInput);
  if (auto k = check_options(s, c); !k.is_ok()) return fail(k.error(), kExitBadInput);
  if (s.trajectory.kind == "calibration_poses") {
    return fail({ErrorCode::kInvalidArgument,
                 "scenario " + s.name + " is a calibration, not a navigation run"},
                kExitBadInput);
  }
  if (auto k = check_run_size(s, false); !k.is_ok()) return fail(k.error(), kExitBadInput);
  const std::string& out_dir = dir.value();
  if (auto d =
          make_dir(out_dir, "gfins-sim", {"covariance.csv", "budget.csv", "reference_run.csv"});
      !d.is_ok()) {
    return fail(d.error(), kExitError);
  }
  auto traj = make_trajectory(s.trajectory);
  if (!traj.is_ok()) return fail(traj.error(), kExitBadInput);
  CovarianceSpec spec;
  spec.trajectory = traj.value().get();
  spec.geometry = nav::table1_geometry<double>(s.rho_m);
  spec.gravity = gravity_model(s);
  spec.duration_s = covered_duration_s(s);  // the same samples as a run of it
  spec.dt_s = 1.0 / s.rate_hz;
  spec.decimation = static_cast<std::size_t>(std::max(1.0, std::round(s.rate_hz / 100.0)));
  const double g = nav::kStandardGravity;
  const AccelErrors qa = AccelErrors::qa1100_typical();
  const double noise = s.noise_mps2 > 0 ? s.noise_mps2 : (s.qa1100 ? qa.noise_g * g : 0.0);
  const double rw = c.bias_rw_ug_sqrt_s > 0 ? c.bias_rw_ug_sqrt_s * 1e-6 * g
                                            : (s.qa1100 ? qa.bias_rw_g_per_sqrt_s * g : 0.0);
  spec.noise.white_sigma_mps2.fill(noise);
  spec.noise.bias_rw_mps2_sqrt_s.fill(rw);
  spec.noise.bias_sigma_mps2.fill(c.bias_ug * 1e-6 * g);
  spec.constants.scale_factor_sigma.fill(c.scale_ppm * 1e-6);
  spec.constants.orientation_sigma_rad.fill(c.orientation_urad * 1e-6);
  spec.constants.location_sigma_m.fill(c.location_mm * 1e-3);
  std::vector<double> times = c.times_s;
  if (times.empty()) times = {0.25 * spec.duration_s, 0.5 * spec.duration_s, spec.duration_s};
  std::printf(
      "gfins-sim covariance %s: noise %.3g m/s^2, bias %.3g ug, bias rw %.3g m/s^2/sqrt(s)\n",
      describe(s).c_str(), noise, c.bias_ug, rw);
  // The propagation keeps decimated envelopes only; the reference run holds its series.
  print_estimate(sample_count(s), 1,
                 static_cast<double>(run_memory_bytes(s, false) + kProcessBaseBytes),
                 static_cast<double>(sample_count(s)) * kInMemoryRunSecondsPerSample,
                 "the reference run; the propagation adds its own time");
  // Ctrl-C/SIGTERM are taken between the phases (propagation, files, reference run), so every
  // file written is whole; the phases themselves run to their end (seconds for the built-ins).
  const StopSignals handlers;
  const auto interrupted = [&](const char* kept) {
    std::fprintf(stderr, "gfins-sim: interrupted (signal %d): %s\n",
                 static_cast<int>(g_stop_signal), kept);
    return kExitInterrupted;
  };
  const CovarianceReport report = covariance_report(spec, times, c.jobs);
  if (g_stop_signal != 0) return interrupted("nothing written");
  const CovarianceResult& r = report.envelopes;
  if (auto w = write_covariance_csv(r, out_dir + "/covariance.csv"); !w.is_ok()) {
    return fail(w.error(), kExitError);
  }
  const ErrorBudget& b = report.budget;
  if (auto w = write_budget_csv(b, out_dir + "/budget.csv"); !w.is_ok()) {
    return fail(w.error(), kExitError);
  }
  // The predicted σ at each budget time (--at, or T/4, T/2, T): the nearest kept sample, as the
  // budget takes it.
  const auto block = [&](std::size_t off, std::size_t k) {
    return std::sqrt(r.sigma[off][k] * r.sigma[off][k] + r.sigma[off + 1][k] * r.sigma[off + 1][k] +
                     r.sigma[off + 2][k] * r.sigma[off + 2][k]);
  };
  std::printf("predicted 1 sigma, all sources together (budget.csv splits them):\n");
  for (const double t : b.t_s) {
    const auto it = std::lower_bound(r.t_s.begin(), r.t_s.end(), t);
    std::size_t k = static_cast<std::size_t>(it - r.t_s.begin());
    if (k == r.t_s.size() || (k > 0 && t - r.t_s[k - 1] < r.t_s[k] - t)) k = k == 0 ? 0 : k - 1;
    std::printf("  t = %.4g s: |phi| %.4g deg, |dr| %.4g m, |dv| %.4g m/s, |dw| %.4g rad/s\n",
                r.t_s[k], block(0, k) * 180.0 / M_PI, block(3, k), block(6, k), block(9, k));
  }
  std::printf("written: %s/covariance.csv, %s/budget.csv\n", out_dir.c_str(), out_dir.c_str());
  // One run of the scenario (its own sensor errors) through the navigation core in the chosen
  // scalar: a sample of what the envelopes predict, written next to them. The propagation
  // above is the linear error model in double whatever the core's scalar.
  if (g_stop_signal != 0)
    return interrupted("covariance.csv and budget.csv written, no reference run");
  const auto ref =
      run_scenario(s, run_progress("reference run", covered_duration_s(s)), false, scalar.value());
  if (g_stop_signal != 0)
    return interrupted("covariance.csv and budget.csv written, no reference run");
  if (!ref.is_ok()) return fail(ref.error(), kExitError);
  const std::string ref_path = out_dir + "/reference_run.csv";
  if (auto w = write_series_csv(ref.value().compensated, ref_path, spec.decimation); !w.is_ok()) {
    return fail(w.error(), kExitError);
  }
  const NavSummary ns = nav_summary(ref.value().compensated);
  std::printf(
      "one run through the %s: final |att| %.4g deg, |dr| %.4g m, |dv| %.4g m/s\nwritten: %s\n",
      scalar_text(scalar.value()), ns.att_final_deg, ns.pos_final_m, ns.vel_final_mps,
      ref_path.c_str());
  if (!out.plot) return kExitOk;
  const std::string title = s.name + ", reference run in the " +
                            (scalar.value() == NavScalar::kFloat ? "float32" : "double") + " core";
  if (const int rc = plot_step("gfins-sim", "plot_covariance.py", {out_dir, title});
      rc != kExitOk) {
    return rc;
  }
  return kExitOk;
}

}  // namespace gfins::sim::app
