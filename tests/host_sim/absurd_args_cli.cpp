// Numbers on the command lines of gfins-sim and gfins-replay that are not numbers (NaN, inf) or
// are absurd (1e300 µg of bias, a 1e308 s alignment) are refused at the command line, naming the
// option, before any work: they used to reach the arithmetic and end in NaN results with exit 0.
// The tools are the real binaries, started without a shell; the oracle is the documented exit
// code 2 (bad input) and the option's name in the message.
#include <gtest/gtest.h>

#include <string>
#include <utility>
#include <vector>

#include "support/cli_fixture.hpp"

namespace gfins::sim {
namespace {

using test::CliResult;

constexpr int kExitBadInput = 2;        // gfins-sim and gfins-replay --help
constexpr int kCalibrateExitInput = 1;  // gfins-calibrate --help: input rejected

struct Case {
  const char* exe;
  std::vector<std::string> args;
  const char* option;
};

class AbsurdArgsCli : public test::CliTest {};

TEST_F(AbsurdArgsCli, NonFiniteAndAbsurdNumbersAreRefusedNamingTheOption) {
  const std::string gfr = path("none.gfr");  // never read: the command line fails first
  const std::vector<Case> cases = {
      {GFINS_REPLAY_BIN, {gfr, "--heading-deg", "nan"}, "--heading-deg"},
      {GFINS_REPLAY_BIN, {gfr, "--heading-deg", "inf"}, "--heading-deg"},
      {GFINS_REPLAY_BIN, {gfr, "--gravity", "nan"}, "--gravity"},
      {GFINS_REPLAY_BIN, {gfr, "--align-s", "1e308"}, "--align-s"},
      {GFINS_REPLAY_BIN, {gfr, "--align-s", "nan"}, "--align-s"},
      {GFINS_SIM_BIN, {"covariance", "rest", "--bias-ug", "1e300"}, "--bias-ug"},
      {GFINS_SIM_BIN, {"covariance", "rest", "--bias-ug", "nan"}, "--bias-ug"},
      {GFINS_SIM_BIN, {"covariance", "rest", "--bias-rw", "inf"}, "--bias-rw"},
      {GFINS_SIM_BIN, {"covariance", "rest", "--scale-ppm", "1e300"}, "--scale-ppm"},
      {GFINS_SIM_BIN, {"covariance", "rest", "--orientation-urad", "nan"}, "--orientation-urad"},
      {GFINS_SIM_BIN, {"covariance", "rest", "--location-mm", "1e300"}, "--location-mm"},
      {GFINS_SIM_BIN, {"--duration", "nan"}, "--duration"},
      {GFINS_SIM_BIN, {"--noise-mg", "inf"}, "--noise-mg"},
  };
  for (const Case& c : cases) {
    const CliResult r = run(c.exe, c.args);
    const std::string what = std::string(c.exe) + " " + c.args.back();
    EXPECT_EQ(r.exit_code, kExitBadInput) << what << "\n" << r.output;
    EXPECT_NE(r.output.find(c.option), std::string::npos) << what << "\n" << r.output;
    EXPECT_EQ(r.output.find("nan\n"), std::string::npos) << what << "\n" << r.output;
  }
}

// gfins-calibrate: NaN used to stand for "no --latitude given", so --latitude nan was taken as
// absent and the run asked for the gravity it had just been given; a NaN nominal scale factor was
// taken. Both are refused naming the value (exit 1, gfins-calibrate --help).
TEST_F(AbsurdArgsCli, CalibrateRefusesANaNItUsedToTakeForAbsent) {
  const std::vector<std::string> base = {
      "--means", GFINS_GOLDEN_MEANS, "--adc-lsb", "1e-6", "--device-id", "b1", "--dry-run"};
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
      {{"--latitude", "nan"}, "--latitude nan: the geodetic latitude must be between -90 and 90"},
      {{"--gravity", "9.79", "--nominal-sf", "nan"},
       "--nominal-sf nan: a nominal scale factor must be between 1e-06 and 1e+06 V/g"},
  };
  for (const auto& [extra, message] : cases) {
    std::vector<std::string> args = base;
    args.insert(args.end(), extra.begin(), extra.end());
    const CliResult r = run(GFINS_CALIBRATE_BIN, args);
    EXPECT_EQ(r.exit_code, kCalibrateExitInput) << r.output;
    EXPECT_NE(r.output.find(message), std::string::npos) << r.output;
    EXPECT_EQ(r.output.find("is required"), std::string::npos) << r.output;
  }
}

// Inputs that never end (/dev/zero) are refused after their size limit, quickly and naming the
// limit, where they used to be read until gigabytes of memory were gone.
TEST_F(AbsurdArgsCli, EndlessInputsAreRefusedAfterTheirLimit) {
  const CliResult sim = run(GFINS_SIM_BIN, {"run", "/dev/zero", "-o", path("o")});
  EXPECT_EQ(sim.exit_code, kExitBadInput) << sim.output;
  EXPECT_NE(sim.output.find("larger than 1048576 bytes"), std::string::npos) << sim.output;
  const CliResult cal =
      run(GFINS_CALIBRATE_BIN, {"--means", "/dev/zero", "--adc-lsb", "1e-6", "--device-id", "b1",
                                "--gravity", "9.8", "-o", path("cal.toml")});
  EXPECT_NE(cal.exit_code, 0) << cal.output;
  EXPECT_NE(cal.output.find("larger than 16777216 bytes"), std::string::npos) << cal.output;
  // A recording is sized and read by offset: /dev/zero read as "a file of 0 bytes" and a folder
  // failed at a seek. Each is named as what it is.
  for (const auto& [input, what] :
       {std::pair{std::string("/dev/zero"), "is a device"}, std::pair{path("."), "is a folder"}}) {
    const CliResult replay = run(GFINS_REPLAY_BIN, {input, "-o", path("r")});
    EXPECT_EQ(replay.exit_code, kExitBadInput) << replay.output;
    EXPECT_NE(replay.output.find(what), std::string::npos) << replay.output;
    EXPECT_NE(replay.output.find("not a recording file"), std::string::npos) << replay.output;
  }
}

}  // namespace
}  // namespace gfins::sim
