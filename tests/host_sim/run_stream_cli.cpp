// Long runs of `gfins-sim run` ("Inputs checked before work starts"): the CSV files and
// the recording are written while the run navigates, so memory does not grow with the duration,
// and SIGINT stops a run cleanly with what was written so far and exit code 130.
//
// The tool is the real binary (GFINS_SIM_BIN), started without a shell (tests/support/
// run_cli.hpp). Oracles: the sample law of the source (duration × rate + 1 samples, t_k = k /
// rate), the physics of an array at rest (true velocity, position, rate and acceleration zero),
// the in-memory size formula of a run (per sample a TruthState, two RawSamples and two
// SampleRecords, whose sizes the compiler gives), the recording format's reader, and an
// uninterrupted run of the same scenario (its rows, byte for byte).
#include <gtest/gtest.h>

#include <chrono>
#include <csignal>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "gfins/host_sim/recording.hpp"
#include "gfins/host_sim/scenario.hpp"
#include "support/cli_fixture.hpp"
#include "support/csv.hpp"

namespace gfins::sim {
namespace {

namespace fs = std::filesystem;
using test::CliResult;

// Exit codes of gfins-sim (--help, docs/install.md).
constexpr int kExitOk = 0;
constexpr int kExitInterrupted = 130;

// The memory limit given to the runs through $GFINS_MAX_RUN_MEMORY_BYTES (documented for tests):
// 1 MB, far below what either run below would hold in memory.
constexpr const char* kSmallMemoryLimit = "1000000";

// A streamed run's peak resident set may grow with the duration by at most this fraction of
// what the extra samples would take in memory. A run that kept even one of its two series would
// grow by sizeof(SampleRecord) / per-sample bytes ≈ 36 % of it (320 of 880 bytes); allocator
// and page-rounding noise between two runs of the same program is a few hundred KiB, < 2 % of the
// 28 MB difference here.
constexpr double kMaxRssGrowthFraction = 0.15;

std::string rest_scenario(double duration_s, double rate_hz) {
  std::ostringstream s;
  s << "[scenario]\ndescription = \"rest (streaming test)\"\nduration_s = " << duration_s
    << "\nrate_hz = " << rate_hz
    << "\n[trajectory]\nkind = \"rest\"\neuler_deg = [3.0, -2.0, 45.0]\n"
       "[sensors]\norientation = \"paper_table6\"\nnoise_mg = 1.0\n"
       "[compensator]\nkind = \"paper\"\n";
  return s.str();
}

class RunStreamCli : public test::CliTest {
 protected:
  fs::path write_scenario(const std::string& name, const std::string& text) const {
    return file(name + ".toml", text);
  }
};

using test::lines_of;
using test::numbers_of;

// (1) Above the memory limit, a run still completes: its files are streamed. The CSV has the
// analytic row count and last row, and the peak memory does not follow the duration.
TEST_F(RunStreamCli, RunAboveTheMemoryLimitCompletesWithBoundedMemory) {
  ASSERT_EQ(setenv("GFINS_MAX_RUN_MEMORY_BYTES", kSmallMemoryLimit, 1), 0);
  constexpr double kRate = 1000.0;
  constexpr double kShort = 4.0, kLong = 36.0;  // s
  const fs::path short_toml = write_scenario("short", rest_scenario(kShort, kRate));
  const fs::path long_toml = write_scenario("long", rest_scenario(kLong, kRate));

  // The limit is in force: a run kept in memory (check_run_size, as montecarlo uses it) of the
  // long scenario is refused under it.
  const auto s = load_scenario(long_toml.string());
  ASSERT_TRUE(s.is_ok()) << s.error().message;
  const double per_sample =
      sizeof(TruthState) + 2.0 * sizeof(RawSample) + 2.0 * sizeof(SampleRecord);
  const double in_memory_long = per_sample * (kLong * kRate + 1);
  EXPECT_EQ(static_cast<double>(run_memory_bytes(s.value())), in_memory_long);
  EXPECT_FALSE(check_run_size(s.value()).is_ok());

  // Both runs first, then the files: posix_spawn shares the test's address space until exec,
  // and Linux counts that in the child's peak RSS, so the test holds no CSV while it spawns.
  long rss_kib[2] = {0, 0};
  for (int i = 0; i < 2; ++i) {
    const fs::path toml = i == 0 ? short_toml : long_toml;
    const fs::path out = dir() / (i == 0 ? "short" : "long");
    const CliResult r = run(GFINS_SIM_BIN, {"run", toml.string(), "-o", out.string(), "--no-plot"});
    ASSERT_EQ(r.exit_code, kExitOk) << r.output;
    rss_kib[i] = r.max_rss_kib;
  }
  for (int i = 0; i < 2; ++i) {
    const fs::path out = dir() / (i == 0 ? "short" : "long");
    const double duration = i == 0 ? kShort : kLong;
    for (const char* file : {"uncompensated.csv", "compensated.csv"}) {
      const auto lines = lines_of(test::slurp(out / file));
      // Header + duration × rate + 1 samples (the start at t = 0 and every sample after it).
      ASSERT_EQ(lines.size(), 1 + static_cast<std::size_t>(duration * kRate) + 1) << file;
      const test::Csv head{test::cells_of(lines.front()), {}};
      const auto last = numbers_of(lines.back());
      char t_text[32];
      std::snprintf(t_text, sizeof t_text, "%.6f,", duration);
      EXPECT_EQ(lines.back().rfind(t_text, 0), 0u) << "last row starts with t = " << t_text;
      // At rest the truth has no velocity, position, rate or acceleration, whatever the noise.
      for (const char* name : {"true_v_n", "true_r_n", "true_w_b", "true_a_n"}) {
        for (const char* ax : {"x", "y", "z"}) {
          const std::string unit = std::string(name) == "true_v_n"   ? "mps"
                                   : std::string(name) == "true_r_n" ? "m"
                                   : std::string(name) == "true_w_b" ? "rps"
                                                                     : "mps2";
          EXPECT_EQ(last.at(head.index(std::string(name) + "_" + ax + "_" + unit)), 0.0)
              << file << " " << name << " " << ax;
        }
      }
    }
  }
  const double growth_bytes = static_cast<double>(rss_kib[1] - rss_kib[0]) * 1024.0;
  const double extra_in_memory = per_sample * (kLong - kShort) * kRate;
  EXPECT_LT(growth_bytes, kMaxRssGrowthFraction * extra_in_memory)
      << "peak RSS " << rss_kib[0] << " KiB (" << kShort << " s) vs " << rss_kib[1] << " KiB ("
      << kLong << " s)";
  ASSERT_EQ(unsetenv("GFINS_MAX_RUN_MEMORY_BYTES"), 0);
}

// A run whose files cannot fit on the disk is refused before any work, with the figures, and
// leaves no folder behind. 10^11 samples (10^6 s at 100 kHz, the largest a scenario allows)
// make at least 2 × 10^11 CSV rows of > 100 bytes each: 2 × 10^13 bytes, more than any file
// system this test runs on has free (checked below with std::filesystem::space). 100 kHz is
// beyond the ADC model (32 kHz): the scenario runs in m/s² ([sensors] adc = false).
TEST_F(RunStreamCli, RunThatCannotFitOnTheDiskIsRefusedWithTheNumbers) {
  constexpr double kMinBytesNeeded = 2e13;
  ASSERT_LT(static_cast<double>(fs::space(dir()).available), kMinBytesNeeded);
  std::string text = rest_scenario(1.0e6, 1.0e5);
  text.replace(text.find("noise_mg = 1.0\n"), 15, "noise_mg = 1.0\nadc = false\n");
  const fs::path toml = write_scenario("huge", text);
  const fs::path out = dir() / "a" / "huge";
  const CliResult r = run(GFINS_SIM_BIN, {"run", toml.string(), "-o", out.string(), "--no-plot"});
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("1e+11 samples"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("MB free"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir() / "a")) << "a refused run left a folder";
}

// (2) SIGINT after the first progress line: exit 130, CSV rows a prefix of an uninterrupted
// run's, a valid recording with as many samples as CSV rows, a summary saying where it stopped.
TEST_F(RunStreamCli, SigintStopsCleanlyWithAPrefixOfTheRun) {
  ASSERT_EQ(setenv("GFINS_PROGRESS_INTERVAL_S", "0.1", 1), 0);
  constexpr double kRate = 100.0, kDuration = 800.0;  // 80,001 samples: seconds of work
  const fs::path toml = write_scenario("long", rest_scenario(kDuration, kRate));
  const fs::path cut = dir() / "cut";
  const fs::path gfr = dir() / "cut.gfr";
  const fs::path log = dir() / "log";
  fs::create_directories(log);
  test::StartedTool t = test::start_tool(
      GFINS_SIM_BIN,
      {"run", toml.string(), "-o", cut.string(), "--no-plot", "--record", gfr.string()}, log);
  ASSERT_GT(t.child.pid, 0);
  // Wait (bounded) for the first progress line on stderr, then interrupt.
  const bool seen = test::wait_for_stderr(t, "progress: ", std::chrono::seconds(60));
  EXPECT_TRUE(seen) << "no progress line within 60 s";
  ASSERT_TRUE(drivers::lnx::signal_program(t.child, SIGINT).is_ok());
  const CliResult r = test::finish_tool(t);
  ASSERT_EQ(r.exit_code, kExitInterrupted) << r.output;
  EXPECT_NE(r.output.find("interrupted at t = "), std::string::npos) << r.output;
  const std::string summary = test::slurp(cut / "summary.txt");
  EXPECT_NE(summary.find("interrupted (signal 2) at t = "), std::string::npos) << summary;

  const auto cut_rows = lines_of(test::slurp(cut / "compensated.csv"));
  ASSERT_GE(cut_rows.size(), 3u);  // header, the start, at least one navigated sample
  const std::size_t rows = cut_rows.size() - 1;
  EXPECT_LT(rows, static_cast<std::size_t>(kDuration * kRate) + 1) << "the run was not cut";

  // The recording is whole (record_count written, every block's CRC checked by the reader) and
  // holds exactly the samples the CSV rows navigated, in order.
  const auto rec = read_recording(gfr.string());
  ASSERT_TRUE(rec.is_ok()) << rec.error().message;
  EXPECT_EQ(rec.value().header.record_count, rows);
  ASSERT_EQ(rec.value().samples.size(), rows);
  for (std::size_t k = 0; k < rows; ++k) ASSERT_EQ(rec.value().samples[k].seq, k);

  // The uninterrupted run of the same scenario: the cut files are prefixes of its files.
  unsetenv("GFINS_PROGRESS_INTERVAL_S");
  const fs::path full = dir() / "full";
  const CliResult f = run(GFINS_SIM_BIN, {"run", toml.string(), "-o", full.string(), "--no-plot"});
  ASSERT_EQ(f.exit_code, kExitOk) << f.output;
  for (const char* file : {"uncompensated.csv", "compensated.csv"}) {
    const std::string cut_text = test::slurp(cut / file);
    const std::string full_text = test::slurp(full / file);
    ASSERT_LT(cut_text.size(), full_text.size()) << file;
    EXPECT_EQ(full_text.compare(0, cut_text.size(), cut_text), 0)
        << file << ": the interrupted rows are not a prefix of the uninterrupted run's";
    EXPECT_EQ(lines_of(cut_text).size(), rows + 1) << file;
  }
}

}  // namespace
}  // namespace gfins::sim
