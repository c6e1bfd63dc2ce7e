// Register-level ADS131M06 model: see the header for what is modelled and the datasheet sections.
#include "gfins/host_sim/chip/ads131m06_model.hpp"

#include <cmath>

#include "gfins/sample/raw_sample.hpp"

namespace gfins::sim {

namespace reg = drivers::ads131m06;

Ads131m06Model::Ads131m06Model(double vref_v, std::uint8_t id_low_byte)
    : vref_v_(vref_v), id_low_byte_(id_low_byte) {
  reset_registers();
}

void Ads131m06Model::reset_registers() {
  regs_.fill(0);
  regs_[reg::addr(reg::Reg::kId)] = static_cast<std::uint16_t>(reg::kIdResetValue | id_low_byte_);
  regs_[reg::addr(reg::Reg::kStatus)] = reg::kStatusResetValue;
  regs_[reg::addr(reg::Reg::kMode)] = reg::kModeResetValue;
  regs_[reg::addr(reg::Reg::kClock)] = reg::kClockResetValue;
  regs_[reg::addr(reg::Reg::kGain1)] = reg::kGainResetValue;
  regs_[reg::addr(reg::Reg::kGain2)] = reg::kGainResetValue;
  regs_[reg::addr(reg::Reg::kCfg)] = reg::kCfgResetValue;
  for (int ch = 0; ch < reg::kChannels; ++ch)
    regs_[reg::channel_reg(ch, 3)] = reg::kGcalMsbResetValue;
  new_data_ = false;
  crc_err_ = false;
  locked_ = false;
  standby_ = false;
  pending_ = Pending::kStatus;
  codes_.fill(0);
}

void Ads131m06Model::power_on_reset() { reset_registers(); }

void Ads131m06Model::upset_register(reg::Reg r, std::uint16_t value) {
  regs_[reg::addr(r)] = value;
}

void Ads131m06Model::stick_channel(int ch, std::int32_t code) {
  stuck_[static_cast<std::size_t>(ch)] = true;
  stuck_code_[static_cast<std::size_t>(ch)] = code;
}

void Ads131m06Model::saturate_channel(int ch, bool positive) {
  stick_channel(ch, positive ? kAdcCodeMax : kAdcCodeMin);
}

void Ads131m06Model::clear_channel_faults() { stuck_.fill(false); }

std::size_t Ads131m06Model::word_bytes() const {
  const auto wl = static_cast<reg::WordLength>(
      (regs_[reg::addr(reg::Reg::kMode)] & reg::mode::kWlengthMask) >> reg::mode::kWlengthShift);
  return reg::word_bytes(wl);
}

std::uint16_t Ads131m06Model::status() const {
  const std::uint16_t mode = regs_[reg::addr(reg::Reg::kMode)];
  std::uint16_t s = static_cast<std::uint16_t>(
      mode & (reg::mode::kCrcType | reg::mode::kReset | reg::mode::kWlengthMask));
  if (locked_) s = static_cast<std::uint16_t>(s | reg::status::kLock);
  if (crc_err_) s = static_cast<std::uint16_t>(s | reg::status::kCrcErr);
  if (new_data_) {
    const auto enabled = static_cast<std::uint16_t>(
        (regs_[reg::addr(reg::Reg::kClock)] & reg::clock::kChannelEnableMask) >>
        reg::clock::kChannelEnableShift);
    s = static_cast<std::uint16_t>(s | (enabled & reg::status::kDrdyMask));
  }
  return s;
}

int Ads131m06Model::gain(int ch) const {
  const std::uint16_t g = regs_[reg::addr(ch < 4 ? reg::Reg::kGain1 : reg::Reg::kGain2)];
  return 1 << ((g >> reg::gain_shift(ch)) & reg::kGainFieldMask);
}

double Ads131m06Model::data_rate_hz(double clkin_hz) const {
  const unsigned code =
      (regs_[reg::addr(reg::Reg::kClock)] & reg::clock::kOsrMask) >> reg::clock::kOsrShift;
  return reg::data_rate_hz(clkin_hz, reg::kOsrValues[code]);
}

std::int32_t Ads131m06Model::code_for(int ch, double pin_volts) const {
  // §8.5.1.9: full scale ±vref/gain maps to ±2^23; outside it the code clips at 7FFFFFh/800000h.
  const double x = pin_volts * static_cast<double>(gain(ch)) / vref_v_ * 8388608.0;
  if (!std::isfinite(x)) return 0;
  if (x >= static_cast<double>(kAdcCodeMax)) return kAdcCodeMax;
  if (x <= static_cast<double>(kAdcCodeMin)) return kAdcCodeMin;
  return static_cast<std::int32_t>(std::lround(x));
}

bool Ads131m06Model::convert_codes(const Codes& codes) {
  if (standby_) return false;
  if (halted_ > 0) {
    --halted_;
    return false;
  }
  const std::uint16_t clock = regs_[reg::addr(reg::Reg::kClock)];
  for (std::size_t ch = 0; ch < codes_.size(); ++ch) {
    const bool enabled = (clock & (1u << (reg::clock::kChannelEnableShift + ch))) != 0;
    codes_[ch] = stuck_[ch] ? stuck_code_[ch] : (enabled ? codes[ch] : 0);
  }
  new_data_ = true;
  return true;
}

bool Ads131m06Model::convert(const PinVolts& pin_volts) {
  Codes c{};
  for (std::size_t ch = 0; ch < c.size(); ++ch)
    c[ch] = code_for(static_cast<int>(ch), pin_volts[ch]);
  return convert_codes(c);
}

std::uint16_t Ads131m06Model::crc(std::span<const std::uint8_t> bytes) const {
  if ((regs_[reg::addr(reg::Reg::kMode)] & reg::mode::kCrcType) == 0) {
    return reg::crc16_ccitt(bytes);
  }
  // ANSI CRC-16, x^16 + x^15 + x^2 + 1 (8005h), seed FFFFh, MSB first (§8.3.12, Table 8-7).
  std::uint16_t c = reg::kCrcSeed;
  for (const std::uint8_t b : bytes) {
    c = static_cast<std::uint16_t>(c ^ (b << 8));
    for (int i = 0; i < 8; ++i) {
      c = (c & 0x8000) != 0 ? static_cast<std::uint16_t>((c << 1) ^ 0x8005)
                            : static_cast<std::uint16_t>(c << 1);
    }
  }
  return c;
}

void Ads131m06Model::put_code(std::span<std::uint8_t> word, std::int32_t code) const {
  const auto wl = static_cast<reg::WordLength>(
      (regs_[reg::addr(reg::Reg::kMode)] & reg::mode::kWlengthMask) >> reg::mode::kWlengthShift);
  switch (wl) {
    case reg::WordLength::k16: {  // the 16 MSBs of the 24-bit result (§8.5.1.8)
      const auto u = static_cast<std::uint32_t>(code) & 0xFFFFFFu;
      word[0] = static_cast<std::uint8_t>(u >> 16);
      word[1] = static_cast<std::uint8_t>((u >> 8) & 0xFF);
      break;
    }
    case reg::WordLength::k24:
    case reg::WordLength::k32ZeroPad:
      reg::put_code24(word, code);
      break;
    case reg::WordLength::k32SignExtend: {
      const auto u = static_cast<std::uint32_t>(code);
      for (std::size_t i = 0; i < 4; ++i) word[i] = static_cast<std::uint8_t>(u >> (24 - 8 * i));
      break;
    }
  }
}

Status Ads131m06Model::do_transfer(std::span<const std::uint8_t> tx, std::span<std::uint8_t> rx) {
  ++frames_;
  const std::size_t wb = word_bytes();
  std::array<std::uint8_t, kMaxTransferBytes> out{};
  auto word = [&](std::size_t i) { return std::span<std::uint8_t>(out).subspan(i * wb, wb); };
  const std::size_t max_words = out.size() / wb;

  // ---- output: the answer to the previous frame's command, then data or registers, then CRC.
  std::size_t n = 0;
  switch (pending_) {
    case Pending::kStatus:
      reg::put_word16(word(n++), status());
      crc_err_ = false;  // §8.3.12: CRC_ERR clears when STATUS is output
      break;
    case Pending::kWord:
      reg::put_word16(word(n++), pending_word_);
      break;
    case Pending::kMultiRead:
      reg::put_word16(word(n++), static_cast<std::uint16_t>(reg::kRregMultiAckBase |
                                                            (multi_addr_ << reg::cmd::kAddrShift) |
                                                            (multi_count_ - 1)));
      break;
  }
  if (pending_ == Pending::kMultiRead) {
    // Table 8-11 note 1: the registers follow the acknowledgment; no conversion data.
    for (std::size_t i = 0; i < multi_count_ && n + 1 < max_words; ++i) {
      const std::size_t a = multi_addr_ + i;
      const std::uint16_t v =
          a == reg::addr(reg::Reg::kStatus) ? status() : (a < regs_.size() ? regs_[a] : 0);
      reg::put_word16(word(n++), v);
    }
  } else {
    for (const std::int32_t c : codes_) put_code(word(n++), c);
    new_data_ = false;  // assumption (header): DRDYn clear once the data went out
  }
  const std::uint16_t out_crc = crc(std::span<const std::uint8_t>(out).first(n * wb));
  reg::put_word16(word(n), out_crc);
  if (corrupt_out_ > 0) {
    --corrupt_out_;
    out[wb] ^= 0x01;  // a DOUT bit error in channel 0's data, after the CRC was computed
  }
  for (std::size_t i = 0; i < rx.size(); ++i) rx[i] = i < out.size() ? out[i] : 0;

  // ---- input: the command of this frame (answered in the next one).
  const std::uint16_t command = reg::get_word16(tx.first(2));
  const bool is_wreg = (command & reg::cmd::kOpcodeMask) == reg::cmd::kWregBase;
  const std::size_t crc_index = is_wreg ? 1 + reg::command_count(command) : 1;
  bool crc_ok = true;
  if ((regs_[reg::addr(reg::Reg::kMode)] & reg::mode::kRxCrcEn) != 0) {
    if ((crc_index + 1) * wb > tx.size()) {
      crc_ok = false;  // the frame ended before the CRC word
    } else {
      std::uint16_t got = reg::get_word16(tx.subspan(crc_index * wb, wb));
      if (corrupt_in_ > 0) {
        --corrupt_in_;
        got ^= 0x0001;
      }
      crc_ok = got == crc(tx.first(crc_index * wb));
    }
  }
  execute(command, tx, crc_ok);
  return Status::ok();
}

void Ads131m06Model::execute(std::uint16_t command, std::span<const std::uint8_t> tx, bool crc_ok) {
  const std::size_t wb = word_bytes();
  const std::uint16_t op = command & reg::cmd::kOpcodeMask;
  auto write_regs = [&]() {
    const std::uint8_t a = reg::command_address(command);
    const std::uint8_t cnt = reg::command_count(command);
    for (std::size_t i = 0; i < cnt; ++i) {
      if ((2 + i) * wb > tx.size()) break;
      const std::size_t addr = a + i;
      // ID and STATUS are read only; addresses beyond the map are ignored (not specified).
      if (addr <= reg::addr(reg::Reg::kStatus) || addr >= regs_.size()) continue;
      regs_[addr] = reg::get_word16(tx.subspan((1 + i) * wb, wb));
    }
  };
  pending_ = Pending::kStatus;
  if (!crc_ok) {
    // §8.3.12: nothing executes after an input CRC error except WREG; CRC_ERR is set and the
    // next response is that of NULL.
    crc_err_ = true;
    ++input_crc_failures_;
    if (op == reg::cmd::kWregBase) write_regs();
    return;
  }
  // LOCK leaves only NULL, UNLOCK and RREG valid (Table 8-11). What the chip answers to a
  // refused or unknown command is not specified: the model answers like NULL.
  if (locked_ && command != reg::cmd::kNull && command != reg::cmd::kUnlock &&
      op != reg::cmd::kRregBase) {
    return;
  }
  ++commands_executed_;
  switch (command) {
    case reg::cmd::kNull:
      return;
    case reg::cmd::kReset:
      reset_registers();
      pending_ = Pending::kWord;
      pending_word_ = reg::kResetAck;
      return;
    case reg::cmd::kStandby:
      standby_ = true;
      pending_ = Pending::kWord;
      pending_word_ = command;
      return;
    case reg::cmd::kWakeup:
      standby_ = false;
      pending_ = Pending::kWord;
      pending_word_ = command;
      return;
    case reg::cmd::kLock:
      locked_ = true;
      pending_ = Pending::kWord;
      pending_word_ = command;
      return;
    case reg::cmd::kUnlock:
      locked_ = false;
      pending_ = Pending::kWord;
      pending_word_ = command;
      return;
    default:
      break;
  }
  if (op == reg::cmd::kRregBase) {
    const std::uint8_t a = reg::command_address(command);
    const std::uint8_t cnt = reg::command_count(command);
    if (cnt == 1) {
      pending_ = Pending::kWord;
      pending_word_ = a == reg::addr(reg::Reg::kStatus) ? status() : regs_[a];
    } else {
      pending_ = Pending::kMultiRead;
      multi_addr_ = a;
      multi_count_ = cnt;
    }
  } else if (op == reg::cmd::kWregBase) {
    write_regs();
    pending_ = Pending::kWord;
    pending_word_ = reg::wreg_ack(reg::command_address(command), reg::command_count(command));
  }
}

}  // namespace gfins::sim
