// SPI device seam: one chip select on one bus, full-duplex transfers (Pigweed pw_spi style: the
// public method checks its arguments, the backend implements do_transfer()).
//
// Backends: drivers/linux (spidev, SPI_IOC_MESSAGE) and host_sim (the ADC chip model answering
// at register level), so the same ADC driver runs on the board and in simulation.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include "gfins/status/status.hpp"

namespace gfins::hal {

class SpiDevice {
 public:
  /// Largest single transfer any driver of this project needs (an ADS131M06 frame at 32-bit
  /// words is 8 words = 32 bytes), with margin. Larger requests are refused, not truncated.
  static constexpr std::size_t kMaxTransferBytes = 64;

  virtual ~SpiDevice() = default;

  /// Clocks `tx` out while clocking the same number of bytes into `rx`, chip select held for the
  /// whole transfer. kInvalidArgument when the sizes differ, are zero or exceed
  /// kMaxTransferBytes; otherwise what the backend reports (kIoError with errno, kUnavailable).
  [[nodiscard]] Status transfer(std::span<const std::uint8_t> tx, std::span<std::uint8_t> rx) {
    if (tx.size() != rx.size() || tx.empty()) {
      return Status(ErrorCode::kInvalidArgument,
                    "spi: tx and rx must have the same, non-zero size");
    }
    if (tx.size() > kMaxTransferBytes) {
      return Status(ErrorCode::kInvalidArgument, "spi: transfer longer than kMaxTransferBytes");
    }
    return do_transfer(tx, rx);
  }

 private:
  virtual Status do_transfer(std::span<const std::uint8_t> tx, std::span<std::uint8_t> rx) = 0;
};

}  // namespace gfins::hal
