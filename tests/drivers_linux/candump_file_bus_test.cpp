// The candump log the file bus writes: the exact text (written out in the test, including the
// microsecond truncation), what Debian's
// can-utils make of it (log2asc, an independent parser), and what happens when the disk is full.
#include "gfins/drivers/lnx/candump_file_bus.hpp"

#include <fcntl.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <spawn.h>
#include <stdlib.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "gfins/drivers/lnx/candump.hpp"
#include "support/fake_clock.hpp"
#include "support/temp_dir.hpp"

extern char** environ;

namespace gfins::drivers::lnx {
namespace {

using ::testing::HasSubstr;

using SimClock = gfins::testing::FakeClock;
/// A temporary folder named for these tests (tests/support/temp_dir.hpp).
class TempDir : public gfins::testing::TempDir {
 public:
  TempDir() : gfins::testing::TempDir("gfins-candump") {}
};
using gfins::testing::read_text;

hal::CanFrame make(std::uint32_t id, bool ext, std::vector<std::uint8_t> bytes) {
  hal::CanFrame f;
  f.id = id;
  f.extended = ext;
  f.len = static_cast<std::uint8_t>(bytes.size());
  for (std::size_t i = 0; i < bytes.size(); ++i) f.data[i] = bytes[i];
  return f;
}

// The three frames every file test sends, and the log text they must produce.
void send_three(hal::CanBus& bus, SimClock& clock) {
  clock.t_ns = 1000250000;
  ASSERT_TRUE(bus.send(make(0x123, false, {0x01, 0x02, 0xA0, 0xFF})).is_ok());
  clock.t_ns = 1500000000;
  ASSERT_TRUE(bus.send(make(0x1ABCDEF0, true, {})).is_ok());
  clock.t_ns = 2000001999;  // 2.000001999 s: candump truncates to 2.000001
  ASSERT_TRUE(
      bus.send(make(0x7FF, false, {0x00, 0x11, 0x22, 0x33, 0x44, 0x55, 0x66, 0x77})).is_ok());
}
constexpr const char* kThreeLines =
    "(0000000001.000250) can0 123#0102A0FF\n"
    "(0000000001.500000) can0 1ABCDEF0#\n"
    "(0000000002.000001) can0 7FF#0011223344556677\n";

TEST(CandumpFileBus, WritesOneLinePerSentFrameStampedByTheGivenClock) {
  const TempDir dir;
  const auto path = (dir.path() / "out.log").string();
  SimClock clock;
  {
    auto bus = CandumpFileBus::open({.path = path, .interface = "can0"}, clock);
    ASSERT_TRUE(bus.is_ok()) << bus.status().message();
    send_three(*bus.value(), clock);
    ASSERT_TRUE(bus.value()->flush().is_ok());
    EXPECT_EQ(bus.value()->counters().tx_frames, 3u);
  }
  EXPECT_EQ(read_text(path), kThreeLines);
}

TEST(CandumpFileBus, LinesStayBufferedUntilTheFlushIntervalOrTheBufferFills) {
  const TempDir dir;
  const auto path = (dir.path() / "out.log").string();
  SimClock clock;
  auto bus = CandumpFileBus::open({.path = path,
                                   .interface = "can0",
                                   .buffer_bytes = 4 * CandumpFileBus::kLineMax,
                                   .flush_interval_ns = 1000000000},
                                  clock);
  ASSERT_TRUE(bus.is_ok());
  send_three(*bus.value(), clock);
  bus.value()->service();  // t = 2.000001 s >= 1 s after open at t = 0: written
  EXPECT_EQ(read_text(path), kThreeLines);
  clock.t_ns = 2500000000;
  ASSERT_TRUE(bus.value()->send(make(0x1, false, {})).is_ok());
  bus.value()->service();  // 0.5 s after the last write: kept
  EXPECT_EQ(read_text(path), kThreeLines);
  for (int i = 0; i < 10; ++i) ASSERT_TRUE(bus.value()->send(make(0x2, false, {})).is_ok());
  // eleven 30-byte lines do not fit in 388 bytes: the buffer was written when it filled
  EXPECT_GT(read_text(path).size(), std::string(kThreeLines).size());
  EXPECT_EQ(bus.value()->receive(1000000).status().code(), ErrorCode::kTimeout);
}

// Runs a program without a shell; returns its exit status.
int run(const std::vector<std::string>& argv) {
  std::vector<char*> args;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  pid_t pid = 0;
  if (::posix_spawn(&pid, args[0], nullptr, nullptr, args.data(), environ) != 0) return -1;
  int status = 0;
  if (::waitpid(pid, &status, 0) != pid) return -1;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(CandumpFileBus, CanUtilsLog2ascReadsTheLogBackToTheSameFrames) {
  const TempDir dir;
  const auto log = (dir.path() / "out.log").string();
  const auto asc = (dir.path() / "out.asc").string();
  SimClock clock;
  {
    auto bus = CandumpFileBus::open({.path = log, .interface = "can0"}, clock);
    ASSERT_TRUE(bus.is_ok());
    send_three(*bus.value(), clock);
  }  // destruction flushes
  ASSERT_EQ(run({GFINS_LOG2ASC, "-I", log, "-O", asc, "can0"}), 0);
  // Vector ASC, as can-utils 2020.11 writes it: times relative to the first frame, channel 1,
  // "x" after an extended id, the length then the bytes.
  const std::string text = read_text(asc);
  const std::string body = text.substr(text.find("no internal events logged\n") + 26);
  EXPECT_EQ(body,
            "   0.000000 1  123             Rx   d 4 01 02 A0 FF\n"
            "   0.499750 1  1ABCDEF0x       Rx   d 0\n"
            "   0.999751 1  7FF             Rx   d 8 00 11 22 33 44 55 66 77\n");
}

// A simulation's offset: its clock starts at 0, its log at kSimulatedLogEpochS. log2asc (can-utils)
// writes its "date" header once for such a log; for one starting at 0 it repeated it (903 times
// for 2 s of gfins-fw --sim). An offset that could overflow the nanoseconds is refused.
TEST(CandumpFileBus, ASimulationsLogStartsAtTheDocumentedEpochAndLog2ascReadsItWithOneHeader) {
  const TempDir dir;
  const auto log = (dir.path() / "sim.log").string();
  const auto asc = (dir.path() / "sim.asc").string();
  SimClock clock;
  const std::int64_t epoch_ns = kSimulatedLogEpochS * 1000000000;
  {
    auto bus =
        CandumpFileBus::open({.path = log, .interface = "can0", .time_offset_ns = epoch_ns}, clock);
    ASSERT_TRUE(bus.is_ok()) << bus.status().message();
    send_three(*bus.value(), clock);
  }
  EXPECT_EQ(read_text(log),
            "(1700000001.000250) can0 123#0102A0FF\n"
            "(1700000001.500000) can0 1ABCDEF0#\n"
            "(1700000002.000001) can0 7FF#0011223344556677\n");
  ASSERT_EQ(run({GFINS_LOG2ASC, "-I", log, "-O", asc, "can0"}), 0);
  const std::string text = read_text(asc);
  std::size_t headers = 0;
  for (std::size_t at = text.find("date "); at != std::string::npos;
       at = text.find("date ", at + 1)) {
    ++headers;
  }
  EXPECT_EQ(headers, 1U) << text;
  for (const std::int64_t bad : {std::int64_t{-1}, std::int64_t{4000000001} * 1000000000}) {
    EXPECT_EQ(CandumpFileBus::open({.path = log, .time_offset_ns = bad}, clock).status().code(),
              ErrorCode::kInvalidArgument);
  }
}

TEST(CandumpFileBus, ADiskThatIsFullDropsAndCountsTheFramesAndNeverCrashes) {
  // /dev/full answers every write with ENOSPC: the real kernel's disk-full path.
  if (::access("/dev/full", W_OK) != 0) GTEST_SKIP() << "no /dev/full";
  SimClock clock;
  auto bus = CandumpFileBus::open({.path = "/dev/full", .interface = "can0"}, clock);
  ASSERT_TRUE(bus.is_ok()) << bus.status().message();
  send_three(*bus.value(), clock);
  const Status s = bus.value()->flush();
  EXPECT_EQ(s.code(), ErrorCode::kIoError);
  EXPECT_EQ(s.os_error(), ENOSPC);
  EXPECT_THAT(s.message(), HasSubstr("disk full"));
  EXPECT_EQ(bus.value()->counters().tx_dropped, 3u);
  EXPECT_EQ(bus.value()->counters().tx_frames, 0u);
  EXPECT_EQ(bus.value()->write_errors(), 1u);
  // And the bus keeps accepting frames afterwards
  EXPECT_TRUE(bus.value()->send(make(0x1, false, {})).is_ok());
}

// The real kernel, but the disk fills after `room` bytes.
class FillingOs : public Os {
 public:
  explicit FillingOs(std::size_t room) : room_(room) {}
  long write(int fd, const void* b, std::size_t n) override {
    if (room_ == 0) {
      errno = ENOSPC;
      return -1;
    }
    const std::size_t k = n < room_ ? n : room_;
    room_ -= k;
    return Os::write(fd, b, k);
  }

 private:
  std::size_t room_;
};

TEST(CandumpFileBus, APartlyWrittenLineIsCutSoTheFileStaysAValidLog) {
  const TempDir dir;
  const auto path = (dir.path() / "out.log").string();
  SimClock clock;
  const std::string first = "(0000000001.000250) can0 123#0102A0FF\n";
  FillingOs os(first.size() + 10);  // the disk fills 10 bytes into the second line
  {
    auto bus = CandumpFileBus::open({.path = path, .interface = "can0"}, clock, os);
    ASSERT_TRUE(bus.is_ok());
    send_three(*bus.value(), clock);
    EXPECT_EQ(bus.value()->flush().os_error(), ENOSPC);
    EXPECT_EQ(bus.value()->counters().tx_frames, 1u);
    EXPECT_EQ(bus.value()->counters().tx_dropped, 2u);
  }
  EXPECT_EQ(read_text(path), first);
}

// The real kernel, but every write() waits until the test opens the gate, and says which thread
// called it.
class GatedOs : public Os {
 public:
  long write(int fd, const void* b, std::size_t n) override {
    writer_thread = std::this_thread::get_id();
    calls.fetch_add(1);
    while (!open.load()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    return Os::write(fd, b, n);
  }
  std::atomic<bool> open{false};
  std::atomic<int> calls{0};
  std::thread::id writer_thread{};
};

TEST(CandumpFileBus, BackgroundWriterKeepsFileWritesOffTheCallersThreadAndNeverWaits) {
  const TempDir dir;
  const auto path = (dir.path() / "out.log").string();
  SimClock clock;
  GatedOs os;
  // Buffers of 4 line maxima; each line "(0000000000.000000) can0 123#01\n" is 32 bytes and a
  // buffer is handed over when less than one line maximum is left: L lines per buffer.
  constexpr std::size_t kLine = 32;
  constexpr std::size_t kCapacity = 4 * CandumpFileBus::kLineMax;
  constexpr std::size_t kLinesPerBuffer = (kCapacity - CandumpFileBus::kLineMax) / kLine + 1;
  auto bus = CandumpFileBus::open(
      {.path = path, .interface = "can0", .buffer_bytes = kCapacity, .background_writer = true},
      clock, os);
  ASSERT_TRUE(bus.is_ok()) << bus.status().message();
  // Whatever fails below, the disk answers before the bus is destroyed (its flush would wait).
  struct OpenAtExit {
    GatedOs& os;
    ~OpenAtExit() { os.open.store(true); }
  } open_at_exit{os};
  const hal::CanFrame f = make(0x123, false, {0x01});
  // The first buffer fills and goes to the writer, whose write() hangs; the second fills; the
  // next frame finds the writer still busy: dropped, counted, and send() returned at once.
  std::size_t accepted = 0;
  Status refused;
  for (int i = 0; i < 100; ++i) {
    const Status st = bus.value()->send(f);
    if (!st.is_ok()) {
      refused = st;
      break;
    }
    ++accepted;
  }
  EXPECT_EQ(accepted, 2 * kLinesPerBuffer);
  EXPECT_EQ(refused.code(), ErrorCode::kResourceExhausted);
  EXPECT_EQ(bus.value()->counters().tx_dropped, 1u);
  for (int i = 0; i < 5000 && os.calls.load() == 0; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  ASSERT_GT(os.calls.load(), 0) << "the writer thread never wrote";
  EXPECT_NE(os.writer_thread, std::this_thread::get_id());  // not the caller's thread
  EXPECT_EQ(read_text(path), "");                           // nothing written yet
  // The disk answers: flush() waits for both buffers, every accepted line is in the file.
  os.open.store(true);
  ASSERT_TRUE(bus.value()->flush().is_ok());
  EXPECT_EQ(bus.value()->counters().tx_frames, accepted);
  const std::string text = read_text(path);
  EXPECT_EQ(static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n')), accepted);
}

TEST(CandumpFileBus, BackgroundWriterReportsADiskThatIsFull) {
  if (::access("/dev/full", W_OK) != 0) GTEST_SKIP() << "no /dev/full";
  SimClock clock;
  auto bus = CandumpFileBus::open(
      {.path = "/dev/full", .interface = "can0", .background_writer = true}, clock);
  ASSERT_TRUE(bus.is_ok());
  send_three(*bus.value(), clock);
  const Status s = bus.value()->flush();
  EXPECT_EQ(s.os_error(), ENOSPC);
  EXPECT_EQ(bus.value()->counters().tx_dropped, 3u);
  EXPECT_EQ(bus.value()->write_errors(), 1u);
  EXPECT_EQ(bus.value()->last_error().os_error(), ENOSPC);
}

TEST(CandumpFileBus, AFileThatCannotBeCreatedIsAnIoErrorWithErrno) {
  SimClock clock;
  auto bus = CandumpFileBus::open({.path = "/nonexistent-dir/out.log"}, clock);
  EXPECT_EQ(bus.status().code(), ErrorCode::kIoError);
  EXPECT_EQ(bus.status().os_error(), ENOENT);
  EXPECT_EQ(CandumpFileBus::open({.path = "x", .interface = "has space"}, clock).status().code(),
            ErrorCode::kInvalidArgument);
}

}  // namespace
}  // namespace gfins::drivers::lnx
