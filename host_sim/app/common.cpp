#include "common.hpp"

#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <thread>

#include "gfins/drivers/lnx/spawn.hpp"
#include "gfins/host_sim/data_paths.hpp"
#include "gfins/host_sim/progress_interval.hpp"

namespace gfins::sim::app {

int fail(const HostError& e, int exit_code) {
  std::fprintf(stderr, "gfins-sim: %s\n", e.message.c_str());
  return exit_code;
}

HostResult<Scenario> load(const std::string& file_or_name) { return load_scenario(file_or_name); }

HostStatus make_dir(const std::string& dir, const char* program,
                    std::initializer_list<const char*> outputs) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) return HostError{ErrorCode::kIoError, "cannot create " + dir + ": " + ec.message()};
  std::string there;
  for (const char* name : outputs) {
    if (!std::filesystem::exists(std::filesystem::path(dir) / name, ec)) continue;
    there += (there.empty() ? "" : ", ") + std::string(name);
  }
  if (!there.empty()) {
    std::fprintf(stderr, "%s: note: %s already holds %s: replaced by this run\n", program,
                 dir.c_str(), there.c_str());
  }
  return Done{};
}

HostStatus check_writable(const std::vector<std::string>& paths) {
  for (const std::string& p : paths) {
    std::error_code ec;
    const bool existed = std::filesystem::exists(p, ec);
    std::FILE* f = std::fopen(p.c_str(), existed ? "r+" : "w");
    if (f == nullptr) {
      return HostError{ErrorCode::kIoError, "cannot write " + p + ": " + std::strerror(errno) +
                                                " (checked before the work)"};
    }
    static_cast<void>(std::fclose(f));
    if (!existed) static_cast<void>(std::remove(p.c_str()));
  }
  return Done{};
}

HostStatus close_output(std::FILE* f, const std::string& path) {
  const bool write_failed = std::ferror(f) != 0;
  if (std::fclose(f) != 0 || write_failed) {
    return HostError{ErrorCode::kIoError, "error writing " + path};
  }
  return Done{};
}

namespace {
// Waits for a plot script, polling so that a stop signal taken by this program's handler is
// noticed (a SA_RESTART handler never wakes a blocking wait): the script gets SIGTERM, then
// SIGKILL after a grace period if it ignores that.
HostStatus wait_for_script(drivers::lnx::ChildProcess& child, const std::string& script,
                           drivers::lnx::ProcessExit& ended) {
  namespace lnx = gfins::drivers::lnx;
  constexpr auto kPoll = std::chrono::milliseconds(20);
  constexpr auto kGrace = std::chrono::seconds(5);
  std::chrono::steady_clock::time_point stop_sent{};
  bool term_sent = false;
  bool kill_sent = false;
  for (;;) {
    auto polled = lnx::poll_program(child);
    if (!polled.is_ok()) {
      return HostError{ErrorCode::kIoError, "plotting failed: waiting for " + script + ": " +
                                                polled.status().message() + ": " +
                                                std::strerror(polled.status().os_error())};
    }
    if (polled.value()) {
      ended = *polled.value();
      return Done{};
    }
    if (g_stop_signal != 0 && !term_sent) {
      (void)lnx::signal_program(child, SIGTERM);
      term_sent = true;
      stop_sent = std::chrono::steady_clock::now();
    } else if (term_sent && !kill_sent && std::chrono::steady_clock::now() - stop_sent > kGrace) {
      (void)lnx::signal_program(child, SIGKILL);
      kill_sent = true;
    }
    std::this_thread::sleep_for(kPoll);
  }
}
}  // namespace

HostStatus plot(const std::string& script, const std::vector<std::string>& args) {
  namespace lnx = gfins::drivers::lnx;
  const char* env = std::getenv("GFINS_PYTHON");
  std::error_code ec;
  const std::string python = env != nullptr && env[0] != '\0'                  ? env
                             : std::filesystem::exists("/usr/bin/python3", ec) ? "/usr/bin/python3"
                                                                               : "python3";
  const paths::DataLookup dir = paths::scripts_dir();
  if (!dir.found()) {
    return HostError{ErrorCode::kUnavailable,
                     "plotting failed: " +
                         dir.explain("plot script",
                                     "the plot scripts are installed with gfins-tools "
                                     "(share/gfins/scripts); set GFINS_SCRIPTS_DIR, or pass "
                                     "--no-plot") +
                         "; the CSV files are written"};
  }
  const std::string path = (dir.dir / script).string();
  std::vector<std::string> argv = {python, path};
  argv.insert(argv.end(), args.begin(), args.end());
  // The summary first, then the script's own output (both go to the same terminal or log).
  (void)std::fflush(stdout);
  // Ctrl-C while the script runs: a terminal's Ctrl-C reaches the script too (it dies by SIGINT,
  // quietly: the scripts restore SIGINT's default action); a signal sent to this program alone
  // is passed on as SIGTERM. Either way the caller reports the interruption, not a failed plot.
  const StopSignals handlers;
  auto started = lnx::start_program(argv);
  if (!started.is_ok()) {
    const int err = started.status().os_error();
    return HostError{ErrorCode::kUnavailable,
                     "plotting failed: cannot start " + python + " " + path + ": " +
                         started.status().message() +
                         (err != 0 ? std::string(": ") + std::strerror(err) : std::string()) +
                         "; the CSV files are written"};
  }
  lnx::ChildProcess child = started.value();
  lnx::ProcessExit ended;
  if (HostStatus w = wait_for_script(child, script, ended); !w.is_ok()) return w;
  if (g_stop_signal != 0) {
    return HostError{ErrorCode::kUnavailable,
                     "interrupted (signal " + std::to_string(static_cast<int>(g_stop_signal)) +
                         ") while plotting: " + script + " stopped (" + lnx::describe(ended) +
                         "); the CSV files are written, the PNG figures are not"};
  }
  if (!ended.ok()) {
    return HostError{ErrorCode::kUnavailable,
                     "plotting failed: " + script + " ended with " + lnx::describe(ended) +
                         " (its message is above; set GFINS_PYTHON to a python3 with matplotlib, "
                         "or pass --no-plot); the CSV files are written"};
  }
  return Done{};
}

