// Runs one of the project's command-line tools from a test WITHOUT a shell (gfins::spawn,
// posix_spawn with an argument vector), collecting its exit code and its stdout + stderr.
//
// The string overload splits its arguments at single spaces: the tests' arguments are paths
// under a temporary folder and numbers, which never hold a space; an argument that does (a
// deliberately bad device id "a b") goes through the vector overload, byte for byte.
#pragma once

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "gfins/drivers/linux/spawn.hpp"

namespace gfins::test {

struct CliResult {
  int exit_code = -1;    // -1: not started, or killed by a signal
  std::string output;    // stdout, then stderr
  long max_rss_kib = 0;  // the child's peak resident set (wait4), KiB
};

inline std::vector<std::string> split_at_spaces(const std::string& args) {
  std::vector<std::string> out;
  std::istringstream in(args);
  for (std::string word; in >> word;) out.push_back(word);
  return out;
}

inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// A tool started without waiting (start_tool), e.g. to be interrupted: its stdout and stderr go
/// to log_dir/cli.out and log_dir/cli.err, which the test may read while it runs.
struct StartedTool {
  drivers::lnx::ChildProcess child;
  std::filesystem::path log_dir;
  std::filesystem::path stderr_path() const { return log_dir / "cli.err"; }
};

inline StartedTool start_tool(const std::string& exe, const std::vector<std::string>& args,
                              const std::filesystem::path& log_dir) {
  std::vector<std::string> argv{exe};
  argv.insert(argv.end(), args.begin(), args.end());
  drivers::lnx::SpawnOptions o;
  o.search_path = false;
  o.stdout_path = (log_dir / "cli.out").string();
  o.stderr_path = (log_dir / "cli.err").string();
  StartedTool t;
  t.log_dir = log_dir;
  if (auto c = drivers::lnx::start_program(argv, o); c.is_ok()) t.child = c.value();
  return t;
}

/// Waits for a started tool: exit code (-1 when killed by a signal or never started), output.
inline CliResult finish_tool(StartedTool& t) {
  CliResult r;
  if (t.child.pid > 0) {
    const auto e = drivers::lnx::wait_program(t.child);
    if (e.is_ok() && e->exited) r.exit_code = e->code;
    if (e.is_ok()) r.max_rss_kib = e->max_rss_kib;
  }
  r.output = slurp(t.log_dir / "cli.out") + slurp(t.log_dir / "cli.err");
  return r;
}

/// Runs a tool to its end (start_tool + finish_tool): exit code and stdout + stderr.
inline CliResult run_tool(const std::string& exe, const std::vector<std::string>& args,
                          const std::filesystem::path& log_dir) {
  StartedTool t = start_tool(exe, args, log_dir);
  return finish_tool(t);
}

inline CliResult run_tool(const std::string& exe, const std::string& args,
                          const std::filesystem::path& log_dir) {
  return run_tool(exe, split_at_spaces(args), log_dir);
}

}  // namespace gfins::test
