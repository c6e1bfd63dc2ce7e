// Starting a helper program without a shell (docs/architecture.md: process I/O is a Linux backend;
// the project brief: user text never goes through a shell; posix_spawn with an argument vector).
//
// The program and every argument go to posix_spawn(3) as separate argv strings, so an argument
// is never parsed: quotes, `;`, `$()`, spaces, newlines and a leading `-` reach the child as the
// bytes they are. The child inherits the environment and the standard streams; the caller waits
// for it and gets its exit status.
#pragma once

#include <optional>
#include <span>
#include <string>

#include "gfins/status/status.hpp"

namespace gfins::drivers::lnx {

/// How a child ended.
struct ProcessExit {
  bool exited = false;   // true: it returned from main / called exit(); false: killed by a signal
  int code = 0;          // exit code when exited
  int signal = 0;        // signal number when killed
  long max_rss_kib = 0;  // the child's peak resident set (getrusage ru_maxrss of wait4), KiB
  bool ok() const { return exited && code == 0; }
};

struct SpawnOptions {
  /// Working directory of the child; empty: the caller's.
  std::string cwd;
  /// Look `argv[0]` up in PATH when it holds no '/' (execvp rules); otherwise it is a path.
  bool search_path = true;
  /// Files (created or truncated) that receive the child's stdout / stderr; empty: inherited.
  std::string stdout_path;
  std::string stderr_path;
};

/// Runs argv[0] with arguments argv[1..] and waits for it. Fails (kInvalidArgument) on an empty
/// argv or an argument holding a NUL byte, (kUnavailable, os_error = errno) when the program
/// cannot be started (not found, not executable), (kIoError, os_error) when waiting fails. A
/// child that runs and fails is not an error of this call: look at ProcessExit.
Result<ProcessExit> run_program(std::span<const std::string> argv,
                                const SpawnOptions& options = {});

/// A child started by start_program and not yet waited for.
struct ChildProcess {
  int pid = -1;
};

/// start_program + wait_program in one: the child is started as run_program does, but the
/// caller gets control back at once, e.g. to send it a signal (signal_program) before waiting.
/// The same errors as run_program for starting.
Result<ChildProcess> start_program(std::span<const std::string> argv,
                                   const SpawnOptions& options = {});
/// Sends `signal` (SIGINT, SIGTERM, ...) to a started child. kIoError (os_error) when kill fails.
Status signal_program(const ChildProcess& child, int signal);
/// Waits for a started child and reaps it (its pid is then -1). kIoError when waiting fails.
Result<ProcessExit> wait_program(ChildProcess& child);
/// wait_program without blocking: nullopt while the child runs, its exit (reaped) once it ended.
/// For a caller that must notice its own stop flag while a child runs: SA_RESTART handlers (what
/// std::signal installs) never wake a blocking wait.
Result<std::optional<ProcessExit>> poll_program(ChildProcess& child);

/// "exit status 3" / "killed by signal 9 (Killed)": for messages.
std::string describe(const ProcessExit& e);

}  // namespace gfins::drivers::lnx
