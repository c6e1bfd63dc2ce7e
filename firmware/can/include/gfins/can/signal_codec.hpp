// Signal-level encode/decode driven by SignalDef (message_table.hpp): the only place that turns
// physical values into bits and back. Little-endian (Intel) bit numbering: bit k of the 64-bit
// payload is bit (k mod 8) of data byte k/8, exactly DBC's "@1" convention.
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>

#include "gfins/can/crc8.hpp"
#include "gfins/can/message_table.hpp"
#include "gfins/hal/can_bus.hpp"

namespace gfins::can {

constexpr std::uint64_t low_mask(std::uint8_t length) {
  return length >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << length) - 1;
}

constexpr std::uint64_t payload_of(const hal::CanFrame& f) {
  std::uint64_t p = 0;
  for (std::size_t i = 0; i < kFrameLength; ++i) p |= std::uint64_t{f.data[i]} << (8 * i);
  return p;
}

constexpr void set_payload(hal::CanFrame& f, std::uint64_t p) {
  for (std::size_t i = 0; i < kFrameLength; ++i) {
    f.data[i] = static_cast<std::uint8_t>((p >> (8 * i)) & 0xFFu);
  }
}

/// The signal's raw bits (unsigned, `length` wide) from a payload.
constexpr std::uint64_t extract_bits(std::uint64_t payload, const SignalDef& s) {
  return (payload >> s.start_bit) & low_mask(s.length);
}

/// Writes `bits` (only the low `length` bits are used) into the signal's place.
constexpr std::uint64_t insert_bits(std::uint64_t payload, const SignalDef& s, std::uint64_t bits) {
  const std::uint64_t mask = low_mask(s.length) << s.start_bit;
  return (payload & ~mask) | ((bits << s.start_bit) & mask);
}

/// Raw integer value of the bits (two's complement sign extension for signed signals).
constexpr std::int64_t raw_value(const SignalDef& s, std::uint64_t bits) {
  if (s.is_signed && s.length < 64 && ((bits >> (s.length - 1)) & 1u) != 0) {
    return static_cast<std::int64_t>(bits | ~low_mask(s.length));
  }
  return static_cast<std::int64_t>(bits);
}

constexpr std::uint64_t bits_of(const SignalDef& s, std::int64_t raw) {
  return static_cast<std::uint64_t>(raw) & low_mask(s.length);
}

/// Raw value of a physical value without limits: round((x - offset) / factor), or rounded up
/// for a signal that must never show less than the value (σ). The 1e-9 of a step absorbs the
/// division's rounding, so an exact multiple is not pushed one step up.
inline std::int64_t raw_of_physical(const SignalDef& s, double x) {
  const double r = (x - s.offset) / s.factor;
  if (s.round_up) return static_cast<std::int64_t>(std::ceil(r - 1e-9));
  return static_cast<std::int64_t>(std::llround(r));
}

constexpr double physical_of_raw(const SignalDef& s, std::int64_t raw) {
  return static_cast<double>(raw) * s.factor + s.offset;
}

struct EncodedSignal {
  std::uint64_t bits = 0;
  bool saturated = false;      // clipped to [min, max]
  bool not_available = false;  // NaN/inf: sent as the not-available raw value
};

/// Physical value -> bits. Saturating signals clip to [min, max] (flagged); wrapping signals take
/// the integer value modulo 2^length; a non-finite value becomes the not-available raw value
/// (or min for a signal without one), flagged.
inline EncodedSignal encode_signal(const SignalDef& s, double x) {
  EncodedSignal e;
  if (!std::isfinite(x)) {
    e.not_available = true;
    e.bits = bits_of(s, s.has_na ? s.na_raw : raw_of_physical(s, s.min));
    return e;
  }
  if (s.overflow == Overflow::kWrap) {
    // Counters and times: exact integers below 2^53, reduced modulo 2^length.
    const double r = std::floor((x - s.offset) / s.factor + 0.5);
    const double m = std::ldexp(1.0, s.length);
    double red = std::fmod(r, m);
    if (red < 0) red += m;
    e.bits = static_cast<std::uint64_t>(red) & low_mask(s.length);
    return e;
  }
  if (x > s.max) {
    x = s.max;
    e.saturated = true;
  } else if (x < s.min) {
    x = s.min;
    e.saturated = true;
  }
  e.bits = bits_of(s, raw_of_physical(s, x));
  return e;
}

/// Bits -> physical value; NaN for the not-available raw value.
constexpr double decode_signal(const SignalDef& s, std::uint64_t bits) {
  const std::int64_t raw = raw_value(s, bits);
  if (s.has_na && raw == s.na_raw) return std::numeric_limits<double>::quiet_NaN();
  return physical_of_raw(s, raw);
}

/// The signal of `m` carrying `field` (for per-channel fields, the one with `index`; for a field
/// several selector values share, the one of selector value `mux`). The codecs ask only for
/// fields their message has (their tests encode every one); a field it lacks gives the first
/// signal.
constexpr const SignalDef& signal_of(const MessageDef& m, Field field, std::uint8_t index = 0,
                                     std::int16_t mux = kNotMultiplexed) {
  for (const SignalDef& s : m.signals) {
    if (s.field == field && s.index == index && (mux == kNotMultiplexed || s.mux == mux)) return s;
  }
  return m.signals[0];
}

/// The payload bits used by the signals present for selector value `mux` (every signal of a
/// message without a selector); the rest are reserved and must be zero.
constexpr std::uint64_t used_bits(const MessageDef& m, std::int16_t mux = kNotMultiplexed) {
  std::uint64_t used = 0;
  for (const SignalDef& s : m.signals) {
    if (s.mux == kNotMultiplexed || s.mux == kMultiplexor || s.mux == mux) {
      used |= low_mask(s.length) << s.start_bit;
    }
  }
  return used;
}

/// `payload` with the physical value `x` encoded into signal `s` (encode_signal's rules).
inline std::uint64_t put_signal(std::uint64_t payload, const SignalDef& s, double x) {
  return insert_bits(payload, s, encode_signal(s, x).bits);
}

/// CRC-8/SAE-J1850 of a frame: identifier low byte, identifier high byte, data bytes 0..6.
constexpr std::uint8_t frame_crc(const hal::CanFrame& f) {
  const std::array<std::uint8_t, 2> id{static_cast<std::uint8_t>(f.id & 0xFFu),
                                       static_cast<std::uint8_t>((f.id >> 8) & 0xFFu)};
  std::uint8_t reg = crc8_update(kCrc8Init, id);
  reg = crc8_update(reg, std::span<const std::uint8_t>(f.data.data(), kCrcByte));
  return static_cast<std::uint8_t>(reg ^ kCrc8XorOut);
}

/// Writes the CRC into data byte 7.
constexpr void seal_frame(hal::CanFrame& f) { f.data[kCrcByte] = frame_crc(f); }

constexpr bool crc_ok(const hal::CanFrame& f) {
  return f.len == kFrameLength && f.data[kCrcByte] == frame_crc(f);
}

}  // namespace gfins::can
