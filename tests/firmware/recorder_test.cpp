// The board's raw-sample recorder (gfins/app/recorder.hpp; docs/replay.md, "Recording on the
// board"): the sample loop on the simulated board with a recorder attached, the file read back
// with the host's reader. The oracles are what went into the loop, taken apart from the recorder:
// the samples the loop read (a tap in front of it) and the frames the test put on the bus.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "gfins/app/recorder.hpp"
#include "gfins/host_sim/recording.hpp"
#include "sim_rig.hpp"

namespace gfins::app {
namespace {

using testing::SimRig;

std::string temp_path(const char* name) {
  return (std::filesystem::temp_directory_path() / (std::string("gfins_recorder_") + name))
      .string();
}

// A recorder on `path` attached to the rig's loop (header as gfins-fw writes it); null (and a
// test failure) when it cannot be opened.
std::unique_ptr<Recorder> attach(SimRig& rig, const std::string& path) {
  Recorder::Opened opened = Recorder::open(path, testing::recording_header(rig));
  EXPECT_TRUE(opened.recorder) << opened.error;
  if (opened.recorder) rig.loop->set_recorder(&opened.recorder->queue());
  return std::move(opened.recorder);
}

hal::CanFrame frame(std::uint32_t id, std::uint8_t len, std::uint8_t first) {
  hal::CanFrame f;
  f.id = id;
  f.len = len;
  for (std::uint8_t i = 0; i < len; ++i) f.data[i] = static_cast<std::uint8_t>(first + i);
  return f;
}

TEST(Recorder, TheLoopsSamplesAndReceivedFramesLandInTheFileInTheirOrder) {
  // Given the loop on the simulated board with a recorder, and frames put on its bus before
  // cycles 5, 400 (two) and 900: frames of no interest to the board (other nodes' identifiers),
  // which it reads and ignores,
  SimRig rig("rest", 1.0);
  rig.configure();
  const std::string path = temp_path("order.gfr");
  const std::unique_ptr<Recorder> recorder = attach(rig, path);
  ASSERT_TRUE(recorder);
  Recorder& rec = *recorder;
  struct Sent {
    std::uint32_t cycle;
    hal::CanFrame f;
  };
  const std::vector<Sent> sent = {{5, frame(0x7E5, 3, 1)},
                                  {400, frame(0x123, 8, 10)},
                                  {400, frame(0x124, 0, 0)},
                                  {900, frame(0x7FF, 1, 0xAB)}};
  std::size_t next = 0;
  for (std::uint32_t cycle = 0; !rig.source->finished(); ++cycle) {
    for (; next < sent.size() && sent[next].cycle == cycle; ++next) {
      ASSERT_TRUE(rig.bus->inject_rx(sent[next].f));
    }
    rig.loop->step();
    if (cycle % 100 == 0) rec.drain();  // as the writer thread would, now and then
  }
  ASSERT_EQ(rec.stop(), "");
  // when the file is read back,
  const auto r = sim::read_recording(path);
  ASSERT_TRUE(r.is_ok()) << r.error().message;
  // then it holds every sample the loop read, bit for bit, and each frame after the sample of
  // the cycle that received it, with that sample's time,
  const std::vector<RawSample>& want = rig.tap->samples();
  ASSERT_EQ(r.value().samples.size(), want.size());
  for (std::size_t i = 0; i < want.size(); ++i) {
    EXPECT_EQ(r.value().samples[i].seq, want[i].seq);
    EXPECT_EQ(r.value().samples[i].t_ns, want[i].t_ns);
    EXPECT_EQ(r.value().samples[i].counts, want[i].counts);
    EXPECT_EQ(r.value().samples[i].flags, want[i].flags);
  }
  ASSERT_EQ(r.value().frames.size(), sent.size());
  for (std::size_t k = 0; k < sent.size(); ++k) {
    const sim::RecordedFrame& f = r.value().frames[k];
    EXPECT_EQ(f.samples_before, sent[k].cycle + 1u) << k;
    EXPECT_EQ(f.frame.t_ns, want[sent[k].cycle].t_ns) << k;
    EXPECT_EQ(f.frame.id, sent[k].f.id) << k;
    EXPECT_EQ(f.frame.len, sent[k].f.len) << k;
    EXPECT_EQ(f.frame.data, sent[k].f.data) << k;
  }
  // and the header counts every record and carries the chain's LSB and the rate.
  EXPECT_EQ(r.value().header.record_count, want.size() + sent.size());
  EXPECT_EQ(r.value().header.volts_per_count[0], rig.adc->volts_per_count());
  EXPECT_EQ(r.value().header.sample_rate_hz, rig.s.rate_hz);
  EXPECT_EQ(rig.loop->health().record_dropped, 0u);
  std::filesystem::remove(path);
}

TEST(Recorder, AFullQueueIsCountedLoggedAndReportedAtTheEnd) {
  // Given a recorder whose writer never runs while the loop reads 9 s of samples (9001: more
  // than the queue's 8192 records),
  SimRig rig("rest", 9.0);
  rig.configure();
  const std::string path = temp_path("full.gfr");
  const std::unique_ptr<Recorder> recorder = attach(rig, path);
  ASSERT_TRUE(recorder);
  rig.run();
  // then the loop kept its pace and counted each record it could not queue,
  const std::uint32_t lost = rig.samples - static_cast<std::uint32_t>(kRecordQueueCapacity);
  EXPECT_EQ(rig.loop->health().record_dropped, lost);
  EXPECT_EQ(rig.loop->health().samples, rig.samples);
  bool logged = false;
  for (const std::string& line : rig.drain_log()) {
    logged = logged || line.find("recorder queue full") != std::string::npos;
  }
  EXPECT_TRUE(logged);
  // and the end says the recording has holes, while the records queued reach the file.
  const std::string e = recorder->stop();
  EXPECT_NE(e.find(std::to_string(lost) + " records lost"), std::string::npos) << e;
  const auto r = sim::read_recording(path);
  ASSERT_TRUE(r.is_ok()) << r.error().message;
  EXPECT_EQ(r.value().samples.size(), kRecordQueueCapacity);
  std::filesystem::remove(path);
}

TEST(Recorder, AFileThatCannotBeWrittenIsAnErrorNamingIt) {
  // Given a device that refuses every write (/dev/full: ENOSPC), then opening fails with the
  // path and the reason; and a folder that does not exist fails at once.
  recording::Header h;
  h.volts_per_count.fill(1e-6);
  h.geometry = nav::table1_geometry(0.1);
  if (std::FILE* f = std::fopen("/dev/full", "wb"); f != nullptr) {
    (void)std::fclose(f);
    const Recorder::Opened full = Recorder::open("/dev/full", h);
    EXPECT_FALSE(full.recorder);
    EXPECT_NE(full.error.find("/dev/full"), std::string::npos) << full.error;
  }
  const Recorder::Opened missing = Recorder::open("/nonexistent-folder/x.gfr", h);
  EXPECT_FALSE(missing.recorder);
  EXPECT_NE(missing.error.find("cannot create /nonexistent-folder/x.gfr"), std::string::npos)
      << missing.error;
}

}  // namespace
}  // namespace gfins::app
