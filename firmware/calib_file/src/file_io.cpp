// Reading a calibration file and saving one atomically (POSIX: mkstemp, fsync, rename).
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>
#include <vector>

#include "gfins/calib_file/calibration_file.hpp"

namespace gfins::calib_file {
namespace {

constexpr std::size_t kMaxFileBytes = 1 << 20;  // a calibration file is ~5 kB

std::string prefix_of(const std::filesystem::path& path) {
  return "calibration file '" + path.string() + "': ";
}

std::string errno_text(int err) { return std::string(std::strerror(err)); }

// Closes a descriptor on scope exit unless released.
class Fd {
 public:
  explicit Fd(int fd) : fd_(fd) {}
  Fd(const Fd&) = delete;
  Fd& operator=(const Fd&) = delete;
  ~Fd() {
    if (fd_ >= 0) ::close(fd_);
  }
  int get() const { return fd_; }
  int release() {
    const int fd = fd_;
    fd_ = -1;
    return fd;
  }

 private:
  int fd_;
};

int write_all(int fd, const std::string& text) {
  std::size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      return errno;
    }
    done += static_cast<std::size_t>(n);
  }
  return 0;
}

}  // namespace

const char* to_string(SaveStep step) {
  switch (step) {
    case SaveStep::kCreateTemp:
      return "creating the temporary file";
    case SaveStep::kWrite:
      return "writing the temporary file";
    case SaveStep::kSyncFile:
      return "fsync of the temporary file";
    case SaveStep::kCloseFile:
      return "closing the temporary file";
    case SaveStep::kRename:
      return "renaming the temporary file over the target";
    case SaveStep::kSyncDir:
      return "fsync of the directory";
  }
  return "unknown step";
}

FileResult<CalibrationData> load_calibration_file(const std::filesystem::path& path) {
  const std::string prefix = prefix_of(path);
  Fd fd(::open(path.c_str(), O_RDONLY | O_CLOEXEC));
  if (fd.get() < 0) {
    return FileStatus(ErrorCode::kIoError, prefix + "cannot open: " + errno_text(errno));
  }
  std::string text;
  char buf[4096];
  for (;;) {
    const ssize_t n = ::read(fd.get(), buf, sizeof buf);
    if (n < 0) {
      if (errno == EINTR) continue;
      return FileStatus(ErrorCode::kIoError, prefix + "cannot read: " + errno_text(errno));
    }
    if (n == 0) break;
    text.append(buf, static_cast<std::size_t>(n));
    if (text.size() > kMaxFileBytes) {
      return FileStatus(ErrorCode::kInvalidArgument,
                        prefix + "larger than 1 MiB: not a calibration file");
    }
  }
  return parse_calibration_text(text, path.string());
}

FileStatus save_calibration_file(const std::filesystem::path& path, const CalibrationData& data,
                                 const SaveOptions& options) {
  const std::string prefix = prefix_of(path);
  const Problem problem = validate(data);
  if (problem.found()) {
    return FileStatus(ErrorCode::kOutOfRange,
                      prefix + "not saved: " + problem.key + " " + problem.problem);
  }
  const std::string text = to_toml_text(data);
  const std::filesystem::path dir =
      path.has_parent_path() ? path.parent_path() : std::filesystem::path(".");
  std::string temp = (dir / ("." + path.filename().string() + ".tmp-XXXXXX")).string();
  bool temp_exists = false;

  const auto fail = [&](SaveStep step, int err) {
    if (temp_exists) ::unlink(temp.c_str());
    std::string what = prefix + "not saved: " + to_string(step) + " failed: " + errno_text(err);
    what += step == SaveStep::kSyncDir
                ? "; the new file is in place but may not survive a power cut"
                : "; the previous file, if any, is unchanged";
    return FileStatus(ErrorCode::kIoError, what);
  };
  const auto injected = [&options](SaveStep step) {
    return options.inject_failure ? options.inject_failure(step) : 0;
  };

  if (const int err = injected(SaveStep::kCreateTemp)) return fail(SaveStep::kCreateTemp, err);
  Fd fd(::mkostemp(temp.data(), O_CLOEXEC));
  if (fd.get() < 0) return fail(SaveStep::kCreateTemp, errno);
  temp_exists = true;
  // mkstemp makes the file 0600; a calibration file is world-readable like any configuration.
  if (::fchmod(fd.get(), 0644) != 0) return fail(SaveStep::kCreateTemp, errno);

  int err = injected(SaveStep::kWrite);
  if (err == 0) err = write_all(fd.get(), text);
  if (err != 0) return fail(SaveStep::kWrite, err);

  err = injected(SaveStep::kSyncFile);
  if (err == 0 && ::fsync(fd.get()) != 0) err = errno;
  if (err != 0) return fail(SaveStep::kSyncFile, err);

  err = injected(SaveStep::kCloseFile);
  if (err == 0 && ::close(fd.release()) != 0) err = errno;
  if (err != 0) return fail(SaveStep::kCloseFile, err);

  err = injected(SaveStep::kRename);
  if (err == 0 && ::rename(temp.c_str(), path.c_str()) != 0) err = errno;
  if (err != 0) return fail(SaveStep::kRename, err);
  temp_exists = false;

  err = injected(SaveStep::kSyncDir);
  if (err == 0) {
    Fd dir_fd(::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC));
    if (dir_fd.get() < 0 || ::fsync(dir_fd.get()) != 0) err = errno;
  }
  if (err != 0) return fail(SaveStep::kSyncDir, err);
  return FileStatus::ok();
}

}  // namespace gfins::calib_file
