#include "gfins/drivers/lnx/spidev.hpp"

#include <fcntl.h>
#include <linux/spi/spidev.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

#include "fd.hpp"

namespace gfins::drivers::lnx {
namespace {

// Writes `value` with `wr`, reads it back with `rd` and compares (spidev.rst, "IOCTL commands").
template <typename T>
Status set_and_verify(Os& os, int fd, unsigned long wr, unsigned long rd, T value,
                      const char* wr_failed, const char* rd_failed, const char* mismatch) {
  T v = value;
  if (os.ioctl(fd, wr, &v) < 0) return Status(ErrorCode::kIoError, wr_failed, errno);
  T back{};
  if (os.ioctl(fd, rd, &back) < 0) return Status(ErrorCode::kIoError, rd_failed, errno);
  if (back != value) return Status(ErrorCode::kFailedPrecondition, mismatch);
  return Status::ok();
}

}  // namespace

void spidev_path(unsigned bus, unsigned chip_select, char (&out)[32]) {
  std::snprintf(out, sizeof out, "/dev/spidev%u.%u", bus, chip_select);
}

Result<std::unique_ptr<Spidev>> Spidev::open(const SpidevConfig& config, Os& os) {
  if (config.mode > 3) return Status(ErrorCode::kInvalidArgument, "spidev: mode must be 0..3");
  if (config.bits_per_word == 0 || config.max_speed_hz == 0) {
    return Status(ErrorCode::kInvalidArgument, "spidev: bits per word and speed must be > 0");
  }
  char path[32];
  spidev_path(config.bus, config.chip_select, path);
  Fd fd(os, os.open(path, O_RDWR | O_CLOEXEC, 0));
  if (!fd.valid()) {
    const int err = errno;
    if (err == ENOENT || err == ENODEV || err == ENXIO) {
      return Status(ErrorCode::kUnavailable,
                    "spidev: no such device node (is the spidev overlay loaded?)", err);
    }
    return Status(ErrorCode::kIoError, "spidev: cannot open the device node", err);
  }
  // Mode is written as the 8-bit SPI_IOC_WR_MODE: CPHA/CPOL are bits 0-1 (SPI_MODE_0..3).
  Status s = set_and_verify<std::uint8_t>(
      os, fd.get(), SPI_IOC_WR_MODE, SPI_IOC_RD_MODE, config.mode, "spidev: SPI_IOC_WR_MODE failed",
      "spidev: SPI_IOC_RD_MODE failed", "spidev: the controller did not keep the SPI mode");
  if (!s.is_ok()) return s;
  s = set_and_verify<std::uint8_t>(os, fd.get(), SPI_IOC_WR_BITS_PER_WORD, SPI_IOC_RD_BITS_PER_WORD,
                                   config.bits_per_word, "spidev: SPI_IOC_WR_BITS_PER_WORD failed",
                                   "spidev: SPI_IOC_RD_BITS_PER_WORD failed",
                                   "spidev: the controller did not keep the bits per word");
  if (!s.is_ok()) return s;
  s = set_and_verify<std::uint32_t>(os, fd.get(), SPI_IOC_WR_MAX_SPEED_HZ, SPI_IOC_RD_MAX_SPEED_HZ,
                                    config.max_speed_hz, "spidev: SPI_IOC_WR_MAX_SPEED_HZ failed",
                                    "spidev: SPI_IOC_RD_MAX_SPEED_HZ failed",
                                    "spidev: the controller did not keep the maximum speed");
  if (!s.is_ok()) return s;
  std::unique_ptr<Spidev> dev(new Spidev(os, fd.release(), config));
  return dev;
}

Spidev::Spidev(Os& os, int fd, const SpidevConfig& config) : os_(os), fd_(fd), config_(config) {
  spidev_path(config.bus, config.chip_select, path_);
}

Spidev::~Spidev() { (void)os_.close(fd_); }

Status Spidev::do_transfer(std::span<const std::uint8_t> tx, std::span<std::uint8_t> rx) {
  spi_ioc_transfer xfer{};
  // The kernel ABI carries user pointers as __u64 (spidev.h).
  xfer.tx_buf = reinterpret_cast<std::uintptr_t>(tx.data());
  xfer.rx_buf = reinterpret_cast<std::uintptr_t>(rx.data());
  xfer.len = static_cast<std::uint32_t>(tx.size());
  xfer.speed_hz = config_.max_speed_hz;
  xfer.bits_per_word = config_.bits_per_word;
  xfer.cs_change = 0;  // chip select released at the end of the message
  const int n = os_.ioctl(fd_, SPI_IOC_MESSAGE(1), &xfer);
  if (n < 0) return Status(ErrorCode::kIoError, "spidev: SPI_IOC_MESSAGE failed", errno);
  if (static_cast<std::size_t>(n) != tx.size()) {
    return Status(ErrorCode::kIoError, "spidev: SPI_IOC_MESSAGE moved fewer bytes than asked");
  }
  return Status::ok();
}

}  // namespace gfins::drivers::lnx
