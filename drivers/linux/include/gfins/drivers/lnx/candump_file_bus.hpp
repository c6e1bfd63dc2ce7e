// hal::CanBus that writes every sent frame to a candump log file, one line per frame as
// can-utils' `candump -L` writes it (formatted by format_candump_line, candump.hpp), for the
// simulated board: `gfins-fw --sim` output that canplayer can replay onto a real bus and that
// log2asc converts for other tools.
//
// Timestamps come from the hal::Clock it is given (the simulated sample clock in simulation),
// so a simulated run writes the same file every time. Lines are collected in a buffer
// allocated once at open() and written when it fills, at every service() call at least
// `flush_interval_ns` after the last write, by flush(), and on destruction.
//
// Where the write() happens: with `background_writer` (the firmware's choice on the board and in
// real-time pacing) a writer thread started by open() does every file write. The caller's thread
// (the sample loop) only formats lines into one of two buffers allocated at open() and hands a
// full one over (an atomic flag and a futex wake, no lock, no syscall that blocks); when the
// writer has not finished the previous buffer and the current one is full, the frame is dropped
// and counted (tx_dropped), the loop never waits for the disk. Without it (tests, fast pacing:
// deterministic output) the calling thread writes.
//
// Failures never crash and never block: a write that fails (ENOSPC: disk full, EIO, ...) drops
// the buffered frames, counts them in tx_dropped and write_errors, cuts the file back to its
// last complete line (ftruncate) so it stays readable by can-utils, and keeps the Status for
// last_error(). Receiving from a log file is not possible: receive() reports kTimeout at once.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <thread>

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
  bool background_writer = false;                     // file writes on a thread of its own
  std::int64_t time_offset_ns = 0;  // added to the clock's time on every line (a simulation's
                                    // kSimulatedLogEpochS; 0 on a board: its own clock)
};

class CandumpFileBus final : public hal::CanBus {
 public:
  /// Room one line needs in the buffer: kMaxCandumpLine plus the '\n'.
  static constexpr std::size_t kLineMax = 97;

  /// Errors: kInvalidArgument (empty path, bad interface name, buffer smaller than one line);
  /// kIoError with errno (the file cannot be created).
  static Result<std::unique_ptr<CandumpFileBus>> open(const CandumpFileBusConfig& config,
                                                      hal::Clock& clock, Os& os = real_os());

  ~CandumpFileBus() override;
  CandumpFileBus(const CandumpFileBus&) = delete;
  CandumpFileBus& operator=(const CandumpFileBus&) = delete;

  /// Writes the buffered lines now (and waits for the writer thread to have written them);
  /// kIoError with errno when the write failed (the buffered frames are then counted as
  /// dropped). Blocks: never from the sample loop.
  [[nodiscard]] Status flush();
  std::uint32_t write_errors() const { return write_errors_.load(std::memory_order_relaxed); }
  Status last_error() const;

 private:
  CandumpFileBus(Os& os, hal::Clock& clock, int fd, const CandumpFileBusConfig& config);
  Status do_send(const hal::CanFrame& f) override;
  Result<hal::CanFrame> do_receive(std::int64_t timeout_ns) override;
  void do_service() override;
  hal::CanBusState do_state() const override { return hal::CanBusState::kErrorActive; }
  hal::CanCounters do_counters() const override;

  /// The current buffer goes to the file: written here, or handed to the writer thread (false
  /// when that one is still busy with the previous buffer: nothing changed).
  bool hand_over();
  /// write() of one buffer with the accounting of whole lines (the writer thread, or the caller
  /// without one).
  Status write_out(const char* data, std::size_t used, std::uint32_t frames);
  void writer_main();
  void wait_writer_idle();

  Os& os_;
  hal::Clock& clock_;
  int fd_;
  std::string interface_;
  std::unique_ptr<char[]> buffers_[2];
  int active_ = 0;  // the buffer the caller formats into
  std::size_t capacity_;
  std::size_t used_ = 0;
  std::uint32_t pending_frames_ = 0;  // lines in the active buffer
  long committed_bytes_ = 0;          // file length up to the last complete line (writer side)
  std::int64_t flush_interval_ns_;
  std::int64_t time_offset_ns_;
  std::int64_t last_flush_ns_ = 0;
  hal::CanCounters counters_;  // caller side: frames refused before reaching a buffer
  // Writer side, read by the caller: frames written, frames lost to failed writes, errors.
  std::atomic<std::uint32_t> written_{0};
  std::atomic<std::uint32_t> write_dropped_{0};
  std::atomic<std::uint32_t> write_errors_{0};
  mutable std::mutex error_mutex_;  // last_error_ / last_write_ (never taken by the caller's
                                    // send/service path)
  Status last_error_;
  Status last_write_;
  // Hand-over to the writer thread: 0 idle, 1 a buffer is waiting or being written, 2 stop.
  bool background_ = false;
  std::atomic<int> slot_{0};
  const char* handed_data_ = nullptr;
  std::size_t handed_used_ = 0;
  std::uint32_t handed_frames_ = 0;
  std::thread writer_;
};

}  // namespace gfins::drivers::lnx
