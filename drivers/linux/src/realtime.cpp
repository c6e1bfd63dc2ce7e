#include "gfins/drivers/lnx/realtime.hpp"

#include <sys/mman.h>

#include <cerrno>

namespace gfins::drivers::lnx {

Status set_fifo_priority(int priority, Os& os) {
  // sched(7): SCHED_FIFO priorities are 1 (low) .. 99 (high) on Linux.
  if (priority < 1 || priority > 99) {
    return Status(ErrorCode::kInvalidArgument, "realtime: SCHED_FIFO priority must be 1..99");
  }
  const int err = os.set_fifo_priority(priority);
  if (err == 0) return Status::ok();
  if (err == EPERM) {
    return Status(ErrorCode::kUnavailable,
                  "realtime: SCHED_FIFO not permitted (needs CAP_SYS_NICE or RLIMIT_RTPRIO)", err);
  }
  return Status(ErrorCode::kIoError, "realtime: pthread_setschedparam(SCHED_FIFO) failed", err);
}

Status lock_memory(Os& os) {
  if (os.mlockall(MCL_CURRENT | MCL_FUTURE) == 0) return Status::ok();
  const int err = errno;
  if (err == EPERM || err == ENOMEM) {
    return Status(ErrorCode::kUnavailable,
                  "realtime: mlockall not permitted (needs CAP_IPC_LOCK or a larger "
                  "RLIMIT_MEMLOCK)",
                  err);
  }
  return Status(ErrorCode::kIoError, "realtime: mlockall failed", err);
}

}  // namespace gfins::drivers::lnx
