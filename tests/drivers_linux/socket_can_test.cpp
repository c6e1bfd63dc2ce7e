// SocketCan against a fake kernel: socket, options and binding; non-blocking sends with the
// bounded queue on ENOBUFS/EAGAIN; interface down and up again; error frames decoded into the
// fault-confinement state; receive filters and timeouts. Then the real kernel's answer here.
#include "gfins/drivers/lnx/socket_can.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <linux/can.h>
#include <linux/can/error.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/socket.h>

#include <cerrno>
#include <cstring>
#include <deque>
#include <map>
#include <vector>

#include "drivers_linux/fake_os.hpp"
#include "gfins/drivers/lnx/error_text.hpp"

namespace gfins::drivers::lnx {
namespace {

using testing::fail_with;
using testing::FakeOs;
using ::testing::HasSubstr;

constexpr int kFd = 7;

// A CAN network stack with one interface whose index, up/down flag, tx queue and rx queue the
// test controls.
class FakeCanKernel : public FakeOs {
 public:
  FakeCanKernel() {
    on_socket = [this](int d, int t, int p) {
      domain = d;
      type = t;
      protocol = p;
      ++sockets;
      return kFd;
    };
    on_if_nametoindex = [this](const char* n) -> unsigned {
      const auto it = interfaces.find(n);
      if (it == interfaces.end()) {
        errno = ENODEV;
        return 0;
      }
      return it->second;
    };
    on_setsockopt = [this](int, int level, int name, const void* v, unsigned len) {
      const auto* b = static_cast<const std::uint8_t*>(v);
      options.push_back({level, name, std::vector<std::uint8_t>(b, b + len)});
      return 0;
    };
    on_bind = [this](int, const void* a, unsigned len) {
      EXPECT_EQ(len, sizeof(sockaddr_can));
      std::memcpy(&bound, a, sizeof bound);
      ++binds;
      return 0;
    };
    on_write = [this](int, const void* b, std::size_t n) -> long {
      if (!write_errnos.empty()) {
        const int e = write_errnos.front();
        write_errnos.pop_front();
        if (e != 0) return fail_with(e);
      }
      can_frame f;
      std::memcpy(&f, b, sizeof f);
      written.push_back(f);
      return static_cast<long>(n);
    };
    // A raw CAN socket answers recvmsg with one struct can_frame in the first iovec, and, when
    // SO_RXQ_OVFL is on and the socket has dropped frames, one control message: level
    // SOL_SOCKET, type SO_RXQ_OVFL, a __u32 with the total dropped since the socket was made
    // (socket(7); the layout is cmsg(3)'s, built here with its macros).
    on_recvmsg = [this](int, void* m, int) -> long {
      auto* msg = static_cast<msghdr*>(m);
      if (rx.empty()) return fail_with(read_errno);
      EXPECT_GE(msg->msg_iovlen, 1u);
      EXPECT_GE(msg->msg_iov[0].iov_len, sizeof(can_frame));
      std::memcpy(msg->msg_iov[0].iov_base, &rx.front(), sizeof(can_frame));
      rx.pop_front();
      std::int64_t drops = -1;
      if (!rx_drops.empty()) {
        drops = rx_drops.front();
        rx_drops.pop_front();
      }
      if (drops >= 0 && rxq_ovfl_enabled()) {
        EXPECT_GE(msg->msg_controllen, CMSG_SPACE(sizeof(std::uint32_t)));
        cmsghdr* c = CMSG_FIRSTHDR(msg);
        c->cmsg_level = SOL_SOCKET;
        c->cmsg_type = SO_RXQ_OVFL;
        c->cmsg_len = CMSG_LEN(sizeof(std::uint32_t));
        const auto total = static_cast<std::uint32_t>(drops);
        std::memcpy(CMSG_DATA(c), &total, sizeof total);
        msg->msg_controllen = CMSG_SPACE(sizeof(std::uint32_t));
      } else {
        msg->msg_controllen = 0;  // no ancillary data with this frame
      }
      return static_cast<long>(sizeof(can_frame));
    };
    on_ioctl = [this](int, unsigned long req, void* arg) {
      if (req != SIOCGIFFLAGS) return fail_with(ENOTTY);
      auto* r = static_cast<ifreq*>(arg);
      asked_flags_for = r->ifr_name;
      r->ifr_flags = static_cast<short>(up ? (IFF_UP | IFF_RUNNING) : 0);
      return 0;
    };
  }

