// gfins-sim: the host simulation (docs/simulation.md). One file per subcommand:
//
//   gfins-sim                      cmd_default.cpp: a scenario's trajectory with an ideal array
//                                  and white noise (the project's main job, scripts/bootstrap.sh)
//   gfins-sim run FILE|NAME        cmd_run.cpp: without and with compensation, CSV, summary, PNG
//   gfins-sim paper63              cmd_paper63.cpp: the paper's §6.3 (Figs. 7-10), four configs
//   gfins-sim montecarlo [NAME]    cmd_montecarlo.cpp: N seeds, statistics and growth slopes
//   gfins-sim consistency [NAME]   cmd_consistency.cpp: the aided filter's NEES and NIS, N seeds
//   gfins-sim covariance [NAME]    cmd_covariance.cpp: predicted 1σ envelopes, error budget
//   gfins-sim list                 cmd_list.cpp: the built-in scenarios
//
// Every run goes through the one sample source and navigation loop of host_sim; scenarios come
// from the one registry, host_sim/scenarios/*.toml, installed as share/gfins/scenarios and found
// relative to this program (gfins/host_sim/data_paths.hpp), never through a build-tree path.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>
#include <string>
#include <tuple>
#include <vector>

#include "commands.hpp"
#include "common.hpp"
#include "finite_range.hpp"
#include "gfins/version/version.hpp"

