// The operating-system calls the Linux backends make, behind one small virtual interface.
//
// Production code uses real_os(), whose methods forward to the libc call of the same name and
// keep its contract (return value and errno). Tests derive a fake kernel from it and override
// the calls they want to observe or fail (Pigweed's pw_digital_io_linux does the same with the
// linker's --wrap; a virtual table works under the sanitizers and needs no link tricks). The
// signatures use only built-in types so this header stays free of Linux headers; the kernel
// structures travel as `void*` and are documented per call.
#pragma once

#include <cstddef>
#include <cstdint>

struct timespec;  // NOLINT(readability-identifier-naming): <time.h>'s

namespace gfins::drivers::lnx {

class Os {
 public:
  virtual ~Os() = default;

  // Files and devices (<fcntl.h>, <unistd.h>, <sys/ioctl.h>, <sys/stat.h>, <stdlib.h>).
  virtual int open(const char* path, int flags, unsigned mode);
  virtual int close(int fd);
  virtual long read(int fd, void* buf, std::size_t n);
  virtual long write(int fd, const void* buf, std::size_t n);
  virtual int ioctl(int fd, unsigned long request, void* arg);
  virtual int fsync(int fd);
  virtual int ftruncate(int fd, long length);
  virtual int fchmod(int fd, unsigned mode);
  virtual int mkostemp(char* path_template, int flags);
  virtual int rename(const char* from, const char* to);
  virtual int unlink(const char* path);
  // `st` is a struct stat; the link itself is described, not what it points to.
  virtual int lstat(const char* path, void* st);

  // Sockets (<sys/socket.h>, <net/if.h>, <poll.h>). `addr` is a struct sockaddr_*; `fds` an
  // array of struct pollfd; `timeout` a struct timespec (nullptr = wait forever).
  virtual int socket(int domain, int type, int protocol);
  virtual int bind(int fd, const void* addr, unsigned addr_len);
  virtual int setsockopt(int fd, int level, int name, const void* value, unsigned len);
  virtual unsigned if_nametoindex(const char* name);
  virtual int ppoll(void* fds, unsigned long nfds, const timespec* timeout);
  // `msg` is a struct msghdr (iovecs and the ancillary-data buffer, socket(7), cmsg(3)).
  virtual long recvmsg(int fd, void* msg, int flags);

  // Time (<time.h>). clock_nanosleep returns an error number instead of setting errno.
  virtual int clock_gettime(int clock_id, timespec* ts);
  virtual int clock_nanosleep(int clock_id, int flags, const timespec* request);

  // Real-time set-up (<sched.h>, <pthread.h>, <sys/mman.h>). set_fifo_priority applies
  // SCHED_FIFO to the calling thread and returns an error number (pthread convention).
  virtual int set_fifo_priority(int priority);
  virtual int mlockall(int flags);
};

/// The process-wide real implementation (stateless, never destroyed).
Os& real_os();

/// CLOCK_MONOTONIC through `os`, in ns: the time base of every deadline the backends compute
/// (what is left of a wait after a signal or a partial read). clock_gettime cannot fail for
/// CLOCK_MONOTONIC with a valid pointer (clock_gettime(2)).
std::int64_t monotonic_ns(Os& os);

}  // namespace gfins::drivers::lnx