int plot_step(const char* program, const std::string& script,
              const std::vector<std::string>& args) {
  const HostStatus p = plot(script, args);
  if (p.is_ok()) return kExitOk;
  std::fprintf(stderr, "%s: %s\n", program, p.error().message.c_str());
  return g_stop_signal != 0 ? kExitInterrupted : kExitPlotFailed;
}

ProgressFn tty_progress(const std::string& what) {
  if (isatty(fileno(stderr)) == 0) return {};
  return [what, last = -1](double f) mutable {
    const int pct = static_cast<int>(f * 100.0);
    if (pct == last) return;
    last = pct;
    std::fprintf(stderr, "\r  %s: %3d %%%s", what.c_str(), pct, pct >= 100 ? "\n" : "");
  };
}

volatile std::sig_atomic_t g_stop_signal = 0;

namespace {
extern "C" void on_stop_signal(int sig) { g_stop_signal = sig; }
}  // namespace

StopSignals::StopSignals() {
  g_stop_signal = 0;
  old_int_ = std::signal(SIGINT, on_stop_signal);
  old_term_ = std::signal(SIGTERM, on_stop_signal);
}

StopSignals::~StopSignals() {
  std::signal(SIGINT, old_int_);
  std::signal(SIGTERM, old_term_);
}

void print_estimate(std::uint64_t samples, std::size_t runs, double memory_bytes, double seconds,
                    const std::string& note) {
  std::string text = "estimate: " + std::to_string(samples) + " samples";
  if (runs > 1) text += " x " + std::to_string(runs) + " runs";
  char buf[128];
  if (memory_bytes >= 0) {
    std::snprintf(buf, sizeof buf, ", memory about %.0f MB", memory_bytes / 1e6);
    text += buf;
  }
  if (seconds >= 0) {
    std::snprintf(buf, sizeof buf, ", time about %.2g s", seconds);
    text += buf;
  }
  if (!note.empty()) text += " (" + note + ")";
  std::printf("%s\n", text.c_str());
  static_cast<void>(std::fflush(stdout));
}

ProgressFn run_progress(const std::string& what, double duration_s) {
  return log_progress(what, duration_s, "s");
}

ProgressFn log_progress(const std::string& what, double total, const std::string& unit) {
  if (isatty(fileno(stderr)) != 0) return tty_progress(what);
  const double interval = paths::progress_interval_s();
  using Clock = std::chrono::steady_clock;
  const auto every =
      std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(interval));
  return [what, total, unit, every, next = Clock::now() + every](double f) mutable {
    const auto now = Clock::now();
    if (now < next || f >= 1.0) return;
    next = now + every;
    if (unit == "s") {
      std::fprintf(stderr, "progress: %s: %.0f %% (t = %.3f of %.3f s)\n", what.c_str(), f * 100.0,
                   f * total, total);
    } else {
      std::fprintf(stderr, "progress: %s: %.0f %% (%.0f of %.0f %s)\n", what.c_str(), f * 100.0,
                   std::floor(f * total + 1e-9), total, unit.c_str());
    }
    static_cast<void>(std::fflush(stderr));
  };
}

