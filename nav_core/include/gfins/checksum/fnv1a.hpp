// FNV-1a, 64 bits: the one non-cryptographic hash of the project (the calibration file's
// checksum, docs/calibration-file.md; the replay output hash, host_sim/nav_loop.hpp).
// Std only, no heap, constexpr: usable on the board, on the host and in static_asserts.
//
// Parameters (Fowler/Noll/Vo, 64-bit): offset basis 0xcbf29ce484222325, prime 0x100000001b3;
// per byte: h ^= byte, then h *= prime (mod 2^64). fnv1a64("") = 0xcbf29ce484222325,
// fnv1a64("a") = 0xaf63dc4c8601ec8c.
#pragma once

#include <array>
#include <cstdint>
#include <cstring>
#include <span>
#include <string_view>
#include <type_traits>

namespace gfins {

class Fnv1a64 {
 public:
  static constexpr std::uint64_t kOffsetBasis = 0xcbf29ce484222325ull;
  static constexpr std::uint64_t kPrime = 0x100000001b3ull;

  constexpr void add(std::span<const std::uint8_t> bytes) {
    for (const std::uint8_t b : bytes) add_byte(b);
  }
  constexpr void add(std::string_view text) {
    for (const char c : text) add_byte(static_cast<std::uint8_t>(c));
  }
  /// The object representation of a trivially copyable value (host byte order).
  template <typename V>
  void add_value(const V& v) {
    static_assert(std::is_trivially_copyable_v<V>, "hash values, not objects with pointers");
    std::array<std::uint8_t, sizeof(V)> b{};
    std::memcpy(b.data(), &v, sizeof(V));
    add(b);
  }
  constexpr std::uint64_t value() const { return h_; }

 private:
  constexpr void add_byte(std::uint8_t b) {
    h_ ^= b;
    h_ *= kPrime;
  }
  std::uint64_t h_ = kOffsetBasis;
};

/// FNV-1a 64 of a byte string.
constexpr std::uint64_t fnv1a64(std::string_view text) {
  Fnv1a64 h;
  h.add(text);
  return h.value();
}

static_assert(fnv1a64("") == 0xcbf29ce484222325ull);
static_assert(fnv1a64("a") == 0xaf63dc4c8601ec8cull);

}  // namespace gfins
