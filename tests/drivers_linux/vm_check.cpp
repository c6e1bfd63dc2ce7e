// Real-kernel checks of SocketCan and GpiodDataReady, for the virtual board (scripts/vboard):
// a QEMU guest with Debian's kernel, a vcan interface and a gpio-sim chip. Outside the guest
// every case skips, naming what it needs.
//
// Environment (set by the guest's test script):
//   GFINS_VM=1                    run; without it every case skips
//   GFINS_VM_CAN=vcan0            a vcan interface, up (ip link add dev vcan0 type vcan)
//   GFINS_VM_GPIO_CHIP=gpiochip0  the gpio-sim chip
//   GFINS_VM_GPIO_OFFSET=0        the simulated line used as data-ready
//   GFINS_VM_GPIO_PULL=/sys/devices/platform/<dev>/<chip>/sim_gpio0/pull
//                                 writing pull-up / pull-down there makes an edge
//
// Run: GFINS_VM=1 GFINS_VM_GPIO_PULL=... ./drivers_linux_vm_check
#include <fcntl.h>
#include <gtest/gtest.h>
#include <net/if.h>
#include <stdlib.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include <cstring>
#include <string>
#include <vector>

#include "gfins/drivers/lnx/error_text.hpp"
#include "gfins/drivers/lnx/gpiod_data_ready.hpp"
#include "gfins/drivers/lnx/monotonic_clock.hpp"
#include "gfins/drivers/lnx/socket_can.hpp"

