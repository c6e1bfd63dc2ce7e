// The fixture of the tests that run the project's programs (gfins-sim, gfins-replay,
// gfins-calibrate, ...): a fresh folder per test (TempDir), input files written into it, the
// programs started without a shell (run_cli.hpp) with their output collected in it.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "support/run_cli.hpp"
#include "support/temp_dir.hpp"

namespace gfins::test {

class CliTest : public ::testing::Test {
 protected:
  const std::filesystem::path& dir() const { return dir_.path(); }
  /// dir()/name as a string (a program argument).
  std::string path(const std::string& name) const { return (dir() / name).string(); }
  /// Writes `text` to dir()/name; returns the path.
  std::string file(const std::string& name, const std::string& text) const {
    testing::write_text(dir() / name, text);
    return path(name);
  }
  /// Runs `exe args...` to its end, its output collected in dir() (cli.out, cli.err); in `cwd`
  /// when one is given.
  CliResult run(const std::string& exe, const std::vector<std::string>& args,
                const std::filesystem::path& cwd = {}) const {
    return run_tool(exe, args, dir(), cwd);
  }

 private:
  testing::TempDir dir_{"gfins-cli"};
};

}  // namespace gfins::test
