// nav::from_int64<float>: the conversion of nanosecond times the core makes without the
// soft-float __aeabi_l2f (math.hpp). The oracle is the platform's own int64 -> float conversion
// (x86-64: the cvtsi2ss instruction; armhf, where the board tests run: libgcc's __aeabi_l2f), both
// correctly rounded to nearest-even, compared bit for bit.
#include <gtest/gtest.h>

#include <bit>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include "gfins/nav_core/math.hpp"

namespace gfins::nav {
namespace {

void expect_same(std::int64_t v) {
  const float want = static_cast<float>(v);
  const float got = from_int64<float>(v);
  EXPECT_EQ(std::bit_cast<std::uint32_t>(got), std::bit_cast<std::uint32_t>(want))
      << v << ": " << got << " instead of " << want;
}

TEST(FromInt64, EdgesAndTiesRoundAsTheHardwareDoes) {
  constexpr std::int64_t kMin = std::numeric_limits<std::int64_t>::min();
  constexpr std::int64_t kMax = std::numeric_limits<std::int64_t>::max();
  const std::vector<std::int64_t> edges = {
      0, 1, -1, 2147483647, -2147483647, 2147483648LL, -2147483648LL, 2147483649LL, -2147483649LL,
      kMax, kMin, kMin + 1, kMax - 1,
      // Ties at a magnitude where float's step is 2^17 (2^40 .. 2^41): exactly half a step above
      // an even and an odd multiple (to even: down, then up), and one unit either side of a tie
      // (decided by the bits a plain truncation to 31 bits would lose: the sticky bit).
      (1LL << 40) + (1LL << 16), (1LL << 40) + 3 * (1LL << 16), (1LL << 40) + (1LL << 16) + 1,
      (1LL << 40) + (1LL << 16) - 1, -((1LL << 40) + (1LL << 16) + 1),
      // 1e18 ns (31.7 years) and a day, a GNSS fix age of 3 s.
      1000000000000000000LL, 86400000000000LL, 3000000000LL, -3000000000LL};
  for (const std::int64_t v : edges) expect_same(v);
}

TEST(FromInt64, AMillionValuesOfEveryMagnitudeRoundAsTheHardwareDoes) {
  // Fixed seed: a deterministic sweep, not a statistical test. Each value has a random number of
  // significant bits (0..63) and sign, so every shift count of the long path is taken.
  std::mt19937_64 rng(20261206);
  for (int i = 0; i < 1000000; ++i) {
    const std::uint64_t bits = rng() >> (rng() % 64);
    const auto v = static_cast<std::int64_t>(bits >> 1);
    expect_same((rng() & 1u) != 0 ? -v : v);
    if (HasFailure()) return;
  }
}

TEST(FromInt64, DoubleIsThePlainConversion) {
  EXPECT_EQ(from_int64<double>(123456789012345678LL), 123456789012345678.0);
}

}  // namespace
}  // namespace gfins::nav
