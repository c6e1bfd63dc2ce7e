// hal::Clock on CLOCK_MONOTONIC: the clock libgpiod stamps data-ready edges with, unaffected by
// NTP steps. sleep_until_ns() is clock_nanosleep(TIMER_ABSTIME), resumed after a signal (EINTR)
// with the same absolute deadline, so signals never shorten or lengthen the period.
#pragma once

#include <memory>

#include "gfins/drivers/lnx/os.hpp"
#include "gfins/hal/clock.hpp"
#include "gfins/status/status.hpp"

namespace gfins::drivers::lnx {

class MonotonicClock final : public hal::Clock {
 public:
  /// Checks the clock is readable (kIoError with errno otherwise).
  static Result<std::unique_ptr<MonotonicClock>> open(Os& os = real_os());

 private:
  explicit MonotonicClock(Os& os) : os_(os) {}
  std::int64_t do_now_ns() override;
  Status do_sleep_until_ns(std::int64_t t_ns) override;

  Os& os_;
};

}  // namespace gfins::drivers::lnx
