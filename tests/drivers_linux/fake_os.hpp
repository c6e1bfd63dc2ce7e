// A fake kernel for the Linux backends' tests: every lnx::Os call is logged and answered by a
// replaceable handler. Default handlers fail with ENOSYS, so a backend making a call the test
// did not expect fails loudly instead of reaching the real kernel.
#pragma once

#include <cerrno>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "gfins/drivers/lnx/os.hpp"

namespace gfins::drivers::lnx::testing {

inline int fail_with(int err) {
  errno = err;
  return -1;
}

class FakeOs : public Os {
 public:
  std::vector<std::string> log;  // call names in order

  std::function<int(const char*, int, unsigned)> on_open = [](const char*, int, unsigned) {
    return fail_with(ENOSYS);
  };
  std::function<int(int)> on_close = [](int) { return 0; };
  std::function<long(int, void*, std::size_t)> on_read = [](int, void*, std::size_t) -> long {
    return fail_with(ENOSYS);
  };
  std::function<long(int, const void*, std::size_t)> on_write =
      [](int, const void*, std::size_t) -> long { return fail_with(ENOSYS); };
  std::function<int(int, unsigned long, void*)> on_ioctl = [](int, unsigned long, void*) {
    return fail_with(ENOSYS);
  };
  std::function<int(int, int, int)> on_socket = [](int, int, int) { return fail_with(ENOSYS); };
  std::function<int(int, const void*, unsigned)> on_bind = [](int, const void*, unsigned) {
    return fail_with(ENOSYS);
  };
  std::function<int(int, int, int, const void*, unsigned)> on_setsockopt =
      [](int, int, int, const void*, unsigned) { return fail_with(ENOSYS); };
  std::function<unsigned(const char*)> on_if_nametoindex = [](const char*) {
    errno = ENODEV;
    return 0U;
  };
  std::function<int(void*, unsigned long, const timespec*)> on_ppoll =
      [](void*, unsigned long, const timespec*) { return 0; };
  std::function<long(int, void*, int)> on_recvmsg = [](int, void*, int) -> long {
    return fail_with(ENOSYS);
  };
  std::function<int(int, timespec*)> on_clock_gettime;  // nullptr: time stands at 1000 s
  std::function<int(int, int, const timespec*)> on_clock_nanosleep = [](int, int, const timespec*) {
    return ENOSYS;
  };
  std::function<int(int)> on_set_fifo_priority = [](int) { return ENOSYS; };
  std::function<int(int)> on_mlockall = [](int) { return fail_with(ENOSYS); };

  int open(const char* p, int f, unsigned m) override {
    rec("open");
    return on_open(p, f, m);
  }
  int close(int fd) override {
    rec("close");
    return on_close(fd);
  }
  long read(int fd, void* b, std::size_t n) override {
    rec("read");
    return on_read(fd, b, n);
  }
  long write(int fd, const void* b, std::size_t n) override {
    rec("write");
    return on_write(fd, b, n);
  }
  int ioctl(int fd, unsigned long r, void* a) override {
    rec("ioctl");
    return on_ioctl(fd, r, a);
  }
  int socket(int d, int t, int p) override {
    rec("socket");
    return on_socket(d, t, p);
  }
  int bind(int fd, const void* a, unsigned l) override {
    rec("bind");
    return on_bind(fd, a, l);
  }
  int setsockopt(int fd, int lv, int n, const void* v, unsigned l) override {
    rec("setsockopt");
    return on_setsockopt(fd, lv, n, v, l);
  }
  unsigned if_nametoindex(const char* n) override {
    rec("if_nametoindex");
    return on_if_nametoindex(n);
  }
  int ppoll(void* f, unsigned long n, const timespec* t) override {
    rec("ppoll");
    return on_ppoll(f, n, t);
  }
  long recvmsg(int fd, void* m, int f) override {
    rec("recvmsg");
    return on_recvmsg(fd, m, f);
  }
  int clock_gettime(int id, timespec* ts) override;
  int clock_nanosleep(int id, int f, const timespec* r) override {
    rec("clock_nanosleep");
    return on_clock_nanosleep(id, f, r);
  }
  int set_fifo_priority(int p) override {
    rec("set_fifo_priority");
    return on_set_fifo_priority(p);
  }
  int mlockall(int f) override {
    rec("mlockall");
    return on_mlockall(f);
  }

  std::size_t count(const std::string& name) const {
    std::size_t n = 0;
    for (const auto& c : log) n += c == name ? 1 : 0;
    return n;
  }

 private:
  void rec(const char* name) { log.emplace_back(name); }
};

}  // namespace gfins::drivers::lnx::testing