namespace gfins::drivers::lnx {
namespace {

constexpr std::int64_t kMs = 1000000;
// Generous against a TCG-emulated guest, which runs 10-50x slower than the host.
constexpr std::int64_t kReceiveTimeoutNs = 2000 * kMs;

std::string env(const char* name, const char* fallback) {
  const char* v = std::getenv(name);
  return v != nullptr && v[0] != '\0' ? v : fallback;
}

bool in_vm() { return env("GFINS_VM", "") == "1"; }

#define GFINS_NEEDS_VM(what)                                                  \
  if (!in_vm()) {                                                             \
    GTEST_SKIP() << "needs " what                                             \
                    " in the virtual board (scripts/vboard): set GFINS_VM=1 " \
                    "to run";                                                 \
  }

hal::CanFrame frame(std::uint32_t id, std::uint8_t b0) {
  hal::CanFrame f;
  f.id = id;
  f.len = 8;
  for (std::uint8_t i = 0; i < 8; ++i) f.data[i] = static_cast<std::uint8_t>(b0 + i);
  return f;
}

std::unique_ptr<SocketCan> open_can(const std::string& name) {
  SocketCanConfig c;
  c.interface = name;
  auto r = SocketCan::open(c);
  EXPECT_TRUE(r.is_ok()) << describe(name, r.status()) << " — needs " << name
                         << " (ip link add dev " << name << " type vcan && ip link set up " << name
                         << ")";
  return r.is_ok() ? std::move(r).value() : nullptr;
}

// ip link set <name> up/down, by ioctl (no shell, no iproute2 needed in the guest).
bool set_link(const std::string& name, bool up) {
  const int fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return false;
  ifreq r{};
  std::memcpy(r.ifr_name, name.c_str(), name.size() + 1);
  bool ok = ::ioctl(fd, SIOCGIFFLAGS, &r) == 0;
  if (ok) {
    r.ifr_flags = static_cast<short>(up ? (r.ifr_flags | IFF_UP) : (r.ifr_flags & ~IFF_UP));
    ok = ::ioctl(fd, SIOCSIFFLAGS, &r) == 0;
  }
  ::close(fd);
  return ok;
}

TEST(VmSocketCan, FramesSentOnOneSocketArriveOnAnotherIntact) {
  GFINS_NEEDS_VM("vcan0");
  const std::string name = env("GFINS_VM_CAN", "vcan0");
  auto tx = open_can(name);
  auto rx = open_can(name);
  ASSERT_TRUE(tx && rx);
  constexpr int kFrames = 200;
  for (int i = 0; i < kFrames; ++i) {
    ASSERT_TRUE(
        tx->send(frame(0x100 + static_cast<std::uint32_t>(i % 0x100), static_cast<std::uint8_t>(i)))
            .is_ok());
    tx->service();
  }
  for (int i = 0; i < kFrames; ++i) {
    const auto r = rx->receive(kReceiveTimeoutNs);
    ASSERT_TRUE(r.is_ok()) << "frame " << i << ": " << describe(name, r.status());
    EXPECT_EQ(r->id, 0x100u + static_cast<std::uint32_t>(i % 0x100));
    EXPECT_EQ(r->data[7], static_cast<std::uint8_t>(i + 7));
  }
  EXPECT_EQ(tx->counters().tx_frames + tx->counters().tx_dropped, std::uint32_t{kFrames});
  EXPECT_EQ(rx->counters().rx_frames, std::uint32_t{kFrames});
  EXPECT_EQ(rx->receive(10 * kMs).status().code(), ErrorCode::kTimeout);
}

TEST(VmSocketCan, FiltersPassOnlyTheCommandIds) {
  GFINS_NEEDS_VM("vcan0");
  const std::string name = env("GFINS_VM_CAN", "vcan0");
  auto tx = open_can(name);
  auto rx = open_can(name);
  ASSERT_TRUE(tx && rx);
  const CanFilter commands[] = {{0x600, 0x7F0, false}};
  ASSERT_TRUE(rx->set_filters(commands).is_ok());
  ASSERT_TRUE(tx->send(frame(0x123, 1)).is_ok());
  ASSERT_TRUE(tx->send(frame(0x605, 2)).is_ok());
  const auto r = rx->receive(kReceiveTimeoutNs);
  ASSERT_TRUE(r.is_ok()) << describe(name, r.status());
  EXPECT_EQ(r->id, 0x605u);
  EXPECT_EQ(rx->receive(10 * kMs).status().code(), ErrorCode::kTimeout);
}

TEST(VmSocketCan, InterfaceDownThenUpRecoversAndCountsARestart) {
  GFINS_NEEDS_VM("vcan0");
  const std::string name = env("GFINS_VM_CAN", "vcan0");
  auto tx = open_can(name);
  auto rx = open_can(name);
  ASSERT_TRUE(tx && rx);
  ASSERT_TRUE(set_link(name, false)) << "ip link set " << name << " down failed (root?)";
  const Status s = tx->send(frame(0x101, 1));
  EXPECT_EQ(s.code(), ErrorCode::kUnavailable) << describe(name, s);
  EXPECT_EQ(tx->state(), hal::CanBusState::kDown);
  ASSERT_TRUE(set_link(name, true));
  tx->service();
  EXPECT_EQ(tx->state(), hal::CanBusState::kErrorActive);
  EXPECT_EQ(tx->counters().restarts, 1u);
  rx->service();  // reads the ENETDOWN the kernel queued for it, then recovers too
  rx->service();
  ASSERT_TRUE(tx->send(frame(0x102, 2)).is_ok());
  const auto r = rx->receive(kReceiveTimeoutNs);
  ASSERT_TRUE(r.is_ok()) << describe(name, r.status());
  EXPECT_EQ(r->id, 0x102u);
}

class GpioSim {
 public:
  GpioSim() : pull_(env("GFINS_VM_GPIO_PULL", "")) {}
  bool usable() const { return !pull_.empty(); }
  bool set(bool high) {
    const int fd = ::open(pull_.c_str(), O_WRONLY | O_CLOEXEC);
    if (fd < 0) return false;
    const char* v = high ? "pull-up" : "pull-down";
    const bool ok = ::write(fd, v, std::strlen(v)) == static_cast<ssize_t>(std::strlen(v));
    ::close(fd);
    return ok;
  }
  const std::string& path() const { return pull_; }

