#include "gfins/drivers/lnx/dev_watchdog.hpp"

#include <fcntl.h>
#include <linux/watchdog.h>

#include <cerrno>
#include <string>

#include "fd.hpp"

namespace gfins::drivers::lnx {

Result<std::unique_ptr<DevWatchdog>> DevWatchdog::open(std::string_view path, int timeout_s,
                                                       Os& os) {
  if (path.empty()) return Status(ErrorCode::kInvalidArgument, "watchdog: empty device path");
  if (timeout_s < 1 || timeout_s > 3600) {
    return Status(ErrorCode::kInvalidArgument, "watchdog: timeout must be 1..3600 s");
  }
  const std::string p(path);
  Fd fd(os, os.open(p.c_str(), O_WRONLY | O_CLOEXEC, 0));
  if (!fd.valid()) {
    const int err = errno;
    if (err == ENOENT) {
      return Status(ErrorCode::kUnavailable, "watchdog: no such device (watchdog driver loaded?)",
                    err);
    }
    return Status(ErrorCode::kIoError,
                  err == EBUSY ? "watchdog: device already open by another process"
                               : "watchdog: cannot open the device",
                  err);
  }
  int t = timeout_s;
  if (os.ioctl(fd.get(), WDIOC_SETTIMEOUT, &t) != 0) {
    const int err = errno;
    // The device is armed by open(): disarm before giving up, or the board resets.
    (void)os.write(fd.get(), "V", 1);
    return Status(ErrorCode::kIoError, "watchdog: WDIOC_SETTIMEOUT failed", err);
  }
  std::unique_ptr<DevWatchdog> w(new DevWatchdog(os, fd.release(), t));
  return w;
}

DevWatchdog::DevWatchdog(Os& os, int fd, int timeout_s) : os_(os), fd_(fd), timeout_s_(timeout_s) {}

DevWatchdog::~DevWatchdog() {
  if (fd_ >= 0) (void)os_.close(fd_);  // no magic character: the board resets (see header)
}

Status DevWatchdog::do_kick() {
  if (fd_ < 0) return Status(ErrorCode::kFailedPrecondition, "watchdog: disarmed");
  int dummy = 0;
  if (os_.ioctl(fd_, WDIOC_KEEPALIVE, &dummy) != 0) {
    return Status(ErrorCode::kIoError, "watchdog: WDIOC_KEEPALIVE failed", errno);
  }
  return Status::ok();
}

Status DevWatchdog::disarm() {
  if (fd_ < 0) return Status::ok();
  long n = 0;
  do {
    n = os_.write(fd_, "V", 1);
  } while (n < 0 && errno == EINTR);
  const int err = n == 1 ? 0 : errno;
  (void)os_.close(fd_);
  fd_ = -1;
  if (err != 0) return Status(ErrorCode::kIoError, "watchdog: magic close write failed", err);
  return Status::ok();
}

}  // namespace gfins::drivers::lnx
