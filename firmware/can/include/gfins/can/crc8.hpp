// CRC-8 of the end-to-end check carried by every gfins CAN frame (docs/can-interface.md,
// "End-to-end protection"): SAE J1850 parameters — polynomial 0x1D (x^8 + x^4 + x^3 + x^2 + 1),
// initial value 0xFF, no reflection, final XOR 0xFF; check value over the ASCII bytes "123456789"
// is 0x4B (the catalogue value "CRC-8/SAE-J1850"). The same polynomial AUTOSAR E2E profile 1 uses,
// so the check is familiar to automotive tools.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

namespace gfins::can {

inline constexpr std::uint8_t kCrc8Polynomial = 0x1D;
inline constexpr std::uint8_t kCrc8Init = 0xFF;
inline constexpr std::uint8_t kCrc8XorOut = 0xFF;

namespace detail {
/// 256-entry table of the MSB-first CRC register update, built at compile time.
constexpr std::array<std::uint8_t, 256> make_crc8_table() {
  std::array<std::uint8_t, 256> t{};
  for (unsigned i = 0; i < 256; ++i) {
    unsigned r = i;
    for (int b = 0; b < 8; ++b) r = (r & 0x80u) != 0 ? ((r << 1) ^ kCrc8Polynomial) : (r << 1);
    t[i] = static_cast<std::uint8_t>(r & 0xFFu);
  }
  return t;
}
inline constexpr std::array<std::uint8_t, 256> kCrc8Table = make_crc8_table();
}  // namespace detail

/// Continues a CRC register over `bytes` (no init, no final XOR): for checks over several spans.
constexpr std::uint8_t crc8_update(std::uint8_t reg, std::span<const std::uint8_t> bytes) {
  for (std::uint8_t b : bytes) reg = detail::kCrc8Table[static_cast<std::uint8_t>(reg ^ b)];
  return reg;
}

/// CRC-8/SAE-J1850 of `bytes`.
constexpr std::uint8_t crc8_sae_j1850(std::span<const std::uint8_t> bytes) {
  return static_cast<std::uint8_t>(crc8_update(kCrc8Init, bytes) ^ kCrc8XorOut);
}

}  // namespace gfins::can
