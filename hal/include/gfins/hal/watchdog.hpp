// Watchdog and service-manager seam. The firmware kicks the watchdog once per healthy loop
// cycle (never from a thread that would keep kicking while the loop hangs) and tells the
// service manager when it is ready and what its status is.
//
// Linux backends: systemd's sd_notify (READY=1, WATCHDOG=1, STATUS=...) and /dev/watchdog.
#pragma once

#include "gfins/status/status.hpp"

namespace gfins::hal {

class Watchdog {
 public:
  virtual ~Watchdog() = default;

  /// Proves the loop alive. Cheap enough to call every cycle; backends rate-limit themselves.
  [[nodiscard]] Status kick() { return do_kick(); }

  /// Start-up finished: the service manager may consider the service started.
  [[nodiscard]] Status notify_ready() { return do_notify_ready(); }

  /// A one-line status for the service manager (`systemctl status`); `text` is NUL-terminated.
  [[nodiscard]] Status notify_status(const char* text) {
    if (text == nullptr) return Status(ErrorCode::kInvalidArgument, "watchdog: null status");
    return do_notify_status(text);
  }

 private:
  virtual Status do_kick() = 0;
  virtual Status do_notify_ready() { return Status::ok(); }
  virtual Status do_notify_status(const char* /*text*/) { return Status::ok(); }
};

}  // namespace gfins::hal