namespace {

namespace app = gfins::sim::app;

int sim_main(int argc, char** argv) {
  app::DefaultOptions o;
  o.scalar = GFINS_NAV_SCALAR_DEFAULT;
  CLI::App cli{"gfins-sim: scenarios through the gyro-free navigation core"};
  const std::string footer =
      "Exit codes: 0 ok; 1 an output could not be written or a run failed; 2 command line or "
      "scenario rejected (also: a run whose files would not fit on the disk); 3 CSV written but "
      "plotting failed (PNG asked for); 4 consistency: files written, the NEES or NIS check "
      "failed; 130 stopped by Ctrl-C/SIGINT or SIGTERM: every file "
      "written is whole (run: up to the time in summary.txt; montecarlo: the runs finished; "
      "covariance: the files it names; while plotting: everything but the PNG).\n"
      "A scenario argument with a '/' or ending in .toml is a file (./drive), otherwise a "
      "built-in name (gfins-sim list).\n"
      "Environment: GFINS_SCENARIO_DIR (built-in scenarios), GFINS_SCRIPTS_DIR (plot scripts; "
      "both default to ../share/gfins/ next to this program), GFINS_PYTHON (python3 with "
      "matplotlib).";
  cli.footer(footer);
  cli.set_version_flag("--version", gfins::version::version_line("gfins-sim"));
  const auto scenario_dir = gfins::sim::builtin_scenario_dir();
  const std::vector<std::string> names = scenario_dir.is_ok()
                                             ? gfins::sim::builtin_scenarios(scenario_dir.value())
                                             : std::vector<std::string>{};
  cli.add_option("-s,--scenario", o.scenario, "trajectory of a built-in scenario")
      ->check(CLI::IsMember(names))
      ->capture_default_str();
  cli.add_option("-d,--duration", o.duration_s, "simulated time, s")
      ->check(app::finite_range(1e-3, 1e6))
      ->capture_default_str();
  cli.add_option("-r,--rate", o.rate_hz, "sample rate, Hz")
      ->check(app::finite_range(1.0, 1e5))
      ->capture_default_str();
  cli.add_option("--rho", o.rho_m, "cube half-size rho, m (Table 1)")
      ->check(app::finite_range(1e-3, 10.0))
      ->capture_default_str();
  cli.add_option("--noise-mg", o.noise_mg, "white noise per sensor for the noisy run, milli-g")
      ->check(app::finite_range(0.0, 1e3))
      ->capture_default_str();
  cli.add_option("--seed", o.seed, "noise seed")->capture_default_str();
  cli.add_option("--scalar", o.scalar, "navigation core scalar")
      ->check(CLI::IsMember({"float", "double"}))
      ->capture_default_str();
  auto* csv_opt = cli.add_option("--csv", o.csv_path,
                                 "write t, attitude/velocity/position errors of the ideal run");

  std::string scenario_name;
  app::OutputOptions out;
  bool no_plot = false;
  std::size_t mc_runs = 50;
  std::uint64_t mc_seed = 1;
  auto* run_cmd = cli.add_subcommand("run", "run a scenario file or built-in scenario");
  run_cmd
      ->add_option("scenario", scenario_name, "file (has a '/' or ends in .toml) or built-in name")
      ->required();
  auto* aided_cmd = cli.add_subcommand(
      "aided", "a scenario aided (its [aiding] switched on) and unaided: errors side by side");
  aided_cmd
      ->add_option("scenario", scenario_name, "file (has a '/' or ends in .toml) or built-in name")
      ->default_val("urban-stop-and-go");
  std::size_t aided_decimate = 100;
  aided_cmd
      ->add_option("--decimate", aided_decimate,
                   "write every N-th sample to the CSV files (default 100: 10 rows/s at 1 kHz)")
      ->check(CLI::Range(std::size_t{1}, std::size_t{1000000}))
      ->capture_default_str();
  auto* p63 = cli.add_subcommand("paper63", "the paper's §6.3 experiment, Figs. 7-10");
  auto* mc = cli.add_subcommand("montecarlo", "N seeds: error statistics and growth slopes");
  mc->add_option("scenario", scenario_name, "file, or built-in name")
      ->default_val("rest-calibrated");
  mc->add_option("-n,--runs", mc_runs, "number of runs")
      ->check(CLI::Range(2, 100000))
      ->capture_default_str();
  mc->add_option("--seed0", mc_seed, "seed of the first run")->capture_default_str();
  app::ConsistencyOptions nees_opts;
  auto* nees = cli.add_subcommand(
      "consistency", "the aided filter's NEES and NIS by Monte-Carlo against chi-square bounds");
  nees->add_option("scenario", scenario_name, "file, or built-in name")
      ->default_val("urban-stop-and-go");
  nees->add_option("-n,--runs", nees_opts.runs, "number of runs")
      ->check(CLI::Range(2, 100000))
      ->capture_default_str();
  nees->add_option("--seed0", nees_opts.seed0, "seed of the first run")->capture_default_str();
  nees->add_option("--from", nees_opts.from_s, "judge epochs and fixes from this time on, s")
      ->check(app::finite_range(0.0, 1e6))
      ->capture_default_str();
  nees->add_option("--stated-sigma-scale", nees_opts.stated_sigma_scale,
                   "offer the GNSS fixes with the receiver's sigma times this (below 1: a "
                   "receiver that claims a better accuracy than it has)")
      ->check(app::finite_range(0.01, 100.0))
      ->capture_default_str();
  app::CovarianceOptions cov_opts;
  auto* cov = cli.add_subcommand("covariance", "predicted 1-sigma envelopes and error budget");
  cov->add_option("scenario", scenario_name, "file, or built-in name")
      ->default_val("rest-calibrated");
  // Upper limits: 1 g of bias (1e6 ug), 1 g/sqrt(s) of walk, a 100 % scale error, 1 rad of
  // axis error, 1 m of location error; beyond them the linear error model means nothing and
  // the products overflow.
  cov->add_option("--bias-ug", cov_opts.bias_ug, "random-constant bias 1 sigma per sensor, ug")
      ->check(app::finite_range(0.0, 1e6));
  cov->add_option("--bias-rw", cov_opts.bias_rw_ug_sqrt_s, "bias random walk, ug/sqrt(s)")
      ->check(app::finite_range(0.0, 1e6));
  cov->add_option("--scale-ppm", cov_opts.scale_ppm, "residual scale-factor error 1 sigma, ppm")
      ->check(app::finite_range(0.0, 1e6));
  cov->add_option("--orientation-urad", cov_opts.orientation_urad,
                  "residual axis orientation error 1 sigma per axis, urad")
      ->check(app::finite_range(0.0, 1e6));
  cov->add_option("--location-mm", cov_opts.location_mm,
                  "residual location error 1 sigma per axis, mm")
      ->check(app::finite_range(0.0, 1e3));
  cov->add_option("--at", cov_opts.times_s, "budget times, s (default T/4, T/2, T)");
  auto* record_opt =
      run_cmd->add_option("--record", out.record,
                          "also write the raw-sample recording (.gfr, docs/recording-format.md) of "
                          "the samples the run navigated");
  run_cmd->add_option("--decimate", out.decimate, "write every N-th sample to the CSV files")
      ->check(CLI::Range(std::size_t{1}, std::size_t{1000000}))
      ->capture_default_str();
  std::vector<CLI::Option*> out_opts;
  for (auto* c : {run_cmd, aided_cmd, p63, mc, nees, cov}) {
    out_opts.push_back(
        c->add_option("-o,--out", out.dir, "output folder (default sim-out/<name>)"));
    c->add_flag("--no-plot", no_plot, "write CSV only, no PNG");
    c->add_option("--scalar", out.scalar,
                  "navigation core scalar: float (the board's float32 core) or double (host "
                  "reference)")
        ->check(CLI::IsMember({"float", "double"}))
        ->capture_default_str();
  }
  std::size_t jobs = 0;  // 0: one thread per hardware thread (host_sim/parallel.hpp)
  for (auto* c : {mc, nees, cov}) {
    c->add_option("-j,--jobs", jobs,
                  "threads (default: the hardware's); the output does not depend on it")
        ->check(CLI::Range(1, 1024));
  }
  auto* list_cmd = cli.add_subcommand("list", "list the built-in scenarios");
  for (auto* c : {run_cmd, aided_cmd, p63, mc, nees, cov, list_cmd}) c->footer(footer);
  cli.require_subcommand(0, 1);
  try {
    cli.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int rc = cli.exit(e);
    return rc == 0 ? app::kExitOk : app::kExitBadInput;
  }
  out.plot = !no_plot;
  for (const auto* opt : out_opts) out.dir_given = out.dir_given || opt->count() > 0;
  // An empty file name given on purpose is a mistake, not "no file" (it was silently ignored).
  for (const auto& [opt, value, what] :
       {std::tuple{record_opt, &out.record, "the recording's file name (.gfr)"},
        std::tuple{csv_opt, &o.csv_path, "the CSV file's name"}}) {
    if (opt->count() > 0 && value->empty()) {
      std::fprintf(stderr, "gfins-sim: %s is empty: give %s, or leave the option out\n",
                   opt->get_name().c_str(), what);
      return app::kExitBadInput;
    }
  }
  if (*run_cmd) return app::cmd_run(scenario_name, out);
  if (*aided_cmd) {
    out.decimate = aided_decimate;
    return app::cmd_aided(scenario_name, out);
  }
  if (*p63) return app::cmd_paper63(out);
  if (*mc) return app::cmd_montecarlo(scenario_name, mc_runs, mc_seed, jobs, out);
  nees_opts.jobs = jobs;
  if (*nees) return app::cmd_consistency(scenario_name, nees_opts, out);
  cov_opts.jobs = jobs;
  if (*cov) return app::cmd_covariance(scenario_name, cov_opts, out);
  if (*list_cmd) return app::cmd_list();
  return app::cmd_default(o);
}

}  // namespace

int main(int argc, char** argv) {
  // Library calls return HostError values; what may still throw here is allocation and the
  // covariance propagation's argument checks. Any of them is a message and exit code 1.
  try {
    return sim_main(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "gfins-sim: %s\n", e.what());
    return app::kExitError;
  }
}
