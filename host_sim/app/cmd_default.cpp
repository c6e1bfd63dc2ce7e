// gfins-sim without a subcommand, the project's main job (scripts/bootstrap.sh): a scenario's
// trajectory with an ideal array (the scenario's sensor errors and compensator are left out),
// once without and once with white noise, through the same sample source, ADC and navigation
// loop as every other run, in the board's float32 core by default.
#include <cmath>
#include <string>

#include "commands.hpp"
#include "common.hpp"
#include "gfins/host_sim/montecarlo.hpp"

namespace gfins::sim::app {
namespace {

struct Errors {
  double attitude_deg = 0;
  double velocity_mps = 0;
  double position_m = 0;
};

struct RunResult {
  Errors final_err;
  Errors max_err;
  std::size_t samples = 0;
};

Errors errors_of(const SampleRecord& x) {
  Errors e;
  e.attitude_deg = x.truth.q_nb.angularDistance(x.q_nb_est) * 180.0 / M_PI;
  e.velocity_mps = x.v_err_n().norm();
  e.position_m = x.r_err_n().norm();
  return e;
}

HostResult<RunResult> run(const Scenario& s, NavScalar scalar, std::FILE* csv,
                          const std::string& what) {
  GFINS_TRY(const ScenarioOutcome o,
            run_scenario(s, tty_progress(what), /*with_uncompensated=*/false, scalar));
  RunResult r;
  for (const SampleRecord& x : o.compensated.samples) {
    if (x.t_s <= 0) continue;  // the given initial state
    const Errors e = errors_of(x);
    r.max_err.attitude_deg = std::max(r.max_err.attitude_deg, e.attitude_deg);
    r.max_err.velocity_mps = std::max(r.max_err.velocity_mps, e.velocity_mps);
    r.max_err.position_m = std::max(r.max_err.position_m, e.position_m);
    r.final_err = e;
    ++r.samples;
    if (csv != nullptr) {
      std::fprintf(csv, "%.6f,%.9g,%.9g,%.9g\n", x.t_s, e.attitude_deg, e.velocity_mps,
                   e.position_m);
    }
  }
  return r;
}

}  // namespace

int cmd_default(const DefaultOptions& o) {
  auto loaded = load(o.scenario);
  if (!loaded.is_ok()) return fail(loaded.error(), kExitBadInput);
  Scenario s = std::move(loaded).value();
  if (s.trajectory.kind == "calibration_poses") {
    return fail({ErrorCode::kInvalidArgument,
                 "scenario " + s.name + " is a calibration, not a navigation run"},
                kExitBadInput);
  }
  // The scenario's trajectory and gravity, the options' duration, rate, ρ and seed; an ideal
  // array: no misalignment, no bias, no compensator, through the ADC.
  s.duration_s = o.duration_s;
  s.rate_hz = o.rate_hz;
  s.rho_m = o.rho_m;
  s.seed = o.seed;
  s.misalignment = {};
  s.bias_mps2 = {};
  s.qa1100 = false;
  s.adc = true;
  s.noise_uniform = false;
  s.compensator = nav::CompensatorKind::kNone;
  s.misalignment_source = MisalignmentSource::kTrue;
  if (auto c = check_run_size(s, false); !c.is_ok()) return fail(c.error(), kExitBadInput);
  const NavScalar scalar = o.scalar == "float" ? NavScalar::kFloat : NavScalar::kDouble;
  std::FILE* csv = nullptr;
  if (!o.csv_path.empty()) {
    csv = std::fopen(o.csv_path.c_str(), "w");
    if (csv == nullptr) return fail({ErrorCode::kIoError, "cannot write " + o.csv_path}, 1);
    std::fprintf(csv, "t_s,attitude_err_deg,velocity_err_mps,position_err_m\n");
  }
  std::printf("gfins-sim: scenario %s, %.1f s at %.0f Hz, rho %.3f m, %s navigation core\n",
              s.trajectory.kind.c_str(), o.duration_s, o.rate_hz, o.rho_m, o.scalar.c_str());
  // Two runs (ideal, noisy), one after the other, each held in memory (run_memory_bytes).
  print_estimate(sample_count(s), o.noise_mg > 0 ? 2 : 1,
                 static_cast<double>(run_memory_bytes(s, false) + kProcessBaseBytes),
                 static_cast<double>(sample_count(s)) * (o.noise_mg > 0 ? 2.0 : 1.0) *
                     kInMemoryRunSecondsPerSample,
                 "");
  s.noise_mps2 = 0.0;
  const auto ideal = run(s, scalar, csv, s.name + ", ideal");
  if (csv != nullptr) {
    if (auto c = close_output(csv, o.csv_path); !c.is_ok()) return fail(c.error(), kExitError);
  }
  if (!ideal.is_ok()) return fail(ideal.error(), kExitError);
  const double noise = o.noise_mg * 1e-3 * nav::kStandardGravity;
  RunResult noisy;
  if (noise > 0) {
    s.noise_mps2 = noise;
    char what[64];
    std::snprintf(what, sizeof what, ", noise %.2f mg", o.noise_mg);
    auto r = run(s, scalar, nullptr, s.name + what);
    if (!r.is_ok()) return fail(r.error(), kExitError);
    noisy = r.value();
  }
  std::printf("\n%-22s %14s %14s %14s\n", "sensors", "attitude deg", "velocity m/s", "position m");
  const auto row = [](const char* what, const Errors& e) {
    std::printf("%-22s %14.4e %14.4e %14.4e\n", what, e.attitude_deg, e.velocity_mps, e.position_m);
  };
  row("ideal: final error", ideal.value().final_err);
  row("ideal: max error", ideal.value().max_err);
  if (noise > 0) {
    char label[64];
    std::snprintf(label, sizeof label, "%.2f mg: final error", o.noise_mg);
    row(label, noisy.final_err);
    std::snprintf(label, sizeof label, "%.2f mg: max error", o.noise_mg);
    row(label, noisy.max_err);
  }
  std::printf(
      "\n%zu samples per run, as 24-bit ADC counts (the 'ideal' run carries their\n"
      "quantisation). Without a gyroscope, ω is integrated from ω̇ = S·s/(2ρ): a sensor error\n"
      "grows as t in rate, t² in attitude and t⁴ in position (docs/math.md).\n",
      ideal.value().samples);
  return kExitOk;
}

}  // namespace gfins::sim::app
