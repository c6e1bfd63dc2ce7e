// gfins-replay as a user meets it: inputs checked
// before any work (an alignment longer than the recording, an array that turns during the
// alignment), SIGINT stopping between two samples with whole files, a flagged-saturated frame
// not navigated, a file name with a newline kept out of the dump's '#' header.
//
// The tools are the real binaries, started without a shell. Oracles: the recording format's
// writer and reader (the samples written are the ones read), the scenario's physics (a spin at
// 3 rad/s about a skew axis turns gravity through the body: each sensor's output swings by a
// large part of 1 g), the exit codes of --help, the CSV structure (cells per row = header's).
#include <gtest/gtest.h>

#include <chrono>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <regex>
#include <string>
#include <vector>

#include "gfins/host_sim/recording.hpp"
#include "gfins/nav_core/geometry.hpp"
#include "support/cli_fixture.hpp"
#include "support/csv.hpp"

namespace gfins::sim {
namespace {

namespace fs = std::filesystem;
using test::CliResult;

// Exit codes of gfins-replay (--help).
constexpr int kExitOk = 0;
constexpr int kExitBadInput = 2;
constexpr int kExitInterrupted = 130;

constexpr const char* kRest2s = R"([scenario]
duration_s = 2.0
rate_hz = 1000.0
[trajectory]
kind = "rest"
euler_deg = [3.0, -2.0, 10.0]
[sensors]
noise_mg = 1.0
)";

class ReplayChecksCli : public test::CliTest {
 protected:
  /// A recording made by gfins-sim run --record of `scenario` (a built-in name or a file).
  std::string record(const std::string& scenario, const std::string& name) const {
    const std::string gfr = path(name + ".gfr");
    const CliResult r = run(
        GFINS_SIM_BIN, {"run", scenario, "--record", gfr, "--no-plot", "-o", path(name + "-sim")});
    EXPECT_EQ(r.exit_code, kExitOk) << r.output;
    return gfr;
  }
};

TEST_F(ReplayChecksCli, AlignmentLongerThanTheRecordingIsRefusedBeforeAnyWork) {
  // Given a 2 s recording (2001 samples),
  const std::string gfr = record(file("rest2.toml", kRest2s), "rest2");
  // when the alignment asks for 100 s, then exit 2 naming --align-s and the length, no folder;
  const CliResult r =
      run(GFINS_REPLAY_BIN, {gfr, "--align-s", "100", "--no-plot", "-o", path("long-align")});
  EXPECT_EQ(r.exit_code, kExitBadInput) << r.output;
  EXPECT_NE(r.err.find("--align-s 100"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("2001"), std::string::npos) << r.err;
  EXPECT_EQ(r.output.find("written:"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir() / "long-align"));
  // and the default 1 s alignment on the same (still) recording navigates.
  const CliResult ok = run(GFINS_REPLAY_BIN, {gfr, "--no-plot", "-o", path("ok")});
  EXPECT_EQ(ok.exit_code, kExitOk) << ok.output;
}

TEST_F(ReplayChecksCli, ARecordingThatTurnsDuringTheAlignmentIsRefusedWithTheFigures) {
  // Given the built-in spin (3 rad/s about a skew body axis from t = 0),
  const std::string gfr = record("spin", "spin");
  // when replayed, then it is refused before any work, with each channel's figure and the bound,
  const CliResult r = run(GFINS_REPLAY_BIN, {gfr, "--no-plot", "-o", path("spin-out")});
  EXPECT_EQ(r.exit_code, kExitBadInput) << r.output;
  EXPECT_NE(r.err.find("not still during the alignment"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("below 0.005 g"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--no-still-check"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir() / "spin-out"));
  // and --no-still-check navigates it anyway.
  const CliResult forced =
      run(GFINS_REPLAY_BIN, {gfr, "--no-still-check", "--no-plot", "-o", path("spin-forced")});
  EXPECT_EQ(forced.exit_code, kExitOk) << forced.output;
}

TEST_F(ReplayChecksCli, SigintStopsBetweenTwoSamplesWithWholeFiles) {
  // Given a long recording written with the format's writer (400 s at 1 kHz, constant counts:
  // an array at rest without noise, still by construction),
  constexpr std::uint64_t kSamples = 400000;
  const std::string gfr = path("long.gfr");
  {
    RecordingHeader h;
    h.sample_rate_hz = 1000.0;
    h.volts_per_count.fill(1.2 / 8388608.0);  // 1.2 V full scale over 2^23 codes
    h.geometry = nav::table1_geometry<double>(0.1);
    auto w = RecordingWriter::open(gfr, h);
    ASSERT_TRUE(w.is_ok()) << w.error().message;
    // Gravity (1 g up, body z down) on each sensor: θ_i · (0, 0, −1) g × 1.33 V/g in counts.
    RawSample x{};
    for (std::size_t j = 0; j < 6; ++j) {
      const double v = -h.geometry.theta_b[j].z() * 1.33;
      x.counts[j] = static_cast<std::int32_t>(v / h.volts_per_count[j]);
    }
    for (std::uint64_t k = 0; k < kSamples; ++k) {
      x.seq = static_cast<std::uint32_t>(k);
      x.t_ns = static_cast<std::int64_t>(k) * 1000000;
      ASSERT_TRUE(w.value().append(x).is_ok());
    }
    ASSERT_TRUE(w.value().close().is_ok());
  }
  ASSERT_EQ(setenv("GFINS_PROGRESS_INTERVAL_S", "0.05", 1), 0);
  const fs::path out = dir() / "cut";
  const fs::path log = dir() / "log";
  fs::create_directories(log);
  test::StartedTool t =
      test::start_tool(GFINS_REPLAY_BIN, {gfr, "--no-plot", "-o", out.string()}, log);
  ASSERT_GT(t.child.pid, 0);
  // when SIGINT comes after the first progress line (a log, not a terminal, gets them too),
  const bool seen = test::wait_for_stderr(t, "progress: replay: ", std::chrono::seconds(60));
  ASSERT_EQ(unsetenv("GFINS_PROGRESS_INTERVAL_S"), 0);
  EXPECT_TRUE(seen) << "no progress line within 60 s";
  ASSERT_TRUE(drivers::lnx::signal_program(t.child, SIGINT).is_ok());
  const CliResult r = test::finish_tool(t);
  // then exit 130, a summary saying where it stopped,
  ASSERT_EQ(r.exit_code, kExitInterrupted) << r.output;
  const std::string summary = test::slurp(out / "summary.txt");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(summary, m,
                                std::regex("interrupted \\(signal 2\\) after ([0-9]+) samples")))
      << summary;
  const std::uint64_t offered = std::stoull(m[1].str());
  EXPECT_LT(offered, kSamples);
  // and navigation.csv made of whole rows (every row has the header's cells, the file ends with
  // a newline), one per state: the samples offered minus the alignment's 999 (1 s at 1 kHz, its
  // last sample gives the first state).
  const std::string csv = test::slurp(out / "navigation.csv");
  ASSERT_FALSE(csv.empty());
  EXPECT_EQ(csv.back(), '\n');
  const auto lines = test::lines_of(csv);
  const std::size_t cells = test::cells_of(lines.front()).size();
  for (const auto& l : lines) ASSERT_EQ(test::cells_of(l).size(), cells) << l;
  EXPECT_EQ(lines.size() - 1, offered - 999);
}

TEST_F(ReplayChecksCli, AFrameFlaggedSaturatedIsNotNavigated) {
  // Given a 2 s still recording in which frame 1500 carries the saturated flag (bit 1, counts
  // unchanged: the flag is the only sign),
  const std::string gfr = record(file("rest2.toml", kRest2s), "rest2");
  auto rec = read_recording(gfr);
  ASSERT_TRUE(rec.is_ok()) << rec.error().message;
  rec.value().samples[1500].flags |= 2u;
  const std::string flagged = path("flagged.gfr");
  ASSERT_TRUE(write_recording(flagged, rec.value().header, rec.value().samples).is_ok());
  // when replayed,
  const CliResult r = run(GFINS_REPLAY_BIN, {flagged, "--no-plot", "-o", path("flagged-out")});
  ASSERT_EQ(r.exit_code, kExitOk) << r.output;
  // then the summary counts it rejected, and navigation.csv has no row with seq 1500.
  EXPECT_NE(r.output.find("rejected 1 (CRC error 0, saturated 1)"), std::string::npos) << r.output;
  const auto lines = test::lines_of(test::slurp(dir() / "flagged-out" / "navigation.csv"));
  ASSERT_GT(lines.size(), 2u);
  const std::size_t seq_col = 1;  // t_s,seq,status,...
  ASSERT_EQ(test::cells_of(lines.front())[seq_col], "seq");
  for (std::size_t i = 1; i < lines.size(); ++i) {
    ASSERT_NE(test::cells_of(lines[i])[seq_col], "1500") << "the flagged frame was navigated";
  }
}

TEST_F(ReplayChecksCli, DumpKeepsANewlineInTheFileNameOutOfItsHeader) {
  const std::string gfr = record(file("rest2.toml", kRest2s), "rest2");
  const fs::path odd = dir() / "odd\nname.gfr";
  fs::copy_file(gfr, odd);
  const CliResult r = run(GFINS_REPLAY_BIN, {"dump", odd.string()});
  ASSERT_EQ(r.exit_code, kExitOk) << r.err;
  // Every line before the CSV header is a '#' comment: the name's newline is shown as \x0a.
  const auto lines = test::lines_of(r.output);
  std::size_t i = 0;
  for (; i < lines.size() && lines[i].rfind("seq,", 0) != 0; ++i) {
    EXPECT_EQ(lines[i].rfind('#', 0), 0u) << "line " << i << ": " << lines[i];
  }
  EXPECT_NE(r.output.find("odd\\x0aname.gfr"), std::string::npos);
}

// The usage names all three forms (docs/replay.md): dump and means are read before CLI11 parses,
// so its generated usage line alone named only the first.
TEST_F(ReplayChecksCli, UsageNamesNavigationDumpAndMeans) {
  const CliResult r = run(GFINS_REPLAY_BIN, {"--help"});
  EXPECT_EQ(r.exit_code, kExitOk) << r.output;
  EXPECT_NE(r.output.find("Usage: gfins-replay [OPTIONS] recording"), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("       gfins-replay dump RECORDING.gfr [--frames]\n"), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("       gfins-replay means RECORDING.gfr --mounting K --up X Y Z "
                          "--rate-rad-s W [--header]\n"),
            std::string::npos)
      << r.output;
}

}  // namespace
}  // namespace gfins::sim
