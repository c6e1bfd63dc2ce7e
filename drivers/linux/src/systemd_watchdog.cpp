#include "gfins/drivers/lnx/systemd_watchdog.hpp"

#include <systemd/sd-daemon.h>

#include <cstdio>
#include <cstdlib>

namespace gfins::drivers::lnx {

int SdApi::watchdog_enabled(std::uint64_t* usec) { return ::sd_watchdog_enabled(0, usec); }
int SdApi::notify(const char* state) { return ::sd_notify(0, state); }
bool SdApi::has_notify_socket() {
  const char* s = std::getenv("NOTIFY_SOCKET");  // read once at start-up, never in the loop
  return s != nullptr && s[0] != '\0';
}
SdApi& real_sd() {
  static SdApi sd;
  return sd;
}

Result<std::unique_ptr<SystemdWatchdog>> SystemdWatchdog::open(hal::Clock& clock, SdApi& sd) {
  std::uint64_t usec = 0;
  const int r = sd.watchdog_enabled(&usec);
  if (r < 0) {
    return Status(ErrorCode::kIoError, "systemd: WATCHDOG_USEC/WATCHDOG_PID malformed", -r);
  }
  // Half the interval (sd_watchdog_enabled(3)); usec fits: systemd caps it far below 2^63 ns.
  const std::int64_t interval_ns = r > 0 ? static_cast<std::int64_t>(usec) * 1000 / 2 : 0;
  std::unique_ptr<SystemdWatchdog> w(
      new SystemdWatchdog(clock, sd, sd.has_notify_socket(), interval_ns));
  return w;
}

SystemdWatchdog::SystemdWatchdog(hal::Clock& clock, SdApi& sd, bool under_systemd,
                                 std::int64_t interval_ns)
    : clock_(clock), sd_(sd), under_systemd_(under_systemd), interval_ns_(interval_ns) {}

Status SystemdWatchdog::send(const char* state, const char* failed) {
  if (!under_systemd_) return Status::ok();
  const int r = sd_.notify(state);
  if (r < 0) return Status(ErrorCode::kIoError, failed, -r);
  return Status::ok();
}

Status SystemdWatchdog::do_kick() {
  if (interval_ns_ <= 0) return Status::ok();
  const std::int64_t now = clock_.now_ns();
  if (pinged_ && now - last_ping_ns_ < interval_ns_) return Status::ok();
  const Status s = send("WATCHDOG=1", "systemd: sd_notify(WATCHDOG=1) failed");
  if (s.is_ok()) {
    pinged_ = true;
    last_ping_ns_ = now;
    ++pings_;
  }
  return s;
}

Status SystemdWatchdog::do_notify_ready() {
  return send("READY=1", "systemd: sd_notify(READY=1) failed");
}

Status SystemdWatchdog::do_notify_status(const char* text) {
  // "STATUS=" + one line; longer text is cut (systemctl shows one line anyway). Not a loop call.
  char buf[256];
  std::snprintf(buf, sizeof buf, "STATUS=%s", text);
  for (char* p = buf; *p != '\0'; ++p) {
    if (*p == '\n') *p = ' ';  // a newline would start a new (unknown) variable assignment
  }
  return send(buf, "systemd: sd_notify(STATUS=) failed");
}

}  // namespace gfins::drivers::lnx
