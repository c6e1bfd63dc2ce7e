// gfins-fw as a user runs it: --check-config and the run
// accept and refuse the same configurations with the same message; messages reach the terminal
// whole and escaped; output paths are checked before any work; a CAN log that loses frames
// makes the run fail. The expected texts are written out here.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "support/cli_fixture.hpp"

namespace gfins {
namespace {

class FwCli : public test::CliTest {
 protected:
  test::CliResult fw(const std::vector<std::string>& args) const { return run(GFINS_FW_EXE, args); }
  // The simulated board, factory calibration, 0.2 s after the 1 s alignment: a short run.
  std::vector<std::string> sim_run(std::vector<std::string> extra,
                                   const std::string& scenario = "rest",
                                   const std::string& can_log = "") const {
    std::vector<std::string> a = {"--sim",          scenario,
                                  "--calibration",  "",
                                  "--duration",     "1.2",
                                  "--can-log",      can_log.empty() ? path("out.log") : can_log,
                                  "--scenario-dir", GFINS_SCENARIO_DIR};
    a.insert(a.end(), extra.begin(), extra.end());
    return a;
  }
};

// The run's own start-up line: present only when the run got as far as starting.
constexpr const char* kStarted = "sample loop running";
// --check-config's bus line for the defaults: 903 frames/s (aiding off; the command counters at
// 1 Hz included) x 135 worst-case bits of an 8-byte base frame = 121,905 bit/s, 24.38 % of
// 500 kbit/s (docs/can-interface.md).
constexpr const char* kDefaultLoadLine =
    "gfins-fw: worst-case bus load 24.38 % of 500000 bit/s (limit 50 %)\n";

TEST_F(FwCli, CheckConfigAndTheRunRefuseTheSameConfigurations) {
  struct Case {
    std::vector<std::string> args;
    std::string message;  // stderr, whole
  };
  const std::vector<Case> cases = {
      {sim_run({"--can", "a b"}),
       "gfins-fw: command line: can.interface = \"a b\": must be an interface name of 1..15 "
       "characters without '/', ':' or spaces\n"},
      {sim_run({"--drdy-line", "-5"}),
       "gfins-fw: command line: adc.drdy_line = \"-5\": line offset must be 0..1023\n"},
      {sim_run({"--sample-rate", "2000"}),
       "gfins-fw: built-in defaults + command line: sim.scenario = \"rest\": runs at 1000 Hz: "
       "adc.sample_rate_hz must be the same\n"},
      // The bus budget: the default dividers at 4 kHz send 3608 frames/s of 135 worst-case bits,
      // 97.5 % of 500 kbit/s (docs/can-interface.md), over the default 50 %.
      {sim_run({"--sample-rate", "4000"}),
       "gfins-fw: command line: output = a worst-case bus load of 97.5 % of 500000 bit/s at "
       "adc.sample_rate_hz = 4000: must be at most can.max_bus_load_percent = 50 %: raise the "
       "dividers of [output], switch messages off, or raise can.bit_rate\n"},
      {sim_run({}, "nosuchscenario"), ""},  // the loader's message, checked by prefix
      {sim_run({}, "rest", "/nonexistent-gfins/out.log"),
       "gfins-fw: built-in defaults + command line: can.log_file = "
       "\"/nonexistent-gfins/out.log\": its folder \"/nonexistent-gfins\" does not exist\n"},
      {sim_run({"--latency-csv", "/nonexistent-gfins/x.csv"}),
       "gfins-fw: built-in defaults + command line: --latency-csv = \"/nonexistent-gfins/x.csv\": "
       "its folder \"/nonexistent-gfins\" does not exist\n"},
  };
  for (const Case& c : cases) {
    std::vector<std::string> check = c.args;
    check.push_back("--check-config");
    const test::CliResult checked = fw(check);
    const test::CliResult ran = fw(c.args);
    EXPECT_EQ(checked.exit_code, 2) << checked.output;
    EXPECT_EQ(ran.exit_code, 2) << ran.output;
    EXPECT_EQ(checked.err, ran.err);
    if (!c.message.empty()) {
      EXPECT_EQ(ran.err, c.message);
    } else {
      EXPECT_EQ(ran.err.rfind("gfins-fw: built-in defaults + command line: sim.scenario = "
                              "\"nosuchscenario\": ",
                              0),
                0u)
          << ran.err;
    }
    // Refused before anything started (the output files were never created).
    EXPECT_EQ(ran.output.find(kStarted), std::string::npos) << ran.output;
  }
  // And a configuration one accepts, the other runs.
  std::vector<std::string> good = sim_run({});
  const test::CliResult ran = fw(good);
  good.push_back("--check-config");
  const test::CliResult checked = fw(good);
  EXPECT_EQ(checked.exit_code, 0) << checked.output;
  EXPECT_EQ(checked.output,
            "gfins-fw: configuration (built-in defaults + command line) is valid\n" +
                std::string(kDefaultLoadLine));
  EXPECT_EQ(ran.exit_code, 0) << ran.output;
  EXPECT_NE(ran.output.find(kStarted), std::string::npos) << ran.output;
}

// A configuration path that never ends is refused after its first MiB (before, gfins-fw read
// /dev/zero until the machine's memory ran out), naming the path and the limit; an empty
// configuration file is valid (every key keeps its default).
TEST_F(FwCli, AConfigurationThatNeverEndsIsRefusedAtItsSizeLimit) {
  for (const bool check : {true, false}) {
    std::vector<std::string> args = {"--config", "/dev/zero"};
    if (check) args.emplace_back("--check-config");
    const test::CliResult r = fw(args);
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(
        r.err.find("/dev/zero: larger than 1048576 bytes, the limit for a configuration file"),
        std::string::npos)
        << r.err;
    EXPECT_EQ(r.output.find(kStarted), std::string::npos) << r.output;
  }
  const test::CliResult empty = fw({"--config", file("empty.toml", ""), "--check-config"});
  EXPECT_EQ(empty.exit_code, 0) << empty.output;
}

TEST_F(FwCli, MessagesArriveWholeWithControlCharactersEscaped) {
  // A NUL inside a value used to end the message there (no reason, no newline); an ESC went to
  // the terminal raw.
  const std::string nul = file("n.toml", "[can]\ninterface = \"can0\\u0000x\"\n");
  const test::CliResult n = fw({"-c", nul, "--check-config"});
  EXPECT_EQ(n.exit_code, 2);
  EXPECT_EQ(n.err, "gfins-fw: " + nul +
                       ":2: can.interface = \"can0\\u0000x\": must be an interface name of 1..15 "
                       "characters without '/', ':' or spaces\n");
  const std::string esc = file("e.toml", "[log]\nlevel = \"info\\u001b[31m\"\n");
  const test::CliResult e = fw({"-c", esc, "--check-config"});
  EXPECT_EQ(e.exit_code, 2);
  EXPECT_EQ(e.err, "gfins-fw: " + esc +
                       ":2: log.level = \"info\\u001B[31m\": must be \"trace\", \"debug\", "
                       "\"info\", \"warn\", \"error\" or \"off\"\n");
  EXPECT_EQ(e.err.find('\x1B'), std::string::npos);
  // Options too (CLI11's own message quotes the value): an ESC given on the command line.
  const test::CliResult o = fw({"--compensator", "best\x1B[2J"});
  EXPECT_EQ(o.exit_code, 2);
  EXPECT_EQ(o.err.find('\x1B'), std::string::npos) << o.err;
  EXPECT_NE(o.err.find("best\\u001B[2J"), std::string::npos) << o.err;
}

TEST_F(FwCli, CheckConfigNamesWhatTheConfigurationIsMadeOf) {
  const std::string cfg =
      file("c.toml", std::string("[board]\nkind = \"sim\"\n[calibration]\nfile = "
                                 "\"\"\n[sim]\nscenario_dir = \"") +
                         GFINS_SCENARIO_DIR + "\"\n");
  EXPECT_EQ(fw({"-c", cfg, "--check-config"}).output,
            "gfins-fw: configuration (" + cfg + ") is valid\n" + kDefaultLoadLine);
  EXPECT_EQ(fw({"-c", cfg, "--node-id", "3", "--check-config"}).output,
            "gfins-fw: configuration (" + cfg + " + command line) is valid\n" + kDefaultLoadLine);
  // A UTF-8 path is a path (item 2); the missing file is a note, not an error: the run would
  // start flagged uncalibrated.
  const std::string cafe = path("caf\xC3\xA9.toml");
  const test::CliResult c = fw({"--calibration", cafe, "--check-config"});
  EXPECT_EQ(c.exit_code, 0) << c.output;
  EXPECT_NE(c.output.find(kDefaultLoadLine + std::string("gfins-fw: note: calibration.file = \"") +
                          cafe + "\": "),
            std::string::npos)
      << c.output;
  EXPECT_NE(c.output.find("a run would navigate UNCALIBRATED"), std::string::npos) << c.output;
}

// Two outputs on one file would overwrite each other (the latency table over the start of the
// CAN log): refused before the run with both names, whatever spelling of the path; /dev/null
// for both is not a clash.
TEST_F(FwCli, TwoOutputsOnOneFileAreRefusedBeforeTheRun) {
  const std::string log = path("x.log");
  for (const auto& [extra, names] :
       {std::pair{std::vector<std::string>{"--latency-csv", log},
                  "can.log_file (--can-log) and --latency-csv"},
        std::pair{std::vector<std::string>{"--latency-csv", path(".") + "/./x.log"},
                  "can.log_file (--can-log) and --latency-csv"},
        std::pair{std::vector<std::string>{"--calibration", log},
                  "can.log_file (--can-log) and calibration.file"}}) {
    SCOPED_TRACE(extra[1]);
    std::vector<std::string> args = sim_run({}, "rest", log);
    if (const auto at = std::find(args.begin(), args.end(), extra[0]);
        at != args.end() && at + 1 != args.end()) {
      *(at + 1) = extra[1];  // sim_run's --calibration "" becomes the clashing path
    } else {
      args.insert(args.end(), extra.begin(), extra.end());
    }
    const test::CliResult r = fw(args);
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find(names), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("name the same file"), std::string::npos) << r.output;
    EXPECT_EQ(r.output.find(kStarted), std::string::npos) << r.output;
    EXPECT_FALSE(std::filesystem::exists(log));
  }
  const test::CliResult ok = fw(sim_run({"--latency-csv", "/dev/null"}, "rest", "/dev/null"));
  EXPECT_EQ(ok.exit_code, 0) << ok.output;
}

// A simulated run faster than real time (the default pacing) reports how far it got, every
// interval of wall-clock time ($GFINS_PROGRESS_INTERVAL_S, documented for tests; 5 s otherwise);
// real-time pacing, whose run takes the scenario's own time, does not. Oracle: the run's length
// (20 s of scenario at 1 kHz: tens of thousands of 4096-cycle checks at a 1 ms interval) and the
// line's documented text.
TEST_F(FwCli, AFastSimulatedRunReportsItsProgress) {
  ASSERT_EQ(setenv("GFINS_PROGRESS_INTERVAL_S", "0.001", 1), 0);
  auto args = sim_run({});
  const auto d = std::find(args.begin(), args.end(), "--duration");
  ASSERT_NE(d, args.end());
  *(d + 1) = "20";
  const test::CliResult r = fw(args);
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("progress: "), std::string::npos) << r.output;
  EXPECT_NE(r.output.find(" of 20.0 s of the scenario)"), std::string::npos) << r.output;
  const test::CliResult paced = fw(sim_run({"--pacing", "realtime"}));
  unsetenv("GFINS_PROGRESS_INTERVAL_S");
  EXPECT_EQ(paced.exit_code, 0) << paced.output;
  EXPECT_EQ(paced.output.find("progress: "), std::string::npos) << paced.output;
}

