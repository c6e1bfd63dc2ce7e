// gfins-sim with hostile output folder names ("a security defect first"): the plot
// script is started without a shell, so a folder name is never parsed. Each name is passed as
// given; the oracle is the file system: after the run the working directory holds exactly one
// entry, the folder with the exact bytes of the name, and in it exactly the files `run` writes
// (docs/simulation.md): nothing a shell would have made (PWNED*), nothing else.
//
// Runs the real binaries (GFINS_SIM_BIN, GFINS_REPLAY_BIN) and the real plot scripts, so it needs
// python3-matplotlib (scripts/install-deps.sh); each run is a tiny scenario (0.05 s at 100 Hz).
#include <gtest/gtest.h>

#include <chrono>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "gfins/drivers/lnx/spawn.hpp"
#include "support/cli_fixture.hpp"

namespace gfins::sim {
namespace {

namespace fs = std::filesystem;
namespace lnx = gfins::drivers::lnx;

constexpr const char* kTinyScenario = R"([scenario]
description = "tiny run for the hostile-folder test"
duration_s = 0.05
rate_hz = 100.0
[trajectory]
kind = "rest"
[compensator]
kind = "exact"
)";

// What `gfins-sim run` writes into its output folder (cmd_run.cpp, plot_sim.py run).
const std::set<std::string> kRunFiles = {"summary.txt", "uncompensated.csv", "compensated.csv",
                                         "accel_errors.png", "nav_errors.png"};

// Exit codes of gfins-sim (docs/install.md).
constexpr int kExitOk = 0;
constexpr int kExitPlotFailed = 3;

class HostileOutDir : public test::CliTest {
 protected:
  void SetUp() override {
    fs::create_directories(dir() / "input");
    scenario_ = file("input/tiny.toml", kTinyScenario);
  }

  /// Runs gfins-sim run <tiny> --out=<name> in a fresh folder `work` (its output in dir()).
  test::CliResult run_in(const fs::path& work, const std::string& out_name) const {
    fs::create_directories(work);
    return run(GFINS_SIM_BIN, {"run", scenario_, "--out=" + out_name}, work);
  }

  std::string scenario_;
};

std::set<std::string> names_in(const fs::path& dir) {
  std::set<std::string> out;
  for (const auto& e : fs::directory_iterator(dir)) out.insert(e.path().filename().string());
  return out;
}

TEST_F(HostileOutDir, EveryNameIsAFolderOfThatNameAndNothingElseAppears) {
  const std::vector<std::string> hostile = {
      "q'; touch PWNED; '",  // the reported case: closes the quote, runs touch
      "a\"b\"c",             // double quotes
      "x; touch PWNED2",     // command separator
      "$(touch PWNED3)",     // command substitution
      "`touch PWNED4`",      // backquotes
      "with  two spaces",    // word splitting
      "new\nline",           // a newline ends a shell command
      "-leading-dash",       // an option to python or the script
      "glob*?[x]",           // pathname expansion
  };
  int i = 0;
  for (const std::string& name : hostile) {
    SCOPED_TRACE("folder name: " + name);
    // Given a fresh working folder, when gfins-sim runs with --out=<name>,
    const fs::path work = dir() / ("case" + std::to_string(i++));
    const test::CliResult r = run_in(work, name);
    // then it succeeds (the plot too),
    EXPECT_EQ(r.exit_code, kExitOk) << r.output;
    // the working folder holds exactly the output folder, named byte for byte,
    EXPECT_EQ(names_in(work), std::set<std::string>{name});
    // and the output folder exactly the files of a run: no PWNED, no stray file.
    if (fs::is_directory(work / name)) {
      EXPECT_EQ(names_in(work / name), kRunFiles);
    }
  }
  // Nothing was created next to the inputs either.
  EXPECT_EQ(names_in(dir() / "input"), std::set<std::string>{"tiny.toml"});
}

/// Every entry under `dir`, recursively, whose name starts with "PWNED" (what the hostile names
/// would have made through a shell).
std::vector<std::string> pwned_under(const fs::path& dir) {
  std::vector<std::string> out;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    if (e.path().filename().string().rfind("PWNED", 0) == 0) out.push_back(e.path().string());
  }
  return out;
}

