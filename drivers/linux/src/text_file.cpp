#include "gfins/drivers/lnx/text_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

namespace gfins::drivers::lnx {

namespace {
/// Closes the descriptor on every return (a close error after a read is not actionable).
struct ClosingFd {
  int fd;
  ~ClosingFd() {
    if (fd >= 0) (void)::close(fd);
  }
};
}  // namespace

Status read_text_file(const char* path, std::size_t max_bytes, std::string& out) {
  out.clear();
  // O_NOCTTY: a terminal named as an input never becomes the controlling terminal.
  const ClosingFd fd{::open(path, O_RDONLY | O_CLOEXEC | O_NOCTTY)};
  if (fd.fd < 0) return Status(ErrorCode::kIoError, "cannot open the file", errno);
  constexpr std::size_t kChunk = std::size_t{64} * 1024U;
  for (;;) {
    const std::size_t have = out.size();
    // One byte beyond the limit tells "exactly max_bytes" from "more".
    const std::size_t want = std::min(kChunk, max_bytes + 1 - have);
    out.resize(have + want);
    const ssize_t n = ::read(fd.fd, out.data() + have, want);
    if (n < 0) {
      if (errno == EINTR) {
        out.resize(have);
        continue;
      }
      const int e = errno;
      out.clear();
      return Status(ErrorCode::kIoError, "cannot read the file", e);
    }
    out.resize(have + static_cast<std::size_t>(n));
    if (n == 0) return Status::ok();
    if (out.size() > max_bytes) {
      out.clear();
      return Status(ErrorCode::kOutOfRange, "larger than the limit");
    }
  }
}

std::string text_file_error(std::string_view path, const Status& status, std::size_t max_bytes,
                            std::string_view what) {
  std::string m(path);
  if (status.code() == ErrorCode::kOutOfRange) {
    m += ": larger than " + std::to_string(max_bytes) + " bytes, the limit for ";
    m += what;
    m += " (a device such as /dev/zero, or not the file meant?)";
    return m;
  }
  m += ": ";
  m += status.message();
  if (status.os_error() != 0) {
    m += ": ";
    m += std::strerror(status.os_error());
    m += " (errno " + std::to_string(status.os_error()) + ")";
  }
  return m;
}

}  // namespace gfins::drivers::lnx
