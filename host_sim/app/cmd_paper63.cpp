// gfins-sim paper63: the paper's §6.3 experiment (Figs. 7-10 and the navigation errors) in four
// configurations, with the table of the eight bounds. The only runs whose sensor outputs enter
// the core in m/s² (scenario key adc = false): the paper's experiment has no converter.
#include <algorithm>
#include <string>

#include "commands.hpp"
#include "common.hpp"
#include "run_options.hpp"

namespace gfins::sim::app {
namespace {

struct Paper63Config {
  const char* tag;
  const char* scenario;
  bool calibrated;
  const char* what;
};

}  // namespace

int cmd_paper63(const OutputOptions& out) {
  const auto dir = output_dir(out, "sim-out/paper63");
  if (!dir.is_ok()) return fail(dir.error(), kExitBadInput);
  const auto scalar = nav_scalar(out.scalar);
  if (!scalar.is_ok()) return fail(scalar.error(), kExitBadInput);
  const std::string& out_dir = dir.value();
  if (auto d = make_dir(out_dir, "gfins-sim", {"bounds.csv", "calibration.txt"}); !d.is_ok()) {
    return fail(d.error(), kExitError);
  }
  // The paper's quoted bounds (§6.3, Figs. 7-10), docs/simulation.md.
  const double paper[8] = {-8, 2, -0.1, 0.5, -0.002, 0.003, -0.003, 0.003};
  const Paper63Config configs[] = {
      {"matching", "paper-6.3", false, "sigma 5e-4 m/s^2, true misalignment"},
      {"1mg", "paper-6.3-1mg", false, "stated 1 mg noise, true misalignment"},
      {"calibrated", "paper-6.3", true, "sigma 5e-4 m/s^2, calibrated (1 mg/pose)"},
      {"1mg-calibrated", "paper-6.3-1mg", true, "1 mg noise, calibrated (1 mg/pose)"},
  };
  const std::string csv_path = out_dir + "/bounds.csv";
  std::FILE* csv = std::fopen(csv_path.c_str(), "w");
  if (csv == nullptr) return fail({ErrorCode::kIoError, "cannot write " + csv_path}, kExitError);
  std::fprintf(csv,
               "config,before_lin_lo,before_lin_hi,before_ang_lo,before_ang_hi,after_lin_lo,"
               "after_lin_hi,after_ang_lo,after_ang_hi,improve_lin,improve_ang,"
               "before_att_deg,after_att_deg,before_vel_mps,after_vel_mps,before_pos_m,"
               "after_pos_m\n");
  std::fprintf(csv, "paper");
  for (double v : paper) std::fprintf(csv, ",%g", v);
  std::fprintf(csv, ",,,,,,,,\n");
  std::printf("gfins-sim paper63: the paper's §6.3 (assumptions: docs/simulation.md), %s\n\n",
              scalar_text(scalar.value()));
  std::printf("%-16s %9s %9s %8s %8s | %9s %9s %9s %9s | %7s %7s\n", "config", "bef lin lo",
              "lin hi", "ang lo", "ang hi", "aft lin lo", "lin hi", "ang lo", "ang hi", "x lin",
              "x ang");
  std::printf("%-16s %9.3g %9.3g %8.3g %8.3g | %9.3g %9.3g %9.3g %9.3g |\n", "paper", paper[0],
              paper[1], paper[2], paper[3], paper[4], paper[5], paper[6], paper[7]);
  for (const auto& c : configs) {
    auto loaded = load(c.scenario);
    if (!loaded.is_ok()) {
      (void)close_output(csv, csv_path);
      return fail(loaded.error(), kExitBadInput);
    }
    Scenario s = std::move(loaded).value();
    if (c.calibrated) s.misalignment_source = MisalignmentSource::kCalibrated;
    const auto outcome = run_scenario(s, tty_progress(c.tag), true, scalar.value());
    if (!outcome.is_ok()) {
      (void)close_output(csv, csv_path);
      return fail(outcome.error(), kExitError);
    }
    const ScenarioOutcome& o = outcome.value();
    const auto bl = linear_accel_bounds(o.uncompensated);
    const auto ba = angular_accel_bounds(o.uncompensated);
    const auto al = linear_accel_bounds(o.compensated);
    const auto aa = angular_accel_bounds(o.compensated);
    // Improvement: the largest absolute error before over the largest after.
    const auto peak = [](const Bounds& b) { return std::max(-b.lo, b.hi); };
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
    for (const auto& [series, suffix] :
         {std::pair{&o.uncompensated, "_before.csv"}, std::pair{&o.compensated, "_after.csv"}}) {
      if (auto w = write_series_csv(*series, out_dir + "/" + c.tag + suffix); !w.is_ok()) {
        (void)close_output(csv, csv_path);
        return fail(w.error(), kExitError);
      }
    }
    if (o.calibration.ran && std::string(c.tag) == "calibrated") {
      const std::string cf_path = out_dir + "/calibration.txt";
      std::FILE* cf = std::fopen(cf_path.c_str(), "w");
      if (cf == nullptr) {
        (void)close_output(csv, csv_path);
        return fail({ErrorCode::kIoError, "cannot write " + cf_path}, kExitError);
      }
      print_calibration(cf, s, o.calibration);
      if (auto cl = close_output(cf, cf_path); !cl.is_ok()) {
        (void)close_output(csv, csv_path);
        return fail(cl.error(), kExitError);
      }
    }
  }
  if (auto cl = close_output(csv, csv_path); !cl.is_ok()) return fail(cl.error(), kExitError);
  std::printf(
      "\nlin: nav-frame linear acceleration error (m/s^2), ang: angular acceleration error "
      "(rad/s^2),\nmin/max over the three components and the samples t > 0; x: improvement "
      "(largest |error| before / after).\nwritten: %s/bounds.csv and per-config CSV files\n",
      out_dir.c_str());
  if (!out.plot) return kExitOk;
  if (const int rc = plot_step(
          "gfins-sim", "plot_sim.py",
          {"paper63", out_dir, scalar.value() == NavScalar::kFloat ? "float32" : "double"});
      rc != kExitOk) {
    return rc;
  }
  return kExitOk;
}

}  // namespace gfins::sim::app
