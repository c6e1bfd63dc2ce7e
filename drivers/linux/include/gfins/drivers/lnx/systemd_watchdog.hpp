// hal::Watchdog through systemd's notification protocol (sd_notify(3), Debian's libsystemd).
//
// notify_ready() sends READY=1, notify_status() STATUS=<text>, kick() WATCHDOG=1, the latter
// rate-limited to half of WATCHDOG_USEC (sd_watchdog_enabled(3) recommends pinging at half the
// interval) measured on the hal::Clock it is given, so kick() can be called every loop cycle.
//
// Not started by systemd (no NOTIFY_SOCKET): every call is a harmless no-op returning ok, and
// under_systemd() says so, so the caller can note it once at start-up.
#pragma once

#include <cstdint>
#include <memory>

#include "gfins/hal/clock.hpp"
#include "gfins/hal/watchdog.hpp"
#include "gfins/status/status.hpp"

namespace gfins::drivers::lnx {

/// The libsystemd calls the backend makes (real_sd() forwards to the library; tests fake).
class SdApi {
 public:
  virtual ~SdApi() = default;
  /// sd_watchdog_enabled(0, &usec): > 0 enabled, 0 not enabled, < 0 -errno.
  virtual int watchdog_enabled(std::uint64_t* usec);
  /// sd_notify(0, state): > 0 sent, 0 no NOTIFY_SOCKET, < 0 -errno.
  virtual int notify(const char* state);
  /// Whether NOTIFY_SOCKET is set (sd_booted() is not enough: a service may run by hand).
  virtual bool has_notify_socket();
};
SdApi& real_sd();

class SystemdWatchdog final : public hal::Watchdog {
 public:
  /// Reads WATCHDOG_USEC / WATCHDOG_PID through sd_watchdog_enabled. kIoError (os_error =
  /// errno) when the variables are malformed.
  static Result<std::unique_ptr<SystemdWatchdog>> open(hal::Clock& clock, SdApi& sd = real_sd());

  bool under_systemd() const { return under_systemd_; }
  bool watchdog_enabled() const { return interval_ns_ > 0; }
  /// Half of WATCHDOG_USEC in ns (0 when systemd's watchdog is off).
  std::int64_t kick_interval_ns() const { return interval_ns_; }
  std::uint32_t pings_sent() const { return pings_; }

 private:
  SystemdWatchdog(hal::Clock& clock, SdApi& sd, bool under_systemd, std::int64_t interval_ns);
  Status do_kick() override;
  Status do_notify_ready() override;
  Status do_notify_status(const char* text) override;
  Status send(const char* state, const char* failed);

  hal::Clock& clock_;
  SdApi& sd_;
  bool under_systemd_;
  std::int64_t interval_ns_;
  bool pinged_ = false;
  std::int64_t last_ping_ns_ = 0;
  std::uint32_t pings_ = 0;
};

}  // namespace gfins::drivers::lnx
