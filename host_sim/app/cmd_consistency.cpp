// gfins-sim consistency FILE|NAME: the aided filter's consistency by Monte-Carlo over the whole
// scenario, NEES once a second and NIS per GNSS fix against their χ² 95 % bounds
// (gfins/host_sim/consistency.hpp, docs/navigation-accuracy.md "Filter consistency").
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <system_error>

#include "commands.hpp"
#include "common.hpp"
#include "gfins/host_sim/consistency.hpp"
#include "gfins/host_sim/montecarlo.hpp"
#include "run_options.hpp"

namespace gfins::sim::app {
namespace {

/// Mean of the judged values (NaN when none).
double mean_of(const ConsistencySeries& c) {
  double sum = 0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < c.value.size(); ++i) {
    if (std::isfinite(c.value[i]) && c.judged[i]) {
      sum += c.value[i];
      ++n;
    }
  }
  return n > 0 ? sum / static_cast<double>(n) : std::nan("");
}

void print_verdict(std::FILE* f, const char* what, const char* unit, const ConsistencySeries& c) {
  if (c.offered == 0) {
    std::fprintf(f, "%-22s none (nothing published or gated in the window)\n", what);
    return;
  }
  std::fprintf(f,
               "%-22s %zu of %zu %s inside (%.1f %%; >= 90 %% asked), %zu above (optimistic), "
               "mean %.3f (1 expected): %s; false-failure probability %.2g\n",
               what, c.inside, c.offered, unit,
               100.0 * static_cast<double>(c.inside) / static_cast<double>(c.offered), c.above,
               mean_of(c), c.pass() ? "PASS" : "FAIL", c.false_failure);
}

/// One row per epoch (fix) of `a`; `b` (may be null) as value_b .. dof_b, and for the NEES
/// each group's value as its own column (docs/simulation.md, "gfins-sim consistency").
HostStatus write_series(const std::string& path, const char* time_column,
                        const ConsistencySeries& a, const ConsistencySeries* b,
                        const std::array<ConsistencySeries, kNeesGroups>* groups) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (f == nullptr) return HostError{ErrorCode::kIoError, "cannot write " + path};
  std::fprintf(f, "%s,value,lo,hi,dof", time_column);
  if (b != nullptr) std::fprintf(f, ",value_b,lo_b,hi_b,dof_b");
  if (groups != nullptr) {
    for (const char* g : kNeesGroupNames) std::fprintf(f, ",%s", g);
  }
  std::fprintf(f, "\n");
  for (std::size_t i = 0; i < a.value.size(); ++i) {
    std::fprintf(f, "%.6f,%.6g,%.6g,%.6g,%.0f", a.t_s[i], a.value[i], a.lo[i], a.hi[i], a.dof[i]);
    if (b != nullptr) {
      std::fprintf(f, ",%.6g,%.6g,%.6g,%.0f", b->value[i], b->lo[i], b->hi[i], b->dof[i]);
    }
    if (groups != nullptr) {
      for (const ConsistencySeries& g : *groups) std::fprintf(f, ",%.6g", g.value[i]);
    }
    std::fprintf(f, "\n");
  }
  return close_output(f, path);
}

}  // namespace

