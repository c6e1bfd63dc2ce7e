// gfins-sim with hostile output folder names (issue 10, "a security defect first"): the plot
// script is started without a shell, so a folder name is never parsed. Each name is passed as
// given; the oracle is the file system: after the run the working directory holds exactly one
// entry, the folder with the exact bytes of the name, and in it exactly the files `run` writes
// (docs/simulation.md): nothing a shell would have made (PWNED*), nothing else.
//
// Runs the real binary (GFINS_SIM_BIN) and the real plot script, so it needs python3-matplotlib
// (scripts/install-deps.sh); each run is a tiny scenario (0.05 s at 100 Hz).
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "gfins/drivers/linux/spawn.hpp"

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

class HostileOutDir : public ::testing::Test {
 protected:
  void SetUp() override {
    std::random_device rd;
    root_ = fs::temp_directory_path() / ("gfins_hostile_" + std::to_string(rd()));
    fs::create_directories(root_ / "input");
    scenario_ = (root_ / "input" / "tiny.toml").string();
    std::ofstream(scenario_) << kTinyScenario;
  }
  void TearDown() override { fs::remove_all(root_); }

  /// Runs gfins-sim run <tiny> --out=<name> in a fresh folder; returns the exit.
  lnx::ProcessExit run_in(const fs::path& work, const std::string& out_name) {
    fs::create_directories(work);
    const std::vector<std::string> argv = {GFINS_SIM_BIN, "run", scenario_, "--out=" + out_name};
    lnx::SpawnOptions opts;
    opts.cwd = work.string();
    opts.stdout_path = (root_ / "input" / "stdout.txt").string();
    opts.stderr_path = (root_ / "input" / "stderr.txt").string();
    const auto r = lnx::run_program(argv, opts);
    EXPECT_TRUE(r.is_ok()) << r.status().message();
    return r.is_ok() ? r.value() : lnx::ProcessExit{};
  }

  std::string text(const char* file) const {
    std::ifstream in(root_ / "input" / file);
    return std::string(std::istreambuf_iterator<char>(in), {});
  }

  fs::path root_;
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
    const fs::path work = root_ / ("case" + std::to_string(i++));
    const lnx::ProcessExit e = run_in(work, name);
    // then it succeeds (the plot too),
    EXPECT_TRUE(e.ok()) << lnx::describe(e) << "\n" << text("stderr.txt");
    // the working folder holds exactly the output folder, named byte for byte,
    EXPECT_EQ(names_in(work), std::set<std::string>{name});
    // and the output folder exactly the files of a run: no PWNED, no stray file.
    if (fs::is_directory(work / name)) {
      EXPECT_EQ(names_in(work / name), kRunFiles);
    }
  }
  // Nothing was created next to the inputs either.
  EXPECT_EQ(names_in(root_ / "input"),
            (std::set<std::string>{"tiny.toml", "stdout.txt", "stderr.txt"}));
}

TEST_F(HostileOutDir, MissingMatplotlibIsAClearErrorAndExitCode3WithTheCsvWritten) {
  // Given an interpreter without matplotlib: Debian's python3 with site-packages disabled (-S),
  // behind a wrapper that passes its arguments on unchanged ("$@", no interpolation).
  const fs::path wrapper = root_ / "input" / "python-without-site";
  std::ofstream(wrapper) << "#!/bin/sh\nexec /usr/bin/python3 -S \"$@\"\n";
  fs::permissions(wrapper, fs::perms::owner_all);
  ASSERT_EQ(setenv("GFINS_PYTHON", wrapper.c_str(), 1), 0);
  const lnx::ProcessExit e = run_in(root_ / "nomatplotlib", "out");
  ASSERT_EQ(unsetenv("GFINS_PYTHON"), 0);
  // then gfins-sim exits 3 (kExitPlotFailed) with a message naming the cause,
  EXPECT_TRUE(e.exited);
  EXPECT_EQ(e.code, 3);
  const std::string err = text("stderr.txt");
  EXPECT_NE(err.find("cannot plot"), std::string::npos) << err;
  EXPECT_NE(err.find("matplotlib"), std::string::npos) << err;
  EXPECT_NE(err.find("plotting failed"), std::string::npos) << err;
  // and the CSV files are there.
  EXPECT_TRUE(fs::exists(root_ / "nomatplotlib" / "out" / "compensated.csv"));
}

TEST(Spawn, ArgumentsReachTheChildByteForByte) {
  // printf '%s' prints its argument verbatim: the oracle is the argument itself.
  const std::string arg = "a'b\"c $(x) `y` ; z\n-w";
  const fs::path out = fs::temp_directory_path() / "gfins_spawn_arg.txt";
  lnx::SpawnOptions opts;
  opts.stdout_path = out.string();
  const auto r = lnx::run_program(std::vector<std::string>{"printf", "%s", arg}, opts);
  ASSERT_TRUE(r.is_ok());
  EXPECT_TRUE(r.value().ok());
  std::ifstream in(out);
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(in), {}), arg);
  fs::remove(out);
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

}  // namespace
}  // namespace gfins::sim
