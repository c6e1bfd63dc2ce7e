// Real-time set-up of the sample loop's thread: SCHED_FIFO priority and locked memory.
//
// Both usually need privileges (CAP_SYS_NICE / RLIMIT_RTPRIO, CAP_IPC_LOCK / RLIMIT_MEMLOCK);
// without them they fail with EPERM (or ENOMEM for mlockall over the limit) and the firmware
// runs on, with more latency: the caller logs a warning built with describe().
#pragma once

#include "gfins/drivers/lnx/os.hpp"
#include "gfins/status/status.hpp"

namespace gfins::drivers::lnx {

/// SCHED_FIFO at `priority` (1..99) for the calling thread. kInvalidArgument outside 1..99;
/// kUnavailable with os_error EPERM when not permitted; kIoError otherwise.
[[nodiscard]] Status set_fifo_priority(int priority, Os& os = real_os());

/// mlockall(MCL_CURRENT | MCL_FUTURE): no page faults in the loop after start-up.
/// kUnavailable with os_error EPERM/ENOMEM when not permitted; kIoError otherwise.
[[nodiscard]] Status lock_memory(Os& os = real_os());

}  // namespace gfins::drivers::lnx