// The simulated board's log starts at the documented epoch of simulated logs, 1700000000 s
// (docs/firmware.md), not at 0: the first epoch, at scenario time 0, is stamped
// (1700000000.000000), the last of a 1.2 s run (samples 0..1200 at 1 kHz, an epoch every 10)
// at 1.2 s.
TEST_F(FwCli, ASimulatedLogStartsAtTheDocumentedEpoch) {
  const test::CliResult r = fw(sim_run({}));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string log = test::slurp(path("out.log"));
  EXPECT_EQ(log.rfind("(1700000000.000000) can0 101#", 0), 0U) << log.substr(0, 80);
  const std::size_t last = log.rfind("\n(");
  ASSERT_NE(last, std::string::npos);
  EXPECT_EQ(log.substr(last + 1, 20), "(1700000001.200000) ");
}

// A channel failure of the scenario reaches the board's own detectors: sensor 4 dead (0 V, the
// converter reads a constant code) from sample 1050 is reported stuck by the sample loop when 50
// samples after it have repeated its code (docs/faults.md), i.e. at sample 1100 (t = 1100 ms),
// with the channel's bit (mask 8) in the log line and in the health summary.
TEST_F(FwCli, AScenarioChannelFailureReachesTheBoardsDetectors) {
  const std::string scenario = file("dead4.toml", R"([scenario]
description = "at rest, sensor 4 dies at 1.05 s"
duration_s = 2.0
rate_hz = 1000.0

[trajectory]
kind = "rest"

[sensors]
noise_mg = 1.0

[[sensors.failures]]
kind = "dead"
sensor = 4
start_s = 1.05
)");
  const test::CliResult r = fw(sim_run({}, scenario));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("t=1100ms channel mask 8 stuck: code unchanged for 50 samples"),
            std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("stuck events 1 (mask 0x8)"), std::string::npos) << r.output;
}

