// hal::CanBus that writes every sent frame to a candump log file, one line per frame as
// can-utils' `candump -L` writes it (formatted by gfins::can::format_candump_line), for the
// simulated board: `gfins-fw --sim` output that canplayer can replay onto a real bus and that
// log2asc converts for other tools.
//
// Timestamps come from the hal::Clock it is given (the simulated sample clock in simulation),
// so a simulated run writes the same file every time. Lines are collected in a buffer
// allocated once at open() and written when it fills, at every service() call at least
// `flush_interval_ns` after the last write, by flush(), and on destruction.
//
// Failures never crash and never block: a write that fails (ENOSPC: disk full, EIO, ...) drops
// the buffered frames, counts them in tx_dropped and write_errors, cuts the file back to its
// last complete line (ftruncate) so it stays readable by can-utils, and keeps the Status for
// last_error(). Receiving from a log file is not possible: receive() reports kTimeout at once.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

#include "gfins/drivers/lnx/os.hpp"
#include "gfins/hal/can_bus.hpp"
#include "gfins/hal/clock.hpp"
#include "gfins/status/status.hpp"

namespace gfins::drivers::lnx {

struct CandumpFileBusConfig {
  std::string_view path;                              // the log file, created or truncated
  std::string_view interface = "can0";                // the name written on every line
  std::size_t buffer_bytes = std::size_t{64} * 1024;  // at least CandumpFileBus::kLineMax
  std::int64_t flush_interval_ns = 1000000000;        // service() writes at most this late
};

class CandumpFileBus final : public hal::CanBus {
 public:
  /// Room one line needs in the buffer: gfins::can::kMaxCandumpLine plus the '\n'.
  static constexpr std::size_t kLineMax = 97;

  /// Errors: kInvalidArgument (empty path, bad interface name, buffer smaller than one line);
  /// kIoError with errno (the file cannot be created).
  static Result<std::unique_ptr<CandumpFileBus>> open(const CandumpFileBusConfig& config,
                                                      hal::Clock& clock, Os& os = real_os());

  ~CandumpFileBus() override;
  CandumpFileBus(const CandumpFileBus&) = delete;
  CandumpFileBus& operator=(const CandumpFileBus&) = delete;

  /// Writes the buffered lines now; kIoError with errno when the write failed (the buffered
  /// frames are then counted as dropped).
  [[nodiscard]] Status flush();
  std::uint32_t write_errors() const { return write_errors_; }
  Status last_error() const { return last_error_; }

 private:
  CandumpFileBus(Os& os, hal::Clock& clock, int fd, const CandumpFileBusConfig& config);
  Status do_send(const hal::CanFrame& f) override;
  Result<hal::CanFrame> do_receive(std::int64_t timeout_ns) override;
  void do_service() override;
  hal::CanBusState do_state() const override { return hal::CanBusState::kErrorActive; }
  hal::CanCounters do_counters() const override { return counters_; }

  Os& os_;
  hal::Clock& clock_;
  int fd_;
  std::string interface_;
  std::unique_ptr<char[]> buffer_;
  std::size_t capacity_;
  std::size_t used_ = 0;
  std::uint32_t pending_frames_ = 0;  // lines in the buffer
  long committed_bytes_ = 0;          // file length up to the last complete line
  std::int64_t flush_interval_ns_;
  std::int64_t last_flush_ns_ = 0;
  std::uint32_t write_errors_ = 0;
  Status last_error_;
  hal::CanCounters counters_;
};

}  // namespace gfins::drivers::lnx
