// The seams of the sample loop, each with one implementation per board: where samples come from
// (the ADS131M06 driver on the board and on the simulated board) and where epochs go (the CAN
// publisher). What crosses them is the CAN protocol's own vocabulary (can::Epoch, and for commands
// can::Command / can::Response, which the loop decodes and encodes itself): one type per fact.
// Everything the loop calls through these is allocation-free and non-blocking (read_sample waits
// for data-ready with a timeout: that wait, and the loop's pause of one period after a read that
// failed at once, are its only sleeps).
#pragma once

#include <array>
#include <cstdint>
#include <optional>

#include "gfins/app/config.hpp"
#include "gfins/can/epoch.hpp"
#include "gfins/sample/raw_sample.hpp"
#include "gfins/status/status.hpp"

namespace gfins::app {

/// What the ADC driver counts (cumulative).
struct AdcCounters {
  std::uint32_t crc_errors = 0;
  std::uint32_t missed_edges = 0;
  std::uint32_t extra_edges = 0;
  std::uint32_t chip_resets = 0;
};

class SampleSource {
 public:
  virtual ~SampleSource() = default;
  /// Waits for the next data-ready edge (at most timeout_ns) and reads that conversion.
  /// kTimeout when no edge came; other errors when the frame could not be read.
  [[nodiscard]] Result<RawSample> read_sample(std::int64_t timeout_ns) {
    if (timeout_ns < 0) return Status(ErrorCode::kInvalidArgument, "adc: negative timeout");
    return do_read_sample(timeout_ns);
  }
  AdcCounters counters() const { return do_counters(); }
  /// Volts at the sensor per count (the front end's LSB) of the configured chain.
  double volts_per_count() const { return do_volts_per_count(); }

 private:
  virtual Result<RawSample> do_read_sample(std::int64_t timeout_ns) = 0;
  virtual AdcCounters do_counters() const = 0;
  virtual double do_volts_per_count() const = 0;
};

class EpochSink {
 public:
  virtual ~EpochSink() = default;
  /// Once per sample; sends what the message dividers select. Never blocks. Returns how many
  /// frames it handed to the bus (accepted or refused).
  virtual std::uint32_t publish(const can::Epoch& e) = 0;
  /// Divider of message `message` (index in kMessageNames); 0 = off.
  [[nodiscard]] virtual Status set_divider(std::size_t message, std::uint16_t divider) = 0;
  /// Every divider of kMessageNames at once, under the same rules (nothing changes when refused).
  [[nodiscard]] virtual Status set_dividers(
      const std::array<std::uint16_t, kNumMessages>& dividers) = 0;
};

/// The CAN settings commands changed, which the board keeps across restarts
/// (docs/can-interface.md, "Stored settings"): only what a command set (SetNodeId: the node id
/// of the next start; SetDivider: that message's divider; SetIdBase: an identifier group's base
/// of the next start); the rest is the configuration's.
struct CanSettings {
  std::optional<std::uint8_t> node_id;
  std::array<std::optional<std::uint16_t>, kNumMessages> dividers{};
  std::array<std::optional<std::uint16_t>, can::kIdGroupCount> id_bases{};
  bool empty() const {
    for (const auto& d : dividers) {
      if (d) return false;
    }
    for (const auto& b : id_bases) {
      if (b) return false;
    }
    return !node_id;
  }
  friend bool operator==(const CanSettings&, const CanSettings&) = default;
};

/// Where the loop hands settings a command changed; the store writes them off the loop's thread.
class SettingsPort {
 public:
  virtual ~SettingsPort() = default;
  /// Loop side, never blocks: keep `s` (empty: forget what is kept; the configuration's settings
  /// apply from the next start). False when the writer cannot take it now (busy): the loop
  /// offers it again next cycle.
  virtual bool post(const CanSettings& s) = 0;
  /// Where the settings in use came from: GfinsCommandCounters.SettingsSource.
  virtual std::uint8_t source() const = 0;
};

}  // namespace gfins::app
