// Health of the board: counters (they only grow, wrap at 2^32), the stuck-channel detector and
// the status bits published with every epoch (docs/faults.md maps each fault to all of these).
#pragma once

#include "gfins/can/epoch.hpp"

#include <array>
#include <cstdint>

#include "gfins/sample/raw_sample.hpp"

namespace gfins::app {

struct HealthCounters {
  std::uint32_t samples = 0;            // frames read from the ADC
  std::uint32_t missed_edges = 0;       // data-ready edges lost (sequence jumps)
  std::uint32_t extra_edges = 0;        // data-ready edges without a new conversion
  std::uint32_t drdy_timeouts = 0;      // no data-ready edge within the timeout
  std::uint32_t crc_errors = 0;         // ADC frames with a CRC mismatch
  std::uint32_t adc_resets = 0;         // ADC resets seen and recovered from
  std::uint32_t adc_read_errors = 0;    // read_sample failures other than timeouts
  std::uint32_t saturated_samples = 0;  // samples with a channel at full scale
  std::uint32_t stuck_events = 0;       // channels that became stuck
  std::uint32_t rejected_samples = 0;   // samples not integrated (CRC, saturation)
  std::uint32_t can_tx_dropped = 0;     // frames the CAN backend dropped or refused
  std::uint32_t can_rx_dropped = 0;     // received frames lost: the kernel's socket queue was full
                                        // (SO_RXQ_OVFL) or the controller overflowed
  std::uint32_t bus_off_events = 0;     // transitions into bus-off
  std::uint32_t loop_overruns = 0;      // a cycle finished after the next edge was due
  std::uint32_t log_dropped = 0;        // log records lost to a full queue
  std::uint32_t commands = 0;           // commands executed
  std::uint32_t command_errors = 0;     // commands refused (malformed, out of range, busy, ...)
  std::uint32_t commands_replayed = 0;  // of which refused for their sequence number
  std::uint8_t last_refusal = 0;        // can::ResultCode of the last refusal; 0 = none yet
  std::uint32_t aiding_inputs = 0;      // GNSS fixes and headings decoded from input frames
  std::uint32_t aiding_input_errors = 0;  // input frames refused (CRC, length, range, stale id)
  std::uint32_t gravity_mismatches = 0;   // alignments whose |f| disagreed with the gravity model
  std::uint32_t record_dropped = 0;       // recorder records lost (full queue; record.file set)
  std::uint8_t stuck_mask = 0;            // channels stuck now (bit j = channel j)
  std::uint8_t saturated_mask = 0;        // channels saturated in the last sample
};

/// Bits of can::Epoch::status_bits are the CAN status frame's StatusFlags
/// (firmware/can/include/gfins/can/epoch.hpp, docs/can-interface.md): the firmware sets them by
/// those names. Event bits (sample gap, CRC error, saturation, loop overrun, CAN drops, ADC
/// recovery, data-ready lost, bus-off, extra edge, ADC read error) stay set for kEventHoldSamples
/// after the event so a status frame sent at a lower rate still shows it; the counters are exact.
namespace status_bits = can::status_bits;

/// The counters the bus carries (GfinsHealthAdc / GfinsHealthSystem), out of the loop's.
inline can::Health bus_health(const HealthCounters& h) {
  can::Health c;
  c.missed_drdy_edges = h.missed_edges;
  c.adc_crc_errors = h.crc_errors;
  c.adc_resets = h.adc_resets;
  c.saturated_samples = h.saturated_samples;
  c.stuck_channel_mask = h.stuck_mask;
  c.can_tx_dropped = h.can_tx_dropped;
  c.bus_off_events = h.bus_off_events;
  c.loop_overruns = h.loop_overruns;
  c.log_dropped = h.log_dropped;
  return c;
}

/// GfinsCommandCounters out of the loop's counters and the settings' source.
inline can::CommandCounters bus_command_counters(const HealthCounters& h,
                                                 std::uint8_t settings_source) {
  can::CommandCounters c;
  c.done = h.commands;
  c.refused = h.command_errors;
  c.replayed = h.commands_replayed;
  c.last_refusal = h.last_refusal;
  c.settings_source = settings_source;
  return c;
}

/// Event bits held for one second at 1 kHz (status frames go out at 100 Hz by default).
inline constexpr std::uint32_t kEventHoldSamples = 1000;

/// Holds event bits set for kEventHoldSamples samples after their last occurrence.
class LatchedBits {
 public:
  void set(std::uint32_t bits, std::uint32_t sample) {
    for (unsigned b = 0; b < 32; ++b) {
      if ((bits >> b) & 1u) last_[b] = sample, active_ |= 1u << b;
    }
  }
  std::uint32_t get(std::uint32_t sample) {
    for (unsigned b = 0; b < 32; ++b) {
      if (((active_ >> b) & 1u) != 0 && sample - last_[b] >= kEventHoldSamples) {
        active_ &= ~(1u << b);
      }
    }
    return active_;
  }

 private:
  std::array<std::uint32_t, 32> last_{};
  std::uint32_t active_ = 0;
};

/// A channel is stuck when its code has not changed for kStuckSamples consecutive valid samples
/// while at least one other channel changed in that window (so a noiseless simulation or a
/// genuinely constant input on every channel is not called stuck). Codes at either rail are the
/// saturation detector's business and do not count here.
///
/// K = 50 samples (50 ms at 1 kHz): a live QA-1100 channel at rest shows tens of counts of noise
/// (70 µg rms · 1.33 V/g ≈ 93 µV ≈ 78 counts of 1.19 µV; docs/sensor-model.md), and even a channel
/// with only 2 counts rms repeats its code with probability < 0.15 per sample, so 49 repeats in a
/// row happen with probability < 0.15^49 ≈ 4e-41: no false alarms; 50 ms is short against the
/// seconds over which a wrong channel spoils the navigation solution.
inline constexpr std::uint32_t kStuckSamples = 50;

class StuckDetector {
 public:
  /// Feeds one valid sample; returns the mask of channels stuck now.
  std::uint8_t update(const std::array<std::int32_t, kAdcChannels>& counts) {
    for (std::size_t j = 0; j < kAdcChannels; ++j) {
      const bool rail = counts[j] >= kAdcCodeMax || counts[j] <= kAdcCodeMin;
      if (primed_ && counts[j] == last_[j] && !rail) {
        if (run_[j] < kStuckSamples) ++run_[j];
      } else {
        run_[j] = 0;
      }
      last_[j] = counts[j];
    }
    primed_ = true;
    std::uint8_t mask = 0;
    for (std::size_t j = 0; j < kAdcChannels; ++j) {
      if (run_[j] < kStuckSamples) continue;
      bool others_move = false;
      for (std::size_t k = 0; k < kAdcChannels; ++k) {
        if (k != j && run_[k] < kStuckSamples) others_move = true;
      }
      if (others_move) mask = static_cast<std::uint8_t>(mask | (1u << j));
    }
    return mask;
  }
  void reset() { primed_ = false, run_.fill(0); }

 private:
  std::array<std::int32_t, kAdcChannels> last_{};
  std::array<std::uint32_t, kAdcChannels> run_{};
  bool primed_ = false;
};

}  // namespace gfins::app
