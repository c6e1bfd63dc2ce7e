// gfins-sim: the host simulation (docs/simulation.md).
//
//   gfins-sim                      the default summary: a built-in trajectory with an ideal array
//                                  and white noise (the project's main job, scripts/bootstrap.sh)
//   gfins-sim run FILE|NAME        a scenario file through the same NavPipeline the firmware
//                                  runs, without and with compensation: CSV, summary, PNG figures
//   gfins-sim paper63              the paper's §6.3 experiment (Figs. 7-10 and navigation errors)
//                                  in four configurations, with the table of the eight bounds
//   gfins-sim montecarlo [NAME]    N seeds: error statistics over time and log-log growth slopes
#include <unistd.h>
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <memory>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "gfins/host_sim/array_model.hpp"
#include "gfins/host_sim/covariance.hpp"
#include "gfins/host_sim/montecarlo.hpp"
#include "gfins/host_sim/scenario.hpp"
#include "gfins/host_sim/sensor_model.hpp"
#include "gfins/host_sim/trajectory.hpp"
#include "gfins/nav_core/pipeline.hpp"

namespace {

using gfins::sim::Quatd;
using gfins::sim::Trajectory;
using gfins::sim::TruthState;
using gfins::sim::Vec3d;
namespace nav = gfins::nav;

struct Options {
  std::string scenario = "maneuver";
  double duration_s = 10.0;
  double rate_hz = 1000.0;
  double rho_m = 0.1;
  double noise_mg = 1.0;
  unsigned seed = 1;
  std::string scalar = GFINS_NAV_SCALAR_DEFAULT;
  std::string csv_path;
};

const std::map<std::string, std::function<std::unique_ptr<Trajectory>()>>& scenarios() {
  static const std::map<std::string, std::function<std::unique_ptr<Trajectory>()>> table = {
      {"rest", [] { return gfins::sim::make_rest(nav::quat_from_euler(0.05, -0.03, 0.8)); }},
      {"paper-6.3",
       [] {
         return gfins::sim::make_constant_acceleration(Vec3d(nav::kStandardGravity, 0, 0),
                                                       Quatd::Identity());
       }},
      {"spin",
       [] {
         return gfins::sim::make_spin(Vec3d(1, -2, 0.5).normalized(), 3.0,
                                      nav::quat_from_euler(0.2, -0.1, 0.7));
       }},
      {"coning", [] { return gfins::sim::make_coning(0.2, 2.0 * M_PI); }},
      {"maneuver", [] { return gfins::sim::make_maneuver(1.0); }},
  };
  return table;
}

struct Errors {
  double attitude_deg = 0;
  double velocity_mps = 0;
  double position_m = 0;
};

struct RunResult {
  Errors final_err;
  Errors max_err;
  std::uint32_t samples = 0;
};

template <typename T>
RunResult run(const Trajectory& traj, const Options& o, double noise_mps2, std::FILE* csv) {
  const auto geometry = nav::table1_geometry<double>(o.rho_m);
  const gfins::sim::IdealArrayModel<6> model(
      geometry, nav::GravityModel<double>::constant(nav::kStandardGravity));
  nav::PipelineConfig<T> cfg;
  cfg.nominal = geometry.template cast<T>();
  cfg.front_end.volts_per_count.fill(T(1));
  cfg.front_end.scale_v_per_g.fill(T(1));
  cfg.sample_rate_hz = o.rate_hz;
  static nav::NavPipeline<T> pipeline;  // large object: static storage, as on the board
  if (const auto st = pipeline.configure(cfg); !st.is_ok()) {
    std::fprintf(stderr, "gfins-sim: configuration rejected: %s\n", st.message());
    std::exit(2);
  }
  std::mt19937_64 rng(o.seed);
  std::normal_distribution<double> n01(0.0, 1.0);
  const auto outputs_at = [&](const TruthState& x) {
    nav::Vec6<double> s = model.outputs(x);
    for (int j = 0; j < 6 && noise_mps2 > 0; ++j) s(j) += noise_mps2 * n01(rng);
    return nav::Vec6<T>(s.template cast<T>());
  };
  const double dt = 1.0 / o.rate_hz;
  const auto steps = static_cast<std::uint32_t>(std::llround(o.duration_s * o.rate_hz));
  const TruthState x0 = traj.at(0.0);
  nav::NavState<T> init;
  init.q_nb = x0.q_nb.template cast<T>();
  init.w_b = x0.w_b.template cast<T>();
  init.v_n = x0.v_n.template cast<T>();
  init.r_n = x0.r_n.template cast<T>();
  pipeline.start_at_outputs(init, outputs_at(x0));

  RunResult r;
  const bool show_progress = isatty(fileno(stderr)) != 0;  // a log file gets no \r lines
  const std::uint32_t progress_every = steps >= 10 ? steps / 10 : 1;
  for (std::uint32_t k = 1; k <= steps; ++k) {
    const TruthState x = traj.at(k * dt);
    pipeline.process_outputs(outputs_at(x), static_cast<std::int64_t>(std::llround(x.t_s * 1e9)),
                             k);
    const auto st = pipeline.state().template cast<double>();
    Errors e;
    e.attitude_deg = x.q_nb.angularDistance(st.q_nb) * 180.0 / M_PI;
    e.velocity_mps = (st.v_n - x.v_n).norm();
    e.position_m = (st.r_n - x.r_n).norm();
    r.max_err.attitude_deg = std::max(r.max_err.attitude_deg, e.attitude_deg);
    r.max_err.velocity_mps = std::max(r.max_err.velocity_mps, e.velocity_mps);
    r.max_err.position_m = std::max(r.max_err.position_m, e.position_m);
    r.final_err = e;
    if (csv != nullptr) {
      std::fprintf(csv, "%.6f,%.9g,%.9g,%.9g\n", x.t_s, e.attitude_deg, e.velocity_mps,
                   e.position_m);
    }
    if (show_progress && k % progress_every == 0) {
      std::fprintf(stderr, "\r  %s, noise %.2f mg: %3u %%", traj.name().c_str(),
                   noise_mps2 / (1e-3 * nav::kStandardGravity), 100 * k / steps);
    }
  }
  if (show_progress) std::fprintf(stderr, "\n");
  r.samples = steps;
  return r;
}

}  // namespace

