// hal::SpiDevice on Linux spidev (/dev/spidevB.C, Documentation/spi/spidev.rst).
//
// open() sets the SPI mode, the bits per word and the maximum clock and reads each back
// (SPI_IOC_WR_* then SPI_IOC_RD_*): a controller that silently refuses a setting (a mode its
// hardware lacks, 32-bit words on an 8-bit-only controller) is caught at start-up, not by
// garbage frames later. transfer() is one full-duplex SPI_IOC_MESSAGE(1) with chip select held.
#pragma once

#include <cstdint>
#include <memory>

#include "gfins/drivers/lnx/os.hpp"
#include "gfins/hal/spi_device.hpp"
#include "gfins/status/status.hpp"

namespace gfins::drivers::lnx {

struct SpidevConfig {
  unsigned bus = 0;                      // B of /dev/spidevB.C
  unsigned chip_select = 0;              // C of /dev/spidevB.C
  std::uint8_t mode = 1;                 // SPI mode 0..3 (ADS131M06: CPOL 0, CPHA 1 = mode 1)
  std::uint8_t bits_per_word = 8;        // word size on the wire
  std::uint32_t max_speed_hz = 8000000;  // SCLK; the ADS131M06 allows up to 25 MHz
};

class Spidev final : public hal::SpiDevice {
 public:
  /// Opens and configures the device. Errors (os_error() holds errno):
  /// kInvalidArgument (mode > 3, zero bits or speed); kUnavailable (no such device node);
  /// kIoError (open or an ioctl failed); kFailedPrecondition (a read-back differs).
  static Result<std::unique_ptr<Spidev>> open(const SpidevConfig& config, Os& os = real_os());

  ~Spidev() override;
  Spidev(const Spidev&) = delete;
  Spidev& operator=(const Spidev&) = delete;

  /// "/dev/spidevB.C" of this device (for messages).
  const char* path() const { return path_; }

 private:
  Spidev(Os& os, int fd, const SpidevConfig& config);
  Status do_transfer(std::span<const std::uint8_t> tx, std::span<std::uint8_t> rx) override;

  Os& os_;
  int fd_;
  SpidevConfig config_;
  char path_[32] = {};
};

/// "/dev/spidevB.C" into `out` (at least 32 bytes).
void spidev_path(unsigned bus, unsigned chip_select, char (&out)[32]);

}  // namespace gfins::drivers::lnx
