// A file descriptor closed through lnx::Os when it goes out of scope (private helper).
#pragma once

#include "gfins/drivers/lnx/os.hpp"

namespace gfins::drivers::lnx {

class Fd {
 public:
  Fd() = default;
  Fd(Os& os, int fd) : os_(&os), fd_(fd) {}
  Fd(const Fd&) = delete;
  Fd& operator=(const Fd&) = delete;
  Fd(Fd&& o) noexcept : os_(o.os_), fd_(o.release()) {}
  Fd& operator=(Fd&& o) noexcept {
    if (this != &o) {
      reset();
      os_ = o.os_;
      fd_ = o.release();
    }
    return *this;
  }
  ~Fd() { reset(); }

  int get() const { return fd_; }
  bool valid() const { return fd_ >= 0; }
  int release() {
    const int fd = fd_;
    fd_ = -1;
    return fd;
  }
  // close(2) errors are not actionable here: the descriptor is released by the kernel even when
  // close reports an error (Linux close(2), "Dealing with error returns from close()").
  void reset() {
    if (fd_ >= 0 && os_ != nullptr) (void)os_->close(fd_);
    fd_ = -1;
  }

 private:
  Os* os_ = nullptr;
  int fd_ = -1;
};

}  // namespace gfins::drivers::lnx
