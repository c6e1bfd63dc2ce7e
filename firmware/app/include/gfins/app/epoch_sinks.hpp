// Epoch sinks besides the CAN publisher: a tap that records what the loop hands over (tests
// compare it with a host-only run of the core), and a counting sink.
#pragma once

#include <cstdint>
#include <vector>

#include "gfins/app/ports.hpp"

namespace gfins::app {

/// Forwards to `next` (may be null) and keeps every epoch in a buffer reserved up front, so the
/// loop does not allocate while it records (epochs beyond the reservation are counted, not kept).
class RecordingSink final : public EpochSink {
 public:
  RecordingSink(EpochSink* next, std::size_t reserve) : next_(next) { epochs_.reserve(reserve); }
  std::uint32_t publish(const can::Epoch& e) override {
    if (epochs_.size() < epochs_.capacity()) {
      epochs_.push_back(e);
    } else {
      ++overflow_;
    }
    return next_ != nullptr ? next_->publish(e) : 0;
  }
  Status set_divider(std::size_t m, std::uint16_t d) override {
    return next_ != nullptr ? next_->set_divider(m, d) : Status::ok();
  }
  Status set_dividers(const std::array<std::uint16_t, kNumMessages>& d) override {
    return next_ != nullptr ? next_->set_dividers(d) : Status::ok();
  }
  const std::vector<can::Epoch>& epochs() const { return epochs_; }
  std::uint64_t overflow() const { return overflow_; }

 private:
  EpochSink* next_;
  std::vector<can::Epoch> epochs_;
  std::uint64_t overflow_ = 0;
};

/// Keeps the last epoch and a count (no bus).
class CountingSink final : public EpochSink {
 public:
  std::uint32_t publish(const can::Epoch& e) override {
    last_ = e;
    ++count_;
    return 0;
  }
  Status set_divider(std::size_t m, std::uint16_t) override {
    return m < kNumMessages ? Status::ok() : Status(ErrorCode::kOutOfRange, "no such message");
  }
  Status set_dividers(const std::array<std::uint16_t, kNumMessages>&) override {
    return Status::ok();
  }
  const can::Epoch& last() const { return last_; }
  std::uint64_t count() const { return count_; }

 private:
  can::Epoch last_{};
  std::uint64_t count_ = 0;
};

}  // namespace gfins::app
