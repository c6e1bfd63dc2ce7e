// A clock that reads the time of the sample being processed: no wall clock at all, so a run
// driven by the sample index (the simulated board's fast pacing, the hardware-in-the-loop replay)
// never sees overruns and is reproducible.
#pragma once

#include <cstdint>

#include "gfins/hal/clock.hpp"

namespace gfins::app {

class SampleClock final : public hal::Clock {
 public:
  void set(std::int64_t t_ns) { t_ns_ = t_ns; }

 private:
  std::int64_t do_now_ns() override { return t_ns_; }
  Status do_sleep_until_ns(std::int64_t t_ns) override {
    if (t_ns > t_ns_) t_ns_ = t_ns;
    return Status::ok();
  }
  std::int64_t t_ns_ = 0;
};

}  // namespace gfins::app
