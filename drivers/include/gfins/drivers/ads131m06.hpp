// Driver for the TI ADS131M06 (6-channel, simultaneous-sampling, 24-bit delta-sigma ADC) over the
// hal seams: hal::SpiDevice for the frames, hal::DataReadyLine for the DRDY pin. No heap, no
// exceptions: errors are Status values and every fault is counted (PX4's IMU drivers' pattern:
// an explicit state machine plus error counters published with the samples).
//
// State machine:
//
//   kReset ──start()──► RESET command, identity check (ID = 26xxh) ─► kConfigure
//   kConfigure: write each register of the table, read it back, compare ─► kRun (or kFailed)
//   kRun: one frame per data-ready edge (NULL command, or RREG of the next table register every
//         `verify_every_frames` frames: the read-back arrives in the next frame's response word,
//         so re-verification costs no extra transfer)
//   kRun ─► kRecover on: STATUS.RESET (the chip reset itself), a register that no longer reads
//         what was written, `timeouts_before_recover` data-ready timeouts in a row
//   kRecover: reset + identity + configure again ─► kRun; after `max_recovery_attempts` failed
//         recoveries in a row ─► kFailed (read_sample refuses; start() may be called again)
//
// The frame layout, commands and CRC are in ads131m06_registers.hpp with the datasheet sections.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "gfins/drivers/ads131m06_registers.hpp"
#include "gfins/hal/data_ready.hpp"
#include "gfins/hal/spi_device.hpp"
#include "gfins/sample/raw_sample.hpp"
#include "gfins/status/status.hpp"

namespace gfins::drivers {

enum class Ads131m06State : std::uint8_t { kReset, kConfigure, kRun, kRecover, kFailed };
const char* to_string(Ads131m06State s);

/// Every fault the driver can see, counted since construction (never reset by the driver).
struct Ads131m06Counters {
  std::uint32_t frames = 0;               // data frames read in kRun
  std::uint32_t crc_errors = 0;           // output (DOUT) CRC mismatches: frame discarded
  std::uint32_t input_crc_errors = 0;     // STATUS.CRC_ERR: the chip rejected a DIN frame
  std::uint32_t missed_edges = 0;         // data-ready sequence gaps (edges never delivered)
  std::uint32_t extra_edges = 0;          // edges whose frame carried no new data (DRDYn = 0)
  std::uint32_t chip_resets = 0;          // STATUS.RESET seen while running
  std::uint32_t timeouts = 0;             // wait_edge timed out
  std::uint32_t register_mismatches = 0;  // read-back differs from the table (start or run)
  std::uint32_t recoveries = 0;           // reset + reconfigure cycles started from kRun
  std::uint32_t saturated_samples = 0;    // samples with a channel at a rail
  std::uint32_t stuck_events = 0;         // a channel repeated one code stuck_after_frames times
  std::uint32_t spi_errors = 0;           // SpiDevice::transfer failed
};

struct Ads131m06Config {
  /// Output data rate, Hz. fDATA = fCLKIN / 2 / OSR (§8.3.6, §8.3.7): with the default 8.192 MHz
  /// CLKIN, fMOD = 4.096 MHz and 1 kHz needs OSR = 4096 (code 101b). Rates no OSR reaches
  /// exactly at this CLKIN are refused by start() (kInvalidArgument).
  double sample_rate_hz = 1000.0;
  double clkin_hz = 8.192e6;  // CLKIN, nominal for high-resolution mode (§6.3)
  ads131m06::PowerMode power_mode = ads131m06::PowerMode::kHighResolution;
  std::array<std::uint8_t, ads131m06::kChannels> pga_gain{1, 1, 1, 1, 1, 1};  // 1,2,4..128
  double vref_v = 1.2;    // internal reference (§8.3.4): full scale ±vref/gain at the pins
  bool input_crc = true;  // MODE.RX_CRC_EN: the chip rejects DIN frames with a bad CRC
  std::uint32_t verify_every_frames = 1000;   // one register re-read per this many frames; 0 off
  std::uint32_t timeouts_before_recover = 3;  // consecutive data-ready timeouts
  std::uint32_t max_recovery_attempts = 3;    // consecutive failed recoveries before kFailed
  std::uint32_t stuck_after_frames = 200;     // identical codes in a row → stuck; 0 off
};

/// One register of the configuration table: written at start and on recovery, read back, and
/// re-verified periodically while running.
struct RegisterSetting {
  ads131m06::Reg reg = ads131m06::Reg::kMode;
  std::uint16_t value = 0;
};

class Ads131m06 {
 public:
  static constexpr std::size_t kTableSize = 4;  // MODE, GAIN1, GAIN2, CLOCK
  static constexpr int kConfigAttempts = 3;     // write + read-back attempts per register
  static constexpr int kMaxEdgesPerRead = 4;    // spurious edges skipped inside one read_sample

