// Ctrl-C while a plot script draws: gfins-sim stops the script, says it was interrupted while
// plotting, keeps the CSV files and exits 130, whether the signal reached it alone (kill, a
// service manager) or the whole terminal's process group (the script dies by SIGINT too).
// Before, `run` and `montecarlo` died by the signal without a word, `covariance` ignored a
// SIGINT sent to it alone (exit 0) and a group Ctrl-C gave exit 3 with advice about matplotlib.
//
// The plot script is a stand-in found through $GFINS_SCRIPTS_DIR (documented in --help): it
// writes its pid to $GFINS_TEST_PLOT_MARK and sleeps for a minute, or fails at once when
// $GFINS_TEST_PLOT_FAIL is set (the control: a failed plot stays exit 3). Oracles: exit codes
// and messages of --help and docs/simulation.md; the stand-in's own process (alive or gone).
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/types.h>

#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "support/cli_fixture.hpp"

namespace gfins::sim {
namespace {

namespace fs = std::filesystem;
using test::CliResult;

constexpr int kExitPlotFailed = 3;
constexpr int kExitInterrupted = 130;
// Far longer than the test waits after its signal: a script still alive at the end was not
// stopped (the slowest case, SIGTERM then up to 5 s before SIGKILL, is well inside).
constexpr int kScriptSleepS = 60;
constexpr auto kStoppedWithin = std::chrono::seconds(20);

constexpr const char* kStandIn = R"(import os, signal, sys, time
signal.signal(signal.SIGINT, signal.SIG_DFL)  # as the project's plot scripts do
if os.environ.get("GFINS_TEST_PLOT_FAIL"):
    print("stand-in plot: failing on purpose", file=sys.stderr)
    sys.exit(1)
mark = os.environ["GFINS_TEST_PLOT_MARK"]
with open(mark + ".tmp", "w") as f:
    f.write(str(os.getpid()))
os.rename(mark + ".tmp", mark)
time.sleep(SLEEP)
open(mark + ".done", "w").close()
)";

class PlotInterruptCli : public test::CliTest {
 protected:
  void SetUp() override {
    scripts_ = dir() / "scripts";
    fs::create_directories(scripts_);
    std::string text = kStandIn;
    text.replace(text.find("SLEEP"), 5, std::to_string(kScriptSleepS));
    for (const char* name : {"plot_sim.py", "plot_covariance.py"}) {
      testing::write_text(scripts_ / name, text);
    }
    mark_ = dir() / "plot.pid";
    ASSERT_EQ(setenv("GFINS_SCRIPTS_DIR", scripts_.c_str(), 1), 0);
    ASSERT_EQ(setenv("GFINS_TEST_PLOT_MARK", mark_.c_str(), 1), 0);
    ASSERT_EQ(setenv("GFINS_PYTHON", "/usr/bin/python3", 1), 0);
    unsetenv("GFINS_TEST_PLOT_FAIL");
    scenario_ = file("short.toml",
                     "[scenario]\ndescription = \"rest, 2 s\"\nduration_s = 2.0\nrate_hz = 100.0\n"
                     "[trajectory]\nkind = \"rest\"\neuler_deg = [3.0, -2.0, 45.0]\n"
                     "[sensors]\norientation = \"paper_table6\"\nnoise_mg = 1.0\n"
                     "[compensator]\nkind = \"paper\"\n");
  }
  void TearDown() override {
    unsetenv("GFINS_SCRIPTS_DIR");
    unsetenv("GFINS_TEST_PLOT_MARK");
    unsetenv("GFINS_PYTHON");
    unsetenv("GFINS_TEST_PLOT_FAIL");
  }