  struct Option {
    int level, name;
    std::vector<std::uint8_t> bytes;
  };
  std::map<std::string, unsigned> interfaces = {{"can0", 4}};
  int domain = 0, type = 0, protocol = 0, sockets = 0, binds = 0;
  sockaddr_can bound{};
  std::vector<Option> options;
  std::deque<int> write_errnos;  // one entry per write: 0 = accepted
  std::vector<can_frame> written;
  std::deque<can_frame> rx;
  // Per frame read: the SO_RXQ_OVFL total the kernel attaches, -1 = none (no drop yet).
  std::deque<std::int64_t> rx_drops;
  int read_errno = EAGAIN;
  bool rxq_ovfl_enabled() const {
    for (const auto& o : options) {
      if (o.level == SOL_SOCKET && o.name == SO_RXQ_OVFL && o.bytes.size() == sizeof(int)) {
        int v = 0;
        std::memcpy(&v, o.bytes.data(), sizeof v);
        return v != 0;
      }
    }
    return false;
  }
  bool up = true;
  std::string asked_flags_for;
};

hal::CanFrame frame(std::uint32_t id, std::uint8_t b0, bool ext = false) {
  hal::CanFrame f;
  f.id = id;
  f.extended = ext;
  f.len = 2;
  f.data[0] = b0;
  f.data[1] = 0xA5;
  return f;
}

can_frame error_frame(canid_t classes, std::uint8_t ctrl = 0) {
  can_frame f{};
  f.can_id = CAN_ERR_FLAG | classes;
  f.len = CAN_ERR_DLC;
  f.data[1] = ctrl;
  return f;
}

std::unique_ptr<SocketCan> open_on(FakeCanKernel& k, std::size_t capacity = 4) {
  SocketCanConfig c;
  c.interface = "can0";
  c.tx_queue_capacity = capacity;
  auto r = SocketCan::open(c, k);
  EXPECT_TRUE(r.is_ok()) << r.status().message();
  return r.is_ok() ? std::move(r).value() : nullptr;
}

TEST(SocketCanOpen, ANonBlockingRawSocketBoundToTheInterfaceIndexWithErrorFramesOn) {
  FakeCanKernel k;
  auto bus = open_on(k);
  ASSERT_NE(bus, nullptr);
  EXPECT_EQ(k.domain, PF_CAN);
  EXPECT_EQ(k.protocol, CAN_RAW);
  EXPECT_EQ(k.type & SOCK_RAW, SOCK_RAW);
  EXPECT_NE(k.type & SOCK_NONBLOCK, 0);  // the loop never blocks in write()
  EXPECT_NE(k.type & SOCK_CLOEXEC, 0);
  EXPECT_EQ(k.bound.can_family, AF_CAN);
  EXPECT_EQ(k.bound.can_ifindex, 4);
  // The error classes the state machine needs are subscribed (linux/can/error.h).
  const auto it = std::find_if(k.options.begin(), k.options.end(), [](const auto& o) {
    return o.level == SOL_CAN_RAW && o.name == CAN_RAW_ERR_FILTER;
  });
  ASSERT_NE(it, k.options.end());
  can_err_mask_t mask = 0;
  ASSERT_EQ(it->bytes.size(), sizeof mask);
  std::memcpy(&mask, it->bytes.data(), sizeof mask);
  for (const can_err_mask_t needed : {CAN_ERR_BUSOFF, CAN_ERR_CRTL, CAN_ERR_RESTARTED,
                                      CAN_ERR_TX_TIMEOUT, CAN_ERR_PROT, CAN_ERR_ACK}) {
    EXPECT_NE(mask & needed, 0u) << std::hex << needed;
  }
  EXPECT_EQ(bus->state(), hal::CanBusState::kErrorActive);
}

TEST(SocketCanOpen, TheNameIsCheckedAgainstIfnamsizBeforeAnyCall) {
  FakeCanKernel k;
  SocketCanConfig c;
  c.interface = "a-name-16-chars";  // 15: fits with its NUL
  k.interfaces[std::string(c.interface)] = 9;
  EXPECT_TRUE(SocketCan::open(c, k).is_ok());
  FakeCanKernel k2;
  c.interface = "a-name-16-chars!";  // 16: does not
  const auto r = SocketCan::open(c, k2);
  EXPECT_EQ(r.status().code(), ErrorCode::kInvalidArgument);
  EXPECT_TRUE(k2.log.empty());
}

// Names the kernel never gives (dev_valid_name: ".", "..", '/', ':', white space) and names
// with control characters (ESC would reach the terminal in every message naming the interface)
// are refused before any call; a name the kernel does give (vcan0, can-left_1, a veth pair) is not.
TEST(SocketCanOpen, ANameWithAControlCharacterSpaceSlashOrColonIsRefusedBeforeAnyCall) {
  for (const char* bad :
       {"can\x1b[2J", "can\n0", "can 0", "can/0", "can:0", "can\x7f", ".", "..", "\t"}) {
    SCOPED_TRACE(::testing::PrintToString(std::string(bad)));
    FakeCanKernel k;
    SocketCanConfig c;
    c.interface = bad;
    const auto r = SocketCan::open(c, k);
    EXPECT_EQ(r.status().code(), ErrorCode::kInvalidArgument);
    EXPECT_TRUE(k.log.empty());
  }
  for (const char* good : {"vcan0", "can-left_1", "veth.7", "c"}) {
    FakeCanKernel k;
    SocketCanConfig c;
    c.interface = good;
    k.interfaces[std::string(c.interface)] = 3;
    EXPECT_TRUE(SocketCan::open(c, k).is_ok()) << good;
  }
}

TEST(SocketCanOpen, AMissingInterfaceIsUnavailableWithENODEV) {
  FakeCanKernel k;
  SocketCanConfig c;
  c.interface = "can7";
  const auto r = SocketCan::open(c, k);
  EXPECT_EQ(r.status().code(), ErrorCode::kUnavailable);
  EXPECT_EQ(r.status().os_error(), ENODEV);
  EXPECT_EQ(describe("can7", r.status()),
            "can7: socketcan: no such network interface: No such device (errno 19)");
  EXPECT_EQ(k.count("close"), 1u);
}

TEST(SocketCanOpen, FiltersMatchOnlyDataFramesOfTheirFormat) {
  FakeCanKernel k;
  auto bus = open_on(k);
  ASSERT_NE(bus, nullptr);
  const CanFilter filters[] = {{0x600, 0x7F0, false}, {0x18DA00F1, 0x1FFFFFFF, true}};
  ASSERT_TRUE(bus->set_filters(filters).is_ok());
  const auto& o = k.options.back();
  EXPECT_EQ(o.level, SOL_CAN_RAW);
  EXPECT_EQ(o.name, CAN_RAW_FILTER);
  ASSERT_EQ(o.bytes.size(), 2 * sizeof(can_filter));
  can_filter raw[2];
  std::memcpy(raw, o.bytes.data(), sizeof raw);
  EXPECT_EQ(raw[0].can_id, 0x600u);
  EXPECT_EQ(raw[0].can_mask, 0x7F0u | CAN_EFF_FLAG | CAN_RTR_FLAG);
  EXPECT_EQ(raw[1].can_id, 0x18DA00F1u | CAN_EFF_FLAG);
  EXPECT_EQ(raw[1].can_mask, 0x1FFFFFFFu | CAN_EFF_FLAG | CAN_RTR_FLAG);
  std::vector<CanFilter> too_many(SocketCan::kMaxFilters + 1);
  EXPECT_EQ(bus->set_filters(too_many).code(), ErrorCode::kInvalidArgument);
}

TEST(SocketCanSend, AFrameIsWrittenAsOneClassicCanFrame) {
  FakeCanKernel k;
  auto bus = open_on(k);
  ASSERT_TRUE(bus->send(frame(0x123, 0x01)).is_ok());
  ASSERT_TRUE(bus->send(frame(0x1ABCDEF0, 0x02, true)).is_ok());
  ASSERT_EQ(k.written.size(), 2u);
  EXPECT_EQ(k.written[0].can_id, 0x123u);
  EXPECT_EQ(k.written[0].len, 2u);
  EXPECT_EQ(k.written[0].data[0], 0x01);
  EXPECT_EQ(k.written[0].data[1], 0xA5);
  EXPECT_EQ(k.written[1].can_id, 0x1ABCDEF0u | CAN_EFF_FLAG);
  EXPECT_EQ(bus->counters().tx_frames, 2u);
}

TEST(SocketCanSend, ENOBUFSAndEAGAINQueueTheFrameAndServiceSendsItInOrder) {
  FakeCanKernel k;
  auto bus = open_on(k, 4);
  // Given the interface's tx queue is full for the next two writes
  k.write_errnos = {ENOBUFS, EAGAIN};
  // When two frames are sent, they are queued and send() reports success without blocking
  ASSERT_TRUE(bus->send(frame(0x101, 1)).is_ok());
  ASSERT_TRUE(bus->send(frame(0x102, 2)).is_ok());
  EXPECT_EQ(bus->counters().tx_queued, 2u);
  EXPECT_TRUE(k.written.empty());
  // Then service() hands both over, oldest first
  bus->service();
  ASSERT_EQ(k.written.size(), 2u);
  EXPECT_EQ(k.written[0].can_id, 0x101u);
  EXPECT_EQ(k.written[1].can_id, 0x102u);
  EXPECT_EQ(bus->counters().tx_frames, 2u);
  EXPECT_EQ(bus->counters().tx_dropped, 0u);
}

TEST(SocketCanSend, AFullQueueDropsAndCountsTheNewFrame) {
  FakeCanKernel k;
  auto bus = open_on(k, 2);
  k.write_errnos = {ENOBUFS, ENOBUFS, ENOBUFS, ENOBUFS, ENOBUFS, ENOBUFS};
  EXPECT_TRUE(bus->send(frame(0x1, 1)).is_ok());
  EXPECT_TRUE(bus->send(frame(0x2, 2)).is_ok());
  const Status s = bus->send(frame(0x3, 3));
  EXPECT_EQ(s.code(), ErrorCode::kResourceExhausted);
  EXPECT_EQ(bus->counters().tx_dropped, 1u);
  EXPECT_EQ(bus->counters().tx_queued, 2u);
  k.write_errnos.clear();
  bus->service();
  ASSERT_EQ(k.written.size(), 2u);
  EXPECT_EQ(k.written[1].can_id, 0x2u);
}

TEST(SocketCanSend, AnotherWriteErrorDropsTheFrameWithErrno) {
  FakeCanKernel k;
  auto bus = open_on(k);
  k.write_errnos = {EMSGSIZE};
  const Status s = bus->send(frame(0x1, 1));
  EXPECT_EQ(s.code(), ErrorCode::kIoError);
  EXPECT_EQ(s.os_error(), EMSGSIZE);
  EXPECT_EQ(bus->counters().tx_dropped, 1u);
}

TEST(SocketCanDown, InterfaceDownDropsFramesAndUpAgainRecoversWithARestart) {
  FakeCanKernel k;
  auto bus = open_on(k, 4);
  k.write_errnos = {ENOBUFS};
  ASSERT_TRUE(bus->send(frame(0x1, 1)).is_ok());  // queued
  // When the interface goes down (ip link set can0 down)
  k.up = false;
  k.write_errnos = {ENETDOWN};
  const Status s = bus->send(frame(0x2, 2));
  // Then the frame and the queued one are dropped, the state is down
  EXPECT_EQ(s.code(), ErrorCode::kUnavailable);
  EXPECT_EQ(bus->state(), hal::CanBusState::kDown);
  EXPECT_EQ(bus->counters().tx_dropped, 2u);
  EXPECT_EQ(bus->error_counters().interface_down, 1u);
  // And while down, nothing is written and service() does not recover
  const std::size_t writes = k.count("write");
  EXPECT_EQ(bus->send(frame(0x3, 3)).code(), ErrorCode::kUnavailable);
  bus->service();
  EXPECT_EQ(k.count("write"), writes);
  EXPECT_EQ(bus->state(), hal::CanBusState::kDown);
  EXPECT_EQ(k.asked_flags_for, "can0");
  // When it comes up again, service() notices, counts a restart and sending works
  k.up = true;
  bus->service();
  EXPECT_EQ(bus->state(), hal::CanBusState::kErrorActive);
  EXPECT_EQ(bus->counters().restarts, 1u);
  EXPECT_TRUE(bus->send(frame(0x4, 4)).is_ok());
  EXPECT_EQ(k.written.back().can_id, 0x4u);
  EXPECT_EQ(k.binds, 1);  // same interface index: the socket stays bound
}

TEST(SocketCanDown, AnInterfaceReCreatedWithANewIndexIsBoundAgain) {
  FakeCanKernel k;
  auto bus = open_on(k);
  k.read_errno = ENODEV;  // unregistered: reads fail
  bus->service();
  EXPECT_EQ(bus->state(), hal::CanBusState::kDown);
  k.read_errno = EAGAIN;
  k.interfaces["can0"] = 11;  // ip link del can0; ip link add can0 ...
  bus->service();
  EXPECT_EQ(bus->state(), hal::CanBusState::kErrorActive);
  EXPECT_EQ(k.sockets, 2);
  EXPECT_EQ(k.binds, 2);
  EXPECT_EQ(k.bound.can_ifindex, 11);
}

TEST(SocketCanErrors, ErrorFramesDriveTheFaultConfinementState) {
  FakeCanKernel k;
  auto bus = open_on(k);
  // error-warning (TEC/REC >= 96), then error-passive (>= 128): error.h data[1] bits
  k.rx.push_back(error_frame(CAN_ERR_CRTL, CAN_ERR_CRTL_TX_WARNING));
  bus->service();
  EXPECT_EQ(bus->state(), hal::CanBusState::kErrorWarning);
  k.rx.push_back(error_frame(CAN_ERR_CRTL, CAN_ERR_CRTL_RX_PASSIVE));
  bus->service();
  EXPECT_EQ(bus->state(), hal::CanBusState::kErrorPassive);
  EXPECT_EQ(bus->counters().error_passive_events, 1u);
  // bus-off: sends are dropped without a write
  k.rx.push_back(error_frame(CAN_ERR_BUSOFF));
  bus->service();
  EXPECT_EQ(bus->state(), hal::CanBusState::kBusOff);
  EXPECT_EQ(bus->counters().bus_off_events, 1u);
  const std::size_t writes = k.count("write");
  EXPECT_EQ(bus->send(frame(0x5, 5)).code(), ErrorCode::kUnavailable);
  EXPECT_EQ(k.count("write"), writes);
  // restarted by the driver (restart-ms): error-active again
  k.rx.push_back(error_frame(CAN_ERR_RESTARTED));
  bus->service();
  EXPECT_EQ(bus->state(), hal::CanBusState::kErrorActive);
  EXPECT_EQ(bus->counters().restarts, 1u);
  EXPECT_EQ(bus->counters().error_frames, 4u);
  EXPECT_EQ(bus->counters().rx_frames, 0u);  // error frames are not data
}

TEST(SocketCanErrors, TheOtherErrorClassesAreCounted) {
  FakeCanKernel k;
  auto bus = open_on(k);
  k.rx.push_back(error_frame(CAN_ERR_TX_TIMEOUT));
  k.rx.push_back(error_frame(CAN_ERR_ACK | CAN_ERR_BUSERROR));
  k.rx.push_back(error_frame(CAN_ERR_PROT | CAN_ERR_TRX));
  k.rx.push_back(error_frame(CAN_ERR_CRTL, CAN_ERR_CRTL_RX_OVERFLOW));
  k.rx.push_back(error_frame(CAN_ERR_CRTL, CAN_ERR_CRTL_ACTIVE));
  bus->service();
  const SocketCanErrorCounters& e = bus->error_counters();
  EXPECT_EQ(e.tx_timeouts, 1u);
  EXPECT_EQ(e.no_ack, 1u);
  EXPECT_EQ(e.bus_errors, 1u);
  EXPECT_EQ(e.protocol_violations, 1u);
  EXPECT_EQ(e.transceiver_errors, 1u);
  EXPECT_EQ(e.controller_problems, 2u);
  EXPECT_EQ(bus->counters().rx_dropped, 1u);
  EXPECT_EQ(bus->state(), hal::CanBusState::kErrorActive);
}

TEST(SocketCanReceive, ADataFrameIsReturnedWithItsIdFormatAndBytes) {
  FakeCanKernel k;
  auto bus = open_on(k);
  can_frame f{};
  f.can_id = 0x18DA00F1 | CAN_EFF_FLAG;
  f.len = 3;
  f.data[0] = 0xDE;
  f.data[2] = 0xAD;
  k.rx.push_back(error_frame(CAN_ERR_TX_TIMEOUT));  // skipped, decoded
  k.rx.push_back(f);
  const auto r = bus->receive(0);
  ASSERT_TRUE(r.is_ok()) << r.status().message();
  EXPECT_EQ(r->id, 0x18DA00F1u);
  EXPECT_TRUE(r->extended);
  EXPECT_EQ(r->len, 3u);
  EXPECT_EQ(r->data[0], 0xDE);
  EXPECT_EQ(r->data[2], 0xAD);
  EXPECT_EQ(bus->error_counters().tx_timeouts, 1u);
}

// A burst longer than the backend's queue is not cut short: frames beyond kRxQueue stay in the
// kernel's socket buffer until the caller collects (the virtual board's 200-frame burst lost
// frames 64..127 before this).
TEST(SocketCanReceive, ABurstLongerThanTheQueueArrivesWholeAndInOrder) {
  FakeCanKernel k;
  auto bus = open_on(k);
  constexpr std::uint32_t kBurst = 3 * SocketCan::kRxQueue + 7;
  for (std::uint32_t i = 0; i < kBurst; ++i) {
    can_frame f{};
    f.can_id = i & CAN_SFF_MASK;
    f.len = 1;
    f.data[0] = static_cast<std::uint8_t>(i);
    k.rx.push_back(f);
  }
  bus->service();  // fills the queue, leaves the rest in the (fake) kernel
  for (std::uint32_t i = 0; i < kBurst; ++i) {
    const auto r = bus->receive(0);
    ASSERT_TRUE(r.is_ok()) << "frame " << i << ": " << r.status().message();
    EXPECT_EQ(r->id, i & CAN_SFF_MASK);
    EXPECT_EQ(r->data[0], static_cast<std::uint8_t>(i));
  }
  EXPECT_EQ(bus->counters().rx_frames, kBurst);
  EXPECT_EQ(bus->counters().rx_dropped, 0u);
}

// SO_RXQ_OVFL (socket(7)): the kernel attaches its running total of frames dropped from the
// socket's full receive queue; the backend counts the differences, and a new socket (the
// interface re-created) starts again from zero.
TEST(SocketCanReceive, TheKernelsDroppedFrameCountIsRequestedAndCounted) {
  FakeCanKernel k;
  auto bus = open_on(k);
  ASSERT_NE(bus, nullptr);
  ASSERT_TRUE(k.rxq_ovfl_enabled()) << "setsockopt(SOL_SOCKET, SO_RXQ_OVFL, 1) not made";
  can_frame f{};
  f.can_id = 0x123;
  f.len = 1;
  // Given: no drop yet (no cmsg), then totals 5, 5 (nothing new), 12, then a total that wrapped
  // past 2^32 (0xFFFFFFFE -> 3: 5 more)
  const std::int64_t totals[] = {-1, 5, 5, 12, 0xFFFFFFFE, 3};
  const std::uint32_t expected_after[] = {0, 5, 5, 12, 0xFFFFFFFEu, 0xFFFFFFFEu + 5u};
  for (std::size_t i = 0; i < std::size(totals); ++i) {
    // When the kernel delivers the next frame with that total and the backend reads it
    k.rx.push_back(f);
    k.rx_drops.push_back(totals[i]);
    ASSERT_TRUE(bus->receive(0).is_ok());
    // Then the counter is the kernel's total (wrapping like it), never a frame lost here
    EXPECT_EQ(bus->counters().rx_kernel_dropped, expected_after[i]) << "after frame " << i;
  }
  EXPECT_EQ(bus->counters().rx_frames, std::size(totals));
  EXPECT_EQ(bus->counters().rx_dropped, 0u);  // the controller reported nothing
}

TEST(SocketCanReceive, ANewSocketCountsItsKernelDropsFromZero) {
  FakeCanKernel k;
  auto bus = open_on(k);
  can_frame f{};
  f.can_id = 0x321;
  f.len = 1;
  k.rx.push_back(f);
  k.rx_drops.push_back(40);
  ASSERT_TRUE(bus->receive(0).is_ok());
  EXPECT_EQ(bus->counters().rx_kernel_dropped, 40u);
  // The interface is deleted and re-created with a new index: the backend binds a new socket,
  // whose kernel total starts at 0; its first report of 2 means 2 more, not 2 - 40.
  k.read_errno = ENODEV;
  bus->service();
  ASSERT_EQ(bus->state(), hal::CanBusState::kDown);
  k.read_errno = EAGAIN;
  k.interfaces["can0"] = 11;
  bus->service();
  ASSERT_EQ(k.sockets, 2);
  k.rx.push_back(f);
  k.rx_drops.push_back(2);
  ASSERT_TRUE(bus->receive(0).is_ok());
  EXPECT_EQ(bus->counters().rx_kernel_dropped, 42u);
}

TEST(SocketCanReceive, ANoFrameWaitPollsWithTheRemainingTimeThenTimesOut) {
  FakeCanKernel k;
  auto bus = open_on(k);
  timespec asked{};
  short events = 0;
  k.on_ppoll = [&](void* fds, unsigned long n, const timespec* t) {
    EXPECT_EQ(n, 1u);
    events = static_cast<pollfd*>(fds)->events;
    asked = *t;
    return 0;
  };
  const auto r = bus->receive(1500000);  // 1.5 ms; the fake clock stands still
  EXPECT_EQ(r.status().code(), ErrorCode::kTimeout);
  EXPECT_EQ(events, POLLIN);
  EXPECT_EQ(asked.tv_sec, 0);
  EXPECT_EQ(asked.tv_nsec, 1500000);
}

TEST(SocketCanRealKernel, OpeningNamesTheInterfaceAndTheKernelsReason) {
  // This kernel either lacks SocketCAN (socket() fails with EAFNOSUPPORT, the case on the
  // development machines) or has it but no interface of this name (ENODEV).
  SocketCanConfig c;
  c.interface = "gfins-none0";
  const auto r = SocketCan::open(c);
  ASSERT_FALSE(r.is_ok());
  EXPECT_EQ(r.status().code(), ErrorCode::kUnavailable);
  const std::string text = describe(c.interface, r.status());
  EXPECT_THAT(text, HasSubstr("gfins-none0: "));
  if (r.status().os_error() == EAFNOSUPPORT) {
    EXPECT_EQ(text,
              "gfins-none0: socket(PF_CAN, SOCK_RAW, CAN_RAW) failed: this kernel has no "
              "SocketCAN (modules can, can-raw): Address family not supported by protocol "
              "(errno 97)");
  } else {
    EXPECT_EQ(r.status().os_error(), ENODEV) << text;
  }
}

}  // namespace
}  // namespace gfins::drivers::lnx
