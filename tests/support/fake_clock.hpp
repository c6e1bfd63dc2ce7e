// A hal::Clock whose time the test sets: sleep_until jumps to the requested instant at once, so
// code that paces itself runs without waiting and deterministically.
#pragma once

#include <cstdint>

#include "gfins/hal/clock.hpp"

namespace gfins::testing {

class FakeClock : public hal::Clock {
 public:
  std::int64_t t_ns = 0;  // now, ns

 private:
  std::int64_t do_now_ns() override { return t_ns; }
  Status do_sleep_until_ns(std::int64_t t) override {
    t_ns = t;
    return Status::ok();
  }
};

}  // namespace gfins::testing
