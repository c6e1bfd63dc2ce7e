// Publisher: per-message rate dividers of the sample rate + the message table -> hal::CanBus.
// Called once per sample from the real-time loop: no allocation, no blocking (hal::CanBus::send
// never blocks), no exceptions.
#pragma once

#include <array>
#include <cstdint>
#include <limits>

#include "gfins/can/epoch.hpp"
#include "gfins/can/message_table.hpp"
#include "gfins/hal/can_bus.hpp"
#include "gfins/status/status.hpp"

namespace gfins::can {

/// Dividers of the sample rate per message (index = MessageId); 0 = off.
using Dividers = std::array<std::uint16_t, kMessageCount>;

constexpr Dividers default_dividers() {
  Dividers d{};
  for (std::size_t i = 0; i < kMessageCount; ++i) d[i] = kMessages[i].default_divider;
  return d;
}

/// Worst-case length in bits of a base-format (11-bit identifier) data frame of `data_bytes`
/// bytes (ISO 11898-1): SOF, identifier, RTR, IDE, r0, DLC (4), data and CRC (15) are subject to
/// bit stuffing, at worst one stuff bit per 4 bits after the first; then CRC delimiter, ACK slot,
/// ACK delimiter, EOF (7) and the 3-bit interframe space. 135 bits for 8 data bytes.
constexpr int worst_case_frame_bits(int data_bytes) {
  const int stuffed = 1 + 11 + 1 + 1 + 1 + 4 + 8 * data_bytes + 15;
  return stuffed + (stuffed - 1) / 4 + 1 + 1 + 1 + 7 + 3;
}

/// Bits per second the board's periodic frames take in the worst case (every frame at its
/// stuffed length) with dividers `d` of `sample_rate_hz`. Command responses (one per command
/// received) are not periodic and not counted.
double worst_case_bits_per_s(const Dividers& d, double sample_rate_hz);

/// The share of the bus the board may take: set_divider and the configuration refuse dividers
/// whose worst-case load exceeds max_load x bit_rate. The default (no limit) is for host tools
/// that make logs; the firmware sets its configured bus (can.bit_rate, can.max_bus_load_percent).
struct BusBudget {
  double sample_rate_hz = kDefaultSampleRateHz;
  std::uint32_t bit_rate = kDefaultBitRate;
  double max_load = std::numeric_limits<double>::infinity();  // fraction of bit_rate
  [[nodiscard]] double load(const Dividers& d) const {
    return worst_case_bits_per_s(d, sample_rate_hz) / static_cast<double>(bit_rate);
  }
};

struct PublisherConfig {
  std::uint8_t node_id = 0;  // 0..kMaxNodeId: added to every base identifier
  IdBases ids{};             // the first identifier of each group (docs/can-interface.md)
  Dividers dividers = default_dividers();
  BusBudget budget;
};

struct PublisherCounters {
  std::uint32_t epochs = 0;              // epochs opened (GfinsEpoch frames built)
  std::uint32_t frames_sent = 0;         // frames the bus accepted
  std::uint32_t send_failures = 0;       // frames the bus refused (dropped, bus off, ...)
  std::uint32_t saturated_values = 0;    // values clipped to their signal's limit
  std::uint32_t unavailable_values = 0;  // NaN/inf values sent as not available
};

/// Checks a divider set: Epoch and Status equal (Status rides with every Epoch); every enabled
/// data message a multiple of the Epoch divider (so its frames always follow an Epoch frame);
/// command/response entries 0.
[[nodiscard]] Status check_dividers(const Dividers& d);
/// check_dividers, the node id, and the dividers' load within the budget (kResourceExhausted).
[[nodiscard]] Status check_config(const PublisherConfig& c);

/// Values of one epoch as the bus carries them, before quantisation: what the encoder reads for a
/// (field, index) of the table. Exposed so the host can compare decoded frames with the state.
/// NaN (sent as the signal's not-available code) for a field of a group `e.valid` marks invalid.
double epoch_field(const Epoch& e, Field field, std::uint8_t index);

/// The frame of data message `m` for epoch `e` with epoch counter `counter`: encoded, sealed with
/// its CRC. `saturated`/`unavailable` are incremented per clipped / not-available value (of a
/// navigation value or sensor output; a σ does not count: it is N/A without a filter and reads
/// "at least max" when saturated). A
/// multiplexed message carries the signals of selector value `selector` (ignored otherwise).
/// The identifier is the message's with its group at `ids`.
hal::CanFrame encode_data_frame(const MessageDef& m, const Epoch& e, std::uint8_t node_id,
                                std::uint8_t counter, std::uint32_t* saturated,
                                std::uint32_t* unavailable, std::uint8_t selector = 0,
                                const IdBases& ids = {});

/// Selector values of a multiplexed data message (0..n-1 in turn); 0 when not multiplexed.
std::uint8_t selector_count(const MessageDef& m);

class Publisher {
 public:
  /// An invalid configuration (see check_config) is replaced by the defaults and reported by
  /// init_status(); call check_config() first to refuse it instead.
  Publisher(hal::CanBus& bus, const PublisherConfig& c);

  /// Once per sample. Sends the messages whose divider divides nav.seq, GfinsEpoch and
  /// GfinsStatus first; the status frame carries kCanSaturated / kCanNotAvailable when a value of
  /// this epoch was clipped / not available. Send failures are counted, never retried here.
  void publish(const Epoch& e);

  /// Changes one data message's divider (0 = off) under the rules of check_dividers
  /// (kInvalidArgument / kOutOfRange otherwise) and within the budget (kResourceExhausted);
  /// nothing changes when refused.
  [[nodiscard]] Status set_divider(MessageId m, std::uint16_t divider);
  /// Replaces every divider at once under the same rules; nothing changes when refused.
  [[nodiscard]] Status set_dividers(const Dividers& d);

  std::uint16_t divider(MessageId m) const { return dividers_[static_cast<std::size_t>(m)]; }
  const Dividers& dividers() const { return dividers_; }
  std::uint8_t node_id() const { return node_id_; }
  Status init_status() const { return init_status_; }
  const PublisherCounters& counters() const { return counters_; }

 private:
  hal::CanBus* bus_;
  std::uint8_t node_id_ = 0;
  IdBases ids_{};
  Dividers dividers_{};
  BusBudget budget_{};
  std::uint8_t counter_ = 0;                            // epoch counter, mod 16
  std::array<std::uint8_t, kMessageCount> selector_{};  // next selector of multiplexed messages
  Status init_status_{};
  PublisherCounters counters_{};
};

}  // namespace gfins::can