  // Starts gfins-sim ARGS, waits (bounded) until the stand-in script runs; its pid, or -1.
  pid_t start_until_plotting(test::StartedTool& t, const std::vector<std::string>& args) {
    t = test::start_tool(GFINS_SIM_BIN, args, dir() / "log");
    if (t.child.pid <= 0) return -1;
    const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(120);
    while (std::chrono::steady_clock::now() < end) {
      const std::string pid = test::slurp(mark_);
      if (!pid.empty()) return static_cast<pid_t>(std::stol(pid));
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return -1;
  }

  // True once `pid` is gone (reaped by gfins-sim, which has exited).
  static bool gone(pid_t pid) { return kill(pid, 0) != 0 && errno == ESRCH; }

  // The common verdict: exit 130, the message, the stand-in stopped (not run to its end).
  void expect_interrupted_while_plotting(const CliResult& r, pid_t script,
                                         std::chrono::steady_clock::time_point signalled) {
    EXPECT_EQ(r.exit_code, kExitInterrupted) << r.output;
    EXPECT_NE(r.err.find("interrupted (signal 2) while plotting"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("the CSV files are written, the PNG figures are not"), std::string::npos)
        << r.err;
    EXPECT_EQ(r.err.find("matplotlib"), std::string::npos) << "not a failed plot: " << r.err;
    EXPECT_LT(std::chrono::steady_clock::now() - signalled, kStoppedWithin);
    EXPECT_TRUE(gone(script)) << "the plot script outlived gfins-sim";
    EXPECT_FALSE(fs::exists(mark_.string() + ".done")) << "the plot script ran to its end";
  }

  fs::path scripts_;
  fs::path mark_;
  std::string scenario_;
};

// SIGINT to gfins-sim alone (a `kill -INT`): passed on to the script, exit 130.
TEST_F(PlotInterruptCli, RunStoppedWhilePlottingSaysSoAndKeepsItsFiles) {
  const fs::path out = dir() / "run";
  test::StartedTool t;
  const pid_t script = start_until_plotting(t, {"run", scenario_, "-o", out.string()});
  ASSERT_GT(script, 0) << test::slurp(t.stderr_path());
  const auto signalled = std::chrono::steady_clock::now();
  ASSERT_TRUE(drivers::lnx::signal_program(t.child, SIGINT).is_ok());
  const CliResult r = test::finish_tool(t);
  expect_interrupted_while_plotting(r, script, signalled);
  for (const char* f : {"uncompensated.csv", "compensated.csv", "summary.txt"}) {
    EXPECT_GT(fs::file_size(out / f), 0u) << f;
  }
}

// The terminal's Ctrl-C: the script and gfins-sim both get SIGINT; the script dies by it. Before,
// `covariance` reported that as a failed plot (exit 3) and `montecarlo` died with the script.
TEST_F(PlotInterruptCli, GroupCtrlCWhilePlottingIsAnInterruptionNotAFailedPlot) {
  for (const char* cmd : {"covariance", "montecarlo"}) {
    SCOPED_TRACE(cmd);
    fs::remove(mark_);
    const fs::path out = dir() / cmd;
    std::vector<std::string> args = {cmd, scenario_, "-o", out.string()};
    if (std::string(cmd) == "montecarlo") args.insert(args.end(), {"--runs", "2"});
    test::StartedTool t;
    const pid_t script = start_until_plotting(t, args);
    ASSERT_GT(script, 0) << test::slurp(t.stderr_path());
    const auto signalled = std::chrono::steady_clock::now();
    ASSERT_EQ(kill(script, SIGINT), 0);
    ASSERT_TRUE(drivers::lnx::signal_program(t.child, SIGINT).is_ok());
    const CliResult r = test::finish_tool(t);
    expect_interrupted_while_plotting(r, script, signalled);
    EXPECT_TRUE(
        fs::exists(out / (std::string(cmd) == "covariance" ? "covariance.csv" : "montecarlo.csv")));
  }
}

// SIGINT to `covariance` alone: before, it was taken by its handler and ignored (exit 0 after the
// script's full run).
TEST_F(PlotInterruptCli, CovarianceAloneStopsItsPlotOnSigint) {
  const fs::path out = dir() / "cov";
  test::StartedTool t;
  const pid_t script = start_until_plotting(t, {"covariance", scenario_, "-o", out.string()});
  ASSERT_GT(script, 0) << test::slurp(t.stderr_path());
  const auto signalled = std::chrono::steady_clock::now();
  ASSERT_TRUE(drivers::lnx::signal_program(t.child, SIGINT).is_ok());
  expect_interrupted_while_plotting(test::finish_tool(t), script, signalled);
}

// The control: a plot that fails on its own is still exit 3 with the advice, not 130.
TEST_F(PlotInterruptCli, APlotThatFailsWithoutASignalIsStillAFailedPlot) {
  ASSERT_EQ(setenv("GFINS_TEST_PLOT_FAIL", "1", 1), 0);
  const CliResult r = run(GFINS_SIM_BIN, {"run", scenario_, "-o", path("failed")});
  EXPECT_EQ(r.exit_code, kExitPlotFailed) << r.output;
  EXPECT_NE(r.err.find("plotting failed: plot_sim.py ended with exit status 1"), std::string::npos)
      << r.err;
  EXPECT_EQ(r.err.find("interrupted"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace gfins::sim
