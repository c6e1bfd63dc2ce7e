// gfins-can-gen: the small generator of the CAN interface's derived files. Writes to stdout:
//   gfins-can-gen dbc [node]   docs/can/gfins.dbc (node 1, a stock board's, is the committed one)
//   gfins-can-gen icd          the signal tables of docs/can-interface.md
//   gfins-can-gen budget       the bus budget table of docs/can-interface.md
//   gfins-can-gen log SECONDS  a candump log of a synthetic moving board (tests, benchmarks)
//   gfins-can-gen --version    version and git revision; --help the usage and exit codes
// The tests regenerate the same text and fail when the committed files differ.
#include <cmath>
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
    "  dbc [node]    the DBC of the CAN interface for node id 0..15 (default 1, a stock board)\n"
    "  icd           the signal tables of docs/can-interface.md\n"
    "  budget        the bus budget table of docs/can-interface.md\n"
    "  log SECONDS   a candump log of a synthetic moving board, (0, 86400] s\n"
    "Exit codes: 0 written to stdout; 1 command line rejected; 2 stdout could not be "
    "written.\n";

/// `text` as a whole decimal integer in [lo, hi] (no sign, no trailing characters).
bool parse_int(const char* text, int lo, int hi, int& out) {
  if (text[0] < '0' || text[0] > '9') return false;
  char* end = nullptr;
  const long v = std::strtol(text, &end, 10);
  if (*end != '\0' || v < lo || v > hi) return false;
  out = static_cast<int>(v);
  return true;
}

/// `text` as a whole finite number.
bool parse_number(const char* text, double& out) {
  char* end = nullptr;
  out = std::strtod(text, &end);
  return end != text && *end == '\0' && std::isfinite(out);
}

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
  const bool takes_value = std::strcmp(argv[1], "dbc") == 0 || std::strcmp(argv[1], "log") == 0;
  if (const int max_args = takes_value ? 3 : 2; argc > max_args) {
    std::fprintf(stderr, "gfins-can-gen: unexpected argument '%s'\n%s", argv[max_args], kUsage);
    return 1;
  }
  std::string text;
  if (std::strcmp(argv[1], "dbc") == 0) {
    int node = gfins::can::kDefaultNodeId;
    if (argc > 2 && !parse_int(argv[2], 0, gfins::can::kMaxNodeId, node)) {
      std::fprintf(stderr, "gfins-can-gen: node id '%s': must be a whole number 0..15\n", argv[2]);
      return 1;
    }
    text = generate_dbc(static_cast<std::uint8_t>(node));
  } else if (std::strcmp(argv[1], "icd") == 0) {
    text = generate_signal_tables();
  } else if (std::strcmp(argv[1], "budget") == 0) {
    text = generate_budget_table(gfins::can::kDefaultSampleRateHz, gfins::can::kDefaultBitRate);
  } else if (std::strcmp(argv[1], "log") == 0) {
    double seconds = 10.0;
    if ((argc > 2 && !parse_number(argv[2], seconds)) || !(seconds > 0.0 && seconds <= 86400.0)) {
      std::fprintf(stderr, "gfins-can-gen: log duration '%s': must be a number in (0, 86400] s\n",
                   argc > 2 ? argv[2] : "");
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
