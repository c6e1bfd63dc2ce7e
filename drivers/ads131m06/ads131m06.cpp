// ADS131M06 driver: see gfins/drivers/ads131m06.hpp for the state machine, and
// gfins/drivers/ads131m06_registers.hpp for the datasheet sections of every constant.
#include "gfins/drivers/ads131m06.hpp"

#include <cmath>

namespace gfins::drivers {

namespace reg = ads131m06;

const char* to_string(Ads131m06State s) {
  switch (s) {
    case Ads131m06State::kReset:
      return "reset";
    case Ads131m06State::kConfigure:
      return "configure";
    case Ads131m06State::kRun:
      return "run";
    case Ads131m06State::kRecover:
      return "recover";
    case Ads131m06State::kFailed:
      return "failed";
  }
  return "unknown";
}

Ads131m06::Ads131m06(hal::SpiDevice& spi, hal::DataReadyLine& drdy, const Ads131m06Config& c)
    : spi_(spi), drdy_(drdy), config_(c) {}

double Ads131m06::volts_per_count(int channel) const {
  const int ch = channel < 0 || channel >= reg::kChannels ? 0 : channel;
  // §8.5.1.9: 1 LSB = (2 · VREF / gain) / 2^24 = VREF / (gain · 2^23).
  return config_.vref_v /
         (static_cast<double>(config_.pga_gain[static_cast<std::size_t>(ch)]) * 8388608.0);
}

Result<std::uint8_t> Ads131m06::osr_code_for(double rate_hz, double clkin_hz) {
  if (!(rate_hz > 0.0) || !(clkin_hz > 0.0) || !std::isfinite(rate_hz) ||
      !std::isfinite(clkin_hz)) {
    return Status(ErrorCode::kInvalidArgument, "adc: sample rate and CLKIN must be positive");
  }
  // fDATA = fCLKIN / 2 / OSR (§8.3.6: fMOD = fCLKIN / 2; §8.3.7 eq. 5: OSR = fMOD / fDATA).
  // Default: 8.192 MHz / 2 = 4.096 MHz; 4.096 MHz / 1 kHz = 4096 → code 101b. The chip has no
  // other clock divider, so a rate is either exact for some OSR or not reachable.
  for (std::size_t code = 0; code < reg::kOsrValues.size(); ++code) {
    const double f = reg::data_rate_hz(clkin_hz, reg::kOsrValues[code]);
    if (std::fabs(f - rate_hz) <= 1e-9 * rate_hz) return static_cast<std::uint8_t>(code);
  }
  return Status(ErrorCode::kInvalidArgument,
                "adc: no OSR (128..16384) gives the sample rate at this CLKIN "
                "(fDATA = fCLKIN / 2 / OSR)");
}

Status Ads131m06::make_table(const Ads131m06Config& c,
                             std::array<RegisterSetting, kTableSize>& table) {
  const Result<std::uint8_t> osr = osr_code_for(c.sample_rate_hz, c.clkin_hz);
  if (!osr.is_ok()) return osr.status();
  if (!(c.vref_v > 0.0) || !std::isfinite(c.vref_v)) {
    return Status(ErrorCode::kInvalidArgument, "adc: vref must be positive");
  }
  std::array<std::uint16_t, reg::kChannels> gain_code{};
  for (std::size_t ch = 0; ch < gain_code.size(); ++ch) {
    const unsigned g = c.pga_gain[ch];
    if (g == 0 || g > 128 || (g & (g - 1)) != 0) {
      return Status(ErrorCode::kInvalidArgument, "adc: PGA gain must be 1, 2, 4, ..., 128");
    }
    std::uint16_t code = 0;
    while ((1u << code) < g) ++code;
    gain_code[ch] = code;
  }
  // MODE: 24-bit words (the reset default, so a chip that resets keeps the frame size the driver
  // reads and its STATUS.RESET bit stays visible), CCITT CRC, RESET written 0 to clear it, SPI
  // timeout kept on as after reset, DRDY on the most lagging channel, level format.
  std::uint16_t mode = static_cast<std::uint16_t>(
      (static_cast<unsigned>(reg::kDriverWordLength) << reg::mode::kWlengthShift) |
      reg::mode::kTimeout);
  if (c.input_crc) mode = static_cast<std::uint16_t>(mode | reg::mode::kRxCrcEn);
  std::uint16_t gain1 = 0;
  std::uint16_t gain2 = 0;
  for (int ch = 0; ch < reg::kChannels; ++ch) {
    const auto v =
        static_cast<std::uint16_t>(gain_code[static_cast<std::size_t>(ch)] << reg::gain_shift(ch));
    if (ch < 4) {
      gain1 = static_cast<std::uint16_t>(gain1 | v);
    } else {
      gain2 = static_cast<std::uint16_t>(gain2 | v);
    }
  }
  const auto clock =
      static_cast<std::uint16_t>(reg::clock::kReservedKeep | reg::clock::kChannelEnableMask |
                                 (static_cast<unsigned>(osr.value()) << reg::clock::kOsrShift) |
                                 static_cast<unsigned>(c.power_mode));
  // Order: MODE first (clears RESET, turns on the input CRC), CLOCK last (it restarts the
  // conversions at the new OSR once the gains are set).
  table = {RegisterSetting{reg::Reg::kMode, mode}, RegisterSetting{reg::Reg::kGain1, gain1},
           RegisterSetting{reg::Reg::kGain2, gain2}, RegisterSetting{reg::Reg::kClock, clock}};
  return Status::ok();
}

Status Ads131m06::transfer_frame(std::uint16_t command, std::span<const std::uint16_t> data,
                                 Frame& out) {
  constexpr std::size_t w = reg::kWordBytes;
  tx_.fill(0);
  auto word = [&](std::array<std::uint8_t, reg::kFrameBytes>& buf, std::size_t i) {
    return std::span<std::uint8_t>(buf).subspan(i * w, w);
  };
  reg::put_word16(word(tx_, 0), command);
  std::size_t n = 1;
  for (const std::uint16_t d : data) reg::put_word16(word(tx_, n++), d);
  // Input CRC over every word before it (§8.3.12). Sent even while RX_CRC_EN is still 0 (after
  // a reset): the datasheet asks for zeros then (§8.5.1.7) but does not say a non-zero word is
  // harmful, and sending it always means a RESET reaches a chip that still has RX_CRC_EN = 1.
  const std::uint16_t crc_in = reg::crc16_ccitt(std::span<const std::uint8_t>(tx_).first(n * w));
  reg::put_word16(word(tx_, n), crc_in);

  const Status st = spi_.transfer(tx_, rx_);
  if (!st.is_ok()) {
    ++counters_.spi_errors;
    return st;
  }
  constexpr std::size_t crc_word = reg::kFrameWords - 1;
  const std::span<const std::uint8_t> rx(rx_);
  const std::uint16_t crc_calc = reg::crc16_ccitt(rx.first(crc_word * w));
  out.crc_ok = crc_calc == reg::get_word16(rx.subspan(crc_word * w, w));
  out.response = reg::get_word16(rx.first(w));
  for (std::size_t ch = 0; ch < out.codes.size(); ++ch) {
    out.codes[ch] = reg::get_code24(rx.subspan((ch + 1) * w, w));
  }
  return Status::ok();
}

Result<std::uint16_t> Ads131m06::command_response(std::uint16_t command,
                                                  std::span<const std::uint16_t> data) {
  // The response to a command is the first word of the NEXT frame (§8.5.1.10), so a command
  // costs two frames: the command, then a NULL whose frame carries the answer.
  Frame f;
  Status st = transfer_frame(command, data, f);
  if (!st.is_ok()) return st;
  st = transfer_frame(reg::cmd::kNull, {}, f);
  prev_command_ = reg::cmd::kNull;
  if (!st.is_ok()) return st;
  if (!f.crc_ok) {
    ++counters_.crc_errors;
    return Status(ErrorCode::kDataLoss, "adc: output CRC mismatch on a command response");
  }
  return f.response;
}

Status Ads131m06::reset_and_identify() {
  state_ = Ads131m06State::kReset;
  Result<std::uint16_t> r = command_response(reg::cmd::kReset);
  if (!r.is_ok()) return r.status();
  // Table 8-11: RESET answers FF26h in the following frame. The chip needs some time after a
  // reset before it accepts the next frame (§8.4.1; the figure is in §6.6): frames here follow
  // at SPI speed, which a board backend must slow down if its transfers are back to back.
  if (r.value() != reg::kResetAck) {
    return Status(ErrorCode::kUnavailable, "adc: no reset acknowledgment (expected FF26h)");
  }
  r = command_response(reg::rreg(reg::addr(reg::Reg::kId)));
  if (!r.is_ok()) return r.status();
  // ID = 26xxh (Table 8-12): CHANCNT = 6 in bits 11:8; the low byte is not specified.
  if ((r.value() & reg::kIdMask) != reg::kIdResetValue) {
    return Status(ErrorCode::kUnavailable, "adc: ID register is not an ADS131M06 (26xxh)");
  }
  return Status::ok();
}

Status Ads131m06::configure() {
  state_ = Ads131m06State::kConfigure;
  for (const RegisterSetting& s : table_) {
    bool ok = false;
    for (int attempt = 0; attempt < kConfigAttempts && !ok; ++attempt) {
      const std::uint16_t value[1] = {s.value};
      Result<std::uint16_t> r = command_response(reg::wreg(reg::addr(s.reg)), value);
      if (!r.is_ok()) continue;
      // The acknowledgment 010a aaaa ammm mmmm (Table 8-11). A STATUS word instead means the
      // chip saw an input CRC error (§8.3.12: the next response is that of a NULL); a WREG
      // still executes then, so the read-back below decides.
      if (r.value() != reg::wreg_ack(reg::addr(s.reg)) && (r.value() & reg::status::kCrcErr)) {
        ++counters_.input_crc_errors;
      }
      r = command_response(reg::rreg(reg::addr(s.reg)));
      if (!r.is_ok()) continue;
      if (r.value() == s.value) {
        ok = true;
      } else {
        ++counters_.register_mismatches;
      }
    }
    if (!ok) {
      return Status(ErrorCode::kDataLoss, "adc: a register does not read back what was written");
    }
  }
  // The frame after the last read-back answers NULL with STATUS: RESET must now read 0 and
  // the word length must be the one this driver reads.
  Result<std::uint16_t> st = command_response(reg::cmd::kNull);
  if (!st.is_ok()) return st.status();
  if ((st.value() & reg::status::kCrcErr) != 0) ++counters_.input_crc_errors;
  const unsigned wl = (st.value() & reg::status::kWlengthMask) >> reg::status::kWlengthShift;
  if ((st.value() & reg::status::kReset) != 0 ||
      wl != static_cast<unsigned>(reg::kDriverWordLength)) {
    return Status(ErrorCode::kDataLoss,
                  "adc: STATUS after configuration shows RESET or a "
                  "word length other than 24 bits");
  }
  return Status::ok();
}

Status Ads131m06::bring_up() {
  Status st = reset_and_identify();
  if (st.is_ok()) st = configure();
  if (!st.is_ok()) {
    state_ = Ads131m06State::kFailed;
    return st;
  }
  state_ = Ads131m06State::kRun;
  prev_command_ = reg::cmd::kNull;
  consecutive_timeouts_ = 0;
  frames_since_verify_ = 0;
  same_count_.fill(0);
  stuck_mask_ = 0;
  return Status::ok();
}

Status Ads131m06::start() {
  const Status st = make_table(config_, table_);
  if (!st.is_ok()) {
    state_ = Ads131m06State::kFailed;
    return st;
  }
  osr_ = reg::kOsrValues[(table_[3].value & reg::clock::kOsrMask) >> reg::clock::kOsrShift];
  failed_recoveries_ = 0;
  return bring_up();
}

Status Ads131m06::recover() {
  ++counters_.recoveries;
  state_ = Ads131m06State::kRecover;
  const Status st = bring_up();
  if (st.is_ok()) {
    failed_recoveries_ = 0;
    return st;
  }
  ++failed_recoveries_;
  // Stay in kRecover (the next read_sample tries again) until too many attempts failed.
  state_ = failed_recoveries_ >= config_.max_recovery_attempts ? Ads131m06State::kFailed
                                                               : Ads131m06State::kRecover;
  return st;
}

void Ads131m06::track_stuck(const std::array<std::int32_t, ads131m06::kChannels>& codes) {
  if (config_.stuck_after_frames == 0) return;
  for (std::size_t ch = 0; ch < codes.size(); ++ch) {
    const std::uint32_t bit = 1u << ch;
    if (codes[ch] == last_codes_[ch]) {
      if (same_count_[ch] < config_.stuck_after_frames) ++same_count_[ch];
      if (same_count_[ch] == config_.stuck_after_frames && (stuck_mask_ & bit) == 0) {
        stuck_mask_ |= bit;
        ++counters_.stuck_events;
      }
    } else {
      same_count_[ch] = 0;
      stuck_mask_ &= ~bit;
    }
    last_codes_[ch] = codes[ch];
  }
}

Result<RawSample> Ads131m06::read_sample(std::int64_t timeout_ns) {
  if (state_ == Ads131m06State::kRecover) {
    const Status st = recover();
    if (!st.is_ok()) return st;
  }
  if (state_ != Ads131m06State::kRun) {
    return Status(ErrorCode::kFailedPrecondition,
                  "adc: not running (start() failed or not called)");
  }
  for (int attempt = 0; attempt < kMaxEdgesPerRead; ++attempt) {
    const Result<hal::DataReadyEdge> edge = drdy_.wait_edge(timeout_ns);
    if (!edge.is_ok()) {
      if (edge.status().code() == ErrorCode::kTimeout) {
        ++counters_.timeouts;
        if (++consecutive_timeouts_ >= config_.timeouts_before_recover) {
          consecutive_timeouts_ = 0;
          const Status st = recover();
          if (!st.is_ok()) return st;
        }
      }
      return edge.status();
    }
    consecutive_timeouts_ = 0;
    if (have_last_edge_) {
      const std::uint32_t gap = edge->seq - last_edge_seq_;  // modulo 2^32
      if (gap > 1) counters_.missed_edges += gap - 1;
    }
    have_last_edge_ = true;
    last_edge_seq_ = edge->seq;

    // Every verify_every_frames frames the command is an RREG of the next table register; its
    // answer replaces STATUS in the next frame's response word (§8.5.1.10: a single-register
    // RREG still outputs the conversion data).
    const bool verify =
        config_.verify_every_frames != 0 && frames_since_verify_ + 1 >= config_.verify_every_frames;
    const std::uint16_t command =
        verify ? reg::rreg(reg::addr(table_[verify_index_].reg)) : reg::cmd::kNull;
    const std::uint16_t answered = prev_command_;
    const std::size_t answered_index = pending_verify_index_;
    Frame f;
    const Status st = transfer_frame(command, {}, f);
    if (!st.is_ok()) return st;
    ++counters_.frames;
    prev_command_ = command;
    if (verify) {
      frames_since_verify_ = 0;
      pending_verify_index_ = verify_index_;
      verify_index_ = (verify_index_ + 1) % table_.size();
    } else {
      ++frames_since_verify_;
    }

    RawSample s;
    s.seq = edge->seq - seq_correction_;
    s.t_ns = edge->t_ns;
    if (!f.crc_ok) {
      // §8.3.12: the output CRC covers the response and the data; a mismatch makes the whole
      // frame untrustworthy, the response word included.
      ++counters_.crc_errors;
      s.flags |= sample_flags::kCrcError;
      return s;
    }
    if (answered == reg::cmd::kNull) {
      const std::uint16_t status = f.response;
      if ((status & reg::status::kReset) != 0) {
        // The chip reset itself (power glitch, RESET pin): registers are back to defaults.
        ++counters_.chip_resets;
        const Status rs = recover();
        if (!rs.is_ok()) return rs;
        return Status(ErrorCode::kDataLoss,
                      "adc: chip reset detected (STATUS.RESET); "
                      "registers written again");
      }
      if ((status & reg::status::kCrcErr) != 0) ++counters_.input_crc_errors;
      // DRDYn = 1: new data for channel n since the last read (§8.6 STATUS). None set: this
      // edge was not a conversion (a glitch on the line): skip it and wait for the real one.
      // The datasheet does not say when DRDYn clears; this assumes "when the data are read".
      if ((status & reg::status::kDrdyMask) == 0) {
        ++counters_.extra_edges;
        ++seq_correction_;
        continue;
      }
    } else {
      // The answer to the re-verification RREG of table_[verified_index]. A STATUS word with
      // CRC_ERR here means the chip dropped our RREG (input CRC error): confirm with a full
      // read before deciding the register changed.
      const RegisterSetting& want = table_[answered_index];
      if (f.response != want.value) {
        if ((f.response & reg::status::kCrcErr) != 0) ++counters_.input_crc_errors;
        const Result<std::uint16_t> again = command_response(reg::rreg(reg::addr(want.reg)));
        if (!again.is_ok() || again.value() != want.value) {
          ++counters_.register_mismatches;
          const Status rs = recover();
          if (!rs.is_ok()) return rs;
          return Status(ErrorCode::kDataLoss,
                        "adc: register re-verification failed; "
                        "registers written again");
        }
      }
    }
    if (rail_mask(f.codes) != 0) s.flags |= sample_flags::kSaturated;
    if ((s.flags & sample_flags::kSaturated) != 0) ++counters_.saturated_samples;
    track_stuck(f.codes);
    s.counts = f.codes;
    return s;
  }
  return Status(ErrorCode::kUnavailable, "adc: several data-ready edges in a row without data");
}

}  // namespace gfins::drivers
