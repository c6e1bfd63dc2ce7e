// hal::Watchdog on the kernel watchdog device (Documentation/watchdog/watchdog-api.rst).
//
// open() opens /dev/watchdog (which arms it), sets the timeout (WDIOC_SETTIMEOUT; the driver
// may round it, the value it chose is read back into timeout_s()), kick() is WDIOC_KEEPALIVE.
// disarm() writes the magic character 'V' before closing, so a clean shutdown does not reset
// the board (drivers built with nowayout ignore it, by design). Destroying the object without
// disarm() closes without the magic character: the board resets after the timeout, which is
// what a crash should cause.
#pragma once

#include <memory>
#include <string_view>

#include "gfins/drivers/lnx/os.hpp"
#include "gfins/hal/watchdog.hpp"
#include "gfins/status/status.hpp"

namespace gfins::drivers::lnx {

class DevWatchdog final : public hal::Watchdog {
 public:
  /// kInvalidArgument (timeout outside 1..3600 s, empty path); kUnavailable (no device node,
  /// ENOENT); kIoError (open or WDIOC_SETTIMEOUT failed, e.g. EBUSY: opened by another process).
  static Result<std::unique_ptr<DevWatchdog>> open(std::string_view path, int timeout_s,
                                                   Os& os = real_os());

  ~DevWatchdog() override;
  DevWatchdog(const DevWatchdog&) = delete;
  DevWatchdog& operator=(const DevWatchdog&) = delete;

  /// The timeout the driver applied (seconds).
  int timeout_s() const { return timeout_s_; }
  /// Magic close: writes 'V' and closes; the watchdog stops (unless the driver is nowayout).
  [[nodiscard]] Status disarm();

 private:
  DevWatchdog(Os& os, int fd, int timeout_s);
  Status do_kick() override;

  Os& os_;
  int fd_;
  int timeout_s_;
};

}  // namespace gfins::drivers::lnx
