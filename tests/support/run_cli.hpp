// Runs one of the project's command-line tools from a test WITHOUT a shell (gfins::spawn,
// posix_spawn with an argument vector), collecting its exit code and its stdout + stderr.
//
// The string overload splits its arguments at single spaces: the tests' arguments are paths
// under a temporary folder and numbers, which never hold a space; an argument that does (a
// deliberately bad device id "a b") goes through the vector overload, byte for byte.
#pragma once

#include <chrono>
#include <concepts>
#include <filesystem>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "gfins/drivers/lnx/spawn.hpp"
#include "support/temp_dir.hpp"

namespace gfins::test {

struct CliResult {
  int exit_code = -1;    // -1: not started, or killed by a signal
  std::string output;    // stdout, then stderr
  std::string err;       // stderr alone
  long max_rss_kib = 0;  // the child's peak resident set (wait4), KiB
};

inline std::vector<std::string> split_at_spaces(const std::string& args) {
  std::vector<std::string> out;
  std::istringstream in(args);
  for (std::string word; in >> word;) out.push_back(word);
  return out;
}

/// The whole file ("" when it cannot be opened).
inline std::string slurp(const std::filesystem::path& p) { return testing::read_text(p); }

/// A tool started without waiting (start_tool), e.g. to be interrupted: its stdout and stderr go
/// to log_dir/cli.out and log_dir/cli.err, which the test may read while it runs.
struct StartedTool {
  drivers::lnx::ChildProcess child;
  std::filesystem::path log_dir;
  std::filesystem::path stdout_path() const { return log_dir / "cli.out"; }
  std::filesystem::path stderr_path() const { return log_dir / "cli.err"; }
};

/// Starts `exe args...` with its output in log_dir (made if missing) and, when `cwd` is not
/// empty, that folder as its working directory.
inline StartedTool start_tool(const std::string& exe, const std::vector<std::string>& args,
                              const std::filesystem::path& log_dir,
                              const std::filesystem::path& cwd = {}) {
  std::vector<std::string> argv{exe};
  argv.insert(argv.end(), args.begin(), args.end());
  StartedTool t;
  t.log_dir = log_dir;
  std::error_code ec;
  std::filesystem::create_directories(log_dir, ec);
  drivers::lnx::SpawnOptions o;
  o.search_path = false;
  o.cwd = cwd.string();
  o.stdout_path = t.stdout_path().string();
  o.stderr_path = t.stderr_path().string();
  if (auto c = drivers::lnx::start_program(argv, o); c.is_ok()) t.child = c.value();
  return t;
}

/// Polls a started tool's stderr every 10 ms until `found(stderr text)` holds or `limit` has
/// passed; true when it held. For tests that act (SIGINT) once the tool has reached a point.
template <typename Found>
requires std::predicate<Found, const std::string&>
bool wait_for_stderr(const StartedTool& t, Found found, std::chrono::milliseconds limit) {
  const auto end = std::chrono::steady_clock::now() + limit;
  for (;;) {
    if (found(slurp(t.stderr_path()))) return true;
    if (std::chrono::steady_clock::now() >= end) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
}

/// wait_for_stderr for a fixed piece of text.
inline bool wait_for_stderr(const StartedTool& t, const std::string& text,
                            std::chrono::milliseconds limit) {
  return wait_for_stderr(
      t, [&](const std::string& err) { return err.find(text) != std::string::npos; }, limit);
}

/// Waits for a started tool: exit code (-1 when killed by a signal or never started), output.
inline CliResult finish_tool(StartedTool& t) {
  CliResult r;
  if (t.child.pid > 0) {
    const auto e = drivers::lnx::wait_program(t.child);
    if (e.is_ok() && e->exited) r.exit_code = e->code;
    if (e.is_ok()) r.max_rss_kib = e->max_rss_kib;
  }
  r.err = slurp(t.stderr_path());
  r.output = slurp(t.stdout_path()) + r.err;
  return r;
}

/// Runs a tool to its end (start_tool + finish_tool): exit code and stdout + stderr.
inline CliResult run_tool(const std::string& exe, const std::vector<std::string>& args,
                          const std::filesystem::path& log_dir,
                          const std::filesystem::path& cwd = {}) {
  StartedTool t = start_tool(exe, args, log_dir, cwd);
  return finish_tool(t);
}

inline CliResult run_tool(const std::string& exe, const std::string& args,
                          const std::filesystem::path& log_dir) {
  return run_tool(exe, split_at_spaces(args), log_dir);
}

}  // namespace gfins::test