  Ads131m06(hal::SpiDevice& spi, hal::DataReadyLine& drdy, const Ads131m06Config& c);

  /// Reset → identity check → configuration from the table with read-back. kInvalidArgument for
  /// a configuration the chip cannot do (rate, gain), kUnavailable when the chip does not
  /// answer as an ADS131M06, kDataLoss when a register does not read back; the state is then
  /// kFailed. May be called again to retry.
  Status start();

  /// Waits for the next data-ready edge (at most timeout_ns), reads one frame and decodes it.
  /// seq and t_ns come from the edge (seq corrected for spurious edges, so it stays the
  /// conversion index). flags: kCrcError (counts zeroed), kSaturated. Errors: kTimeout,
  /// kDataLoss (chip reset or register mismatch detected: the driver has already recovered
  /// when it returns), kFailedPrecondition (not started / failed), SPI errors.
  Result<RawSample> read_sample(std::int64_t timeout_ns);

  Ads131m06State state() const { return state_; }
  const Ads131m06Counters& counters() const { return counters_; }
  /// One LSB at the ADC input pins of `channel`, V: vref / (gain · 2^23) (§8.5.1.9).
  double volts_per_count(int channel = 0) const;
  /// Channels whose code has not changed for stuck_after_frames frames (bit n = channel n).
  std::uint32_t stuck_mask() const { return stuck_mask_; }
  std::uint32_t osr() const { return osr_; }
  std::span<const RegisterSetting> register_table() const { return table_; }
  const Ads131m06Config& config() const { return config_; }

  /// The OSR[2:0] code giving exactly `rate_hz` at `clkin_hz` (fDATA = fCLKIN / 2 / OSR).
  static Result<std::uint8_t> osr_code_for(double rate_hz, double clkin_hz);
  /// The register table for a configuration (kInvalidArgument for an impossible one).
  static Status make_table(const Ads131m06Config& c,
                           std::array<RegisterSetting, kTableSize>& table);

 private:
  struct Frame {
    std::uint16_t response = 0;
    std::array<std::int32_t, ads131m06::kChannels> codes{};
    bool crc_ok = false;
  };

  Status transfer_frame(std::uint16_t command, std::span<const std::uint16_t> data, Frame& out);
  Result<std::uint16_t> command_response(std::uint16_t command,
                                         std::span<const std::uint16_t> data = {});
  Status reset_and_identify();
  Status configure();
  Status bring_up();  // reset + identify + configure → kRun or kFailed
  Status recover();
  void track_stuck(const std::array<std::int32_t, ads131m06::kChannels>& codes);

  hal::SpiDevice& spi_;
  hal::DataReadyLine& drdy_;
  Ads131m06Config config_;
  std::array<RegisterSetting, kTableSize> table_{};
  std::uint32_t osr_ = 0;
  Ads131m06State state_ = Ads131m06State::kReset;
  Ads131m06Counters counters_{};

  std::array<std::uint8_t, ads131m06::kFrameBytes> tx_{};
  std::array<std::uint8_t, ads131m06::kFrameBytes> rx_{};
  std::uint16_t prev_command_ = ads131m06::cmd::kNull;  // decides what the response word means
  bool have_last_edge_ = false;
  std::uint32_t last_edge_seq_ = 0;
  std::uint32_t seq_correction_ = 0;  // spurious edges so far (subtracted from edge seq)
  std::uint32_t consecutive_timeouts_ = 0;
  std::uint32_t failed_recoveries_ = 0;
  std::uint32_t frames_since_verify_ = 0;
  std::size_t verify_index_ = 0;          // next table register to re-verify
  std::size_t pending_verify_index_ = 0;  // register of the RREG sent in the previous frame
  std::array<std::int32_t, ads131m06::kChannels> last_codes_{};
  std::array<std::uint32_t, ads131m06::kChannels> same_count_{};
  std::uint32_t stuck_mask_ = 0;
};

}  // namespace gfins::drivers
