// Hardware-in-the-loop replay (docs/hil.md), end to end on loopback: gfins-fw --board hil on an
// ephemeral port, fed by gfins-can hil with a synthetic scenario; plus the link's wire format
// checked against the byte layout written here and the CRC-32 check value of its standard.
#include <gtest/gtest.h>

#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "gfins/drivers/lnx/hil_link.hpp"
#include "gfins/drivers/lnx/spawn.hpp"
#include "gfins/host_sim/recording.hpp"
#include "support/cli_fixture.hpp"
#include "support/sim_chain.hpp"

namespace gfins {
namespace {

namespace lnx = drivers::lnx;
namespace fs = std::filesystem;

// ---- Wire format ------------------------------------------------------------------------------

TEST(HilWire, Crc32IsTheIeee8023Crc) {
  // The standard's check value: CRC-32 of the ASCII digits "123456789" is 0xCBF43926.
  const std::string digits = "123456789";
  const std::vector<std::uint8_t> b(digits.begin(), digits.end());
  EXPECT_EQ(lnx::hil::crc32(b), 0xCBF43926u);
}

TEST(HilWire, SampleFrameLayout) {
  RawSample s;
  s.seq = 0x01020304u;
  s.t_ns = 0x1112131415161718;
  s.counts = {-1, 2, -8388608, 8388607, 0, 5};
  s.flags = 0x21;
  const auto w = lnx::hil::encode_sample(0xA0B0C0D0u, s, true);
  ASSERT_EQ(w.size(), 52u);
  EXPECT_EQ(w[0], 'G');
  EXPECT_EQ(w[1], 'H');
  EXPECT_EQ(w[2], 2);     // last sample
  EXPECT_EQ(w[3], 52);    // length
  EXPECT_EQ(w[4], 0xD0);  // index, little-endian
  EXPECT_EQ(w[7], 0xA0);
  EXPECT_EQ(w[8], 0x04);   // seq
  EXPECT_EQ(w[12], 0x18);  // t_ns
  EXPECT_EQ(w[19], 0x11);
  EXPECT_EQ(w[20], 0xFF);  // counts[0] = -1, two's complement
  EXPECT_EQ(w[23], 0xFF);
  EXPECT_EQ(w[28], 0x00);  // counts[2] = -2^23 = 0xFF800000
  EXPECT_EQ(w[30], 0x80);
  EXPECT_EQ(w[31], 0xFF);
  EXPECT_EQ(w[44], 0x21);  // flags
  const auto r = lnx::hil::parse(w);
  ASSERT_EQ(r.error, lnx::hil::ParseError::kNone);
  EXPECT_EQ(r.used, 52u);
  EXPECT_EQ(r.frame.type, lnx::hil::FrameType::kLastSample);
  EXPECT_EQ(r.frame.index, 0xA0B0C0D0u);
  EXPECT_EQ(r.frame.sample.seq, s.seq);
  EXPECT_EQ(r.frame.sample.t_ns, s.t_ns);
  EXPECT_EQ(r.frame.sample.counts, s.counts);
  EXPECT_EQ(r.frame.sample.flags, s.flags);
}

TEST(HilWire, CanFrameLayoutBothWays) {
  hal::CanFrame f;
  f.id = 0x0C1;
  f.len = 8;
  f.data = {1, 2, 3, 4, 5, 6, 7, 8};
  for (const auto type : {lnx::hil::FrameType::kCan, lnx::hil::FrameType::kCanIn}) {
    const auto w = lnx::hil::encode_can(f, type);
    ASSERT_EQ(w.size(), 24u);
    EXPECT_EQ(w[2], static_cast<std::uint8_t>(type));  // 4: board -> host, 5: host -> board
    EXPECT_EQ(w[3], 24);
    EXPECT_EQ(w[4], 0xC1);  // identifier, little-endian
    EXPECT_EQ(w[5], 0x00);
    EXPECT_EQ(w[8], 8);  // length
    EXPECT_EQ(w[12], 1);
    EXPECT_EQ(w[19], 8);
    const auto r = lnx::hil::parse(w);
    ASSERT_EQ(r.error, lnx::hil::ParseError::kNone);
    EXPECT_EQ(r.frame.type, type);
    EXPECT_EQ(r.frame.can.id, 0x0C1u);
    EXPECT_EQ(r.frame.can.data, f.data);
  }
  EXPECT_EQ(lnx::hil::encode_can(f)[2], 4);  // the default: a frame the firmware published
}

TEST(HilWire, BadFramesAreNamed) {
  const auto good = lnx::hil::encode_sample(7, RawSample{}, false);
  auto bad_crc = good;
  bad_crc[25] ^= 0x10;
  EXPECT_EQ(lnx::hil::parse(bad_crc).error, lnx::hil::ParseError::kBadCrc);
  EXPECT_EQ(lnx::hil::parse(bad_crc).used, 52u);  // skipped whole: the stream stays in step
  auto bad_len = good;
  bad_len[3] = 40;
  EXPECT_EQ(lnx::hil::parse(bad_len).error, lnx::hil::ParseError::kBadLength);
  auto bad_magic = good;
  bad_magic[0] = 'X';
  EXPECT_EQ(lnx::hil::parse(bad_magic).error, lnx::hil::ParseError::kBadMagic);
  auto bad_type = good;
  bad_type[2] = 9;
  EXPECT_EQ(lnx::hil::parse(bad_type).error, lnx::hil::ParseError::kBadType);
  EXPECT_EQ(lnx::hil::parse(std::span(good).first(51)).error, lnx::hil::ParseError::kNeedMore);
}

// A frame whose CRC holds but whose fields the encoder never writes is refused, not read as
// something else (the fuzzer found an acknowledgement verdict 0x40 taken as a verdict, and CAN
// lengths over 8 clamped). The frames are resealed so only the field differs.
TEST(HilWire, FieldsTheEncoderNeverWritesAreRefused) {
  const auto reseal = [](auto w) {
    const std::uint32_t c = lnx::hil::crc32(std::span(w).first(w.size() - 4));
    for (std::size_t i = 0; i < 4; ++i)
      w[w.size() - 4 + i] = static_cast<std::uint8_t>(c >> (8 * i));
    return w;
  };
  const auto ack = lnx::hil::encode_ack(3, lnx::hil::AckVerdict::kBadCrc);
  ASSERT_EQ(lnx::hil::parse(ack).error, lnx::hil::ParseError::kNone);
  auto verdict = ack;
  verdict[8] = 2;  // verdicts: 0 ok, 1 bad CRC
  EXPECT_EQ(lnx::hil::parse(reseal(verdict)).error, lnx::hil::ParseError::kMalformed);
  auto ack_pad = ack;
  ack_pad[10] = 1;
  EXPECT_EQ(lnx::hil::parse(reseal(ack_pad)).error, lnx::hil::ParseError::kMalformed);

  hal::CanFrame f;
  f.id = 0x7FF;
  f.len = 8;
  const auto can = lnx::hil::encode_can(f);
  ASSERT_EQ(lnx::hil::parse(can).error, lnx::hil::ParseError::kNone);
  auto len9 = can;
  len9[8] = 9;
  EXPECT_EQ(lnx::hil::parse(reseal(len9)).error, lnx::hil::ParseError::kMalformed);
  auto id12 = can;
  id12[5] = 0x08;  // identifier 0x800: beyond 11 bits without the extended flag
  EXPECT_EQ(lnx::hil::parse(reseal(id12)).error, lnx::hil::ParseError::kMalformed);
  auto id30 = can;
  id30[7] = 0xA0;  // extended flag (bit 31) and bit 29: beyond 29 bits
  EXPECT_EQ(lnx::hil::parse(reseal(id30)).error, lnx::hil::ParseError::kMalformed);
  auto ext = can;
  ext[7] = 0x9F;  // extended, identifier 0x1F0007FF: the largest 29-bit range holds it
  EXPECT_EQ(lnx::hil::parse(reseal(ext)).error, lnx::hil::ParseError::kNone);
  auto can_pad = can;
  can_pad[11] = 0x80;
  EXPECT_EQ(lnx::hil::parse(reseal(can_pad)).error, lnx::hil::ParseError::kMalformed);
}

// ---- The firmware end's aiding frames, over loopback -------------------------------------------

// A frame from the host is the loop's only once the sample frame after it has been read: a
// read that times out between the two must not hand it over (the loop would apply it a cycle
// early). Frames with a bad CRC, and frames whose sample never comes, are lost and counted.
TEST(HilServerFrames, AFrameIsReceivedInTheCycleOfTheSampleAfterIt) {
  lnx::HilServerConfig cfg;
  auto server = lnx::HilServer::open(cfg);
  ASSERT_TRUE(server.is_ok()) << server.status().message();
  lnx::HilServer& srv = *server.value();
  auto client = lnx::HilClient::connect("127.0.0.1", srv.port());
  ASSERT_TRUE(client.is_ok()) << client.status().message();
  lnx::HilClient& host = *client.value();
  const auto can_in = [](std::uint32_t id) {
    hal::CanFrame f;
    f.id = id;
    f.len = 8;
    f.data[0] = static_cast<std::uint8_t>(id);
    return lnx::hil::encode_can(f, lnx::hil::FrameType::kCanIn);
  };
  constexpr std::int64_t kShortNs = 50000000, kLongNs = 2000000000;
  RawSample s;

  ASSERT_TRUE(host.send(can_in(0x0C1)).is_ok());
  EXPECT_EQ(srv.read_sample(kShortNs).status().code(), ErrorCode::kTimeout);
  EXPECT_EQ(srv.bus().receive(0).status().code(), ErrorCode::kTimeout);  // not before its sample
  ASSERT_TRUE(host.send(lnx::hil::encode_sample(0, s, false)).is_ok());
  ASSERT_TRUE(srv.read_sample(kLongNs).is_ok());
  const auto a = srv.bus().receive(0);
  ASSERT_TRUE(a.is_ok());
  EXPECT_EQ(a.value().id, 0x0C1u);
  EXPECT_EQ(srv.bus().receive(0).status().code(), ErrorCode::kTimeout);

  auto bad = can_in(0x0D1);
  bad[13] ^= 0x01;  // a data bit: the CRC no longer holds
  ASSERT_TRUE(host.send(bad).is_ok());
  ASSERT_TRUE(host.send(can_in(0x0E1)).is_ok());
  s.seq = 1;
  ASSERT_TRUE(host.send(lnx::hil::encode_sample(1, s, false)).is_ok());
  ASSERT_TRUE(srv.read_sample(kLongNs).is_ok());  // the bad frame skipped, the stream in step
  const auto b = srv.bus().receive(0);
  ASSERT_TRUE(b.is_ok());
  EXPECT_EQ(b.value().id, 0x0E1u);
  EXPECT_EQ(srv.counters().can_in, 2u);
  EXPECT_EQ(srv.counters().can_in_lost, 1u);
  EXPECT_EQ(srv.counters().crc_errors, 0u);  // a sample CRC error is another count

  // A frame whose sample never comes: the connection ends first.
  ASSERT_TRUE(host.send(can_in(0x0F1)).is_ok());
  EXPECT_EQ(srv.read_sample(kShortNs).status().code(), ErrorCode::kTimeout);  // read, pending
  host.abort();
  for (int i = 0; i < 40 && srv.connected(); ++i) (void)srv.read_sample(kShortNs);
  EXPECT_FALSE(srv.connected());
  EXPECT_EQ(srv.bus().receive(0).status().code(), ErrorCode::kTimeout);
  EXPECT_EQ(srv.counters().can_in_lost, 2u);
}

// ---- End to end -------------------------------------------------------------------------------

class HilReplay : public test::CliTest {
 protected:
  void TearDown() override {
    // A test that failed before the stream ended leaves the firmware waiting: stop it.
    if (fw_.child.pid > 0 && !fw_done_) {
      (void)lnx::signal_program(fw_.child, SIGTERM);
      (void)fw_result();
    }
  }

