// gfins-sim aided FILE|NAME: the scenario's compensated navigation twice from the same sensor
// stream, aided (the scenario's [aiding], switched on) and unaided, with the errors against the
// truth side by side: at 10 s, 60 s and 10 min, RMS, worst, inside and after each GNSS outage,
// and how often the aided errors lie within the filter's own 3σ (docs/navigation-accuracy.md).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "commands.hpp"
#include "common.hpp"
#include "gfins/host_sim/accuracy.hpp"
#include "gfins/host_sim/scenario.hpp"
#include "run_options.hpp"

namespace gfins::sim::app {
namespace {

/// RMS and worst values are taken from here on: the alignment and the first standstill
/// updates are over by then in every built-in scenario.
constexpr double kSettleS = 10.0;
/// The recovery after an outage is reported this long after its end.
constexpr double kAfterS = 10.0;

AccuracyTracker make_tracker(const Scenario& s) {
  std::vector<double> at;
  for (const double t : {10.0, 60.0, 600.0}) {
    if (t <= s.duration_s) at.push_back(t);
  }
  std::vector<std::pair<double, double>> outages;
  if (s.gnss) outages = s.gnss->outages;
  return AccuracyTracker(at, std::min(kSettleS, s.duration_s / 2), outages, kAfterS);
}

void print_row(std::FILE* f, const std::string& what, const ErrorSnapshot& a,
               const ErrorSnapshot& u) {
  std::fprintf(f, "%-26s", what.c_str());
  for (const ErrorSnapshot* e : {&a, &u}) {
    if (!e->seen) {
      std::fprintf(f, " | %8s %8s %9s %10s", "-", "-", "-", "-");
      continue;
    }
    if (!std::isfinite(e->tilt_deg + e->heading_deg + e->vel_mps + e->pos_h_m)) {
      // A run whose solution left the finite numbers (the unaided gyro-free INS does: its rate
      // error feeds itself) has no error to print.
      std::fprintf(f, " | %38s", "diverged (not finite)");
      continue;
    }
    std::fprintf(f, " | %8.3g %8.3g %9.3g %10.4g", e->tilt_deg, e->heading_deg, e->vel_mps,
                 e->pos_h_m);
  }
  std::fprintf(f, "\n");
}

ErrorSnapshot rms_row(const AccuracyTracker& t) {
  ErrorSnapshot e;
  e.seen = t.rms_samples() > 0;
  e.tilt_deg = t.tilt_rms_deg();
  e.heading_deg = t.heading_rms_deg();
  e.vel_mps = t.vel_rms_mps();
  e.pos_h_m = t.pos_h_rms_m();
  return e;
}

/// Each component's share within 3σ, and where the filter marked σ not available (after a
/// divergence restart), the share of the samples that published it: once when every component
/// shares it (the usual case: the groups come back within a fix of each other), else each.
void print_coverage(std::FILE* f, const Coverage& c) {
  const auto share = [&c](std::size_t k) {
    return 100.0 * static_cast<double>(c.published(k)) / static_cast<double>(c.offered());
  };
  bool same = true;
  for (std::size_t k = 1; k < kConsistencyComponents; ++k) {
    same = same && c.published(k) == c.published(0);
  }
  for (std::size_t k = 0; k < kConsistencyComponents; ++k) {
    std::fprintf(f, "%s %s %.1f %%", k == 0 ? "" : ",", kConsistencyNames[k],
                 100.0 * c.fraction(k));
    if (!same && c.published(k) < c.offered()) {
      std::fprintf(f, " (sigma published in %.1f %% of the samples)", share(k));
    }
  }
  if (same && c.published(0) < c.offered()) {
    std::fprintf(f, "; sigma published in %.1f %% of the samples", share(0));
  }
  std::fprintf(f, "\n");
}

double percent(std::uint64_t part, std::uint64_t whole) {
  return whole > 0 ? 100.0 * static_cast<double>(part) / static_cast<double>(whole) : 0.0;
}

/// The standstill detector's decisions against the truth (DetectorTally).
void print_detector(std::FILE* f, const DetectorTally& d, const AidingSpec& spec) {
  std::fprintf(
      f,
      "standstill detector (windows of %u samples): false alarms %llu of %llu rest "
      "windows (%.2f %%; configured %.2f %%); missed detections %llu of %llu moving "
      "windows (%.2f %%), %llu of them in the %llu that move like rest (every sensor's "
      "output constant within its noise: straight, or a steady turn, at constant speed); %llu "
      "windows straddle a stop's start or end (%llu "
      "declared at rest); stops reached %llu of %llu\n",
      spec.window, static_cast<unsigned long long>(d.false_alarms()),
      static_cast<unsigned long long>(d.rest_windows()),
      percent(d.false_alarms(), d.rest_windows()), 100.0 * spec.false_alarm,
      static_cast<unsigned long long>(d.missed()),
      static_cast<unsigned long long>(d.moving_windows()), percent(d.missed(), d.moving_windows()),
      static_cast<unsigned long long>(d.missed_like_rest()),
      static_cast<unsigned long long>(d.moving_like_rest()),
      static_cast<unsigned long long>(d.mixed_windows()),
      static_cast<unsigned long long>(d.mixed_declared_rest()),
      static_cast<unsigned long long>(d.stops_seen()), static_cast<unsigned long long>(d.stops()));
}

void print_table(std::FILE* f, const AccuracyTracker& a, const AccuracyTracker& u,
                 const AidingSpec& spec) {
  std::fprintf(f, "%-26s | %-38s | %-38s\n", "", "aided", "unaided");
  std::fprintf(f, "%-26s", "error");
  for (int i = 0; i < 2; ++i) {
    std::fprintf(f, " | %8s %8s %9s %10s", "tilt deg", "head deg", "vel m/s", "pos_h m");
  }
  std::fprintf(f, "\n");
  for (std::size_t i = 0; i < a.checkpoints().size(); ++i) {
    char what[64];
    std::snprintf(what, sizeof what, "at %g s",
                  a.checkpoints()[i].seen ? a.checkpoints()[i].t_s : 0.0);
    print_row(f, what, a.checkpoints()[i], u.checkpoints()[i]);
  }
  char what[64];
  std::snprintf(what, sizeof what, "RMS over t >= %g s", a.rms_from_s());
  print_row(f, what, rms_row(a), rms_row(u));
  if (!a.windows().empty()) {
    std::snprintf(what, sizeof what, "RMS outside outages+%g s", kAfterS);
    print_row(f, what, a.rms_outside(), u.rms_outside());
  }
  std::snprintf(what, sizeof what, "worst over t >= %g s", a.rms_from_s());
  print_row(f, what, a.worst(), u.worst());
  for (std::size_t i = 0; i < a.windows().size(); ++i) {
    const auto& wa = a.windows()[i];
    const auto& wu = u.windows()[i];
    std::snprintf(what, sizeof what, "outage %g-%g s: worst", wa.start_s, wa.end_s);
    print_row(f, what, wa.worst_inside, wu.worst_inside);
    std::snprintf(what, sizeof what, "  %g s after it",
                  wa.after.seen ? wa.after.t_s - wa.end_s : 10.0);
    print_row(f, what, wa.after, wu.after);
  }
  std::fprintf(f,
               "(tilt: the larger of |roll| and |pitch| error; pos_h: horizontal position error; "
               "velocity 3-D)\n");
  if (a.sigma_samples() == 0) {
    // Either the filter never started, or it restarted after diverging and never got a σ
    // back: the board marks every value of this stretch not available.
    std::fprintf(f,
                 "aided: no sample from t = %g s on had its sigma published (the filter never "
                 "started, or diverged with nothing to aid it and restarted): the board marks "
                 "these values not available, and the aided errors above are of values it does "
                 "not vouch for\n",
                 a.rms_from_s());
    return;
  }
  std::fprintf(f, "aided errors within the filter's 3 sigma (%llu samples, t >= %g s):",
               static_cast<unsigned long long>(a.sigma_samples()), a.rms_from_s());
  print_coverage(f, a.coverage());
  for (const auto& w : a.windows()) {
    std::fprintf(f, "  inside the outage %g-%g s:", w.start_s, w.end_s);
    print_coverage(f, w.inside);
  }
  std::fprintf(f, "(a consistent filter: about 99.7 %% each)\n");
  const AccuracyTracker::RollPitch rp = a.roll_pitch();
  std::fprintf(f,
               "aided roll / pitch error RMS %.3g / %.3g deg%s; the filter's own 1 sigma, RMS: "
               "%.3g / %.3g deg (what its covariance predicts for them)\n",
               rp.roll_rms_deg, rp.pitch_rms_deg, a.windows().empty() ? "" : " outside outages",
               rp.roll_sigma_rms_deg, rp.pitch_sigma_rms_deg);
  if (spec.standstill) print_detector(f, a.detector(), spec);
}

}  // namespace

int cmd_aided(const std::string& name, const OutputOptions& out) {
  StreamedCommand cmd;
  if (const int rc = prepare_streamed(name, out, "sim-out/aided-",
                                      {"summary.txt", "aided.csv", "unaided.csv"}, cmd);
      rc != kExitOk) {
    return rc;
  }
  const Scenario& s = cmd.scenario;
  std::printf("gfins-sim aided %s\n  navigation: %s\n", describe(s).c_str(),
              scalar_text(cmd.scalar));
  AccuracyTracker trackers[2] = {make_tracker(s), make_tracker(s)};
  StreamedOutcome outcomes[2];
  const char* names[2] = {"aided", "unaided"};
  for (int i = 0; i < 2; ++i) {
    Scenario sx = s;
    sx.aiding.enabled = i == 0;
    sx.name = s.name + " (" + names[i] + ")";
    StreamTargets targets;
    targets.uncompensated_run = false;
    targets.accuracy = &trackers[i];
    targets.compensated_csv = cmd.dir + "/" + names[i] + ".csv";
    targets.decimate = out.decimate;
    targets.stop = &g_stop_signal;
    HostResult<StreamedOutcome> o = [&] {
      const StopSignals handlers;
      return run_scenario_streamed(sx, targets, run_progress(sx.name, sx.duration_s), cmd.scalar);
    }();
    if (!o.is_ok()) return fail(o.error(), kExitError);
    outcomes[i] = o.value();
    if (outcomes[i].interrupted) {
      std::fprintf(stderr, "gfins-sim: interrupted at t = %.6f s (%s run)\n", outcomes[i].t_stop_s,
                   names[i]);
      return kExitInterrupted;
    }
  }
  const std::string summary_path = cmd.dir + "/summary.txt";
  std::FILE* summary = std::fopen(summary_path.c_str(), "w");
  if (summary == nullptr) return fail({ErrorCode::kIoError, "cannot write " + summary_path}, 1);
  for (std::FILE* f : {stdout, summary}) {
    if (f == summary) {
      std::fprintf(f, "%s\n  navigation: %s\n", describe(s).c_str(), scalar_text(cmd.scalar));
    }
    print_table(f, trackers[0], trackers[1], s.aiding);
    print_run_table(f, SeriesStats{}, outcomes[0].compensated);
  }
  if (auto c = close_output(summary, summary_path); !c.is_ok()) return fail(c.error(), kExitError);
  std::printf(
      "written: %s/{aided,unaided}.csv, summary.txt%s\n", cmd.dir.c_str(),
      out.decimate > 1 ? (" (every " + std::to_string(out.decimate) + "th sample)").c_str() : "");
  if (!out.plot) return kExitOk;
  const std::string title = s.name + ", " + nav::to_string(s.compensator) + " compensator, " +
                            (cmd.scalar == NavScalar::kFloat ? "float32" : "double") + " core";
  if (const int rc = plot_step("gfins-sim", "plot_sim.py", {"aided", cmd.dir, title});
      rc != kExitOk) {
    return rc;
  }
  std::printf("figures: %s/accuracy.png\n", cmd.dir.c_str());
  return kExitOk;
}

}  // namespace gfins::sim::app
