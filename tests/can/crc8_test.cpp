// CRC-8/SAE-J1850: the catalogue check value and an independent bit-serial implementation.
#include "gfins/can/crc8.hpp"

#include <gtest/gtest.h>

#include <array>
#include <random>
#include <vector>

#include "gfins/can/signal_codec.hpp"

namespace gfins::can {
namespace {

// The catalogue entry "CRC-8/SAE-J1850": width 8, poly 0x1D, init 0xFF, refin/refout false,
// xorout 0xFF, check 0x4B (CRC of the ASCII bytes "123456789").
constexpr std::uint8_t kCatalogueCheck = 0x4B;

// Bit-serial long division written from the definition (MSB first), independent of the
// table-driven code under test.
std::uint8_t crc_bitwise(const std::vector<std::uint8_t>& bytes) {
  std::uint8_t reg = 0xFF;
  for (std::uint8_t b : bytes) {
    for (int i = 7; i >= 0; --i) {
      const bool in = ((b >> i) & 1u) != 0;
      const bool top = (reg & 0x80u) != 0;
      reg = static_cast<std::uint8_t>(reg << 1);
      if (in != top) reg = static_cast<std::uint8_t>(reg ^ 0x1Du);
    }
  }
  return static_cast<std::uint8_t>(reg ^ 0xFF);
}

TEST(Crc8, CatalogueCheckValue) {
  const std::array<std::uint8_t, 9> ascii{'1', '2', '3', '4', '5', '6', '7', '8', '9'};
  EXPECT_EQ(crc8_sae_j1850(ascii), kCatalogueCheck);
  EXPECT_EQ(crc_bitwise({ascii.begin(), ascii.end()}), kCatalogueCheck);
}

TEST(Crc8, TableMatchesBitSerialOnRandomData) {
  std::mt19937 rng(42);
  for (int n = 0; n < 2000; ++n) {
    std::vector<std::uint8_t> v(static_cast<std::size_t>(rng() % 12));
    for (auto& b : v) b = static_cast<std::uint8_t>(rng());
    ASSERT_EQ(crc8_sae_j1850(v), crc_bitwise(v));
  }
}

TEST(Crc8, FrameCrcCoversIdentifierAndBytes0To6) {
  hal::CanFrame f;
  f.id = 0x123;
  f.len = 8;
  f.data = {1, 2, 3, 4, 5, 6, 7, 0};
  seal_frame(f);
  EXPECT_EQ(f.data[7], crc_bitwise({0x23, 0x01, 1, 2, 3, 4, 5, 6, 7}));
  EXPECT_TRUE(crc_ok(f));
  // Every single-bit error in the identifier or the protected bytes is detected (a CRC with a
  // polynomial having more than one term detects all single-bit errors).
  for (int bit = 0; bit < 11 + 56; ++bit) {
    hal::CanFrame g = f;
    if (bit < 11) {
      g.id ^= 1u << bit;
    } else {
      g.data[static_cast<std::size_t>((bit - 11) / 8)] ^=
          static_cast<std::uint8_t>(1u << ((bit - 11) % 8));
    }
    EXPECT_FALSE(crc_ok(g)) << "bit " << bit;
  }
}

}  // namespace
}  // namespace gfins::can
