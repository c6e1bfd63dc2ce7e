// The subcommands of gfins-sim, one file each (docs/simulation.md).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace gfins::sim::app {

/// gfins-sim without a subcommand: a scenario's trajectory with an ideal array (no misalignment,
/// no bias), once without and once with white noise, through the ADC and the core in `scalar`.
struct DefaultOptions {
  std::string scenario = "maneuver";
  double duration_s = 10.0;
  double rate_hz = 1000.0;
  double rho_m = 0.1;
  double noise_mg = 1.0;
  unsigned seed = 1;
  std::string scalar = "float";
  std::string csv_path;
};
int cmd_default(const DefaultOptions& o);

/// What run, paper63, montecarlo and covariance share on their command line.
struct OutputOptions {
  std::string dir;               // -o/--out; empty and not given: sim-out/<name>
  bool dir_given = false;        // -o was on the command line (then it must not be empty)
  bool plot = true;              // !--no-plot
  std::string scalar = "float";  // --scalar: the navigation core's scalar (float = the board's)
  std::size_t decimate = 1;      // --decimate N (run): every N-th sample in the CSV files
  std::string record;            // --record FILE (run): the raw-sample recording (.gfr)
};

/// gfins-sim run FILE|NAME: without and with compensation, CSV, summary, PNG.
int cmd_run(const std::string& name, const OutputOptions& out);

/// gfins-sim aided FILE|NAME: compensated navigation aided and unaided, errors side by side.
int cmd_aided(const std::string& name, const OutputOptions& out);

/// gfins-sim paper63: the paper's §6.3 in four configurations.
int cmd_paper63(const OutputOptions& out);

/// gfins-sim montecarlo [NAME]: N seeds, envelopes and growth slopes.
int cmd_montecarlo(const std::string& name, std::size_t runs, std::uint64_t seed0, std::size_t jobs,
                   const OutputOptions& out);

/// gfins-sim consistency [NAME]: the aided filter's NEES and NIS by Monte-Carlo.
struct ConsistencyOptions {
  std::size_t runs = 100;
  std::uint64_t seed0 = 1;
  double from_s = 10.0;             // epochs and fixes before this are not judged (the start)
  std::size_t jobs = 0;             // threads, 0: the hardware's (the output does not depend on it)
  double stated_sigma_scale = 1.0;  // the receiver states σ × this (StreamTargets)
};
int cmd_consistency(const std::string& name, const ConsistencyOptions& c, const OutputOptions& out);

/// gfins-sim covariance [NAME]: predicted 1σ envelopes and error budget (docs/error-model.md).
struct CovarianceOptions {
  double bias_ug = 0, bias_rw_ug_sqrt_s = 0, scale_ppm = 0, orientation_urad = 0, location_mm = 0;
  std::vector<double> times_s;
  std::size_t jobs = 0;  // threads, 0: the hardware's (the output does not depend on it)
};
int cmd_covariance(const std::string& name, const CovarianceOptions& c, const OutputOptions& out);

/// gfins-sim list: the scenarios of host_sim/scenarios with their descriptions.
int cmd_list();

}  // namespace gfins::sim::app