TEST_F(FwCli, ACanLogThatLosesFramesFailsTheRun) {
  if (!std::filesystem::exists("/dev/full")) GTEST_SKIP() << "no /dev/full on this system";
  // /dev/full refuses every write with ENOSPC: every frame is lost.
  const test::CliResult r = fw(sim_run({}, "rest", "/dev/full"));
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("[error] can.log_file = \"/dev/full\": candump file: disk full, frames "
                          "dropped: No space left on device (errno 28); "),
            std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find(" frames not written ("), std::string::npos) << r.output;
  // The same run into a file that takes the frames ends well, its log complete.
  const test::CliResult ok = fw(sim_run({}));
  EXPECT_EQ(ok.exit_code, 0) << ok.output;
  EXPECT_EQ(ok.output.find("frames not written"), std::string::npos) << ok.output;
  EXPECT_GT(std::filesystem::file_size(path("out.log")), 0u);
}

// Record and replay as a user sets them up (docs/replay.md): what cannot work is refused before
// the run, by --check-config and the run alike, naming the key and why; a recorder whose file
// cannot be written fails the run, its loop unharmed.
TEST_F(FwCli, AReplayThatCannotWorkIsRefusedBeforeTheRun) {
  const std::string rec = path("short.gfr");
  ASSERT_EQ(fw(sim_run({"--record", rec})).exit_code, 0);
  const struct {
    std::vector<std::string> args;
    const char* says;
  } bad[] = {
      {{"--replay", rec, "--pacing", "realtime"},
       "a recording is replayed by sample index: sim.pacing must be \"fast\""},
      {{"--replay", rec, "--sample-rate", "2000"}, "recorded at 1000"},
      {{"--replay", path("missing.gfr")}, "cannot open"},
      {{"--replay", path("out.log")}, "wrong magic"},
      {{"--replay", rec, "--record", rec}, "name the same file"},
  };
  for (const auto& b : bad) {
    for (const bool check : {true, false}) {
      std::vector<std::string> a = b.args;
      a.insert(a.end(), {"--calibration", "", "--can-log", path("replay.log")});
      if (check) a.push_back("--check-config");
      const test::CliResult r = fw(a);
      EXPECT_EQ(r.exit_code, 2) << b.says << "\n" << r.output;
      EXPECT_NE(r.output.find(b.says), std::string::npos) << r.output;
      EXPECT_EQ(r.output.find(kStarted), std::string::npos) << r.output;
    }
  }
  // The same recording replays; a recorder on /dev/full fails the run at start-up (exit 1).
  EXPECT_EQ(fw({"--replay", rec, "--calibration", "", "--can-log", path("replay.log")}).exit_code,
            0);
  if (std::filesystem::exists("/dev/full")) {
    const test::CliResult full = fw(sim_run({"--record", "/dev/full"}));
    EXPECT_EQ(full.exit_code, 1) << full.output;
    EXPECT_NE(full.output.find("record.file \"/dev/full\": cannot write the header of /dev/full"),
              std::string::npos)
        << full.output;
  }
}

}  // namespace
}  // namespace gfins
