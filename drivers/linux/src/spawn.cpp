#include "gfins/drivers/lnx/spawn.hpp"

#include <fcntl.h>
#include <signal.h>  // kill
#include <spawn.h>
#include <sys/resource.h>  // rusage (wait4)
#include <sys/wait.h>
#include <unistd.h>  // environ (the caller's environment, handed to the child unchanged)

#include <cerrno>
#include <cstring>
#include <utility>
#include <vector>

namespace gfins::drivers::lnx {
namespace {

/// posix_spawn_file_actions_t that is always destroyed.
class FileActions {
 public:
  FileActions() { ok_ = posix_spawn_file_actions_init(&fa_) == 0; }
  ~FileActions() {
    if (ok_) posix_spawn_file_actions_destroy(&fa_);
  }
  FileActions(const FileActions&) = delete;
  FileActions& operator=(const FileActions&) = delete;
  bool ok() const { return ok_; }
  posix_spawn_file_actions_t* get() { return &fa_; }

 private:
  posix_spawn_file_actions_t fa_{};
  bool ok_ = false;
};

}  // namespace

Result<ProcessExit> run_program(std::span<const std::string> argv, const SpawnOptions& options) {
  Result<ChildProcess> child = start_program(argv, options);
  if (!child.is_ok()) return child.status();
  return wait_program(child.value());
}

Result<ChildProcess> start_program(std::span<const std::string> argv, const SpawnOptions& options) {
  if (argv.empty() || argv[0].empty()) {
    return Status(ErrorCode::kInvalidArgument, "spawn: no program given");
  }
  // A NUL byte would silently cut the argument short: refuse rather than pass something else.
  std::vector<char*> args;
  args.reserve(argv.size() + 1);
  for (const std::string& a : argv) {
    if (a.find('\0') != std::string::npos) {
      return Status(ErrorCode::kInvalidArgument, "spawn: an argument holds a NUL byte");
    }
    args.push_back(const_cast<char*>(a.c_str()));  // NOLINT: posix_spawn's char* const[] API
  }
  args.push_back(nullptr);

  FileActions fa;
  if (!fa.ok()) return Status(ErrorCode::kResourceExhausted, "spawn: file actions", ENOMEM);
  if (!options.cwd.empty()) {
    // glibc ≥ 2.29: the child changes directory between fork and exec.
    const int rc = posix_spawn_file_actions_addchdir_np(fa.get(), options.cwd.c_str());
    if (rc != 0) return Status(ErrorCode::kInvalidArgument, "spawn: working directory", rc);
  }
  for (const auto& [fd, path] :
       {std::pair{1, &options.stdout_path}, std::pair{2, &options.stderr_path}}) {
    if (path->empty()) continue;
    const int rc = posix_spawn_file_actions_addopen(fa.get(), fd, path->c_str(),
                                                    O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (rc != 0) return Status(ErrorCode::kInvalidArgument, "spawn: output redirection", rc);
  }
  pid_t pid = 0;
  // glibc reports a failed exec (ENOENT, EACCES) as the return value of posix_spawn.
  const int rc = options.search_path
                     ? posix_spawnp(&pid, args[0], fa.get(), nullptr, args.data(), environ)
                     : posix_spawn(&pid, args[0], fa.get(), nullptr, args.data(), environ);
  if (rc != 0) return Status(ErrorCode::kUnavailable, "spawn: cannot start the program", rc);

  return ChildProcess{pid};
}

Status signal_program(const ChildProcess& child, int signal) {
  if (child.pid <= 0) return Status(ErrorCode::kInvalidArgument, "spawn: no child to signal");
  if (kill(child.pid, signal) != 0) return Status(ErrorCode::kIoError, "spawn: kill failed", errno);
  return Status::ok();
}

namespace {
// One wait4 on `child`; `flags` 0 blocks, WNOHANG returns nullopt while it runs.
Result<std::optional<ProcessExit>> reap(ChildProcess& child, int flags) {
  if (child.pid <= 0) return Status(ErrorCode::kInvalidArgument, "spawn: no child to wait for");
  int wstatus = 0;
  rusage usage{};
  for (;;) {
    const pid_t w = wait4(child.pid, &wstatus, flags, &usage);
    if (w == child.pid) break;
    if (w == 0) return std::optional<ProcessExit>{};  // WNOHANG: still running
    if (w < 0 && errno == EINTR) continue;  // a signal handler ran; the child is still there
    return Status(ErrorCode::kIoError, "spawn: waitpid failed", errno);
  }
  child.pid = -1;
  ProcessExit e;
  e.max_rss_kib = usage.ru_maxrss;  // Linux: kilobytes (getrusage(2))
  if (WIFEXITED(wstatus)) {
    e.exited = true;
    e.code = WEXITSTATUS(wstatus);
  } else if (WIFSIGNALED(wstatus)) {
    e.signal = WTERMSIG(wstatus);
  }
  return std::optional<ProcessExit>{e};
}
}  // namespace

Result<ProcessExit> wait_program(ChildProcess& child) {
  auto r = reap(child, 0);
  if (!r.is_ok()) return r.status();
  return *r.value();
}

Result<std::optional<ProcessExit>> poll_program(ChildProcess& child) {
  return reap(child, WNOHANG);
}

std::string describe(const ProcessExit& e) {
  if (e.exited) return "exit status " + std::to_string(e.code);
  const char* name = strsignal(e.signal);
  return "killed by signal " + std::to_string(e.signal) + " (" + (name ? name : "?") + ")";
}

}  // namespace gfins::drivers::lnx
