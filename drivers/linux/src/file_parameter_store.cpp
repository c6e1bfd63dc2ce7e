#include "gfins/drivers/lnx/file_parameter_store.hpp"

#include <fcntl.h>
#include <limits.h>
#include <sys/stat.h>

#include <array>
#include <cerrno>
#include <string_view>
#include <utility>

#include "fd.hpp"
#include "gfins/drivers/lnx/output_paths.hpp"

namespace gfins::drivers::lnx {
namespace {

// One message per step and outcome: Status messages are static (no heap on any path).
const char* failure_message(SaveStep step) {
  switch (step) {
    case SaveStep::kCheckTarget:
      return "parameter store: not saved: checking the target failed; the previous file is "
             "unchanged";
    case SaveStep::kCreateTemp:
      return "parameter store: not saved: creating the temporary file failed; the previous file "
             "is unchanged";
    case SaveStep::kWrite:
      return "parameter store: not saved: writing the temporary file failed; the previous file "
             "is unchanged";
    case SaveStep::kSyncFile:
      return "parameter store: not saved: fsync of the temporary file failed; the previous file "
             "is unchanged";
    case SaveStep::kCloseFile:
      return "parameter store: not saved: closing the temporary file failed; the previous file "
             "is unchanged";
    case SaveStep::kRename:
      return "parameter store: not saved: renaming the temporary file over the target failed; "
             "the previous file is unchanged";
    case SaveStep::kSyncDir:
      return "parameter store: fsync of the folder failed after the rename; the new file is in "
             "place but may not survive a power cut";
  }
  return "parameter store: save failed";
}

// The store's messages are static (no heap): one per kind that non_regular_kind() names.
const char* not_a_file_message(const char* kind) {
  static constexpr std::array<std::pair<std::string_view, const char*>, 6> kMessages{{
      {"a symbolic link",
       "parameter store: not saved: the path is a symbolic link (name the file it points to); "
       "nothing was replaced"},
      {"a folder", "parameter store: not saved: the path is a folder; nothing was replaced"},
      {"a device node",
       "parameter store: not saved: the path is a device node; nothing was replaced"},
      {"a FIFO", "parameter store: not saved: the path is a FIFO; nothing was replaced"},
      {"a socket", "parameter store: not saved: the path is a socket; nothing was replaced"},
      {"a special file",
       "parameter store: not saved: the path is a special file; nothing was replaced"},
  }};
  for (const auto& [name, message] : kMessages) {
    if (name == kind) return message;
  }
  return "parameter store: not saved: the path is not a regular file; nothing was replaced";
}

}  // namespace

const char* to_string(SaveStep step) {
  switch (step) {
    case SaveStep::kCheckTarget:
      return "checking the target";
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
      return "fsync of the folder";
  }
  return "unknown step";
}

Result<std::unique_ptr<FileParameterStore>> FileParameterStore::open(std::string_view path,
                                                                     Os& os) {
  if (path.empty()) return Status(ErrorCode::kInvalidArgument, "parameter store: empty path");
  if (path.size() >= PATH_MAX - 16) {  // room for the temporary name's suffix
    return Status(ErrorCode::kInvalidArgument, "parameter store: path longer than PATH_MAX");
  }
  if (path.find('\0') != std::string_view::npos) {
    return Status(ErrorCode::kInvalidArgument, "parameter store: path contains a NUL");
  }
  if (path.back() == '/') {
    return Status(ErrorCode::kInvalidArgument, "parameter store: path names a folder");
  }
  const std::size_t slash = path.rfind('/');
  const std::string dir = slash == std::string_view::npos
                              ? "."
                              : (slash == 0 ? "/" : std::string(path.substr(0, slash)));
  const std::string name(slash == std::string_view::npos ? path : path.substr(slash + 1));
  if (name == "." || name == "..") {
    return Status(ErrorCode::kInvalidArgument, "parameter store: path names a folder");
  }
  std::string temp = (dir == "/" ? "" : dir) + "/." + name + ".tmp-XXXXXX";
  std::unique_ptr<FileParameterStore> store(
      new FileParameterStore(os, std::string(path), dir, std::move(temp)));
  return store;
}

FileParameterStore::FileParameterStore(Os& os, std::string path, std::string dir,
                                       std::string temp_template)
    : os_(os),
      path_(std::move(path)),
      dir_(std::move(dir)),
      temp_template_(std::move(temp_template)),
      temp_(temp_template_) {}

Result<std::size_t> FileParameterStore::do_load(std::span<char> buffer) {
  Fd fd(os_, os_.open(path_.c_str(), O_RDONLY | O_CLOEXEC, 0));
  if (!fd.valid()) {
    const int err = errno;
    if (err == ENOENT) return Status(ErrorCode::kUnavailable, "parameter store: no file", err);
    return Status(ErrorCode::kIoError, "parameter store: cannot open the file", err);
  }
  std::size_t size = 0;
  for (;;) {
    if (size == buffer.size()) {
      char extra = 0;
      const long n = os_.read(fd.get(), &extra, 1);
      if (n < 0 && errno == EINTR) continue;
      if (n < 0) return Status(ErrorCode::kIoError, "parameter store: cannot read the file", errno);
      if (n > 0) {
        return Status(ErrorCode::kResourceExhausted,
                      "parameter store: the file is larger than the buffer");
      }
      return size;
    }
    const long n = os_.read(fd.get(), buffer.data() + size, buffer.size() - size);
    if (n < 0) {
      if (errno == EINTR) continue;
      return Status(ErrorCode::kIoError, "parameter store: cannot read the file", errno);
    }
    if (n == 0) return size;
    size += static_cast<std::size_t>(n);
  }
}

Status FileParameterStore::fail(SaveStep step, int err, bool temp_exists) {
  if (temp_exists) (void)os_.unlink(temp_.c_str());
  last_failed_step_ = step;
  return Status(ErrorCode::kIoError, failure_message(step), err);
}

Status FileParameterStore::do_save(std::span<const char> blob) {
  struct stat st {};
  if (os_.lstat(path_.c_str(), &st) == 0) {
    if (const char* kind = non_regular_kind(st.st_mode)) {
      last_failed_step_ = SaveStep::kCheckTarget;
      return Status(ErrorCode::kInvalidArgument, not_a_file_message(kind));
    }
  } else if (errno != ENOENT) {
    return fail(SaveStep::kCheckTarget, errno, false);
  }
  temp_ = temp_template_;  // mkostemp replaces the X's in place
  Fd fd(os_, os_.mkostemp(temp_.data(), O_CLOEXEC));
  if (!fd.valid()) return fail(SaveStep::kCreateTemp, errno, false);
  // mkostemp creates 0600; a calibration file is readable by all like any configuration file.
  if (os_.fchmod(fd.get(), 0644) != 0) return fail(SaveStep::kCreateTemp, errno, true);

  std::size_t done = 0;
  while (done < blob.size()) {
    const long n = os_.write(fd.get(), blob.data() + done, blob.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      return fail(SaveStep::kWrite, errno, true);
    }
    if (n == 0) return fail(SaveStep::kWrite, EIO, true);  // no progress: never loop forever
    done += static_cast<std::size_t>(n);
  }
  if (os_.fsync(fd.get()) != 0) return fail(SaveStep::kSyncFile, errno, true);
  if (os_.close(fd.release()) != 0) return fail(SaveStep::kCloseFile, errno, true);
  if (os_.rename(temp_.c_str(), path_.c_str()) != 0) return fail(SaveStep::kRename, errno, true);

  Fd dir_fd(os_, os_.open(dir_.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC, 0));
  if (!dir_fd.valid()) return fail(SaveStep::kSyncDir, errno, false);
  if (os_.fsync(dir_fd.get()) != 0) return fail(SaveStep::kSyncDir, errno, false);
  return Status::ok();
}

Status remove_file_durably(std::string_view path, Os& os) {
  auto store = FileParameterStore::open(path, os);
  if (!store.is_ok()) return store.status();
  return store.value()->remove();
}

Status FileParameterStore::remove() {
  struct stat st {};
  if (os_.lstat(path_.c_str(), &st) != 0) {
    if (errno == ENOENT) return Status::ok();
    return Status(ErrorCode::kIoError, "parameter store: cannot look at the file to remove", errno);
  }
  if (const char* kind = non_regular_kind(st.st_mode)) {
    return Status(ErrorCode::kInvalidArgument, not_a_file_message(kind));
  }
  if (os_.unlink(path_.c_str()) != 0 && errno != ENOENT) {
    return Status(ErrorCode::kIoError, "parameter store: unlink of the file failed", errno);
  }
  Fd dir_fd(os_, os_.open(dir_.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC, 0));
  if (!dir_fd.valid() || os_.fsync(dir_fd.get()) != 0) {
    return Status(ErrorCode::kIoError,
                  "parameter store: fsync of the folder failed after the removal; the file is gone "
                  "but a power cut may bring it back",
                  errno);
  }
  return Status::ok();
}

Status save_file_atomically(std::string_view path, std::span<const char> blob, Os& os) {
  auto store = FileParameterStore::open(path, os);
  if (!store.is_ok()) return store.status();
  return store.value()->replace(blob);
}

}  // namespace gfins::drivers::lnx
