// gfins-sim run FILE|NAME: a scenario through the navigation core without and with
// compensation: summary, CSV and PNG figures.
#include "commands.hpp"
#include "common.hpp"

namespace gfins::sim::app {

int cmd_run(const std::string& name, std::string out_dir, bool do_plot) {
  auto loaded = load(name);
  if (!loaded.is_ok()) return fail(loaded.error(), kExitBadInput);
  const Scenario& s = loaded.value();
  if (out_dir.empty()) out_dir = "sim-out/" + s.name;
  if (auto d = make_dir(out_dir); !d.is_ok()) return fail(d.error(), kExitError);
  std::printf("gfins-sim run %s\n", describe(s).c_str());
  const auto outcome = run_scenario(s, tty_progress(s.name));
  if (!outcome.is_ok()) return fail(outcome.error(), kExitError);
  const ScenarioOutcome& o = outcome.value();
  const std::string summary_path = out_dir + "/summary.txt";
  std::FILE* summary = std::fopen(summary_path.c_str(), "w");
  if (summary == nullptr) return fail({ErrorCode::kIoError, "cannot write " + summary_path}, 1);
  for (std::FILE* f : {stdout, summary}) {
    if (o.calibration.ran) print_calibration(f, s, o.calibration);
    if (!o.compensated.samples.empty()) print_run_table(f, o);
  }
  if (auto c = close_output(summary, summary_path); !c.is_ok()) return fail(c.error(), kExitError);
  if (o.compensated.samples.empty()) return kExitOk;
  for (const auto& [series, file] : {std::pair{&o.uncompensated, "/uncompensated.csv"},
                                     std::pair{&o.compensated, "/compensated.csv"}}) {
    if (auto w = write_series_csv(*series, out_dir + file); !w.is_ok()) {
      return fail(w.error(), kExitError);
    }
  }
  std::printf("written: %s/{uncompensated,compensated}.csv, summary.txt\n", out_dir.c_str());
  if (!do_plot) return kExitOk;
  if (auto p = plot("plot_sim.py", {"run", out_dir}); !p.is_ok()) {
    return fail(p.error(), kExitPlotFailed);
  }
  std::printf("figures: %s/*.png\n", out_dir.c_str());
  return kExitOk;
}

}  // namespace gfins::sim::app
