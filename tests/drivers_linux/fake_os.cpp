#include "drivers_linux/fake_os.hpp"

#include <time.h>

namespace gfins::drivers::lnx::testing {

int FakeOs::clock_gettime(int id, timespec* ts) {
  rec("clock_gettime");
  if (on_clock_gettime) return on_clock_gettime(id, ts);
  ts->tv_sec = 1000;
  ts->tv_nsec = 0;
  return 0;
}

}  // namespace gfins::drivers::lnx::testing