namespace {

namespace sim = gfins::sim;

/// Progress on a TTY only (a log file gets no \r lines).
sim::ProgressFn tty_progress(const std::string& what) {
  if (isatty(fileno(stderr)) == 0) return {};
  return [what, last = -1](double f) mutable {
    const int pct = static_cast<int>(f * 100.0);
    if (pct == last) return;
    last = pct;
    std::fprintf(stderr, "\r  %s: %3d %%%s", what.c_str(), pct, pct >= 100 ? "\n" : "");
  };
}

sim::Scenario load_or_exit(const std::string& name) {
  const auto parsed = sim::load_scenario(name, GFINS_SCENARIO_DIR);
  if (!parsed.ok()) {
    std::fprintf(stderr, "gfins-sim: %s\n", parsed.error.c_str());
    std::exit(2);
  }
  return *parsed.scenario;
}

void make_dir_or_exit(const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) {
    std::fprintf(stderr, "gfins-sim: cannot create %s: %s\n", dir.c_str(), ec.message().c_str());
    std::exit(1);
  }
}

/// Closes an output file. A failed write or close (disk full, I/O error) leaves the file
/// incomplete, so it is an error, thrown like the library's CSV writers do (write_series_csv)
/// and reported by main. The error flag is read first because fclose alone reports only the last
/// flush (glibc returns 0 after an earlier ENOSPC).
void close_output(std::FILE* f, const std::string& path) {
  const bool write_failed = std::ferror(f) != 0;
  if (std::fclose(f) != 0 || write_failed) throw std::runtime_error("error writing " + path);
}

