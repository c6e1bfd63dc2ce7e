// gfins-sim montecarlo / covariance --jobs N (issue 13, "Scale"): the files written do not depend
// on the thread count. The oracle is the output of --jobs 1, compared byte for byte with --jobs
// 2 and --jobs 7 (more threads than cores and than runs per thread). Runs the real binary
// (GFINS_SIM_BIN) on small scenarios: 12 Monte-Carlo runs of 1 s at 100 Hz, a 0.3 s covariance
// at 100 Hz with every error source (about 1.5 s each under ASan).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

#include "gfins/drivers/linux/spawn.hpp"

namespace gfins::sim {
namespace {

namespace fs = std::filesystem;
namespace lnx = gfins::drivers::lnx;

// Calibrated compensator: every run draws its own sensor noise and its own calibration error.
constexpr const char* kMonteCarloScenario = R"([scenario]
description = "small Monte-Carlo for the --jobs test"
duration_s = 1.0
rate_hz = 100.0
[trajectory]
kind = "maneuver"
[sensors]
orientation = "paper_table6"
noise_mg = 1.0
[compensator]
kind = "exact"
misalignment = "calibrated"
[calibration]
mean_noise_g = 1e-3
)";

constexpr const char* kCovarianceScenario = R"([scenario]
description = "small covariance for the --jobs test"
duration_s = 0.3
rate_hz = 100.0
[trajectory]
kind = "maneuver"
[sensors]
noise_mg = 1.0
[compensator]
kind = "exact"
)";

class JobsCli : public ::testing::Test {
 protected:
  void SetUp() override {
    std::random_device rd;
    root_ = fs::temp_directory_path() / ("gfins_jobs_" + std::to_string(rd()));
    fs::create_directories(root_);
    std::ofstream(root_ / "mc.toml") << kMonteCarloScenario;
    std::ofstream(root_ / "cov.toml") << kCovarianceScenario;
  }
  void TearDown() override { fs::remove_all(root_); }

  /// gfins-sim <args...> --no-plot; returns the exit and leaves stderr in root_/stderr.txt.
  lnx::ProcessExit run(std::vector<std::string> args) {
    args.insert(args.begin(), GFINS_SIM_BIN);
    args.emplace_back("--no-plot");
    lnx::SpawnOptions opts;
    opts.stdout_path = (root_ / "stdout.txt").string();
    opts.stderr_path = (root_ / "stderr.txt").string();
    const auto r = lnx::run_program(args, opts);
    EXPECT_TRUE(r.is_ok()) << r.status().message();
    return r.is_ok() ? r.value() : lnx::ProcessExit{};
  }

  static std::string bytes(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    EXPECT_TRUE(in.good()) << "cannot read " << p;
    return std::string(std::istreambuf_iterator<char>(in), {});
  }

  /// Runs `args` with -o <dir_j> --jobs j for j = 1, 2, 7; expects each of `files` identical.
  void expect_same_files(const std::vector<std::string>& args,
                         const std::vector<std::string>& files) {
    std::vector<std::string> reference;
    for (const int jobs : {1, 2, 7}) {
      SCOPED_TRACE("--jobs " + std::to_string(jobs));
      const fs::path out = root_ / ("out" + std::to_string(jobs));
      std::vector<std::string> a = args;
      a.insert(a.end(), {"-o", out.string(), "--jobs", std::to_string(jobs)});
      const lnx::ProcessExit e = run(a);
      ASSERT_TRUE(e.ok()) << lnx::describe(e) << "\n" << bytes(root_ / "stderr.txt");
      for (std::size_t i = 0; i < files.size(); ++i) {
        const std::string b = bytes(out / files[i]);
        if (jobs == 1) {
          EXPECT_GT(b.size(), 100u) << files[i];  // written, not empty
          reference.push_back(b);
        } else {
          EXPECT_TRUE(b == reference[i]) << files[i] << " differs from --jobs 1";
        }
      }
    }
  }

  fs::path root_;
};

TEST_F(JobsCli, MonteCarloFilesAreByteIdenticalForOneTwoAndSevenThreads) {
  expect_same_files({"montecarlo", (root_ / "mc.toml").string(), "-n", "12", "--seed0", "5"},
                    {"montecarlo.csv", "slopes.txt"});
}

TEST_F(JobsCli, CovarianceFilesAreByteIdenticalForOneTwoAndSevenThreads) {
  expect_same_files({"covariance", (root_ / "cov.toml").string(), "--bias-ug", "10", "--bias-rw",
                     "5", "--scale-ppm", "100", "--orientation-urad", "50", "--location-mm", "0.1"},
                    {"covariance.csv", "budget.csv"});
}

TEST_F(JobsCli, ZeroJobsIsRejectedAsABadCommandLine) {
  const lnx::ProcessExit e =
      run({"montecarlo", (root_ / "mc.toml").string(), "-o", (root_ / "x").string(), "-j", "0"});
  EXPECT_TRUE(e.exited);
  EXPECT_EQ(e.code, 2) << bytes(root_ / "stderr.txt");  // kExitBadInput
  EXPECT_NE(bytes(root_ / "stderr.txt").find("jobs"), std::string::npos);
}

}  // namespace
}  // namespace gfins::sim