  // gfins-fw --board hil on an ephemeral loopback port, with EXTRA arguments; returns the port
  // it bound.
  int start_firmware(const std::vector<std::string>& extra = {}) {
    std::vector<std::string> args = {"--board",         "hil",        "--hil-port", "0",
                                     "--hil-port-file", path("port"), "--watchdog", "none"};
    args.insert(args.end(), extra.begin(), extra.end());
    fs::remove(dir() / "port");
    fw_done_ = false;
    fw_ = test::start_tool(GFINS_FW_EXE, args, dir() / "fw");
    // Readiness, not timing: the port file appears once the socket listens (written whole and
    // renamed). The bound only keeps a broken build from hanging the suite.
    for (int i = 0; i < 6000 && !fs::exists(dir() / "port"); ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    std::ifstream f(dir() / "port");
    int port = 0;
    f >> port;
    return port;
  }

  /// gfins-can hil --port PORT EXTRA..., its output in dir()/log_name.
  test::CliResult run_host(int port, const std::vector<std::string>& extra,
                           const std::string& log_name) const {
    std::vector<std::string> args = {"hil", "--port", std::to_string(port)};
    args.insert(args.end(), extra.begin(), extra.end());
    return test::run_tool(GFINS_CAN_EXE, args, dir() / log_name);
  }

  /// Waits for the firmware to end (once): its exit code and output.
  const test::CliResult& fw_result() {
    if (!fw_done_) {
      fw_exit_ = test::finish_tool(fw_);
      fw_done_ = true;
    }
    return fw_exit_;
  }

  test::StartedTool fw_;
  test::CliResult fw_exit_;
  bool fw_done_ = false;
};

// The firmware's default output dividers (docs/can-interface.md): one epoch every 10 samples.
constexpr int kEpochDivider = 10;
constexpr int kRate = 1000;                     // Hz, the firmware's default adc.sample_rate_hz
constexpr int kSeconds = 3;                     // a few seconds of a moving scenario
constexpr int kSamples = kSeconds * kRate + 1;  // samples 0..3000
constexpr int kEpochs = (kSamples - 1) / kEpochDivider + 1;  // seq 0, 10, ..., 3000

TEST_F(HilReplay, EveryEpochArrivesAndEqualsTheHostCoreRun) {
  const int port = start_firmware();
  ASSERT_GT(port, 0) << fw_result().output;
  const auto host = run_host(port,
                             {"--scenario", "maneuver", "--scenario-dir", GFINS_SCENARIO_DIR,
                              "--duration", std::to_string(kSeconds)},
                             "host");
  const std::string& out = host.output;
  EXPECT_EQ(host.exit_code, 0) << out;
  const std::string n = std::to_string(kSamples), e = std::to_string(kEpochs);
  EXPECT_NE(out.find("sent " + n + ", acknowledged " + n + ", rejected 0"), std::string::npos)
      << out;
  EXPECT_NE(out.find("epochs: expected " + e + ", decoded " + e + ", matching no sample 0"),
            std::string::npos)
      << out;
  EXPECT_NE(out.find("outside quantisation 0"), std::string::npos) << out;
  // Counters continuous, CRCs valid: the decoder found no problem at all.
  EXPECT_NE(out.find("problems 0"), std::string::npos) << out;
  EXPECT_NE(out.find("IDENTICAL"), std::string::npos) << out;
  const std::string& log = fw_result().output;
  EXPECT_EQ(fw_result().exit_code, 0) << log;
  EXPECT_NE(log.find("stopped after " + n + " samples"), std::string::npos) << log;
  EXPECT_NE(log.find("1 connection(s), 0 dropped, " + n + " samples, 0 CRC errors"),
            std::string::npos)
      << log;
}

TEST_F(HilReplay, AKilledConnectionIsReportedAndTheFirmwareCarriesOn) {
  const int port = start_firmware();
  ASSERT_GT(port, 0) << fw_result().output;
  constexpr int kAbortAfter = 1500;
  const auto cut =
      run_host(port,
               {"--scenario", "maneuver", "--scenario-dir", GFINS_SCENARIO_DIR, "--duration",
                std::to_string(kSeconds), "--abort-after", std::to_string(kAbortAfter)},
               "cut");
  const std::string& out = cut.output;
  EXPECT_EQ(cut.exit_code, 8) << out;  // gfins-can --help: 8 hil DIFFERENT or INCOMPLETE
  EXPECT_NE(out.find("INCOMPLETE: connection reset by this host after " +
                     std::to_string(kAbortAfter) + " sample(s)"),
            std::string::npos)
      << out;
  EXPECT_NE(out.find("of " + std::to_string(kEpochs) + " epochs"), std::string::npos) << out;
  // The firmware kept its loop: a second host connects, sends a short stream with one corrupted
  // sample frame, which is refused and counted; the run ends after that stream's last sample.
  const auto second = run_host(port,
                               {"--scenario", "maneuver", "--scenario-dir", GFINS_SCENARIO_DIR,
                                "--duration", "0.05", "--corrupt-at", "5"},
                               "second");
  const std::string& out2 = second.output;
  EXPECT_EQ(second.exit_code, 8) << out2;
  EXPECT_NE(out2.find("board rejected sample 5 (bad CRC on the link)"), std::string::npos) << out2;
  const std::string& log = fw_result().output;
  EXPECT_EQ(fw_result().exit_code, 0) << log;
  // The first connection ended after its sample 1499 (the host may have had up to a window
  // more in flight, all delivered before the reset).
  EXPECT_NE(log.find("2 connection(s), 1 dropped"), std::string::npos) << log;
  EXPECT_NE(log.find("1 CRC errors"), std::string::npos) << log;
  // Counters continuous across the reconnection: the one sample missing from the loop's
  // sequence is the corrupted one (the second stream continues the first, docs/hil.md).
  EXPECT_NE(log.find("health: missed edges 1,"), std::string::npos) << log;
}

TEST_F(HilReplay, ARecordedStreamReplaysIdentically) {
  // A recording written here: 2 s of codes that move (a slow ramp on every channel, different
  // per channel), so the navigation state changes from epoch to epoch.
  constexpr int kRecSamples = 2 * kRate + 1;
  std::vector<RawSample> samples(kRecSamples);
  for (int k = 0; k < kRecSamples; ++k) {
    RawSample& s = samples[static_cast<std::size_t>(k)];
    s.seq = static_cast<std::uint32_t>(k);
    s.t_ns = static_cast<std::int64_t>(k) * 1000000;
    for (int j = 0; j < 6; ++j)
      s.counts[static_cast<std::size_t>(j)] = 100000 * (j - 2) + k * (j + 1);
  }
  sim::RecordingHeader h;
  h.sample_rate_hz = kRate;
  const fs::path rec = dir() / "stream.gfr";
  // Two frame records among them (a recording the firmware made holds what its loop received):
  // node 1's GNSS input identifiers with all-zero data, which no aiding input takes (the
  // firmware's defaults have the aiding inputs off): they stay on the host, said so.
  const std::vector<sim::RecordedFrame> frames = {{100, {99000000, 0x0C1, false, 8, {}}},
                                                  {1500, {1499000000, 0x0D1, false, 8, {}}}};
  const auto image = sim::encode_recording(h, samples, frames);
  ASSERT_TRUE(image.is_ok()) << image.error().message;
  {
    std::FILE* f = std::fopen(rec.string().c_str(), "wb");
    ASSERT_NE(f, nullptr);
    ASSERT_EQ(std::fwrite(image.value().data(), 1, image.value().size(), f), image.value().size());
    ASSERT_EQ(std::fclose(f), 0);
  }
  const int port = start_firmware();
  ASSERT_GT(port, 0) << fw_result().output;
  const auto host = run_host(port, {"--recording", rec.string()}, "rec");
  const std::string& out = host.output;
  EXPECT_EQ(host.exit_code, 0) << out;
  EXPECT_NE(out.find("2 of the 2 recorded CAN frames are not aiding inputs of node 1 (aiding "
                     "inputs are off"),
            std::string::npos)
      << out;
  EXPECT_NE(out.find("aiding frames: 0 in the recording, 0 sent"), std::string::npos) << out;
  const std::string e = std::to_string((kRecSamples - 1) / kEpochDivider + 1);
  EXPECT_NE(out.find("epochs: expected " + e + ", decoded " + e), std::string::npos) << out;
  EXPECT_NE(out.find("outside quantisation 0"), std::string::npos) << out;
  EXPECT_NE(out.find("IDENTICAL"), std::string::npos) << out;
  const std::string& log = fw_result().output;
  EXPECT_NE(log.find("stopped after " + std::to_string(kRecSamples) + " samples"),
            std::string::npos)
      << log;
}

// An aided drive recorded by the firmware on the simulated board (its receiver's GNSS fixes
// arriving as CAN input frames, the board aligning in motion from them) replays through the
// link with its aiding: the hil board receives each fix's frames in the cycle the recording
// board did, and every published value equals the host-only run that applies the same frames
// (docs/hil.md, "Aiding frames"). The negative control leaves one frame of an early fix off the
// link while the host-only run still applies it: the board's navigation then differs.
TEST_F(HilReplay, AnAidedDriveReplaysWithItsGnssFrames) {
  constexpr int kDriveSeconds = 5;
  const std::string cal = path("board-cal.toml");
  test::save_scenario_calibration("drive-gnss", GFINS_SCENARIO_DIR, cal);
  // One configuration for the recording board, the hil board and the host-only run.
  const std::string cfg = file("vehicle.toml",
                               "[aiding]\nenabled = true\ntrack_heading_sigma_deg = 0.5\n"
                               "gnss_lever_arm_m = [-1.0, 0.0, -1.2]\n[calibration]\nfile = \"" +
                                   cal + "\"\n");
  const std::string rec = path("drive.gfr");
  const auto made =
      test::run_tool(GFINS_FW_EXE,
                     {"--config", cfg, "--sim", "drive-gnss", "--scenario-dir", GFINS_SCENARIO_DIR,
                      "--record", rec, "--can-log", path("live.log"), "--duration",
                      std::to_string(kDriveSeconds), "--watchdog", "none"},
                     dir() / "record");
  ASSERT_EQ(made.exit_code, 0) << made.output;
  const auto r = sim::read_recording(rec);
  ASSERT_TRUE(r.is_ok()) << r.error().message;
  // 10 Hz fixes of four frames each over 5 s (the scenario's receiver): about 200 frames.
  const std::size_t n_frames = r.value().frames.size();
  ASSERT_GE(n_frames, 196u);
  ASSERT_LE(n_frames, 204u);
  const std::string nf = std::to_string(n_frames);

  int port = start_firmware({"--config", cfg});
  ASSERT_GT(port, 0) << fw_result().output;
  const auto host = run_host(port, {"--recording", rec, "--fw-config", cfg}, "aided");
  EXPECT_EQ(host.exit_code, 0) << host.output;
  EXPECT_NE(host.output.find("aiding frames: " + nf + " in the recording, " + nf + " sent"),
            std::string::npos)
      << host.output;
  EXPECT_NE(host.output.find("outside quantisation 0"), std::string::npos) << host.output;
  EXPECT_NE(host.output.find("IDENTICAL"), std::string::npos) << host.output;
  const std::string& log = fw_result().output;
  EXPECT_EQ(fw_result().exit_code, 0) << log;

  // Frame 40 is the first of fix 10 (1 s into the drive).
  port = start_firmware({"--config", cfg});
  ASSERT_GT(port, 0) << fw_result().output;
  const auto lost =
      run_host(port, {"--recording", rec, "--fw-config", cfg, "--drop-frame", "40"}, "lost");
  EXPECT_EQ(lost.exit_code, 8) << lost.output;
  EXPECT_NE(lost.output.find("in the recording, " + std::to_string(n_frames - 1) + " sent"),
            std::string::npos)
      << lost.output;
  EXPECT_NE(lost.output.find("DIFFERENT"), std::string::npos) << lost.output;
  EXPECT_EQ(fw_result().exit_code, 0) << fw_result().output;
}

}  // namespace
}  // namespace gfins