int cmd_consistency(const std::string& name, const ConsistencyOptions& c,
                    const OutputOptions& out) {
  StreamedCommand cmd;
  if (const int rc = prepare_streamed(name, out, "sim-out/consistency-",
                                      {"summary.txt", "nees.csv", "nis.csv"}, cmd);
      rc != kExitOk) {
    return rc;
  }
  const Scenario& s = cmd.scenario;
  if (c.from_s >= s.duration_s) {
    char buf[200];
    std::snprintf(buf, sizeof buf,
                  "--from %g s: scenario %s lasts %g s, so nothing would be judged; give a time "
                  "before its end",
                  c.from_s, s.name.c_str(), s.duration_s);
    return fail({ErrorCode::kInvalidArgument, buf}, kExitBadInput);
  }
  // An earlier run's files go now: a run stopped before two runs finish writes none, and must
  // not leave the old ones looking like its own.
  for (const char* f : {"summary.txt", "nees.csv", "nis.csv", "consistency.png"}) {
    std::error_code ec;
    (void)std::filesystem::remove(cmd.dir + "/" + f, ec);  // false: not there (ec tells errors)
    if (ec) {
      return fail({ErrorCode::kIoError,
                   "cannot remove the earlier " + cmd.dir + "/" + f + ": " + ec.message()},
                  kExitError);
    }
  }
  std::printf("gfins-sim consistency: %zu runs of %s\n  navigation: %s, aided\n", c.runs,
              describe(s).c_str(), scalar_text(cmd.scalar));
  if (c.stated_sigma_scale != 1.0) {
    std::printf("  the receiver states %g times its true sigma\n", c.stated_sigma_scale);
  }
  print_estimate(sample_count(s), c.runs, 0.0, montecarlo_seconds_estimate(s, c.runs, c.jobs),
                 "memory: a few kB per run");
  HostResult<ConsistencyResult> result = [&] {
    const StopSignals handlers;
    return run_consistency(s, c.runs, c.seed0, c.from_s,
                           log_progress("consistency", static_cast<double>(c.runs), "runs"),
                           cmd.scalar, c.jobs, c.stated_sigma_scale, &g_stop_signal);
  }();
  if (!result.is_ok()) {
    if (g_stop_signal != 0) {
      std::fprintf(stderr, "gfins-sim: interrupted: %s; nothing written\n",
                   result.error().message.c_str());
      return kExitInterrupted;
    }
    return fail(result.error(), kExitError);
  }
  const ConsistencyResult& r = result.value();
  if (auto w = write_series(cmd.dir + "/nees.csv", "t_s", r.nees, nullptr, &r.group_nees);
      !w.is_ok()) {
    return fail(w.error(), kExitError);
  }
  if (auto w = write_series(cmd.dir + "/nis.csv", "t_valid_s", r.nis_pos, &r.nis_vel, nullptr);
      !w.is_ok()) {
    return fail(w.error(), kExitError);
  }
  const std::string summary_path = cmd.dir + "/summary.txt";
  std::FILE* summary = std::fopen(summary_path.c_str(), "w");
  if (summary == nullptr) {
    return fail({ErrorCode::kIoError, "cannot write " + summary_path}, kExitError);
  }
  for (std::FILE* f : {stdout, summary}) {
    if (f == summary) {
      std::fprintf(f, "%zu runs of %s\n  navigation: %s, aided\n", r.runs, describe(s).c_str(),
                   scalar_text(cmd.scalar));
    }
    if (f == summary && c.stated_sigma_scale != 1.0) {
      std::fprintf(f, "  the receiver states %g times its true sigma\n", c.stated_sigma_scale);
    }
    if (r.runs < c.runs) {
      std::fprintf(f, "interrupted: statistics of the first %zu of %zu runs\n", r.runs, c.runs);
    }
    std::fprintf(f,
                 "run-averaged statistics against their chi-square 95 %% bounds, from t = %g s "
                 "(seeds %llu..%llu):\n",
                 c.from_s, static_cast<unsigned long long>(c.seed0),
                 static_cast<unsigned long long>(c.seed0 + r.runs - 1));
    print_verdict(f, "NEES (published states)", "epochs", r.nees);
    std::fprintf(f, "  by group, mean NEES / dof (inside the bounds):");
    for (std::size_t g = 0; g < kNeesGroups; ++g) {
      std::fprintf(f, "%s %s %.3f (%zu of %zu)", g == 0 ? "" : ";", kNeesGroupNames[g],
                   mean_of(r.group_nees[g]), r.group_nees[g].inside, r.group_nees[g].offered);
    }
    std::fprintf(f, "\n");
    print_verdict(f, "NIS GNSS position", "fixes", r.nis_pos);
    print_verdict(f, "NIS GNSS velocity", "fixes", r.nis_vel);
  }
  if (auto k = close_output(summary, summary_path); !k.is_ok()) return fail(k.error(), kExitError);
  std::printf("written: %s/{nees,nis}.csv, summary.txt\n", cmd.dir.c_str());
  if (r.runs < c.runs) return kExitInterrupted;
  if (out.plot) {
    const std::string title = s.name + ", " + std::to_string(r.runs) + " runs, " +
                              (cmd.scalar == NavScalar::kFloat ? "float32" : "double") + " core";
    if (const int rc = plot_step("gfins-sim", "plot_sim.py", {"consistency", cmd.dir, title});
        rc != kExitOk) {
      return rc;
    }
    std::printf("figure: %s/consistency.png\n", cmd.dir.c_str());
  }
  if (r.nees.offered == 0) {
    // Not a failed check: nothing was published to check (the filter's σ past its horizon all
    // along, as in a scenario with nothing to aid it).
    std::fprintf(stderr,
                 "gfins-sim: nothing to judge: no run published a sigma from t = %g s on (see "
                 "`gfins-sim aided %s`)\n",
                 c.from_s, s.name.c_str());
    return kExitError;
  }
  const bool pass = r.nees.pass() && (r.nis_pos.offered == 0 || r.nis_pos.pass()) &&
                    (r.nis_vel.offered == 0 || r.nis_vel.pass());
  return pass ? kExitOk : kExitCheckFailed;
}

}  // namespace gfins::sim::app