NavSummary nav_summary(const RunSeries& r) {
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

std::string describe(const Scenario& s) {
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "%s: %s\n  %.3g s at %.0f Hz, rho %.3f m, noise %.3g m/s^2 (%s), compensator %s "
                "with the %s misalignment, %s",
                s.name.c_str(), s.description.c_str(), s.duration_s, s.rate_hz, s.rho_m,
                s.noise_mps2, s.noise_uniform ? "uniform" : "gaussian",
                gfins::nav::to_string(s.compensator),
                s.misalignment_source == MisalignmentSource::kTrue ? "true" : "calibrated",
                s.adc ? "counts through the ADC" : "m/s^2 without ADC (paper §6.3)");
  std::string text = buf;
  // A duration that is not a whole number of sample periods ends at the last whole one
  // (sample_count): said, so that 1.4 s at 1 Hz is not mistaken for a run to 1.4 s.
  if (covered_duration_s(s) < s.duration_s * (1.0 - 1e-9)) {
    std::snprintf(buf, sizeof buf,
                  "\n  duration_s %g is not a whole number of sample periods at %g Hz: the run "
                  "ends at the last whole one, t = %.9g s (%llu samples)",
                  s.duration_s, s.rate_hz, covered_duration_s(s),
                  static_cast<unsigned long long>(sample_count(s)));
    text += buf;
  }
  for (const ChannelFailure& f : s.failures) text += "\n  " + describe(f);
  if (!s.board_faults.empty()) {
    std::snprintf(
        buf, sizeof buf,
        "\n  board faults: %zu ([[board.faults]]: made by gfins-fw --sim on its simulated "
        "board; this program has no board and does not make them)",
        s.board_faults.size());
    text += buf;
  }
  return text;
}

std::string describe(const ChannelFailure& f) {
  char buf[160];
  const unsigned sensor = static_cast<unsigned>(f.sensor) + 1U;
  switch (f.kind) {
    case ChannelFailureKind::kBias:
      std::snprintf(buf, sizeof buf, "failure: sensor %u bias step %g mg from %g s", sensor,
                    f.value * 1e3, f.start_s);
      break;
    case ChannelFailureKind::kRamp:
      std::snprintf(buf, sizeof buf, "failure: sensor %u bias ramp %g mg/s from %g s", sensor,
                    f.value * 1e3, f.start_s);
      break;
    case ChannelFailureKind::kNoise:
      std::snprintf(buf, sizeof buf, "failure: sensor %u noise x%g from %g s", sensor, f.value,
                    f.start_s);
      break;
    case ChannelFailureKind::kSaturation:
      std::snprintf(buf, sizeof buf, "failure: sensor %u saturates at %g g from %g s", sensor,
                    f.value, f.start_s);
      break;
    case ChannelFailureKind::kStuck:
      std::snprintf(buf, sizeof buf, "failure: sensor %u stuck from %g s", sensor, f.start_s);
      break;
    case ChannelFailureKind::kDead:
      std::snprintf(buf, sizeof buf, "failure: sensor %u dead (0 V) from %g s", sensor, f.start_s);
      break;
  }
  return buf;
}

void print_calibration(std::FILE* f, const Scenario& s, const CalibrationOutcome& c) {
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

void print_run_table(std::FILE* f, const ScenarioOutcome& o) {
  print_run_table(f, series_stats(o.uncompensated), series_stats(o.compensated));
}

void print_run_table(std::FILE* f, const SeriesStats& uncompensated,
                     const SeriesStats& compensated) {
  std::fprintf(f, "%-44s %11s %11s %11s %11s %11s %11s\n", "run", "lin lo", "lin hi", "ang lo",
               "ang hi", "att deg", "pos m");
  for (const auto* r : {&uncompensated, &compensated}) {
    if (r->samples == 0) continue;
    std::fprintf(f, "%-44s %11.4g %11.4g %11.4g %11.4g %11.4g %11.4g\n", r->label.c_str(),
                 r->linear.lo, r->linear.hi, r->angular.lo, r->angular.hi, r->att_final_deg,
                 r->pos_final_m);
  }
  std::fprintf(
      f,
      "(lin: linear acceleration error, nav frame, m/s^2; ang: angular acceleration error, "
      "rad/s^2;\n min/max over components and samples t > 0; att, pos: final error)\n");
  const NavReport& rep = compensated.report;
  if (rep.rejected != 0 || !rep.gaps.empty()) {
    std::fprintf(f, "samples rejected by the pipeline (saturated or CRC error): %llu, gaps: %zu\n",
                 static_cast<unsigned long long>(rep.rejected), rep.gaps.size());
  }
  if (rep.aided) {
    // The filter's updates of the compensated run, per kind: accepted / rejected by the χ² gate /
    // invalid (nav::FilterCounters).
    static constexpr const char* kKinds[] = {"ZUPT", "ZARU", "GNSS position", "GNSS velocity",
                                             "heading"};
    std::fprintf(f, "aiding updates (accepted/rejected/invalid):");
    for (std::size_t k = 0; k < std::size(kKinds); ++k) {
      std::fprintf(f, "%s %s %u/%u/%u", k == 0 ? "" : ",", kKinds[k], rep.filter.accepted[k],
                   rep.filter.rejected[k], rep.filter.invalid[k]);
    }
    std::fprintf(f,
                 "; standstill decisions vetoed (moving) %u, GNSS lock-out resets %u, "
                 "divergence restarts %u, re-levels at rest %u (among the ZUPTs), covariance "
                 "resets %u\n",
                 rep.motion_vetoes, rep.filter.gnss_lockout_resets, rep.filter.divergence_restarts,
                 rep.filter.rest_relevels, rep.filter.covariance_resets);
  }
}

}  // namespace gfins::sim::app