 private:
  std::string pull_;
};

std::unique_ptr<GpiodDataReady> open_line(std::int64_t period_ns) {
  GpiodDataReadyConfig c;
  c.chip = env("GFINS_VM_GPIO_CHIP", "gpiochip0");
  c.line_offset = std::atoi(env("GFINS_VM_GPIO_OFFSET", "0").c_str());
  c.nominal_period_ns = period_ns;
  auto r = GpiodDataReady::open(c);
  EXPECT_TRUE(r.is_ok()) << describe(c.chip, r.status()) << " — needs a gpio-sim chip";
  return r.is_ok() ? std::move(r).value() : nullptr;
}

void sleep_ns(std::int64_t ns) {
  timespec t{static_cast<time_t>(ns / 1000000000), static_cast<long>(ns % 1000000000)};
  ::nanosleep(&t, nullptr);
}

TEST(VmGpiod, EachFallingEdgeArrivesWithAMonotonicKernelTimestampAndTheNextSequence) {
  GFINS_NEEDS_VM("a gpio-sim line");
  GpioSim sim;
  ASSERT_TRUE(sim.usable()) << "needs GFINS_VM_GPIO_PULL (the gpio-sim line's sysfs pull file)";
  constexpr std::int64_t kPeriod = 50 * kMs;  // slow enough for an emulated guest
  ASSERT_TRUE(sim.set(true)) << sim.path();
  auto line = open_line(kPeriod);
  ASSERT_TRUE(line);
  auto clock = MonotonicClock::open();
  ASSERT_TRUE(clock.is_ok());
  EXPECT_EQ(line->wait_edge(10 * kMs).status().code(), ErrorCode::kTimeout);
  std::int64_t previous = 0;
  for (std::uint32_t i = 0; i < 10; ++i) {
    const std::int64_t before = clock.value()->now_ns();
    ASSERT_TRUE(sim.set(false));
    const auto e = line->wait_edge(kReceiveTimeoutNs);
    ASSERT_TRUE(e.is_ok()) << "edge " << i << ": " << describe("gpio", e.status());
    const std::int64_t after = clock.value()->now_ns();
    // The kernel stamped the edge between our write and our wake-up, on CLOCK_MONOTONIC.
    EXPECT_GE(e->t_ns, before);
    EXPECT_LE(e->t_ns, after);
    EXPECT_GT(e->t_ns, previous);
    previous = e->t_ns;
    ASSERT_TRUE(sim.set(true));
    // Next falling edge (new data, as the ADS131M06 signals it) one period after this one.
    const std::int64_t next = e->t_ns + kPeriod;
    const std::int64_t now = clock.value()->now_ns();
    if (next > now) sleep_ns(next - now);
  }
  EXPECT_EQ(line->counters().edges, 10u);
}

TEST(VmGpiod, ABurstWhileTheReaderStallsIsCountedNotLost) {
  GFINS_NEEDS_VM("a gpio-sim line");
  GpioSim sim;
  ASSERT_TRUE(sim.usable()) << "needs GFINS_VM_GPIO_PULL";
  constexpr std::int64_t kPeriod = 20 * kMs;
  ASSERT_TRUE(sim.set(true));
  auto line = open_line(kPeriod);
  ASSERT_TRUE(line);
  // Five falling edges one period apart while nobody reads
  for (int i = 0; i < 5; ++i) {
    ASSERT_TRUE(sim.set(false));
    sleep_ns(kPeriod / 2);
    ASSERT_TRUE(sim.set(true));
    sleep_ns(kPeriod / 2);
  }
  std::vector<std::uint32_t> seqs;
  for (int i = 0; i < 5; ++i) {
    const auto e = line->wait_edge(kReceiveTimeoutNs);
    ASSERT_TRUE(e.is_ok()) << i << ": " << describe("gpio", e.status());
    seqs.push_back(e->seq);
  }
  EXPECT_EQ(line->counters().edges, 5u);
  // Sequence numbers advance by whole periods; with the guest's scheduling jitter an interval
  // may round to 2, so only the count of edges is exact, the sum of steps is >= 4.
  EXPECT_GE(seqs.back() - seqs.front(), 4u);
}

}  // namespace
}  // namespace gfins::drivers::lnx
