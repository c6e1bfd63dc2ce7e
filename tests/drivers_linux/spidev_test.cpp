// Spidev against a fake kernel: the ioctl numbers and arguments it passes, the read-back checks,
// every errno path; and the real kernel's answer for a device node that does not exist.
#include "gfins/drivers/lnx/spidev.hpp"

#include <fcntl.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <linux/spi/spidev.h>

#include <array>
#include <cerrno>
#include <cstring>
#include <vector>

#include "drivers_linux/fake_os.hpp"
#include "gfins/drivers/lnx/error_text.hpp"

namespace gfins::drivers::lnx {
namespace {

using testing::fail_with;
using testing::FakeOs;
using ::testing::HasSubstr;

// The request numbers as the _IOC encoding of asm-generic/ioctl.h gives them, written out by
// hand from spidev.h (magic 'k' = 0x6b; dir bits 30-31: 1 write, 2 read; size bits 16-29):
// a backend using the wrong macro (RD for WR, a 32-bit mode) fails these.
constexpr unsigned long kWrMode = 0x40016b01;    // _IOW('k', 1, __u8)
constexpr unsigned long kRdMode = 0x80016b01;    // _IOR('k', 1, __u8)
constexpr unsigned long kWrBits = 0x40016b03;    // _IOW('k', 3, __u8)
constexpr unsigned long kRdBits = 0x80016b03;    // _IOR('k', 3, __u8)
constexpr unsigned long kWrSpeed = 0x40046b04;   // _IOW('k', 4, __u32)
constexpr unsigned long kRdSpeed = 0x80046b04;   // _IOR('k', 4, __u32)
constexpr unsigned long kMessage1 = 0x40206b00;  // _IOW('k', 0, char[32]): one 32-byte xfer
constexpr int kFd = 42;

struct IoctlCall {
  unsigned long request;
  std::uint32_t value;  // the byte/word passed (WR) or 0
};

// A spidev node that keeps what it is told and reports it back.
class FakeSpidev : public FakeOs {
 public:
  FakeSpidev() {
    on_open = [this](const char* p, int flags, unsigned) {
      opened_path = p;
      open_flags = flags;
      return kFd;
    };
    on_close = [this](int fd) {
      closed.push_back(fd);
      return 0;
    };
    on_ioctl = [this](int, unsigned long req, void* arg) { return ioctl_impl(req, arg); };
  }

  int ioctl_impl(unsigned long req, void* arg) {
    if (req == fail_request) return fail_with(fail_errno);
    switch (req) {
      case kWrMode:
        mode = *static_cast<std::uint8_t*>(arg);
        calls.push_back({req, mode});
        return 0;
      case kRdMode:
        *static_cast<std::uint8_t*>(arg) = mode_override >= 0 ? std::uint8_t(mode_override) : mode;
        calls.push_back({req, 0});
        return 0;
      case kWrBits:
        bits = *static_cast<std::uint8_t*>(arg);
        calls.push_back({req, bits});
        return 0;
      case kRdBits:
        *static_cast<std::uint8_t*>(arg) = bits;
        calls.push_back({req, 0});
        return 0;
      case kWrSpeed:
        speed = *static_cast<std::uint32_t*>(arg);
        calls.push_back({req, speed});
        return 0;
      case kRdSpeed:
        *static_cast<std::uint32_t*>(arg) = speed;
        calls.push_back({req, 0});
        return 0;
      case kMessage1: {
        std::memcpy(&xfer, arg, sizeof xfer);
        calls.push_back({req, 0});
        // Loopback with every byte inverted: MISO = ~MOSI.
        const auto* tx =
            reinterpret_cast<const std::uint8_t*>(static_cast<std::uintptr_t>(xfer.tx_buf));
        auto* rx = reinterpret_cast<std::uint8_t*>(static_cast<std::uintptr_t>(xfer.rx_buf));
        for (std::uint32_t i = 0; i < xfer.len; ++i) rx[i] = static_cast<std::uint8_t>(~tx[i]);
        return short_transfer ? static_cast<int>(xfer.len) - 1 : static_cast<int>(xfer.len);
      }
      default:
        return fail_with(ENOTTY);
    }
  }