/// Calls scripts/plot_sim.py; a missing python3/matplotlib is reported, not fatal. The
/// interpreter is $GFINS_PYTHON, else Debian's /usr/bin/python3 (python3-matplotlib), because a
/// python3 first on PATH (pyenv, venv) often lacks matplotlib.
void plot(const std::string& mode, const std::string& dir) {
  const char* env = std::getenv("GFINS_PYTHON");
  const std::string python = env != nullptr                                ? env
                             : std::filesystem::exists("/usr/bin/python3") ? "/usr/bin/python3"
                                                                           : "python3";
  const std::string cmd =
      python + " '" + std::string(GFINS_SCRIPTS_DIR) + "/plot_sim.py' " + mode + " '" + dir + "'";
  if (std::system(cmd.c_str()) != 0) {
    std::fprintf(stderr, "gfins-sim: plotting failed (%s); the CSV files are written\n",
                 cmd.c_str());
  } else {
    std::printf("figures: %s/*.png\n", dir.c_str());
  }
}

struct NavSummary {
  double att_final_deg = 0, att_max_deg = 0;
  double vel_final_mps = 0, vel_max_mps = 0;
  double pos_final_m = 0, pos_max_m = 0;
};

NavSummary nav_summary(const sim::RunSeries& r) {
  NavSummary n;
  for (const auto& x : r.samples) {
    const double a = x.att_err_b().norm() * 180.0 / M_PI;
    n.att_max_deg = std::max(n.att_max_deg, a);
    n.vel_max_mps = std::max(n.vel_max_mps, x.v_err_n().norm());
    n.pos_max_m = std::max(n.pos_max_m, x.r_err_n().norm());
    n.att_final_deg = a;
    n.vel_final_mps = x.v_err_n().norm();
    n.pos_final_m = x.r_err_n().norm();
  }
  return n;
}

std::string describe(const sim::Scenario& s) {
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "%s: %s\n  %.3g s at %.0f Hz, rho %.3f m, noise %.3g m/s^2 (%s), compensator %s "
                "with the %s misalignment",
                s.name.c_str(), s.description.c_str(), s.duration_s, s.rate_hz, s.rho_m,
                s.noise_mps2, s.noise_uniform ? "uniform" : "gaussian",
                gfins::nav::to_string(s.compensator),
                s.misalignment_source == sim::MisalignmentSource::kTrue ? "true" : "calibrated");
  return buf;
}

void print_calibration(std::FILE* f, const sim::Scenario& s, const sim::CalibrationOutcome& c) {
  std::fprintf(f, "simulated calibration (Tables 2/3 poses, %.3g g per pose mean):\n",
               s.calibration.mean_noise_g);
  std::fprintf(f, "  %-6s %12s %12s %12s\n", "angle", "true deg", "est deg", "1sigma deg");
  const char* names[6] = {"xy", "xz", "yx", "yz", "zx", "zy"};
  const double k = 180.0 / M_PI;
  for (std::size_t i = 0; i < 6; ++i) {
    std::fprintf(f, "  b_%-4s %12.6f %12.6f %12.6f\n", names[i],
                 s.misalignment.orientation.beta[i] * k, c.estimated.beta[i] * k,
                 c.std_rad.beta[i] * k);
  }
  for (std::size_t i = 0; i < 6; ++i) {
    std::fprintf(f, "  a_%-4s %12.6f %12.6f %12.6f\n", names[i],
                 s.misalignment.orientation.alpha[i] * k, c.estimated.alpha[i] * k,
                 c.std_rad.alpha[i] * k);
  }
  std::fprintf(f, "  RMS angle error %.4f deg\n", c.rms_angle_error_rad * k);
}

