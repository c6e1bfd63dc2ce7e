// What the subcommands of gfins-sim share: exit codes, scenario loading, output files, the plot
// scripts (started without a shell), progress and the summary tables.
#pragma once

#include <csignal>
#include <cstdint>
#include <cstdio>
#include <initializer_list>
#include <string>
#include <vector>

#include "gfins/host_sim/error.hpp"
#include "gfins/host_sim/scenario.hpp"

namespace gfins::sim::app {

// Exit codes of gfins-sim (also in --help and docs/simulation.md).
inline constexpr int kExitOk = 0;
inline constexpr int kExitError = 1;       // an output could not be written, a run failed
inline constexpr int kExitBadInput = 2;    // command line or scenario file rejected
inline constexpr int kExitPlotFailed = 3;  // CSV written, but the PNG figures asked for are not
// `consistency`: every file written, and the filter failed its NEES or NIS check.
inline constexpr int kExitCheckFailed = 4;
// `run` stopped by SIGINT/SIGTERM (Ctrl-C): files closed and valid up to the last sample done
// (128 + SIGINT, the shells' convention for a program ended by Ctrl-C).
inline constexpr int kExitInterrupted = 130;

/// Cost of one sample of a run held in memory and written as CSV afterwards (the default command,
/// covariance's reference run): 60 s of `rest` at 1 kHz took 1.60 s on the 2-core development
/// machine (`drive` 1.38 s): 13 µs. A Monte-Carlo run writes no rows: kMcSecondsPerSampleRun.
inline constexpr double kInMemoryRunSecondsPerSample = 13e-6;

/// Prints "gfins-sim: <message>" on stderr and returns `exit_code`.
int fail(const HostError& e, int exit_code);

/// A scenario file (a path: contains '/' or ends in .toml), or a built-in scenario by name,
/// found relative to the program (sim::load_scenario; $GFINS_SCENARIO_DIR overrides).
HostResult<Scenario> load(const std::string& file_or_name);

/// Creates the output folder (and its parents). `outputs` are the files the command writes into
/// it: those already there (an earlier run's, perhaps of another scenario or command) are named
/// in a note on stderr, "<program>: note: DIR already holds A, B: replaced by this run", so that
/// two runs into one folder do not overwrite each other silently.
HostStatus make_dir(const std::string& dir, const char* program = "gfins-sim",
                    std::initializer_list<const char*> outputs = {});

/// Before the work: each of `paths` can be created for writing (a read-only folder, a name that
/// is a folder, a full disk's quota fail here, not after minutes of work). The probe files are
/// removed again.
HostStatus check_writable(const std::vector<std::string>& paths);

/// Closes an output file. A failed write or close (disk full, I/O error) leaves the file
/// incomplete, so it is an error. The error flag is read first because fclose alone reports
/// only the last flush (glibc returns 0 after an earlier ENOSPC).
HostStatus close_output(std::FILE* f, const std::string& path);

/// Runs the plot script <script> (found by paths::scripts_dir(): $GFINS_SCRIPTS_DIR, else
/// PREFIX/share/gfins/scripts next to the program) with `args` through the Python interpreter
/// ($GFINS_PYTHON, else Debian's /usr/bin/python3, which has python3-matplotlib; a python3 first on
/// PATH often lacks it), without a shell: the arguments reach the script as they are, whatever they
/// contain. Fails with a message naming the script and its exit status (or why it could not start).
/// Ctrl-C (SIGINT) or SIGTERM while it runs stops the script and fails with "interrupted (signal
/// N) while plotting"; g_stop_signal then says so.
HostStatus plot(const std::string& script, const std::vector<std::string>& args);

/// plot() as the last step of a command: kExitOk; or its message on stderr after "<program>: "
/// and kExitInterrupted (stopped by a signal) or kExitPlotFailed.
int plot_step(const char* program, const std::string& script, const std::vector<std::string>& args);

/// Progress on a TTY only (a log file gets no \r lines).
ProgressFn tty_progress(const std::string& what);

/// Progress of a long run on stderr: on a terminal the percentage (\r line, as tty_progress);
/// otherwise (a log file, a pipe) one line "progress: NAME: P % (t = X of D s)" every
/// paths::progress_interval_s() seconds of wall-clock time (5, or $GFINS_PROGRESS_INTERVAL_S:
/// for tests, which wait for the first line before they interrupt a run), none for a run that
/// ends sooner.
ProgressFn run_progress(const std::string& what, double duration_s);

/// The same for work counted in other units (montecarlo: runs; replay: samples): off a terminal
/// "progress: NAME: P % (X of TOTAL UNIT)" every paths::progress_interval_s() seconds.
ProgressFn log_progress(const std::string& what, double total, const std::string& unit);

/// Set to the signal's number by the handler StopSignals installs; the long commands (run,
/// montecarlo, gfins-replay) poll it and stop at a clean point, with what they wrote complete.
extern volatile std::sig_atomic_t g_stop_signal;

/// SIGINT/SIGTERM handlers for the lifetime of the object (g_stop_signal reset to 0 first), the
/// previous ones back on destruction.
class StopSignals {
 public:
  StopSignals();
  ~StopSignals();
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;

 private:
  void (*old_int_)(int);
  void (*old_term_)(int);
};

/// Printed before the work starts (estimate samples, memory and time before
/// starting): "estimate: N samples[ x R runs], memory about M MB, time about T s". A negative
/// memory or time is left out.
void print_estimate(std::uint64_t samples, std::size_t runs, double memory_bytes, double seconds,
                    const std::string& note);

struct NavSummary {
  double att_final_deg = 0, att_max_deg = 0;
  double vel_final_mps = 0, vel_max_mps = 0;
  double pos_final_m = 0, pos_max_m = 0;
};
NavSummary nav_summary(const RunSeries& r);

/// One paragraph: name, description, duration, rate, ρ, noise, compensator.
std::string describe(const Scenario& s);
/// One line naming a channel failure of the scenario (sensor 1-6, kind, magnitude, onset).
std::string describe(const ChannelFailure& f);
void print_calibration(std::FILE* f, const Scenario& s, const CalibrationOutcome& c);
void print_run_table(std::FILE* f, const ScenarioOutcome& o);
/// The same table from statistics accumulated while streaming (run_scenario_streamed).
void print_run_table(std::FILE* f, const SeriesStats& uncompensated,
                     const SeriesStats& compensated);

}  // namespace gfins::sim::app
