// Register-level model of the TI ADS131M06 behind hal::SpiDevice (ArduPilot SITL / Zephyr
// emul style): the real driver talks to it with the same bytes it sends to the chip.
//
// What is modelled (sections of the datasheet, see gfins/drivers/ads131m06_registers.hpp):
// - frames of WLENGTH-sized words (16, 24, 32 zero-padded, 32 sign-extended; §8.5.1.8); the
//   response word answers the command of the PREVIOUS frame (§8.5.1.10, Table 8-11);
// - NULL, RESET, STANDBY, WAKEUP, LOCK, UNLOCK, RREG (single, and several registers with the
//   111a... acknowledgment and no conversion data), WREG (one or several registers; ID and
//   STATUS are read only);
// - STATUS built from the state: LOCK, CRC_ERR (cleared when STATUS is output), CRC_TYPE,
//   RESET and WLENGTH mirrored from MODE, DRDYn = new data for channel n since the last frame
//   that output conversion data (an assumption: the datasheet does not say when DRDYn clears);
// - output CRC always (CCITT or ANSI per MODE.CRC_TYPE, seed FFFFh, §8.3.12); input CRC checked
//   when MODE.RX_CRC_EN: a failing command is not executed except WREG, which always executes,
//   and the next response is that of NULL (§8.3.12);
// - conversions: code = round(v_pin · gain / vref · 2^23) clipped to the 24-bit range
//   (§8.5.1.9), gain from GAIN1/GAIN2 (§8.3.3), disabled channels (CLOCK.CHn_EN = 0) read 0.
// Not modelled: timing (tREGACQ after reset, SPI timeout), the digital filter's settling and
// group delay, the register map CRC, DC block, phase and gain/offset calibration registers
// (stored, not applied), global chop, current detect.
//
// Fault injection: output CRC corruption, input CRC errors, stuck and saturated channels, a
// chip reset at any time, a register upset, a wrong ID, halted conversions.
#pragma once

#include <array>
#include <cstdint>
#include <span>

#include "gfins/drivers/ads131m06_registers.hpp"
#include "gfins/hal/spi_device.hpp"

namespace gfins::sim {

class Ads131m06Model : public hal::SpiDevice {
 public:
  using Codes = std::array<std::int32_t, drivers::ads131m06::kChannels>;
  using PinVolts = std::array<double, drivers::ads131m06::kChannels>;

  /// `id_low_byte`: the unspecified low byte of the ID register (26xxh).
  explicit Ads131m06Model(double vref_v = 1.2, std::uint8_t id_low_byte = 0x00);

  // --- analog side -------------------------------------------------------------------------
  /// One simultaneous conversion of the pin voltages. false when no conversion happens
  /// (standby, or halted by fault injection): the data-ready pin must then stay quiet.
  bool convert(const PinVolts& pin_volts);
  /// Same with codes given directly (scripted tests).
  bool convert_codes(const Codes& codes);
  /// The code the chip produces for `pin_volts` on channel `ch` at its current gain.
  std::int32_t code_for(int ch, double pin_volts) const;
  /// Output data rate at `clkin_hz` with the current CLOCK.OSR (§8.3.7).
  double data_rate_hz(double clkin_hz) const;
  int gain(int ch) const;

  // --- fault injection ---------------------------------------------------------------------
  /// Flip one data bit in the next `frames` output frames after the CRC is computed.
  void corrupt_output_crc(std::uint32_t frames) { corrupt_out_ = frames; }
  /// Corrupt the input CRC word of the next `frames` input frames (a DIN bit error).
  void corrupt_input_crc(std::uint32_t frames) { corrupt_in_ = frames; }
  /// Channel `ch` keeps outputting `code` whatever the input.
  void stick_channel(int ch, std::int32_t code);
  /// Channel `ch` reads positive (or negative) full scale whatever the input.
  void saturate_channel(int ch, bool positive = true);
  void clear_channel_faults();
  /// A chip reset (brown-out, RESET pin): registers back to their reset values, STATUS.RESET set.
  void power_on_reset();
  /// Overwrite a register behind the driver's back (a single-event upset).
  void upset_register(drivers::ads131m06::Reg r, std::uint16_t value);
  /// The next `n` conversions do not happen (lost clock): no data, no data-ready edge.
  void halt_conversions(std::uint32_t n) { halted_ = n; }
  void set_id(std::uint16_t id) { regs_[0] = id; }

  // --- introspection -----------------------------------------------------------------------
  std::uint16_t reg(drivers::ads131m06::Reg r) const { return regs_[drivers::ads131m06::addr(r)]; }
  std::uint16_t status() const;
  bool standby() const { return standby_; }
  /// Whether the next convert() produces a conversion (not in standby, not halted).
  bool will_convert() const { return !standby_ && halted_ == 0; }
  bool locked() const { return locked_; }
  std::uint32_t frames() const { return frames_; }
  std::uint32_t input_crc_failures() const { return input_crc_failures_; }
  std::uint32_t commands_executed() const { return commands_executed_; }

 private:
  enum class Pending : std::uint8_t { kStatus, kWord, kMultiRead };

  Status do_transfer(std::span<const std::uint8_t> tx, std::span<std::uint8_t> rx) override;
  void reset_registers();
  std::size_t word_bytes() const;
  std::uint16_t crc(std::span<const std::uint8_t> bytes) const;
  void put_code(std::span<std::uint8_t> word, std::int32_t code) const;
  void execute(std::uint16_t command, std::span<const std::uint8_t> tx, bool crc_ok);

  double vref_v_;
  std::uint8_t id_low_byte_;
  std::array<std::uint16_t, drivers::ads131m06::kRegisterCount> regs_{};
  Codes codes_{};
  bool new_data_ = false;
  bool crc_err_ = false;
  bool locked_ = false;
  bool standby_ = false;
  Pending pending_ = Pending::kStatus;
  std::uint16_t pending_word_ = 0;
  std::uint8_t multi_addr_ = 0;
  std::uint8_t multi_count_ = 0;

  std::array<bool, drivers::ads131m06::kChannels> stuck_{};
  Codes stuck_code_{};
  std::uint32_t corrupt_out_ = 0;
  std::uint32_t corrupt_in_ = 0;
  std::uint32_t halted_ = 0;
  std::uint32_t frames_ = 0;
  std::uint32_t input_crc_failures_ = 0;
  std::uint32_t commands_executed_ = 0;
};

}  // namespace gfins::sim