void print_run_table(std::FILE* f, const sim::ScenarioOutcome& o) {
  std::fprintf(f, "%-44s %11s %11s %11s %11s %11s %11s\n", "run", "lin lo", "lin hi", "ang lo",
               "ang hi", "att deg", "pos m");
  for (const auto* r : {&o.uncompensated, &o.compensated}) {
    if (r->samples.empty()) continue;
    const auto lin = sim::linear_accel_bounds(*r);
    const auto ang = sim::angular_accel_bounds(*r);
    const NavSummary n = nav_summary(*r);
    std::fprintf(f, "%-44s %11.4g %11.4g %11.4g %11.4g %11.4g %11.4g\n", r->label.c_str(), lin.lo,
                 lin.hi, ang.lo, ang.hi, n.att_final_deg, n.pos_final_m);
  }
  std::fprintf(
      f,
      "(lin: linear acceleration error, nav frame, m/s^2; ang: angular acceleration error, "
      "rad/s^2;\n min/max over components and samples t > 0; att, pos: final error)\n");
}

int cmd_run(const std::string& name, std::string out_dir, bool do_plot) {
  const sim::Scenario s = load_or_exit(name);
  if (out_dir.empty()) out_dir = "sim-out/" + s.name;
  make_dir_or_exit(out_dir);
  std::printf("gfins-sim run %s\n", describe(s).c_str());
  const sim::ScenarioOutcome o = sim::run_scenario(s, tty_progress(s.name));
  const std::string summary_path = out_dir + "/summary.txt";
  std::FILE* summary = std::fopen(summary_path.c_str(), "w");
  for (std::FILE* f : {stdout, summary}) {
    if (f == nullptr) continue;
    if (o.calibration.ran) print_calibration(f, s, o.calibration);
    if (!o.compensated.samples.empty()) print_run_table(f, o);
  }
  if (summary != nullptr) close_output(summary, summary_path);
  if (o.compensated.samples.empty()) return 0;
  sim::write_series_csv(o.uncompensated, out_dir + "/uncompensated.csv");
  sim::write_series_csv(o.compensated, out_dir + "/compensated.csv");
  std::printf("written: %s/{uncompensated,compensated}.csv, summary.txt\n", out_dir.c_str());
  if (do_plot) plot("run", out_dir);
  return 0;
}

struct Paper63Config {
  const char* tag;
  const char* scenario;
  bool calibrated;
  const char* what;
};

