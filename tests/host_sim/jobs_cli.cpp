// gfins-sim montecarlo / covariance --jobs N ("Scale"): the files written do not depend
// on the thread count. The oracle is the output of --jobs 1, compared byte for byte with --jobs
// 2 and --jobs 7 (more threads than cores and than runs per thread). Runs the real binary
// (GFINS_SIM_BIN) on small scenarios: 12 Monte-Carlo runs of 1 s at 100 Hz, a 0.3 s covariance
// at 100 Hz with every error source (about 1.5 s each under ASan).
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "support/cli_fixture.hpp"

namespace gfins::sim {
namespace {

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

// Exit code of gfins-sim for a rejected command line (docs/install.md).
constexpr int kExitBadInput = 2;

class JobsCli : public test::CliTest {
 protected:
  void SetUp() override {
    file("mc.toml", kMonteCarloScenario);
    file("cov.toml", kCovarianceScenario);
  }

  /// gfins-sim <args...> --no-plot.
  test::CliResult sim(std::vector<std::string> args) const {
    args.emplace_back("--no-plot");
    return run(GFINS_SIM_BIN, args);
  }

  /// Runs `args` with -o <dir_j> --jobs j for j = 1, 2, 7; expects each of `files` identical.
  void expect_same_files(const std::vector<std::string>& args,
                         const std::vector<std::string>& files) const {
    std::vector<std::string> reference;
    for (const int jobs : {1, 2, 7}) {
      SCOPED_TRACE("--jobs " + std::to_string(jobs));
      const std::string out = path("out" + std::to_string(jobs));
      std::vector<std::string> a = args;
      a.insert(a.end(), {"-o", out, "--jobs", std::to_string(jobs)});
      const test::CliResult r = sim(a);
      ASSERT_EQ(r.exit_code, 0) << r.output;
      for (std::size_t i = 0; i < files.size(); ++i) {
        const std::string b = test::slurp(out + "/" + files[i]);
        if (jobs == 1) {
          EXPECT_GT(b.size(), 100u) << files[i];  // written, not empty
          reference.push_back(b);
        } else {
          EXPECT_TRUE(b == reference[i]) << files[i] << " differs from --jobs 1";
        }
      }
    }
  }
};

TEST_F(JobsCli, MonteCarloFilesAreByteIdenticalForOneTwoAndSevenThreads) {
  expect_same_files({"montecarlo", path("mc.toml"), "-n", "12", "--seed0", "5"},
                    {"montecarlo.csv", "slopes.txt"});
}

TEST_F(JobsCli, CovarianceFilesAreByteIdenticalForOneTwoAndSevenThreads) {
  expect_same_files({"covariance", path("cov.toml"), "--bias-ug", "10", "--bias-rw", "5",
                     "--scale-ppm", "100", "--orientation-urad", "50", "--location-mm", "0.1"},
                    {"covariance.csv", "budget.csv"});
}

TEST_F(JobsCli, ZeroJobsIsRejectedAsABadCommandLine) {
  const test::CliResult r = sim({"montecarlo", path("mc.toml"), "-o", path("x"), "-j", "0"});
  EXPECT_EQ(r.exit_code, kExitBadInput) << r.output;
  EXPECT_NE(r.err.find("jobs"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace gfins::sim
