#include "gfins/drivers/lnx/candump_file_bus.hpp"

#include <fcntl.h>

#include <algorithm>
#include <cerrno>

#include "gfins/can/candump.hpp"

namespace gfins::drivers::lnx {

Result<std::unique_ptr<CandumpFileBus>> CandumpFileBus::open(const CandumpFileBusConfig& config,
                                                             hal::Clock& clock, Os& os) {
  if (config.path.empty()) return Status(ErrorCode::kInvalidArgument, "candump file: empty path");
  hal::CanFrame probe;
  char line[can::kMaxCandumpLine];
  if (can::format_candump_line(line, 0, 0, config.interface, probe) == 0) {
    return Status(ErrorCode::kInvalidArgument,
                  "candump file: interface name must be 1..15 characters without spaces");
  }
  if (config.buffer_bytes < kLineMax) {
    return Status(ErrorCode::kInvalidArgument, "candump file: buffer smaller than one line");
  }
  const std::string path(config.path);
  const int fd = os.open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) return Status(ErrorCode::kIoError, "candump file: cannot create the file", errno);
  std::unique_ptr<CandumpFileBus> bus(new CandumpFileBus(os, clock, fd, config));
  return bus;
}

CandumpFileBus::CandumpFileBus(Os& os, hal::Clock& clock, int fd,
                               const CandumpFileBusConfig& config)
    : os_(os),
      clock_(clock),
      fd_(fd),
      interface_(config.interface),
      buffer_(new char[config.buffer_bytes]),
      capacity_(config.buffer_bytes),
      flush_interval_ns_(config.flush_interval_ns),
      last_flush_ns_(clock.now_ns()) {}

CandumpFileBus::~CandumpFileBus() {
  (void)flush();  // the outcome is in the counters; a destructor has nobody to tell
  (void)os_.close(fd_);
}

Status CandumpFileBus::flush() {
  last_flush_ns_ = clock_.now_ns();
  std::size_t done = 0;
  while (done < used_) {
    const long n = os_.write(fd_, buffer_.get() + done, used_ - done);
    if (n > 0) {
      done += static_cast<std::size_t>(n);
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    const int err = n < 0 ? errno : EIO;
    // Lines written whole before the failure are in the file; the rest are lost.
    std::uint32_t whole = 0;
    std::size_t whole_bytes = 0;
    for (std::size_t i = 0; i < done; ++i) {
      if (buffer_[i] == '\n') {
        ++whole;
        whole_bytes = i + 1;
      }
    }
    counters_.tx_frames += whole;
    counters_.tx_dropped += pending_frames_ - whole;
    committed_bytes_ += static_cast<long>(whole_bytes);
    // Cut a partly written line so the file stays a valid log (canplayer stops at a bad line).
    if (done != whole_bytes) (void)os_.ftruncate(fd_, committed_bytes_);
    ++write_errors_;
    used_ = 0;
    pending_frames_ = 0;
    last_error_ = Status(ErrorCode::kIoError,
                         err == ENOSPC ? "candump file: disk full, frames dropped"
                                       : "candump file: write failed, frames dropped",
                         err);
    return last_error_;
  }
  counters_.tx_frames += pending_frames_;
  committed_bytes_ += static_cast<long>(used_);
  used_ = 0;
  pending_frames_ = 0;
  return Status::ok();
}

Status CandumpFileBus::do_send(const hal::CanFrame& f) {
  // On a failed flush the buffered frames are counted as dropped; this one still gets a chance.
  if (capacity_ - used_ < kLineMax) (void)flush();
  // candump prints the kernel's struct timeval: whole microseconds, the rest truncated.
  const std::int64_t t_ns = std::max<std::int64_t>(clock_.now_ns(), 0);
  const std::size_t n = can::format_candump_line(
      std::span<char>(buffer_.get() + used_, capacity_ - used_ - 1), t_ns / 1000000000,
      static_cast<std::uint32_t>(t_ns % 1000000000 / 1000), interface_, f);
  if (n == 0) {
    ++counters_.tx_dropped;
    return Status(ErrorCode::kInvalidArgument, "candump file: frame cannot be formatted");
  }
  used_ += n;
  buffer_[used_++] = '\n';
  ++pending_frames_;
  return Status::ok();
}

Result<hal::CanFrame> CandumpFileBus::do_receive(std::int64_t /*timeout_ns*/) {
  return Status(ErrorCode::kTimeout, "candump file: a log file receives nothing");
}

void CandumpFileBus::do_service() {
  if (used_ > 0 && clock_.now_ns() - last_flush_ns_ >= flush_interval_ns_) (void)flush();
}

}  // namespace gfins::drivers::lnx
