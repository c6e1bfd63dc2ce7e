// SystemdWatchdog through the real libsystemd to a notification socket the test owns (what
// systemd would receive), DevWatchdog and MonotonicClock against a fake kernel, and the
// real-time helpers' error paths.
#include <fcntl.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <linux/watchdog.h>
#include <stdlib.h>
#include <sys/mman.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <time.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>
#include <vector>

#include "drivers_linux/fake_os.hpp"
#include "gfins/drivers/lnx/dev_watchdog.hpp"
#include "gfins/drivers/lnx/monotonic_clock.hpp"
#include "gfins/drivers/lnx/realtime.hpp"
#include "gfins/drivers/lnx/systemd_watchdog.hpp"
#include "support/fake_clock.hpp"

namespace gfins::drivers::lnx {
namespace {

using testing::fail_with;
using testing::FakeOs;
using ::testing::HasSubstr;

using SimClock = gfins::testing::FakeClock;

// Plays systemd: a datagram socket at $NOTIFY_SOCKET and the watchdog variables of a unit with
// WatchdogSec=100ms, restored afterwards.
class NotifySocket {
 public:
  explicit NotifySocket(const char* watchdog_usec) {
    path_ = "/tmp/gfins-notify-" + std::to_string(::getpid());
    ::unlink(path_.c_str());
    fd_ = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
    sockaddr_un a{};
    a.sun_family = AF_UNIX;
    std::memcpy(a.sun_path, path_.c_str(), path_.size() + 1);
    bound_ = ::bind(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0;
    ::setenv("NOTIFY_SOCKET", path_.c_str(), 1);
    ::setenv("WATCHDOG_USEC", watchdog_usec, 1);
    ::setenv("WATCHDOG_PID", std::to_string(::getpid()).c_str(), 1);
  }
  NotifySocket(const NotifySocket&) = delete;
  NotifySocket& operator=(const NotifySocket&) = delete;
  ~NotifySocket() {
    ::unsetenv("NOTIFY_SOCKET");
    ::unsetenv("WATCHDOG_USEC");
    ::unsetenv("WATCHDOG_PID");
    ::close(fd_);
    ::unlink(path_.c_str());
  }
  bool bound() const { return bound_; }
  // Every message received so far.
  std::vector<std::string> messages() {
    std::vector<std::string> out;
    char buf[512];
    for (;;) {
      const ssize_t n = ::recv(fd_, buf, sizeof buf, 0);
      if (n < 0) break;
      out.emplace_back(buf, static_cast<std::size_t>(n));
    }
    return out;
  }

 private:
  std::string path_;
  int fd_ = -1;
  bool bound_ = false;
};

TEST(SystemdWatchdog, SendsReadyStatusAndWatchdogPingsAtHalfTheInterval) {
  NotifySocket systemd("100000");  // WatchdogSec=100ms
  ASSERT_TRUE(systemd.bound());
  SimClock clock;
  auto w = SystemdWatchdog::open(clock);
  ASSERT_TRUE(w.is_ok()) << w.status().message();
  EXPECT_TRUE(w.value()->under_systemd());
  EXPECT_EQ(w.value()->kick_interval_ns(), 50000000);  // half of 100 ms, sd_watchdog_enabled(3)
  ASSERT_TRUE(w.value()->notify_ready().is_ok());
  ASSERT_TRUE(w.value()->notify_status("navigating\nmode 2").is_ok());
  // Kicked every millisecond for 120 ms: pings at 0, 50 and 100 ms only
  for (std::int64_t t = 0; t <= 120; ++t) {
    clock.t_ns = t * 1000000;
    ASSERT_TRUE(w.value()->kick().is_ok());
  }
  EXPECT_EQ(systemd.messages(),
            (std::vector<std::string>{"READY=1", "STATUS=navigating mode 2", "WATCHDOG=1",
                                      "WATCHDOG=1", "WATCHDOG=1"}));
  EXPECT_EQ(w.value()->pings_sent(), 3u);
}

TEST(SystemdWatchdog, NotUnderSystemdEveryCallIsAHarmlessNoOp) {
  ::unsetenv("NOTIFY_SOCKET");
  ::unsetenv("WATCHDOG_USEC");
  SimClock clock;
  auto w = SystemdWatchdog::open(clock);
  ASSERT_TRUE(w.is_ok());
  EXPECT_FALSE(w.value()->under_systemd());
  EXPECT_FALSE(w.value()->watchdog_enabled());
  EXPECT_TRUE(w.value()->notify_ready().is_ok());
  EXPECT_TRUE(w.value()->kick().is_ok());
  EXPECT_EQ(w.value()->pings_sent(), 0u);
}

TEST(SystemdWatchdog, AWatchdogMeantForAnotherProcessIsNotOurs) {
  NotifySocket systemd("100000");
  ::setenv("WATCHDOG_PID", "1", 1);  // the variables were inherited from a parent
  SimClock clock;
  auto w = SystemdWatchdog::open(clock);
  ASSERT_TRUE(w.is_ok());
  EXPECT_FALSE(w.value()->watchdog_enabled());
}

class RefusingSd : public SdApi {
 public:
  int watchdog_enabled(std::uint64_t* usec) override {
    *usec = 2000000;
    return 1;
  }
  int notify(const char*) override { return -ECONNREFUSED; }
  bool has_notify_socket() override { return true; }
};

TEST(SystemdWatchdog, ANotificationTheManagerRefusesIsAnIoErrorWithErrno) {
  RefusingSd sd;
  SimClock clock;
  auto w = SystemdWatchdog::open(clock, sd);
  ASSERT_TRUE(w.is_ok());
  const Status s = w.value()->kick();
  EXPECT_EQ(s.code(), ErrorCode::kIoError);
  EXPECT_EQ(s.os_error(), ECONNREFUSED);
  EXPECT_EQ(w.value()->pings_sent(), 0u);
}

// /dev/watchdog as the kernel's watchdog core answers: the driver rounds 10 s to 8 s.
class FakeWatchdogDev : public FakeOs {
 public:
  FakeWatchdogDev() {
    on_open = [this](const char* p, int flags, unsigned) {
      path = p;
      open_flags = flags;
      return 5;
    };
    on_ioctl = [this](int, unsigned long req, void* arg) {
      requests.push_back(req);
      if (req == WDIOC_SETTIMEOUT) {
        if (settimeout_errno != 0) return fail_with(settimeout_errno);
        asked_timeout = *static_cast<int*>(arg);
        *static_cast<int*>(arg) = 8;
      }
      return 0;
    };
    on_write = [this](int, const void* b, std::size_t n) -> long {
      written.append(static_cast<const char*>(b), n);
      return static_cast<long>(n);
    };
  }
  std::string path, written;
  int open_flags = 0, asked_timeout = 0, settimeout_errno = 0;
  std::vector<unsigned long> requests;
};

TEST(DevWatchdog, SetsTheTimeoutKeepsAliveAndDisarmsWithTheMagicCharacter) {
  FakeWatchdogDev os;
  auto w = DevWatchdog::open("/dev/watchdog0", 10, os);
  ASSERT_TRUE(w.is_ok()) << w.status().message();
  EXPECT_EQ(os.path, "/dev/watchdog0");
  EXPECT_EQ(os.open_flags & O_ACCMODE, O_WRONLY);
  EXPECT_EQ(os.asked_timeout, 10);
  EXPECT_EQ(w.value()->timeout_s(), 8);  // what the driver applied
  ASSERT_TRUE(w.value()->kick().is_ok());
  EXPECT_EQ(os.requests.back(), static_cast<unsigned long>(WDIOC_KEEPALIVE));
  ASSERT_TRUE(w.value()->disarm().is_ok());
  EXPECT_EQ(os.written, "V");
  EXPECT_EQ(os.count("close"), 1u);
  EXPECT_EQ(w.value()->kick().code(), ErrorCode::kFailedPrecondition);
}

TEST(DevWatchdog, DestroyedWithoutDisarmItClosesWithoutTheMagicCharacter) {
  FakeWatchdogDev os;
  { auto w = DevWatchdog::open("/dev/watchdog", 10, os); }
  EXPECT_EQ(os.written, "");  // a crash must reset the board
  EXPECT_EQ(os.count("close"), 1u);
}

TEST(DevWatchdog, ARefusedTimeoutDisarmsBeforeReportingErrno) {
  FakeWatchdogDev os;
  os.settimeout_errno = EINVAL;
  auto w = DevWatchdog::open("/dev/watchdog", 10, os);
  EXPECT_EQ(w.status().code(), ErrorCode::kIoError);
  EXPECT_EQ(w.status().os_error(), EINVAL);
  EXPECT_EQ(os.written, "V");
  EXPECT_EQ(os.count("close"), 1u);
}

TEST(DevWatchdogRealKernel, AMissingDeviceIsUnavailableWithENOENT) {
  // Never the real /dev/watchdog in a test: opening it arms the machine's watchdog.
  auto w = DevWatchdog::open("/dev/gfins-no-watchdog", 10);
  EXPECT_EQ(w.status().code(), ErrorCode::kUnavailable);
  EXPECT_EQ(w.status().os_error(), ENOENT);
  EXPECT_EQ(DevWatchdog::open("/dev/watchdog", 0).status().code(), ErrorCode::kInvalidArgument);
}

TEST(MonotonicClock, SleepsToAnAbsoluteDeadlineAndResumesTheSameOneAfterSignals) {
  FakeOs os;
  std::vector<timespec> requests;
  int calls = 0;
  os.on_clock_nanosleep = [&](int id, int flags, const timespec* r) {
    EXPECT_EQ(id, CLOCK_MONOTONIC);
    EXPECT_EQ(flags, TIMER_ABSTIME);
    requests.push_back(*r);
    return ++calls < 3 ? EINTR : 0;  // two signals, then the deadline
  };
  auto c = MonotonicClock::open(os);
  ASSERT_TRUE(c.is_ok());
  ASSERT_TRUE(c.value()->sleep_until_ns(12345678901).is_ok());
  ASSERT_EQ(requests.size(), 3u);
  for (const timespec& r : requests) {
    EXPECT_EQ(r.tv_sec, 12);
    EXPECT_EQ(r.tv_nsec, 345678901);
  }
  os.on_clock_nanosleep = [](int, int, const timespec*) { return EINVAL; };
  const Status s = c.value()->sleep_until_ns(1);
  EXPECT_EQ(s.code(), ErrorCode::kIoError);
  EXPECT_EQ(s.os_error(), EINVAL);
  EXPECT_EQ(c.value()->now_ns(), 1000000000000);  // the fake's 1000 s
}

TEST(MonotonicClockRealKernel, NeverGoesBackwardsAndAPastDeadlineReturnsAtOnce) {
  auto c = MonotonicClock::open();
  ASSERT_TRUE(c.is_ok());
  std::int64_t last = c.value()->now_ns();
  for (int i = 0; i < 10000; ++i) {
    const std::int64_t t = c.value()->now_ns();
    ASSERT_GE(t, last);
    last = t;
  }
  EXPECT_TRUE(c.value()->sleep_until_ns(last - 1).is_ok());
}

TEST(Realtime, PrioritiesOutsideSchedFifosRangeAreRefusedWithoutACall) {
  FakeOs os;
  EXPECT_EQ(set_fifo_priority(0, os).code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(set_fifo_priority(100, os).code(), ErrorCode::kInvalidArgument);
  EXPECT_TRUE(os.log.empty());
}

TEST(Realtime, MissingPrivilegesAreUnavailableWithEPERMSoTheCallerCanWarn) {
  FakeOs os;
  int asked = 0;
  os.on_set_fifo_priority = [&](int p) {
    asked = p;
    return EPERM;
  };
  Status s = set_fifo_priority(80, os);
  EXPECT_EQ(asked, 80);
  EXPECT_EQ(s.code(), ErrorCode::kUnavailable);
  EXPECT_EQ(s.os_error(), EPERM);
  int flags = 0;
  os.on_mlockall = [&](int f) {
    flags = f;
    return fail_with(ENOMEM);
  };
  s = lock_memory(os);
  EXPECT_EQ(flags, MCL_CURRENT | MCL_FUTURE);
  EXPECT_EQ(s.code(), ErrorCode::kUnavailable);
  EXPECT_EQ(s.os_error(), ENOMEM);
  os.on_mlockall = [](int) { return 0; };
  EXPECT_TRUE(lock_memory(os).is_ok());
}

}  // namespace
}  // namespace gfins::drivers::lnx
