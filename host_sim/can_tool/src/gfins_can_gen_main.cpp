// gfins-can-gen: the small generator of the CAN interface's derived files. Writes to stdout:
//   gfins-can-gen dbc [node]   docs/can/gfins.dbc (node 0 is the committed one)
//   gfins-can-gen icd          the signal tables of docs/can-interface.md
//   gfins-can-gen budget       the bus budget table of docs/can-interface.md
//   gfins-can-gen log SECONDS  a candump log of a synthetic moving board (tests, benchmarks)
//   gfins-can-gen --version    version and git revision; --help the usage and exit codes
// The tests regenerate the same text and fail when the committed files differ.
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "generate.hpp"
#include "gfins/can/message_table.hpp"
#include "gfins/version/version.hpp"

namespace {

constexpr const char* kUsage =
    "usage: gfins-can-gen dbc [node] | icd | budget | log SECONDS | --help | --version\n"
    "  dbc [node]    the DBC of the CAN interface for node id 0..15 (default 0)\n"
    "  icd           the signal tables of docs/can-interface.md\n"
    "  budget        the bus budget table of docs/can-interface.md\n"
    "  log SECONDS   a candump log of a synthetic moving board, (0, 86400] s\n"
    "Exit codes: 0 written to stdout; 1 command line rejected; 2 stdout could not be "
    "written.\n";

}  // namespace

int main(int argc, char** argv) {
  using namespace gfins::can_tool;
  if (argc < 2) {
    (void)std::fputs(kUsage, stderr);  // the exit code says it either way
    return 1;
  }
  if (std::strcmp(argv[1], "--help") == 0 || std::strcmp(argv[1], "-h") == 0) {
    return std::fputs(kUsage, stdout) < 0 ? 2 : 0;
  }
  if (std::strcmp(argv[1], "--version") == 0) {
    const std::string v = gfins::version::version_line("gfins-can-gen") + "\n";
    return std::fputs(v.c_str(), stdout) < 0 ? 2 : 0;
  }
  std::string text;
  if (std::strcmp(argv[1], "dbc") == 0) {
    const int node = argc > 2 ? std::atoi(argv[2]) : 0;
    if (node < 0 || node > gfins::can::kMaxNodeId) {
      std::fprintf(stderr, "gfins-can-gen: node id must be 0..15\n");
      return 1;
    }
    text = generate_dbc(static_cast<std::uint8_t>(node));
  } else if (std::strcmp(argv[1], "icd") == 0) {
    text = generate_signal_tables();
  } else if (std::strcmp(argv[1], "budget") == 0) {
    text = generate_budget_table(gfins::can::kDefaultSampleRateHz, gfins::can::kDefaultBitRate);
  } else if (std::strcmp(argv[1], "log") == 0) {
    const double seconds = argc > 2 ? std::atof(argv[2]) : 10.0;
    if (!(seconds > 0.0 && seconds <= 86400.0)) {
      std::fprintf(stderr, "gfins-can-gen: log duration must be in (0, 86400] s\n");
      return 1;
    }
    if (!write_synthetic_log(stdout, seconds, gfins::can::kDefaultSampleRateHz, 0) ||
        std::fflush(stdout) != 0) {
      std::fprintf(stderr, "gfins-can-gen: write failed\n");
      return 2;
    }
    return 0;
  } else {
    std::fprintf(stderr, "gfins-can-gen: unknown output '%s'\n%s", argv[1], kUsage);
    return 1;
  }
  if (std::fwrite(text.data(), 1, text.size(), stdout) != text.size() || std::fflush(stdout) != 0) {
    std::fprintf(stderr, "gfins-can-gen: write failed\n");
    return 2;
  }
  return 0;
}
