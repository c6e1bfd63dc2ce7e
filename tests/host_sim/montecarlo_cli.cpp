// gfins-sim montecarlo as a user meets it: the memory
// estimate printed before the work bounds the memory the run really takes, counts the threads,
// and is checked against the limit; progress lines reach a log; SIGINT stops cleanly.
//
// The tool is the real binary (GFINS_SIM_BIN), started without a shell. Oracles: the child's
// peak resident set as the kernel measured it (wait4's ru_maxrss), the exit codes of --help, and
// the files' own structure (a CSV row count, the slopes file's text).
#include <gtest/gtest.h>
#include <sys/resource.h>

#include <array>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "gfins/host_sim/montecarlo.hpp"
#include "gfins/host_sim/scenario.hpp"
#include "support/cli_fixture.hpp"
#include "support/csv.hpp"

namespace gfins::sim {
namespace {

namespace fs = std::filesystem;
using test::CliResult;

// Exit codes of gfins-sim (--help).
constexpr int kExitOk = 0;
constexpr int kExitBadInput = 2;
constexpr int kExitInterrupted = 130;

// The estimate is an upper bound of the peak: it adds every in-flight run at its own peak and
// every result that may wait. Measured (this test, Release): -j 1 1.19×, -j 2 1.25× the peak;
// the review's case (600 s, -n 2) -j 1 599 MB for 523 MB, -j 2 1.38 GB for 751 MB (before the
// waiting results were capped at the run count). Twice the peak is the most it may overshoot:
// beyond, runs that fit would be refused. The review's estimate (0.349 GiB for 511 MB measured)
// was 0.73× and fails the lower bound.
constexpr double kMaxOvershoot = 2.0;

std::string rest_scenario(double duration_s) {
  std::ostringstream s;
  s << "[scenario]\nduration_s = " << duration_s
    << "\nrate_hz = 1000.0\n[trajectory]\nkind = \"rest\"\n[sensors]\nnoise_mg = 1.0\n"
       "[compensator]\nkind = \"paper\"\n";
  return s.str();
}

/// The "memory about N MB" of the estimate line, in bytes; -1 when absent.
double printed_memory_bytes(const std::string& out) {
  std::smatch m;
  if (!std::regex_search(out, m,
                         std::regex("estimate: [0-9]+ samples x [0-9]+ runs, memory "
                                    "about ([0-9]+) MB, time about [0-9.e+]+ s"))) {
    return -1;
  }
  return std::stod(m[1].str()) * 1e6;
}

class MontecarloCli : public test::CliTest {};

TEST_F(MontecarloCli, MemoryEstimateBoundsTheMeasuredPeakForOneAndTwoThreads) {
  // 30 s at 1 kHz: 30,001 samples per run, tens of MB per run, about a second per run.
  const std::string toml = file("m30.toml", rest_scenario(30.0));
  const auto s = load_scenario(toml);
  ASSERT_TRUE(s.is_ok()) << s.error().message;
  for (const std::size_t jobs : {std::size_t{1}, std::size_t{2}}) {
    SCOPED_TRACE("-j " + std::to_string(jobs));
    const std::size_t runs = 2 * jobs;  // every thread runs twice: results wait their turn
    const CliResult r = run(
        GFINS_SIM_BIN, {"montecarlo", toml, "-n", std::to_string(runs), "-j", std::to_string(jobs),
                        "--no-plot", "-o", path("mc" + std::to_string(jobs))});
    ASSERT_EQ(r.exit_code, kExitOk) << r.output;
    // The estimate is printed before the work (before the results' first line).
    const double printed = printed_memory_bytes(r.output);
    ASSERT_GT(printed, 0) << r.output;
    EXPECT_LT(r.output.find("estimate: "), r.output.find("log-log slope")) << r.output;
    const double estimate = static_cast<double>(montecarlo_memory_bytes(s.value(), runs, jobs));
    EXPECT_NEAR(printed, estimate, 0.5e6) << "printed rounded to MB";
    const double peak = static_cast<double>(r.max_rss_kib) * 1024.0;
    EXPECT_GE(estimate, peak) << "estimate " << estimate / 1e6 << " MB, measured peak "
                              << peak / 1e6 << " MB";
    EXPECT_LE(estimate, kMaxOvershoot * peak)
        << "estimate " << estimate / 1e6 << " MB, measured peak " << peak / 1e6 << " MB";
    std::printf("-j %zu: estimate %.1f MB, measured peak %.1f MB (ratio %.2f)\n", jobs,
                estimate / 1e6, peak / 1e6, estimate / peak);
  }
}

TEST_F(MontecarloCli, TheLimitCountsTheThreads) {
  // Given a limit between the estimates of one and of two threads (the review: -j 2 took 707 MB
  // where one thread took 511 MB, and both were accepted under the same estimate),
  const std::string toml = file("m30.toml", rest_scenario(30.0));
  const auto s = load_scenario(toml);
  ASSERT_TRUE(s.is_ok()) << s.error().message;
  const std::uint64_t one = montecarlo_memory_bytes(s.value(), 4, 1);
  const std::uint64_t two = montecarlo_memory_bytes(s.value(), 4, 2);
  ASSERT_LT(one, two);
  ASSERT_EQ(setenv("GFINS_MAX_RUN_MEMORY_BYTES", std::to_string((one + two) / 2).c_str(), 1), 0);
  // when run with -j 2 it is refused before any work (no folder), naming -j 1 as the way out,
  const CliResult r2 =
      run(GFINS_SIM_BIN, {"montecarlo", toml, "-n", "4", "-j", "2", "--no-plot", "-o", path("j2")});
  EXPECT_EQ(r2.exit_code, kExitBadInput) << r2.output;
  EXPECT_NE(r2.err.find("-j 1 needs about"), std::string::npos) << r2.err;
  EXPECT_NE(r2.err.find("30001 samples per run"), std::string::npos) << r2.err;
  EXPECT_FALSE(fs::exists(dir() / "j2"));
  // and with -j 1 it runs.
  const CliResult r1 =
      run(GFINS_SIM_BIN, {"montecarlo", toml, "-n", "4", "-j", "1", "--no-plot", "-o", path("j1")});
  EXPECT_EQ(r1.exit_code, kExitOk) << r1.output;
  ASSERT_EQ(unsetenv("GFINS_MAX_RUN_MEMORY_BYTES"), 0);
}

TEST_F(MontecarloCli, UnderAnAddressSpaceLimitALargeRunIsRefusedNotEndedByBadAlloc) {
  // Given the review's case: 600 s at 1 kHz, 2 runs on 2 threads under `ulimit -v 600000` (KiB),
  // which ended in "gfins-sim: std::bad_alloc", exit 1, after the work had started. The child
  // inherits the test's soft limit (restored below; the test itself stays far under it).
  const std::string toml = file("m600.toml", rest_scenario(600.0));
  rlimit old{};
  ASSERT_EQ(getrlimit(RLIMIT_AS, &old), 0);
  rlimit lim = old;
  lim.rlim_cur = 600000ull * 1024ull;
  ASSERT_EQ(setrlimit(RLIMIT_AS, &lim), 0);
  const CliResult r =
      run(GFINS_SIM_BIN, {"montecarlo", toml, "-n", "2", "-j", "2", "--no-plot", "-o", path("as")});
  ASSERT_EQ(setrlimit(RLIMIT_AS, &old), 0);
  // then it is refused before any work, with the figures.
  EXPECT_EQ(r.exit_code, kExitBadInput) << r.output;
  EXPECT_NE(r.err.find("above the limit of"), std::string::npos) << r.err;
  EXPECT_EQ(r.output.find("bad_alloc"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir() / "as"));
}

TEST_F(MontecarloCli, ProgressReachesALogAndSigintKeepsTheFinishedRuns) {
  // Given a long Monte-Carlo (200 runs of 5 s) whose stderr is a file, with progress every 0.05 s,
  ASSERT_EQ(setenv("GFINS_PROGRESS_INTERVAL_S", "0.05", 1), 0);
  constexpr int kRuns = 200;
  const std::string toml = file("m5.toml", rest_scenario(5.0));
  const fs::path out = dir() / "cut";
  const fs::path log = dir() / "log";
  fs::create_directories(log);
  test::StartedTool t = test::start_tool(
      GFINS_SIM_BIN,
      {"montecarlo", toml, "-n", std::to_string(kRuns), "-j", "1", "--no-plot", "-o", out.string()},
      log);
  ASSERT_GT(t.child.pid, 0);
  // when a progress line says at least 2 runs are done (bounded wait), SIGINT is sent;
  const std::regex done("progress: montecarlo: [0-9]+ % \\(([0-9]+) of 200 runs\\)");
  const bool seen = test::wait_for_stderr(
      t,
      [&](const std::string& err) {
        for (std::sregex_iterator it(err.begin(), err.end(), done), end; it != end; ++it) {
          if (std::stoi((*it)[1].str()) >= 2) return true;
        }
        return false;
      },
      std::chrono::seconds(60));
  ASSERT_EQ(unsetenv("GFINS_PROGRESS_INTERVAL_S"), 0);
  EXPECT_TRUE(seen) << "no progress line with 2 runs done within 60 s";
  ASSERT_TRUE(drivers::lnx::signal_program(t.child, SIGINT).is_ok());
  const CliResult r = test::finish_tool(t);
  // then it exits 130 saying how many runs it kept,
  ASSERT_EQ(r.exit_code, kExitInterrupted) << r.output;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(r.err, m, std::regex("interrupted after ([0-9]+) of 200 runs")))
      << r.err;
  const int kept = std::stoi(m[1].str());
  EXPECT_GE(kept, 2);
  EXPECT_LT(kept, kRuns);
  // slopes.txt says the statistics are of those runs,
  const std::string slopes = test::slurp(out / "slopes.txt");
  EXPECT_NE(slopes.find("interrupted: statistics of the first " + std::to_string(kept) + " of " +
                        std::to_string(kRuns) + " runs"),
            std::string::npos)
      << slopes;
  // and montecarlo.csv is whole: a header and one row per sample (5 s at 1 kHz + the start),
  // each with the header's number of cells.
  const auto lines = test::lines_of(test::slurp(out / "montecarlo.csv"));
  ASSERT_EQ(lines.size(), 1u + 5001u);
  const std::size_t cells = test::cells_of(lines.front()).size();
  for (const auto& l : lines) ASSERT_EQ(test::cells_of(l).size(), cells) << l;
}

TEST_F(MontecarloCli, CovarianceShowsProgressInALogAndStopsBetweenPhasesOnSigint) {
  // Given covariance of 600 s of rest (its reference run holds 600,001 samples: seconds of work)
  // with progress every 0.05 s to a log,
  ASSERT_EQ(setenv("GFINS_PROGRESS_INTERVAL_S", "0.05", 1), 0);
  const std::string toml = file("c600.toml", rest_scenario(600.0));
  const fs::path out = dir() / "cov";
  const fs::path log = dir() / "log";
  fs::create_directories(log);
  test::StartedTool t =
      test::start_tool(GFINS_SIM_BIN, {"covariance", toml, "--no-plot", "-o", out.string()}, log);
  ASSERT_GT(t.child.pid, 0);
  // when SIGINT comes after the reference run's first progress line,
  const bool seen =
      test::wait_for_stderr(t, "progress: reference run: ", std::chrono::seconds(120));
  ASSERT_EQ(unsetenv("GFINS_PROGRESS_INTERVAL_S"), 0);
  EXPECT_TRUE(seen) << "no progress line within 120 s";
  ASSERT_TRUE(drivers::lnx::signal_program(t.child, SIGINT).is_ok());
  const CliResult r = test::finish_tool(t);
  // then exit 130 saying what was kept: the envelopes whole, no reference run.
  ASSERT_EQ(r.exit_code, kExitInterrupted) << r.output;
  EXPECT_NE(r.err.find("covariance.csv and budget.csv written, no reference run"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(out / "reference_run.csv"));
  for (const char* name : {"covariance.csv", "budget.csv"}) {
    const std::string text = test::slurp(out / name);
    ASSERT_FALSE(text.empty()) << name;
    EXPECT_EQ(text.back(), '\n') << name;
    const auto lines = test::lines_of(text);
    const std::size_t cells = test::cells_of(lines.front()).size();
    for (const auto& l : lines) ASSERT_EQ(test::cells_of(l).size(), cells) << name << ": " << l;
  }
}

// covariance prints the predicted σ at every budget time asked with --at (it printed the final
// time alone): one line per time, each the total of budget.csv at that time (|φ| the norm of the
// three components, in degrees; the print has 4 significant digits, so 1e-3 relative).
TEST_F(MontecarloCli, CovariancePrintsThePredictionAtEveryTimeAsked) {
  const CliResult r = run(GFINS_SIM_BIN, {"covariance", "rest-calibrated", "--at", "0.5", "--at",
                                          "1.5", "--no-plot", "-o", path("cov")});
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::map<double, double> total_phi_deg;  // budget.csv "total" rows: t -> |φ|
  std::istringstream budget(test::slurp(path("cov") + "/budget.csv"));
  for (std::string line; std::getline(budget, line);) {
    if (line.rfind("total,", 0) != 0) continue;
    std::istringstream cells(line.substr(6));
    std::array<double, 4> v{};  // t, φx, φy, φz
    char comma = 0;
    cells >> v[0] >> comma >> v[1] >> comma >> v[2] >> comma >> v[3];
    total_phi_deg[v[0]] = std::sqrt(v[1] * v[1] + v[2] * v[2] + v[3] * v[3]) * 180.0 / M_PI;
  }
  ASSERT_EQ(total_phi_deg.size(), 2U) << test::slurp(path("cov") + "/budget.csv");
  const std::regex line_re(R"(  t = ([0-9.e+-]+) s: \|phi\| ([0-9.e+-]+) deg)");
  std::vector<std::pair<double, double>> printed;
  for (auto it = std::sregex_iterator(r.output.begin(), r.output.end(), line_re);
       it != std::sregex_iterator(); ++it) {
    printed.emplace_back(std::stod((*it)[1]), std::stod((*it)[2]));
  }
  ASSERT_EQ(printed.size(), 2U) << r.output;
  EXPECT_EQ(printed[0].first, 0.5);
  EXPECT_EQ(printed[1].first, 1.5);
  for (const auto& [t, phi] : printed) {
    EXPECT_NEAR(phi, total_phi_deg[t], 1e-3 * total_phi_deg[t]) << "t = " << t;
  }
}

}  // namespace
}  // namespace gfins::sim
