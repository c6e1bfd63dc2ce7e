// Monotonic clock seam (CLOCK_MONOTONIC on Linux, the same clock libgpiod stamps edges with;
// a simulated clock advanced by the sample index in simulation).
#pragma once

#include <cstdint>

#include "gfins/status/status.hpp"

namespace gfins::hal {

class Clock {
 public:
  virtual ~Clock() = default;

  /// Nanoseconds on the monotonic clock.
  std::int64_t now_ns() { return do_now_ns(); }

  /// Sleeps until the clock reads at least `t_ns` (returns at once if it already does).
  [[nodiscard]] Status sleep_until_ns(std::int64_t t_ns) { return do_sleep_until_ns(t_ns); }

 private:
  virtual std::int64_t do_now_ns() = 0;
  virtual Status do_sleep_until_ns(std::int64_t t_ns) = 0;
};

}  // namespace gfins::hal
