#include "gfins/drivers/lnx/candump_file_bus.hpp"

#include <fcntl.h>

#include <algorithm>
#include <cerrno>

#include "gfins/drivers/lnx/candump.hpp"

namespace gfins::drivers::lnx {

Result<std::unique_ptr<CandumpFileBus>> CandumpFileBus::open(const CandumpFileBusConfig& config,
                                                             hal::Clock& clock, Os& os) {
  if (config.path.empty()) return Status(ErrorCode::kInvalidArgument, "candump file: empty path");
  // 0 .. 4e9 s: the log's seconds stay within int64 nanoseconds with any clock time of a run.
  if (config.time_offset_ns < 0 ||
      config.time_offset_ns > std::int64_t{4'000'000'000} * 1000000000) {
    return Status(ErrorCode::kInvalidArgument, "candump file: time offset outside 0..4e9 s");
  }
  hal::CanFrame probe;
  char line[kMaxCandumpLine];
  if (format_candump_line(line, 0, 0, config.interface, probe) == 0) {
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
      capacity_(config.buffer_bytes),
      flush_interval_ns_(config.flush_interval_ns),
      time_offset_ns_(config.time_offset_ns),
      last_flush_ns_(clock.now_ns()),
      background_(config.background_writer) {
  buffers_[0].reset(new char[config.buffer_bytes]);
  if (background_) {
    buffers_[1].reset(new char[config.buffer_bytes]);
    writer_ = std::thread([this] { writer_main(); });
  }
}

CandumpFileBus::~CandumpFileBus() {
  (void)flush();  // the outcome is in the counters; a destructor has nobody to tell
  if (writer_.joinable()) {
    wait_writer_idle();
    slot_.store(2, std::memory_order_release);
    slot_.notify_all();
    writer_.join();
  }
  (void)os_.close(fd_);
}

Status CandumpFileBus::last_error() const {
  const std::lock_guard<std::mutex> lock(error_mutex_);
  return last_error_;
}

hal::CanCounters CandumpFileBus::do_counters() const {
  hal::CanCounters c = counters_;
  c.tx_frames += written_.load(std::memory_order_relaxed);
  c.tx_dropped += write_dropped_.load(std::memory_order_relaxed);
  return c;
}

void CandumpFileBus::writer_main() {
  for (;;) {
    slot_.wait(0, std::memory_order_acquire);
    const int v = slot_.load(std::memory_order_acquire);
    if (v == 2) return;
    if (v != 1) continue;
    (void)write_out(handed_data_, handed_used_, handed_frames_);
    slot_.store(0, std::memory_order_release);
    slot_.notify_all();
  }
}

void CandumpFileBus::wait_writer_idle() {
  for (int v = slot_.load(std::memory_order_acquire); v == 1;
       v = slot_.load(std::memory_order_acquire)) {
    slot_.wait(1, std::memory_order_acquire);
  }
}

bool CandumpFileBus::hand_over() {
  last_flush_ns_ = clock_.now_ns();
  if (used_ == 0) return true;
  if (!background_) {
    (void)write_out(buffers_[0].get(), used_, pending_frames_);
  } else {
    if (slot_.load(std::memory_order_acquire) != 0) return false;  // still writing the last one
    handed_data_ = buffers_[active_].get();
    handed_used_ = used_;
    handed_frames_ = pending_frames_;
    active_ ^= 1;
    slot_.store(1, std::memory_order_release);
    slot_.notify_one();
  }
  used_ = 0;
  pending_frames_ = 0;
  return true;
}

Status CandumpFileBus::flush() {
  if (background_) wait_writer_idle();
  {
    const std::lock_guard<std::mutex> lock(error_mutex_);
    last_write_ = Status::ok();
  }
  (void)hand_over();
  if (background_) wait_writer_idle();
  const std::lock_guard<std::mutex> lock(error_mutex_);
  return last_write_;
}

Status CandumpFileBus::write_out(const char* data, std::size_t used, std::uint32_t frames) {
  std::size_t done = 0;
  while (done < used) {
    const long n = os_.write(fd_, data + done, used - done);
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
      if (data[i] == '\n') {
        ++whole;
        whole_bytes = i + 1;
      }
    }
    written_.fetch_add(whole, std::memory_order_relaxed);
    write_dropped_.fetch_add(frames - whole, std::memory_order_relaxed);
    committed_bytes_ += static_cast<long>(whole_bytes);
    // Cut a partly written line so the file stays a valid log (canplayer stops at a bad line).
    if (done != whole_bytes) (void)os_.ftruncate(fd_, committed_bytes_);
    write_errors_.fetch_add(1, std::memory_order_relaxed);
    const Status st(ErrorCode::kIoError,
                    err == ENOSPC ? "candump file: disk full, frames dropped"
                                  : "candump file: write failed, frames dropped",
                    err);
    const std::lock_guard<std::mutex> lock(error_mutex_);
    last_error_ = st;
    last_write_ = st;
    return st;
  }
  written_.fetch_add(frames, std::memory_order_relaxed);
  committed_bytes_ += static_cast<long>(used);
  return Status::ok();
}

Status CandumpFileBus::do_send(const hal::CanFrame& f) {
  // A full buffer goes to the file first; with the writer thread still busy the frame is
  // dropped (counted) rather than the loop waiting. A failed write drops its buffer's frames
  // (counted there); this one still gets a chance.
  if (capacity_ - used_ < kLineMax && !hand_over()) {
    ++counters_.tx_dropped;
    return Status(ErrorCode::kResourceExhausted,
                  "candump file: the writer is behind, frame dropped");
  }
  char* buffer = buffers_[active_].get();
  // candump prints the kernel's struct timeval: whole microseconds, the rest truncated.
  const std::int64_t t_ns = std::max<std::int64_t>(clock_.now_ns(), 0) + time_offset_ns_;
  const std::size_t n =
      format_candump_line(std::span<char>(buffer + used_, capacity_ - used_ - 1), t_ns / 1000000000,
                          static_cast<std::uint32_t>(t_ns % 1000000000 / 1000), interface_, f);
  if (n == 0) {
    ++counters_.tx_dropped;
    return Status(ErrorCode::kInvalidArgument, "candump file: frame cannot be formatted");
  }
  used_ += n;
  buffer[used_++] = '\n';
  ++pending_frames_;
  return Status::ok();
}

Result<hal::CanFrame> CandumpFileBus::do_receive(std::int64_t /*timeout_ns*/) {
  return Status(ErrorCode::kTimeout, "candump file: a log file receives nothing");
}

void CandumpFileBus::do_service() {
  // Busy writer: the buffer is handed over at a later service() (or when it fills).
  if (used_ > 0 && clock_.now_ns() - last_flush_ns_ >= flush_interval_ns_) (void)hand_over();
}

}  // namespace gfins::drivers::lnx
