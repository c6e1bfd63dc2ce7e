#include "gfins/drivers/lnx/monotonic_clock.hpp"

#include <time.h>

#include <cerrno>

namespace gfins::drivers::lnx {

Result<std::unique_ptr<MonotonicClock>> MonotonicClock::open(Os& os) {
  timespec ts{};
  if (os.clock_gettime(CLOCK_MONOTONIC, &ts) != 0) {
    return Status(ErrorCode::kIoError, "clock: clock_gettime(CLOCK_MONOTONIC) failed", errno);
  }
  std::unique_ptr<MonotonicClock> c(new MonotonicClock(os));
  return c;
}

std::int64_t MonotonicClock::do_now_ns() {
  timespec ts{};
  // Cannot fail for CLOCK_MONOTONIC with a valid pointer (checked once by open()).
  (void)os_.clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1000000000 + ts.tv_nsec;
}

Status MonotonicClock::do_sleep_until_ns(std::int64_t t_ns) {
  if (t_ns < 0) return Status(ErrorCode::kInvalidArgument, "clock: negative deadline");
  timespec ts{};
  ts.tv_sec = static_cast<time_t>(t_ns / 1000000000);
  ts.tv_nsec = static_cast<long>(t_ns % 1000000000);
  for (;;) {
    const int err = os_.clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts);
    if (err == 0) return Status::ok();
    if (err == EINTR) continue;  // same absolute deadline: the wake-up time does not drift
    return Status(ErrorCode::kIoError, "clock: clock_nanosleep failed", err);
  }
}

}  // namespace gfins::drivers::lnx