int cmd_paper63(std::string out_dir, bool do_plot) {
  if (out_dir.empty()) out_dir = "sim-out/paper63";
  make_dir_or_exit(out_dir);
  // The paper's quoted bounds (§6.3, Figs. 7-10), notes §4.
  const double paper[8] = {-8, 2, -0.1, 0.5, -0.002, 0.003, -0.003, 0.003};
  const Paper63Config configs[] = {
      {"matching", "paper-6.3", false, "sigma 5e-4 m/s^2, true misalignment"},
      {"1mg", "paper-6.3-1mg", false, "stated 1 mg noise, true misalignment"},
      {"calibrated", "paper-6.3", true, "sigma 5e-4 m/s^2, calibrated (1 mg/pose)"},
      {"1mg-calibrated", "paper-6.3-1mg", true, "1 mg noise, calibrated (1 mg/pose)"},
  };
  const std::string csv_path = out_dir + "/bounds.csv";
  std::FILE* csv = std::fopen(csv_path.c_str(), "w");
  if (csv == nullptr) {
    std::fprintf(stderr, "gfins-sim: cannot write %s\n", csv_path.c_str());
    return 1;
  }
  std::fprintf(csv,
               "config,before_lin_lo,before_lin_hi,before_ang_lo,before_ang_hi,after_lin_lo,"
               "after_lin_hi,after_ang_lo,after_ang_hi,improve_lin,improve_ang,"
               "before_att_deg,after_att_deg,before_vel_mps,after_vel_mps,before_pos_m,"
               "after_pos_m\n");
  std::fprintf(csv, "paper");
  for (double v : paper) std::fprintf(csv, ",%g", v);
  std::fprintf(csv, ",,,,,,,,\n");
  std::printf("gfins-sim paper63: the paper's §6.3 (assumptions: docs/simulation.md)\n\n");
  std::printf("%-16s %9s %9s %8s %8s | %9s %9s %9s %9s | %7s %7s\n", "config", "bef lin lo",
              "lin hi", "ang lo", "ang hi", "aft lin lo", "lin hi", "ang lo", "ang hi", "x lin",
              "x ang");
  std::printf("%-16s %9.3g %9.3g %8.3g %8.3g | %9.3g %9.3g %9.3g %9.3g |\n", "paper", paper[0],
              paper[1], paper[2], paper[3], paper[4], paper[5], paper[6], paper[7]);
  for (const auto& c : configs) {
    sim::Scenario s = load_or_exit(c.scenario);
    if (c.calibrated) s.misalignment_source = sim::MisalignmentSource::kCalibrated;
    const auto o = sim::run_scenario(s, tty_progress(c.tag));
    const auto bl = sim::linear_accel_bounds(o.uncompensated);
    const auto ba = sim::angular_accel_bounds(o.uncompensated);
    const auto al = sim::linear_accel_bounds(o.compensated);
    const auto aa = sim::angular_accel_bounds(o.compensated);
    // Improvement: the largest absolute error before over the largest after.
    const auto peak = [](const sim::Bounds& b) { return std::max(-b.lo, b.hi); };
    const double x_lin = peak(bl) / peak(al);
    const double x_ang = peak(ba) / peak(aa);
    const NavSummary nb = nav_summary(o.uncompensated);
    const NavSummary na = nav_summary(o.compensated);
    std::printf("%-16s %9.3g %9.3g %8.3g %8.3g | %9.3g %9.3g %9.3g %9.3g | %7.1f %7.1f\n", c.tag,
                bl.lo, bl.hi, ba.lo, ba.hi, al.lo, al.hi, aa.lo, aa.hi, x_lin, x_ang);
    std::fprintf(csv, "%s,%g,%g,%g,%g,%g,%g,%g,%g,%g,%g,%g,%g,%g,%g,%g,%g\n", c.tag, bl.lo, bl.hi,
                 ba.lo, ba.hi, al.lo, al.hi, aa.lo, aa.hi, x_lin, x_ang, nb.att_final_deg,
                 na.att_final_deg, nb.vel_final_mps, na.vel_final_mps, nb.pos_final_m,
                 na.pos_final_m);
    sim::write_series_csv(o.uncompensated, out_dir + "/" + c.tag + "_before.csv");
    sim::write_series_csv(o.compensated, out_dir + "/" + c.tag + "_after.csv");
    if (o.calibration.ran && std::string(c.tag) == "calibrated") {
      const std::string cf_path = out_dir + "/calibration.txt";
      std::FILE* cf = std::fopen(cf_path.c_str(), "w");
      if (cf != nullptr) {
        print_calibration(cf, s, o.calibration);
        close_output(cf, cf_path);
      }
    }
  }
  close_output(csv, csv_path);
  std::printf(
      "\nlin: nav-frame linear acceleration error (m/s^2), ang: angular acceleration error "
      "(rad/s^2),\nmin/max over the three components and the samples t > 0; x: improvement "
      "(largest |error| before / after).\nwritten: %s/bounds.csv and per-config CSV files\n",
      out_dir.c_str());
  if (do_plot) plot("paper63", out_dir);
  return 0;
}

