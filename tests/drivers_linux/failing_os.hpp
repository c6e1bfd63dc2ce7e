// The real kernel with one step of the parameter store's atomic save made to fail (shared by
// the store's tests and the calibration file's).
#pragma once

#include <cerrno>
#include <cstddef>

#include "gfins/drivers/lnx/file_parameter_store.hpp"
#include "gfins/drivers/lnx/os.hpp"

namespace gfins::drivers::lnx::testing {

// The real kernel, except that the call making step `fail_at` fails with `err` (close still
// closes: the descriptor must not leak even when close reports an error).
class FailingOs : public Os {
 public:
  FailingOs(SaveStep fail_at, int err) : fail_at_(fail_at), err_(err) {}

  int lstat(const char* path, void* st) override {
    if (fail_at_ == SaveStep::kCheckTarget) return fail();
    return Os::lstat(path, st);
  }
  int mkostemp(char* t, int flags) override {
    if (fail_at_ == SaveStep::kCreateTemp) return fail();
    temp_fd_ = Os::mkostemp(t, flags);
    return temp_fd_;
  }
  long write(int fd, const void* b, std::size_t n) override {
    if (fail_at_ == SaveStep::kWrite) return fail();
    return Os::write(fd, b, n < 5 ? n : 5);  // short writes: the backend must loop
  }
  int fsync(int fd) override {
    const bool dir = fd != temp_fd_;  // the temporary is closed before the folder is opened
    if ((fail_at_ == SaveStep::kSyncFile && !dir) || (fail_at_ == SaveStep::kSyncDir && dir)) {
      return fail();
    }
    return Os::fsync(fd);
  }
  int close(int fd) override {
    const int r = Os::close(fd);
    if (fd != temp_fd_) return r;
    temp_fd_ = -1;  // the folder's descriptor may reuse the number
    if (fail_at_ == SaveStep::kCloseFile) return fail();
    return r;
  }
  int rename(const char* a, const char* b) override {
    if (fail_at_ == SaveStep::kRename) return fail();
    return Os::rename(a, b);
  }

 private:
  int fail() {
    errno = err_;
    return -1;
  }
  SaveStep fail_at_;
  int err_;
  int temp_fd_ = -1;
};

}  // namespace gfins::drivers::lnx::testing
