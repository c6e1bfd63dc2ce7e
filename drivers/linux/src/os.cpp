// The real operating-system calls behind lnx::Os (see os.hpp).
#include "gfins/drivers/lnx/os.hpp"

#include <fcntl.h>
#include <net/if.h>
#include <poll.h>
#include <pthread.h>
#include <sched.h>
#include <stdlib.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include <cstdio>

namespace gfins::drivers::lnx {

int Os::open(const char* path, int flags, unsigned mode) {
  return ::open(path, flags, static_cast<mode_t>(mode));
}
int Os::close(int fd) { return ::close(fd); }
long Os::read(int fd, void* buf, std::size_t n) { return ::read(fd, buf, n); }
long Os::write(int fd, const void* buf, std::size_t n) { return ::write(fd, buf, n); }
int Os::ioctl(int fd, unsigned long request, void* arg) { return ::ioctl(fd, request, arg); }
int Os::fsync(int fd) { return ::fsync(fd); }
int Os::ftruncate(int fd, long length) { return ::ftruncate(fd, static_cast<off_t>(length)); }
int Os::fchmod(int fd, unsigned mode) { return ::fchmod(fd, static_cast<mode_t>(mode)); }
int Os::mkostemp(char* path_template, int flags) { return ::mkostemp(path_template, flags); }
int Os::rename(const char* from, const char* to) { return std::rename(from, to); }
int Os::unlink(const char* path) { return ::unlink(path); }
int Os::lstat(const char* path, void* st) { return ::lstat(path, static_cast<struct stat*>(st)); }

int Os::socket(int domain, int type, int protocol) { return ::socket(domain, type, protocol); }
int Os::bind(int fd, const void* addr, unsigned addr_len) {
  return ::bind(fd, static_cast<const sockaddr*>(addr), addr_len);
}
int Os::setsockopt(int fd, int level, int name, const void* value, unsigned len) {
  return ::setsockopt(fd, level, name, value, len);
}
unsigned Os::if_nametoindex(const char* name) { return ::if_nametoindex(name); }
int Os::ppoll(void* fds, unsigned long nfds, const timespec* timeout) {
  return ::ppoll(static_cast<pollfd*>(fds), nfds, timeout, nullptr);
}
long Os::recvmsg(int fd, void* msg, int flags) {
  return ::recvmsg(fd, static_cast<msghdr*>(msg), flags);
}

int Os::clock_gettime(int clock_id, timespec* ts) { return ::clock_gettime(clock_id, ts); }
int Os::clock_nanosleep(int clock_id, int flags, const timespec* request) {
  return ::clock_nanosleep(clock_id, flags, request, nullptr);
}

int Os::set_fifo_priority(int priority) {
  sched_param p{};
  p.sched_priority = priority;
  return ::pthread_setschedparam(::pthread_self(), SCHED_FIFO, &p);
}
int Os::mlockall(int flags) { return ::mlockall(flags); }

std::int64_t monotonic_ns(Os& os) {
  timespec ts{};
  (void)os.clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1000000000 + ts.tv_nsec;
}

Os& real_os() {
  static Os os;
  return os;
}

}  // namespace gfins::drivers::lnx
