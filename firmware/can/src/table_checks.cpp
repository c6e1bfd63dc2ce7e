// Compile-time checks of the message table: a malformed row fails the build, not a test run.
#include "gfins/can/message_table.hpp"
#include "gfins/can/signal_codec.hpp"

namespace gfins::can {
namespace {

constexpr bool ids_unique_and_in_range() {
  for (std::size_t i = 0; i < kMessageCount; ++i) {
    if (kMessages[i].id != static_cast<MessageId>(i)) return false;  // table order = enum order
    if (std::uint32_t{kMessages[i].base_id} + kMaxNodeId > hal::CanFrame::kMaxStandardId)
      return false;
    for (std::size_t j = i + 1; j < kMessageCount; ++j) {
      const auto a = kMessages[i].base_id;
      const auto b = kMessages[j].base_id;
      if (static_cast<std::uint32_t>(a > b ? a - b : b - a) < kNodeIdSpan)
        return false;  // node ranges overlap
    }
  }
  return true;
}

constexpr bool present_together(const SignalDef& a, const SignalDef& b) {
  const bool a_always = a.mux == kNotMultiplexed || a.mux == kMultiplexor;
  const bool b_always = b.mux == kNotMultiplexed || b.mux == kMultiplexor;
  return a_always || b_always || a.mux == b.mux;
}

/// Signals present together (unmultiplexed, or the same multiplexor value) must not overlap and
/// every signal must fit in the 64-bit payload.
constexpr bool layout_ok(const MessageDef& m) {
  if (m.signals.size() > kMaxSignalsPerMessage) return false;
  for (std::size_t i = 0; i < m.signals.size(); ++i) {
    const SignalDef& a = m.signals[i];
    if (a.length == 0 || a.start_bit + a.length > 64) return false;
    for (std::size_t j = i + 1; j < m.signals.size(); ++j) {
      const SignalDef& b = m.signals[j];
      if (a.name == b.name) return false;
      if (!present_together(a, b)) continue;
      const std::uint64_t ma = low_mask(a.length) << a.start_bit;
      const std::uint64_t mb = low_mask(b.length) << b.start_bit;
      if ((ma & mb) != 0) return false;
    }
  }
  return true;
}

/// Data frames carry the counter at bits 52..55 and the CRC at 56..63; commands and responses
/// the CRC.
constexpr bool e2e_ok(const MessageDef& m) {
  bool counter = false;
  bool crc = false;
  for (const SignalDef& s : m.signals) {
    counter = counter || (s.field == Field::kCounter && s.start_bit == kCounterStartBit &&
                          s.length == kCounterLength);
    crc = crc || (s.field == Field::kCrc && s.start_bit == kCrcStartBit && s.length == 8);
  }
  return crc && (counter || (m.kind != MessageKind::kData && m.kind != MessageKind::kInput));
}

/// The documented limits are representable and distinct from the not-available raw value.
constexpr bool limits_ok(const MessageDef& m) {
  for (const SignalDef& s : m.signals) {
    if (s.min > s.max || s.factor <= 0.0) return false;
    const double lo = s.is_signed ? -static_cast<double>(std::uint64_t{1} << (s.length - 1)) : 0.0;
    const double hi = s.is_signed ? static_cast<double>((std::uint64_t{1} << (s.length - 1)) - 1)
                                  : static_cast<double>(low_mask(s.length));
    const double raw_min = (s.min - s.offset) / s.factor;
    const double raw_max = (s.max - s.offset) / s.factor;
    if (raw_min < lo - 0.5 || raw_max > hi + 0.5) return false;
    if (s.has_na && (static_cast<double>(s.na_raw) >= raw_min - 0.5 &&
                     static_cast<double>(s.na_raw) <= raw_max + 0.5)) {
      return false;
    }
  }
  return true;
}

constexpr bool is_navigation(Field f) {
  return f == Field::kQuaternion || f == Field::kEuler || f == Field::kRate ||
         f == Field::kAngularAccel || f == Field::kAccel || f == Field::kVelocity ||
         f == Field::kPosition;
}

/// Every navigation signal can say "not available" (an invalid group, a non-finite value): none
/// may be forced to send a made-up number.
constexpr bool navigation_has_na(const MessageDef& m) {
  for (const SignalDef& s : m.signals) {
    if (is_navigation(s.field) && !s.has_na) return false;
  }
  return true;
}

constexpr bool all(bool (*check)(const MessageDef&)) {
  for (const MessageDef& m : kMessages) {
    if (!check(m)) return false;
  }
  return true;
}

static_assert(ids_unique_and_in_range(), "message identifiers overlap or exceed 11 bits");
static_assert(all(layout_ok), "signals overlap or leave the 64-bit payload");
static_assert(all(e2e_ok), "a message lacks its counter or CRC at the standard place");
static_assert(all(navigation_has_na), "a navigation signal has no not-available code");
static_assert(all(limits_ok), "a signal's [min, max] is not representable or covers its N/A code");
static_assert(crc8_sae_j1850(std::array<std::uint8_t, 9>{'1', '2', '3', '4', '5', '6', '7', '8',
                                                         '9'}) == 0x4B,
              "CRC-8/SAE-J1850 check value");

}  // namespace
}  // namespace gfins::can