  std::string opened_path;
  int open_flags = 0;
  std::vector<int> closed;
  std::vector<IoctlCall> calls;
  std::uint8_t mode = 0xFF;
  std::uint8_t bits = 0;
  std::uint32_t speed = 0;
  int mode_override = -1;
  unsigned long fail_request = 0;
  int fail_errno = 0;
  bool short_transfer = false;
  spi_ioc_transfer xfer{};
};

TEST(SpidevIoctlNumbers, TheKernelHeaderAgreesWithTheHandEncodedValues) {
  EXPECT_EQ(SPI_IOC_WR_MODE, kWrMode);
  EXPECT_EQ(SPI_IOC_RD_MODE, kRdMode);
  EXPECT_EQ(SPI_IOC_WR_MAX_SPEED_HZ, kWrSpeed);
  EXPECT_EQ(SPI_IOC_MESSAGE(1), kMessage1);
}

TEST(Spidev, OpensTheNodeOfBusAndChipSelectAndSetsThenReadsBackEachSetting) {
  FakeSpidev os;
  const SpidevConfig c{
      .bus = 1, .chip_select = 2, .mode = 1, .bits_per_word = 8, .max_speed_hz = 4000000};
  auto dev = Spidev::open(c, os);
  ASSERT_TRUE(dev.is_ok()) << dev.status().message();
  EXPECT_EQ(os.opened_path, "/dev/spidev1.2");
  EXPECT_EQ(os.open_flags & O_ACCMODE, O_RDWR);
  EXPECT_NE(os.open_flags & O_CLOEXEC, 0);
  const std::vector<std::pair<unsigned long, std::uint32_t>> expected = {
      {kWrMode, 1}, {kRdMode, 0}, {kWrBits, 8}, {kRdBits, 0}, {kWrSpeed, 4000000}, {kRdSpeed, 0}};
  ASSERT_EQ(os.calls.size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(os.calls[i].request, expected[i].first) << "ioctl #" << i;
    EXPECT_EQ(os.calls[i].value, expected[i].second) << "ioctl #" << i;
  }
  EXPECT_STREQ(dev.value()->path(), "/dev/spidev1.2");
  dev.value().reset();
  EXPECT_EQ(os.closed, std::vector<int>{kFd});
}

TEST(Spidev, AModeTheControllerDidNotKeepIsRefusedAndTheNodeClosed) {
  FakeSpidev os;
  os.mode_override = 0;  // the controller only does mode 0
  auto dev = Spidev::open(SpidevConfig{}, os);
  ASSERT_FALSE(dev.is_ok());
  EXPECT_EQ(dev.status().code(), ErrorCode::kFailedPrecondition);
  EXPECT_THAT(dev.status().message(), HasSubstr("SPI mode"));
  EXPECT_EQ(os.closed, std::vector<int>{kFd});
}

class SpidevIoctlFailure : public ::testing::TestWithParam<unsigned long> {};

TEST_P(SpidevIoctlFailure, EachFailingSetupIoctlIsAnIoErrorCarryingErrno) {
  FakeSpidev os;
  os.fail_request = GetParam();
  os.fail_errno = EINVAL;
  auto dev = Spidev::open(SpidevConfig{}, os);
  ASSERT_FALSE(dev.is_ok());
  EXPECT_EQ(dev.status().code(), ErrorCode::kIoError);
  EXPECT_EQ(dev.status().os_error(), EINVAL);
  EXPECT_EQ(os.closed, std::vector<int>{kFd});  // no descriptor leaks on any path
}

INSTANTIATE_TEST_SUITE_P(EverySetupIoctl, SpidevIoctlFailure,
                         ::testing::Values(kWrMode, kRdMode, kWrBits, kRdBits, kWrSpeed, kRdSpeed));

TEST(Spidev, ArgumentsOutsideTheKernelsDomainAreRefusedBeforeAnyCall) {
  FakeSpidev os;
  SpidevConfig c;
  c.mode = 4;
  EXPECT_EQ(Spidev::open(c, os).status().code(), ErrorCode::kInvalidArgument);
  c = SpidevConfig{};
  c.max_speed_hz = 0;
  EXPECT_EQ(Spidev::open(c, os).status().code(), ErrorCode::kInvalidArgument);
  EXPECT_TRUE(os.log.empty());
}

TEST(Spidev, ATransferIsOneFullDuplexMessageWithTheConfiguredSpeedAndWordSize) {
  FakeSpidev os;
  auto dev = Spidev::open(
      SpidevConfig{
          .bus = 0, .chip_select = 0, .mode = 1, .bits_per_word = 8, .max_speed_hz = 2000000},
      os);
  ASSERT_TRUE(dev.is_ok());
  const std::array<std::uint8_t, 3> tx = {0x12, 0x00, 0xF0};
  std::array<std::uint8_t, 3> rx{};
  ASSERT_TRUE(dev.value()->transfer(tx, rx).is_ok());
  EXPECT_EQ(os.calls.back().request, kMessage1);
  EXPECT_EQ(os.xfer.tx_buf, reinterpret_cast<std::uintptr_t>(tx.data()));
  EXPECT_EQ(os.xfer.rx_buf, reinterpret_cast<std::uintptr_t>(rx.data()));
  EXPECT_EQ(os.xfer.len, 3u);
  EXPECT_EQ(os.xfer.speed_hz, 2000000u);
  EXPECT_EQ(os.xfer.bits_per_word, 8u);
  EXPECT_EQ(os.xfer.cs_change, 0u);
  EXPECT_EQ(rx, (std::array<std::uint8_t, 3>{0xED, 0xFF, 0x0F}));
}

TEST(Spidev, AFailedOrShortTransferIsAnIoError) {
  FakeSpidev os;
  auto dev = Spidev::open(SpidevConfig{}, os);
  ASSERT_TRUE(dev.is_ok());
  const std::array<std::uint8_t, 4> tx{};
  std::array<std::uint8_t, 4> rx{};
  os.fail_request = kMessage1;
  os.fail_errno = EIO;
  Status s = dev.value()->transfer(tx, rx);
  EXPECT_EQ(s.code(), ErrorCode::kIoError);
  EXPECT_EQ(s.os_error(), EIO);
  os.fail_request = 0;
  os.short_transfer = true;
  s = dev.value()->transfer(tx, rx);
  EXPECT_EQ(s.code(), ErrorCode::kIoError);
  EXPECT_THAT(s.message(), HasSubstr("fewer bytes"));
}

TEST(SpidevRealKernel, AMissingDeviceNodeIsUnavailableWithENOENTAndAReadableMessage) {
  // No machine has 250 SPI buses: this is the real kernel's answer for a missing node.
  const SpidevConfig c{.bus = 250, .chip_select = 7};
  auto dev = Spidev::open(c);
  ASSERT_FALSE(dev.is_ok());
  EXPECT_EQ(dev.status().code(), ErrorCode::kUnavailable);
  EXPECT_EQ(dev.status().os_error(), ENOENT);
  char path[32];
  spidev_path(250, 7, path);
  EXPECT_EQ(describe(path, dev.status()),
            "/dev/spidev250.7: spidev: no such device node (is the spidev overlay loaded?): No "
            "such file or directory (errno 2)");
}

}  // namespace
}  // namespace gfins::drivers::lnx
