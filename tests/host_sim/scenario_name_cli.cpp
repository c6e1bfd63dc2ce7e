// gfins-sim as a user meets the scenario names: after `run NAME -o NAME` a folder NAME
// sits in the current folder, and `montecarlo NAME` must still run the built-in (the case
// is `drive`; the built-in `paper-6.3` is used here, the same rule for a 0.02 s run, cheap under
// ASan and qemu); an unknown name suggests the closest and `gfins-sim list`; `./NAME` is the
// folder, not the scenario. The oracle: the exit codes of docs/install.md and the files written.
//
// Runs the real binary of the build tree (GFINS_SIM_BIN), which finds its scenarios through the
// build folder's share/gfins link (data_paths.hpp).
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "support/cli_fixture.hpp"

namespace gfins::sim {
namespace {

namespace fs = std::filesystem;

// Exit codes of gfins-sim (docs/install.md, host_sim/app/common.hpp).
constexpr int kExitOk = 0;
constexpr int kExitBadInput = 2;

class ScenarioNameCli : public test::CliTest {
 protected:
  // gfins-sim ARGS run in dir() (the current folder of the child).
  test::CliResult sim(const std::vector<std::string>& args) const {
    return run(GFINS_SIM_BIN, args, dir());
  }
};

TEST_F(ScenarioNameCli, AFolderNamedLikeABuiltInDoesNotShadowIt) {
  // Given the folder left by `run paper-6.3 -o paper-6.3`.
  const auto run = sim({"run", "paper-6.3", "-o", "paper-6.3", "--no-plot"});
  ASSERT_EQ(run.exit_code, kExitOk) << run.output;
  ASSERT_TRUE(fs::is_regular_file(dir() / "paper-6.3/compensated.csv"));
  // When the name is used again, then it is the built-in scenario.
  const auto mc = sim({"montecarlo", "paper-6.3", "-n", "2", "-o", "mc", "--no-plot"});
  EXPECT_EQ(mc.exit_code, kExitOk) << mc.output;
  EXPECT_TRUE(fs::is_regular_file(dir() / "mc/montecarlo.csv")) << mc.output;
  // And the path spelling is the folder, which is no scenario file.
  const auto path = sim({"run", "./paper-6.3", "--no-plot"});
  EXPECT_EQ(path.exit_code, kExitBadInput) << path.output;
  EXPECT_NE(path.output.find("./paper-6.3: is a folder"), std::string::npos) << path.output;
}

TEST_F(ScenarioNameCli, AnUnknownNameSuggestsTheClosestAndList) {
  const auto r = sim({"run", "rest-calib", "--no-plot"});
  EXPECT_EQ(r.exit_code, kExitBadInput) << r.output;
  EXPECT_NE(r.output.find("closest: rest-calibrated, rest"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("gfins-sim list"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir() / "sim-out")) << "nothing is written for a rejected name";
}

TEST_F(ScenarioNameCli, AScenarioNameCannotPutOutputOutsideTheCurrentFolder) {
  // Given the review's file, whose name climbs three folders, run from dir()/a/b/c,
  const fs::path work = dir() / "a" / "b" / "c";
  fs::create_directories(work);
  testing::write_text(work / "t.toml",
                      "[scenario]\nname = \"../../../escaped\"\nduration_s = 0.1\n"
                      "rate_hz = 100\n[trajectory]\nkind = \"rest\"\n");
  for (const char* cmd : {"run", "montecarlo", "covariance"}) {
    SCOPED_TRACE(cmd);
    // when run (without -o, so the default folder sim-out/<name> applies),
    const auto r = run(GFINS_SIM_BIN, {cmd, "./t.toml", "--no-plot"}, work);
    // then it is refused before any work, naming the key and what is allowed,
    EXPECT_EQ(r.exit_code, kExitBadInput) << r.output;
    EXPECT_NE(r.err.find("scenario.name"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("letters, digits"), std::string::npos) << r.err;
    // and nothing is written anywhere: not where the name points, not in the current folder.
    EXPECT_FALSE(fs::exists(dir() / "escaped"));
    EXPECT_FALSE(fs::exists(work / "sim-out"));
  }
}

TEST_F(ScenarioNameCli, ARunShorterThanTwoSamplesIsRefused) {
  // The review's cases: half a sample period in a file (was run to t = 1 s) and on the command
  // line of the default command; floor(0.5 × 1) + 1 = 1 sample.
  testing::write_text(dir() / "s2.toml",
                      "[scenario]\nduration_s = 0.5\nrate_hz = 1\n[trajectory]\nkind = \"rest\"\n");
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"run", "./s2.toml", "-o", "s2", "--no-plot"},
        std::vector<std::string>{"montecarlo", "./s2.toml", "-o", "s2", "--no-plot"},
        std::vector<std::string>{"covariance", "./s2.toml", "-o", "s2", "--no-plot"},
        std::vector<std::string>{"-d", "0.5", "-r", "1"}}) {
    SCOPED_TRACE(args[0]);
    const auto r = sim(args);
    EXPECT_EQ(r.exit_code, kExitBadInput) << r.output;
    EXPECT_NE(r.err.find("at least 2 samples"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir() / "s2"));
  }
}

}  // namespace
}  // namespace gfins::sim