TEST_F(HostileOutDir, EveryOtherCommandThatPlotsOrWritesTakesTheNameAsItIs) {
  // The names that break a shell command line in the most ways (quote, substitution, newline,
  // leading dash), through each other command that starts a plot script or writes a file named by
  // the user: montecarlo, covariance, paper63 (one name: 16 figures), gfins-replay, --record.
  const std::vector<std::string> hostile = {"q'; touch PWNED; '", "$(touch PWNED3)", "new\nline",
                                            "-leading-dash"};
  const std::string gfr = (dir() / "input" / "tiny.gfr").string();
  const test::CliResult rec = run(GFINS_SIM_BIN, {"run", scenario_, "--record=" + gfr, "--no-plot",
                                                  "--out=" + (dir() / "input" / "rec").string()});
  ASSERT_EQ(rec.exit_code, kExitOk) << rec.output;
  struct Command {
    const char* what;
    std::vector<std::string> args;  // the name is appended as --out=NAME
    bool all_names;
  };
  const std::vector<Command> commands = {
      {"montecarlo", {"montecarlo", scenario_, "-n", "2"}, true},
      {"covariance", {"covariance", scenario_}, true},
      {"paper63", {"paper63"}, false},
  };
  int i = 0;
  for (const Command& c : commands) {
    for (const std::string& name : hostile) {
      if (!c.all_names && name != hostile.front()) continue;
      SCOPED_TRACE(std::string(c.what) + ", folder name: " + name);
      const fs::path work = dir() / ("other" + std::to_string(i++));
      fs::create_directories(work);
      std::vector<std::string> args = c.args;
      args.push_back("--out=" + name);
      const test::CliResult r = run(GFINS_SIM_BIN, args, work);
      EXPECT_EQ(r.exit_code, kExitOk) << r.output;
      EXPECT_EQ(names_in(work), std::set<std::string>{name});
      EXPECT_TRUE(pwned_under(work).empty());
    }
  }
  for (const std::string& name : hostile) {
    SCOPED_TRACE("gfins-replay, folder name: " + name);
    const fs::path work = dir() / ("replay" + std::to_string(i++));
    fs::create_directories(work);
    const test::CliResult r = run(GFINS_REPLAY_BIN, {gfr, "--align-s=0.01", "--out=" + name}, work);
    EXPECT_EQ(r.exit_code, kExitOk) << r.output;
    EXPECT_EQ(names_in(work), std::set<std::string>{name});
    if (fs::is_directory(work / name)) {
      EXPECT_EQ(names_in(work / name),
                (std::set<std::string>{"navigation.csv", "summary.txt", "replay.png"}));
    }
    EXPECT_TRUE(pwned_under(work).empty());
  }
  for (const std::string& name : hostile) {
    SCOPED_TRACE("--record name: " + name);
    const fs::path work = dir() / ("record" + std::to_string(i++));
    fs::create_directories(work);
    const test::CliResult r =
        run(GFINS_SIM_BIN, {"run", scenario_, "--record=" + name + ".gfr", "--out=o", "--no-plot"},
            work);
    EXPECT_EQ(r.exit_code, kExitOk) << r.output;
    EXPECT_EQ(names_in(work), (std::set<std::string>{name + ".gfr", "o"}));
    EXPECT_TRUE(pwned_under(work).empty());
  }
  EXPECT_EQ(names_in(dir() / "input"), (std::set<std::string>{"tiny.toml", "tiny.gfr", "rec"}));
}

