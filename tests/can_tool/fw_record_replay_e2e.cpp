// An aided drive recorded by the firmware replays bit-exactly through the firmware
// (docs/replay.md, "Recording on the board" and "Replay through the firmware"):
// `gfins-fw --sim drive-gnss --record drive.gfr` on the simulated board (its receiver sending the
// GNSS fixes as CAN input frames, the board aligning in motion from them), then
// `gfins-fw --replay drive.gfr` with the same configuration and calibration file. The oracle is
// the live run's own CAN log: the replay must put the same frames, with the same timestamps, into
// its log, byte for byte. Checked as well, against the scenario rather than the code:
//  - the recording holds every sample of the run (20 s at 1 kHz, plus sample 0) and one frame
//    record per GNSS input frame the receiver sent (10 Hz, four frames per fix: position N/E,
//    position D and σ, velocity, fix information; docs/can-interface.md, "Aiding inputs");
//  - a negative control: the same samples without the frame records (the recording a version-1
//    recorder would have made) replay to a different log: the frames are what makes the replay
//    aided.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "gfins/host_sim/recording.hpp"
#include "support/cli_fixture.hpp"
#include "support/sim_chain.hpp"

namespace gfins {
namespace {

constexpr int kSeconds = 20;

class FwRecordReplay : public test::CliTest {
 protected:
  // The scenario's true calibration as a file: the recording board's, handed to the replay.
  std::string calibration_file() {
    const std::string p = path("board-cal.toml");
    test::save_scenario_calibration("drive-gnss", GFINS_SCENARIO_DIR, p);
    return p;
  }
};

TEST_F(FwRecordReplay, AnAidedDriveRecordedByTheFirmwareReplaysBitExactly) {
  const std::string cfg = file("vehicle.toml",
                               "[aiding]\nenabled = true\ntrack_heading_sigma_deg = 0.5\n"
                               "gnss_lever_arm_m = [-1.0, 0.0, -1.2]\n");
  const std::string cal = calibration_file();
  const std::string rec = path("drive.gfr"), live = path("live.log"), again = path("again.log");
  const auto fw =
      run(GFINS_FW_EXE, {"--config", cfg, "--sim", "drive-gnss", "--scenario-dir",
                         GFINS_SCENARIO_DIR, "--calibration", cal, "--can-log", live, "--record",
                         rec, "--duration", std::to_string(kSeconds), "--watchdog", "none"});
  ASSERT_EQ(fw.exit_code, 0) << fw.output;

  // The recording: every sample, and the receiver's frames between them.
  const auto r = sim::read_recording(rec);
  ASSERT_TRUE(r.is_ok()) << r.error().message;
  EXPECT_EQ(r.value().header.version, 2u);
  EXPECT_EQ(r.value().samples.size(), kSeconds * 1000u + 1u);
  const std::size_t fixes = r.value().frames.size() / 4;
  EXPECT_EQ(r.value().frames.size() % 4, 0u);
  // 10 Hz over 20 s less the 8-12 s outage of the scenario's receiver: 160 fixes, give or take
  // the one at each edge.
  EXPECT_GE(fixes, 159u);
  EXPECT_LE(fixes, 161u);
  for (const sim::RecordedFrame& f : r.value().frames) {
    ASSERT_GE(f.samples_before, 1u);
    // Handled in the cycle of the sample before it: its time is that sample's.
    EXPECT_EQ(f.frame.t_ns, r.value().samples[f.samples_before - 1].t_ns);
  }

  // The replay through the same loop: the same log, byte for byte.
  const auto re = run(GFINS_FW_EXE, {"--config", cfg, "--replay", rec, "--calibration", cal,
                                     "--can-log", again, "--watchdog", "none"});
  ASSERT_EQ(re.exit_code, 0) << re.output;
  const std::string a = test::slurp(live), b = test::slurp(again);
  EXPECT_GT(a.size(), 100000u);
  EXPECT_TRUE(a == b) << "the replay's CAN log differs from the live run's (" << a.size() << " and "
                      << b.size() << " bytes)";

  // gfins-replay prints the frames as a candump log, one line per frame record, and its own
  // (unaided) navigation of the recording says that it did not apply them.
  const auto dump = run(GFINS_REPLAY_EXE, {"dump", rec, "--frames"});
  ASSERT_EQ(dump.exit_code, 0) << dump.output;
  std::size_t lines = 0;
  for (const char ch : dump.output) lines += ch == '\n' ? 1 : 0;
  EXPECT_EQ(lines, r.value().frames.size());
  EXPECT_EQ(dump.output.rfind("(0000000000.", 0), 0u) << dump.output.substr(0, 80);
  const auto nav =
      run(GFINS_REPLAY_EXE, {rec, "--no-plot", "--no-still-check", "-o", path("replay-out")});
  ASSERT_EQ(nav.exit_code, 0) << nav.output;
  EXPECT_NE(nav.output.find("CAN frames in the recording (what the recording board received: "
                            "aiding inputs, commands): " +
                            std::to_string(r.value().frames.size()) + ", not applied"),
            std::string::npos)
      << nav.output;

  // Negative control: the samples alone.
  const std::string bare = path("bare.gfr"), bare_log = path("bare.log");
  ASSERT_TRUE(sim::write_recording(bare, r.value().header, r.value().samples).is_ok());
  const auto nb = run(GFINS_FW_EXE, {"--config", cfg, "--replay", bare, "--calibration", cal,
                                     "--can-log", bare_log, "--watchdog", "none"});
  ASSERT_EQ(nb.exit_code, 0) << nb.output;
  EXPECT_FALSE(test::slurp(bare_log) == a);
}

}  // namespace
}  // namespace gfins