int cmd_montecarlo(const std::string& name, std::size_t runs, std::uint64_t seed0,
                   std::string out_dir, bool do_plot) {
  const sim::Scenario s = load_or_exit(name);
  if (out_dir.empty()) out_dir = "sim-out/montecarlo-" + s.name;
  make_dir_or_exit(out_dir);
  std::printf("gfins-sim montecarlo: %zu runs of %s\n", runs, describe(s).c_str());
  const auto r = sim::run_montecarlo(s, runs, seed0, tty_progress("montecarlo"));
  sim::write_montecarlo_csv(r, out_dir + "/montecarlo.csv");
  // Fit window: the last decade of the run, where the constant-residual terms dominate the noise
  // random walk (montecarlo.hpp).
  const double t_end = r.t_s.back();
  const double w_slope = sim::loglog_slope(
      r.t_s, r.rms_norm[static_cast<std::size_t>(sim::McQuantity::kRate)], 0.1 * t_end, t_end);
  const double a_slope = sim::loglog_slope(
      r.t_s, r.rms_norm[static_cast<std::size_t>(sim::McQuantity::kAttitude)], 0.1 * t_end, t_end);
  const std::string slopes_path = out_dir + "/slopes.txt";
  std::FILE* f = std::fopen(slopes_path.c_str(), "w");
  for (std::FILE* o : {stdout, f}) {
    if (o == nullptr) continue;
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
  if (f != nullptr) close_output(f, slopes_path);
  if (do_plot) plot("montecarlo", out_dir);
  return 0;
}

// Covariance analysis (docs/error-model.md): predicted 1σ envelopes of the twelve navigation
// errors along the scenario's truth, and the error budget at chosen times. The scenario gives
// trajectory, duration, rate, ρ, gravity and white noise (QA-1100 noise and bias random walk
// with qa1100 = true); the constant-error σ come from the options.
struct CovarianceOptions {
  double bias_ug = 0, bias_rw_ug_sqrt_s = 0, scale_ppm = 0, orientation_urad = 0, location_mm = 0;
  std::vector<double> times_s;
};

int cmd_covariance(const std::string& name, const CovarianceOptions& c, std::string out_dir,
                   bool do_plot) {
  const sim::Scenario s = load_or_exit(name);
  if (out_dir.empty()) out_dir = "sim-out/covariance-" + s.name;
  make_dir_or_exit(out_dir);
  const auto traj = sim::make_trajectory(s.trajectory);
  sim::CovarianceSpec spec;
  spec.trajectory = traj.get();
  spec.geometry = nav::table1_geometry<double>(s.rho_m);
  spec.gravity = sim::gravity_model(s);
  spec.duration_s = s.duration_s;
  spec.dt_s = 1.0 / s.rate_hz;
  spec.decimation = static_cast<std::size_t>(std::max(1.0, std::round(s.rate_hz / 100.0)));
  const double g = nav::kStandardGravity;
  const sim::AccelErrors qa = sim::AccelErrors::qa1100_typical();
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
  if (times.empty()) times = {0.25 * s.duration_s, 0.5 * s.duration_s, s.duration_s};
  std::printf(
      "gfins-sim covariance %s: noise %.3g m/s^2, bias %.3g ug, bias rw %.3g m/s^2/sqrt(s)\n",
      describe(s).c_str(), noise, c.bias_ug, rw);
  const sim::CovarianceResult r = sim::propagate_covariance(spec);
  sim::write_covariance_csv(r, out_dir + "/covariance.csv");
  const sim::ErrorBudget b = sim::error_budget(spec, times);
  sim::write_budget_csv(b, out_dir + "/budget.csv");
  const std::size_t last = r.t_s.size() - 1;
  const auto block = [&](std::size_t off) {
    return std::sqrt(r.sigma[off][last] * r.sigma[off][last] +
                     r.sigma[off + 1][last] * r.sigma[off + 1][last] +
                     r.sigma[off + 2][last] * r.sigma[off + 2][last]);
  };
  std::printf(
      "predicted 1 sigma at t = %.3g s: |phi| %.4g deg, |dr| %.4g m, |dv| %.4g m/s, "
      "|dw| %.4g rad/s\nwritten: %s/covariance.csv, %s/budget.csv\n",
      r.t_s[last], block(0) * 180.0 / M_PI, block(3), block(6), block(9), out_dir.c_str(),
      out_dir.c_str());
  // The summary first, then the plot script's own output. Only the order depends on this flush:
  // if stdout cannot be written the summary is lost either way, and there is nowhere to say so.
  (void)std::fflush(stdout);
  if (do_plot) {
    const char* env = std::getenv("GFINS_PYTHON");
    const std::string python = env != nullptr                                ? env
                               : std::filesystem::exists("/usr/bin/python3") ? "/usr/bin/python3"
                                                                             : "python3";
    const std::string cmd =
        python + " '" + std::string(GFINS_SCRIPTS_DIR) + "/plot_covariance.py' '" + out_dir + "'";
    if (std::system(cmd.c_str()) != 0) {
      std::fprintf(stderr, "gfins-sim: plotting failed (%s); the CSV files are written\n",
                   cmd.c_str());
    }
  }
  return 0;
}

// The program. Errors of files and scenarios come as exceptions from the library (and CLI11
// setup); main turns any of them into a message and exit code 1.
int sim_main(int argc, char** argv) {
  Options o;
  CLI::App app{"gfins-sim: a built-in scenario through the gyro-free navigation core"};
  std::vector<std::string> names;
  for (const auto& [name, _] : scenarios()) names.push_back(name);
  app.add_option("-s,--scenario", o.scenario, "trajectory")
      ->check(CLI::IsMember(names))
      ->capture_default_str();
  app.add_option("-d,--duration", o.duration_s, "simulated time, s")
      ->check(CLI::Range(1e-3, 1e6))
      ->capture_default_str();
  app.add_option("-r,--rate", o.rate_hz, "sample rate, Hz")
      ->check(CLI::Range(1.0, 1e5))
      ->capture_default_str();
  app.add_option("--rho", o.rho_m, "cube half-size rho, m (Table 1)")
      ->check(CLI::Range(1e-3, 10.0))
      ->capture_default_str();
  app.add_option("--noise-mg", o.noise_mg, "white noise per sensor for the noisy run, milli-g")
      ->check(CLI::Range(0.0, 1e3))
      ->capture_default_str();
  app.add_option("--seed", o.seed, "noise seed")->capture_default_str();
  app.add_option("--scalar", o.scalar, "navigation core scalar")
      ->check(CLI::IsMember({"float", "double"}))
      ->capture_default_str();
  app.add_option("--csv", o.csv_path,
                 "write t, attitude/velocity/position errors of the ideal run");

  std::string scenario_name;
  std::string out_dir;
  bool no_plot = false;
  std::size_t mc_runs = 50;
  std::uint64_t mc_seed = 1;
  auto* run_cmd = app.add_subcommand("run", "run a scenario file or built-in scenario");
  run_cmd->add_option("scenario", scenario_name, "file, or built-in name (host_sim/scenarios)")
      ->required();
  auto* p63 = app.add_subcommand("paper63", "the paper's §6.3 experiment, Figs. 7-10");
  auto* mc = app.add_subcommand("montecarlo", "N seeds: error statistics and growth slopes");
  mc->add_option("scenario", scenario_name, "file, or built-in name")
      ->default_val("rest-calibrated");
  mc->add_option("-n,--runs", mc_runs, "number of runs")
      ->check(CLI::Range(2, 100000))
      ->capture_default_str();
  mc->add_option("--seed0", mc_seed, "seed of the first run")->capture_default_str();
  CovarianceOptions cov_opts;
  auto* cov = app.add_subcommand("covariance", "predicted 1-sigma envelopes and error budget");
  cov->add_option("scenario", scenario_name, "file, or built-in name")
      ->default_val("rest-calibrated");
  cov->add_option("--bias-ug", cov_opts.bias_ug, "random-constant bias 1 sigma per sensor, ug");
  cov->add_option("--bias-rw", cov_opts.bias_rw_ug_sqrt_s, "bias random walk, ug/sqrt(s)");
  cov->add_option("--scale-ppm", cov_opts.scale_ppm, "residual scale-factor error 1 sigma, ppm");
  cov->add_option("--orientation-urad", cov_opts.orientation_urad,
                  "residual axis orientation error 1 sigma per axis, urad");
  cov->add_option("--location-mm", cov_opts.location_mm,
                  "residual location error 1 sigma per axis, mm");
  cov->add_option("--at", cov_opts.times_s, "budget times, s (default T/4, T/2, T)");
  for (auto* c : {run_cmd, p63, mc, cov}) {
    c->add_option("-o,--out", out_dir, "output folder (default sim-out/<name>)");
    c->add_flag("--no-plot", no_plot, "write CSV only, no PNG");
  }
  auto* list_cmd = app.add_subcommand("list", "list the built-in scenarios");
  app.require_subcommand(0, 1);
  CLI11_PARSE(app, argc, argv);
  if (*run_cmd) return cmd_run(scenario_name, out_dir, !no_plot);
  if (*p63) return cmd_paper63(out_dir, !no_plot);
  if (*mc) return cmd_montecarlo(scenario_name, mc_runs, mc_seed, out_dir, !no_plot);
  if (*cov) return cmd_covariance(scenario_name, cov_opts, out_dir, !no_plot);
  if (*list_cmd) {
    for (const auto& n : gfins::sim::builtin_scenarios(GFINS_SCENARIO_DIR)) {
      const auto p = gfins::sim::load_scenario(n, GFINS_SCENARIO_DIR);
      std::printf("%-24s %s\n", n.c_str(),
                  p.ok() ? p.scenario->description.c_str() : p.error.c_str());
    }
    return 0;
  }

  const auto traj = scenarios().at(o.scenario)();
  std::FILE* csv = nullptr;
  if (!o.csv_path.empty()) {
    csv = std::fopen(o.csv_path.c_str(), "w");
    if (csv == nullptr) {
      std::perror(("gfins-sim: cannot write " + o.csv_path).c_str());
      return 1;
    }
    std::fprintf(csv, "t_s,attitude_err_deg,velocity_err_mps,position_err_m\n");
  }
  const double noise = o.noise_mg * 1e-3 * nav::kStandardGravity;
  const bool use_float = o.scalar == "float";
  std::printf("gfins-sim: scenario %s, %.1f s at %.0f Hz, rho %.3f m, %s navigation core\n",
              traj->name().c_str(), o.duration_s, o.rate_hz, o.rho_m, o.scalar.c_str());
  const RunResult ideal =
      use_float ? run<float>(*traj, o, 0.0, csv) : run<double>(*traj, o, 0.0, csv);
  if (csv != nullptr) close_output(csv, o.csv_path);
  RunResult noisy;
  if (noise > 0) {
    noisy =
        use_float ? run<float>(*traj, o, noise, nullptr) : run<double>(*traj, o, noise, nullptr);
  }
  std::printf("\n%-22s %14s %14s %14s\n", "sensors", "attitude deg", "velocity m/s", "position m");
  const auto row = [](const char* what, const Errors& e) {
    std::printf("%-22s %14.4e %14.4e %14.4e\n", what, e.attitude_deg, e.velocity_mps, e.position_m);
  };
  row("ideal: final error", ideal.final_err);
  row("ideal: max error", ideal.max_err);
  if (noise > 0) {
    char label[64];
    std::snprintf(label, sizeof label, "%.2f mg: final error", o.noise_mg);
    row(label, noisy.final_err);
    std::snprintf(label, sizeof label, "%.2f mg: max error", o.noise_mg);
    row(label, noisy.max_err);
  }
  std::printf(
      "\n%u samples per run. Without a gyroscope, ω is integrated from ω̇ = S·s/(2ρ): a\n"
      "sensor error grows as t in rate, t² in attitude and t⁴ in position (docs/math.md).\n",
      ideal.samples);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return sim_main(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "gfins-sim: %s\n", e.what());
    return 1;
  }
}