TEST_F(HostileOutDir, MissingMatplotlibIsAClearErrorAndExitCode3WithTheCsvWritten) {
  // Given an interpreter without matplotlib: Debian's python3 with site-packages disabled (-S),
  // behind a wrapper that passes its arguments on unchanged ("$@", no interpolation).
  const std::string wrapper =
      file("python-without-site", "#!/bin/sh\nexec /usr/bin/python3 -S \"$@\"\n");
  fs::permissions(wrapper, fs::perms::owner_all);
  ASSERT_EQ(setenv("GFINS_PYTHON", wrapper.c_str(), 1), 0);
  const test::CliResult r = run_in(dir() / "nomatplotlib", "out");
  ASSERT_EQ(unsetenv("GFINS_PYTHON"), 0);
  // then gfins-sim exits 3 (kExitPlotFailed) with a message naming the cause,
  EXPECT_EQ(r.exit_code, kExitPlotFailed) << r.output;
  const std::string& err = r.err;
  EXPECT_NE(err.find("cannot plot"), std::string::npos) << err;
  EXPECT_NE(err.find("matplotlib"), std::string::npos) << err;
  EXPECT_NE(err.find("plotting failed"), std::string::npos) << err;
  // and the CSV files are there.
  EXPECT_TRUE(fs::exists(dir() / "nomatplotlib" / "out" / "compensated.csv"));
}

TEST(Spawn, ArgumentsReachTheChildByteForByte) {
  // printf '%s' prints its argument verbatim: the oracle is the argument itself.
  const std::string arg = "a'b\"c $(x) `y` ; z\n-w";
  const testing::TempDir tmp;
  const fs::path out = tmp.path() / "printf.out";
  lnx::SpawnOptions opts;
  opts.stdout_path = out.string();
  const auto r = lnx::run_program(std::vector<std::string>{"printf", "%s", arg}, opts);
  ASSERT_TRUE(r.is_ok());
  EXPECT_TRUE(r.value().ok());
  EXPECT_EQ(testing::read_text(out), arg);
}

TEST(Spawn, AProgramThatCannotStartAndOneThatFailsAreTold) {
  const auto missing = lnx::run_program(std::vector<std::string>{"/nonexistent/gfins-no-such"});
  ASSERT_FALSE(missing.is_ok());
  EXPECT_EQ(missing.status().code(), ErrorCode::kUnavailable);
  EXPECT_NE(missing.status().os_error(), 0);
  const auto failed = lnx::run_program(std::vector<std::string>{"false"});
  ASSERT_TRUE(failed.is_ok());
  EXPECT_TRUE(failed.value().exited);
  EXPECT_EQ(failed.value().code, 1);
  EXPECT_FALSE(failed.value().ok());
  const auto nul = lnx::run_program(std::vector<std::string>{"true", std::string("a\0b", 3)});
  EXPECT_EQ(nul.status().code(), ErrorCode::kInvalidArgument);
}

// poll_program: nothing while the child runs, its exit once it ended (reaped: a second poll has
// no child); a signal's end is told as such.
TEST(Spawn, PollingAChildTellsRunningFromEnded) {
  auto started = lnx::start_program(std::vector<std::string>{"sleep", "30"});
  ASSERT_TRUE(started.is_ok());
  lnx::ChildProcess child = started.value();
  const auto running = lnx::poll_program(child);
  ASSERT_TRUE(running.is_ok());
  EXPECT_FALSE(running.value().has_value()) << "sleep 30 ended at once";
  ASSERT_TRUE(lnx::signal_program(child, SIGTERM).is_ok());
  std::optional<lnx::ProcessExit> ended;
  for (int i = 0; i < 1000 && !ended; ++i) {  // up to 10 s
    const auto p = lnx::poll_program(child);
    ASSERT_TRUE(p.is_ok());
    ended = p.value();
    if (!ended) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ASSERT_TRUE(ended.has_value());
  EXPECT_FALSE(ended->exited);
  EXPECT_EQ(ended->signal, SIGTERM);
  EXPECT_EQ(child.pid, -1);
  EXPECT_EQ(lnx::poll_program(child).status().code(), ErrorCode::kInvalidArgument);
}

}  // namespace
}  // namespace gfins::sim
