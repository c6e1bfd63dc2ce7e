// A hal::CanBus that records what is sent into a fixed array (no heap), and can be told to refuse.
#pragma once

#include <array>
#include <cstddef>

#include "gfins/hal/can_bus.hpp"

namespace gfins::testing {

template <std::size_t N>
class ArrayBus final : public hal::CanBus {
 public:
  std::array<hal::CanFrame, N> frames{};
  std::size_t count = 0;
  bool refuse = false;

  void clear() { count = 0; }

 private:
  Status do_send(const hal::CanFrame& f) override {
    if (refuse || count == N) {
      ++counters_.tx_dropped;
      return Status(ErrorCode::kResourceExhausted, "test bus: refused");
    }
    frames[count++] = f;
    ++counters_.tx_frames;
    return Status::ok();
  }
  Result<hal::CanFrame> do_receive(std::int64_t) override {
    return Status(ErrorCode::kTimeout, "test bus: nothing to receive");
  }
  hal::CanBusState do_state() const override { return hal::CanBusState::kErrorActive; }
  hal::CanCounters do_counters() const override { return counters_; }
  hal::CanCounters counters_{};
};

}  // namespace gfins::testing
