// The board's raw-sample recorder (recorder.hpp).
#include "gfins/app/recorder.hpp"

#include <cerrno>
#include <chrono>
#include <cstring>
#include <span>
#include <utility>

namespace gfins::app {

Recorder::Opened Recorder::open(const std::string& path, const recording::Header& header) {
  Opened out;
  recording::Header h = header;
  h.record_count = recording::kRecordCountUnknown;
  if (const recording::CodecStatus c = recording::check_writable(h); !c.ok()) {
    out.error = std::string("recording header: ") + c.what;
    return out;
  }
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr) {
    out.error = "cannot create " + path + ": " + std::strerror(errno);
    return out;
  }
  const auto head = recording::encode_header(h);
  if (std::fwrite(head.data(), 1, head.size(), f) != head.size() || std::fflush(f) != 0) {
    out.error = "cannot write the header of " + path + ": " + std::strerror(errno);
    (void)std::fclose(f);
    return out;
  }
  out.recorder = std::unique_ptr<Recorder>(new Recorder(f, path, h));
  return out;
}

Recorder::Recorder(std::FILE* file, std::string path, const recording::Header& header)
    : file_(file), path_(std::move(path)), header_(header) {
  block_.reserve(header_.records_per_block * recording::kRecordBytes + recording::kCrcBytes);
}

Recorder::~Recorder() { (void)stop(); }

void Recorder::start() {
  if (thread_.joinable() || file_ == nullptr) return;
  stop_.store(false);
  thread_ = std::thread([this] {
    while (!stop_.load(std::memory_order_relaxed)) {
      drain();
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  });
}

void Recorder::drain() {
  RecordSlot slot;
  while (queue_.pop(slot)) {
    if (file_ == nullptr || !error_.empty()) continue;  // after a write error: counted at stop
    block_.insert(block_.end(), slot.bytes.begin(), slot.bytes.end());
    ++records_;
    if (block_.size() == header_.records_per_block * recording::kRecordBytes) write_block();
  }
}

void Recorder::write_block() {
  if (block_.empty() || !error_.empty()) return;
  const std::size_t n = block_.size();
  block_.resize(n + recording::kCrcBytes);
  recording::put_block_crc(std::span(block_).first(n),
                           std::span(block_).subspan(n).first<recording::kCrcBytes>());
  // Each complete block reaches the OS: a board that loses power loses at most one block and
  // the records still queued.
  if (std::fwrite(block_.data(), 1, block_.size(), file_) != block_.size() ||
      std::fflush(file_) != 0) {
    error_ = "write error in " + path_ + ": " + std::strerror(errno);
    records_ -= n / recording::kRecordBytes;
  }
  block_.clear();
}

std::string Recorder::stop() {
  if (thread_.joinable()) {
    stop_.store(true);
    thread_.join();
  }
  if (file_ == nullptr) return error_;
  drain();
  write_block();
  if (error_.empty()) {
    header_.record_count = records_;
    const auto head = recording::encode_header(header_);
    if (std::fseek(file_, 0, SEEK_SET) != 0 ||
        std::fwrite(head.data(), 1, head.size(), file_) != head.size()) {
      error_ = "cannot rewrite the header of " + path_ + ": " + std::strerror(errno);
    }
  }
  if (std::fclose(std::exchange(file_, nullptr)) != 0 && error_.empty()) {
    error_ = "close of " + path_ + " failed: " + std::strerror(errno);
  }
  if (error_.empty() && queue_.dropped() != 0) {
    error_ = path_ + ": " + std::to_string(queue_.dropped()) +
             " records lost to a full queue (the writer fell behind): the recording has holes";
  }
  return error_;
}

}  // namespace gfins::app
