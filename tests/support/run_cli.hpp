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
  int exit_code = -1;  // -1: not started, or killed by a signal
  std::string output;  // stdout, then stderr
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

inline CliResult run_tool(const std::string& exe, const std::vector<std::string>& args,
                          const std::filesystem::path& log_dir) {
  std::vector<std::string> argv{exe};
  argv.insert(argv.end(), args.begin(), args.end());
  drivers::lnx::SpawnOptions o;
  o.search_path = false;
  o.stdout_path = (log_dir / "cli.out").string();
  o.stderr_path = (log_dir / "cli.err").string();
  CliResult r;
  const auto e = drivers::lnx::run_program(argv, o);
  if (e.is_ok() && e->exited) r.exit_code = e->code;
  r.output = slurp(o.stdout_path) + slurp(o.stderr_path);
  return r;
}

inline CliResult run_tool(const std::string& exe, const std::string& args,
                          const std::filesystem::path& log_dir) {
  return run_tool(exe, split_at_spaces(args), log_dir);
}

}  // namespace gfins::test
