// gfins-can: decode gfins CAN traffic (candump logs, stdin, a live SocketCAN interface), check
// it end to end, plot it, and send commands to a board. docs/can-interface.md describes the
// frames; `gfins-can --help` the exit codes.
#include <CLI/CLI.hpp>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "command_client.hpp"
#include "decoder.hpp"
#include "generate.hpp"
#include "gfins/host_sim/version.hpp"
#include "host_io.hpp"
#include "views.hpp"
#if GFINS_CAN_HAVE_HIL
#include <iostream>

#include "hil.hpp"
#endif

namespace {

using namespace gfins;
using namespace gfins::can_tool;

enum Exit : int {
  kExitOk = 0,
  kExitUsage = 1,
  kExitInput = 2,     // a file, stdin or interface could not be read / output not written
  kExitIssues = 3,    // decoded to the end, but problems were found (see the summary)
  kExitRejected = 4,  // cmd: the board answered with an error result
  kExitTimeout = 5,   // cmd: no response in time, or the command could not be sent
  kExitPlot = 6,      // plot: the plot script could not be run or failed
};

constexpr const char* kExitCodes =
    "Exit codes:\n"
    "  0  success (decode: no problem found)\n"
    "  1  command-line error\n"
    "  2  input not readable (file, stdin, interface) or output not writable\n"
    "  3  decoded to the end, but problems were found (malformed lines, bad CRCs, drops, ...)\n"
    "  4  cmd: the board rejected the command (error response)\n"
    "  5  cmd: no response before the timeout, or the command could not be sent\n"
    "  6  plot: the plot script could not be started or failed\n";

struct DecodeOptions {
  std::vector<std::string> sources;
  std::string iface;
  std::string view = "line";
  std::string output;
  int node = -1;
  std::size_t max_issues = 20;  // printed per kind; all are counted
  bool quiet = false;
  double duration_s = 0.0;  // live: stop after this long (0 = until interrupted)
};

void print_summary(const Summary& s, std::FILE* out) {
  std::fprintf(
      out,
      "summary: %llu lines, %llu frames (%llu ok), %llu epochs, %llu commands, "
      "%llu responses, %llu problems\n",
      static_cast<unsigned long long>(s.lines), static_cast<unsigned long long>(s.frames),
      static_cast<unsigned long long>(s.frames_ok), static_cast<unsigned long long>(s.epochs),
      static_cast<unsigned long long>(s.commands), static_cast<unsigned long long>(s.responses),
      static_cast<unsigned long long>(s.total_issues()));
  for (std::size_t k = 0; k < s.issues.size(); ++k) {
    if (s.issues[k] == 0) continue;
    std::fprintf(out, "  %-20s %llu\n", to_string(static_cast<IssueKind>(k)),
                 static_cast<unsigned long long>(s.issues[k]));
  }
  std::fprintf(out, "  frames per message:");
  for (std::size_t m = 0; m < s.per_message.size(); ++m) {
    if (s.per_message[m] == 0) continue;
    std::fprintf(out, " %s=%llu", std::string(can::kMessages[m].name).c_str(),
                 static_cast<unsigned long long>(s.per_message[m]));
  }
  std::putc('\n', out);
}

/// Decodes every source into `view`; returns the exit code.
int decode(const DecodeOptions& o, View& view) {
  std::array<std::size_t, static_cast<std::size_t>(IssueKind::kCount_)> printed{};
  std::string current = "-";
  StreamDecoder dec(
      [&](const DecodedEpoch& e) {
        if (o.node < 0 || e.node_id == o.node) view.epoch(e);
      },
      [&](const Issue& i) {
        if (o.quiet) return;
        auto& n = printed[static_cast<std::size_t>(i.kind)];
        if (n < o.max_issues) {
          std::fprintf(stderr, "%s:%llu: %s: %s\n", current.c_str(),
                       static_cast<unsigned long long>(i.line), to_string(i.kind), i.text.c_str());
        } else if (n == o.max_issues) {
          std::fprintf(stderr, "%s: further '%s' problems are only counted\n", current.c_str(),
                       to_string(i.kind));
        }
        ++n;
      });
  bool input_error = false;
  if (!o.iface.empty()) {
    auto bus = open_live_bus(o.iface);
    if (!bus.is_ok()) {
      std::fprintf(stderr, "gfins-can: cannot open CAN interface '%s': %s\n", o.iface.c_str(),
                   bus.status().message());
      return kExitInput;
    }
    current = o.iface;
    const auto start = std::chrono::steady_clock::now();
    std::uint64_t n = 0;
    while (o.duration_s <= 0 ||
           std::chrono::steady_clock::now() - start < std::chrono::duration<double>(o.duration_s)) {
      (*bus)->service();
      const auto f = (*bus)->receive(100'000'000);
      if (!f.is_ok()) continue;
      const auto t = std::chrono::duration_cast<std::chrono::microseconds>(
                         std::chrono::system_clock::now().time_since_epoch())
                         .count();
      dec.feed_frame(++n, t, *f);
    }
  }
  for (const std::string& src : o.sources) {
    current = src;
    std::FILE* f = src == "-" ? stdin : std::fopen(src.c_str(), "rb");
    if (f == nullptr) {
      std::fprintf(stderr, "gfins-can: cannot open '%s': %s\n", src.c_str(), std::strerror(errno));
      input_error = true;
      continue;
    }
    for_each_line(f, [&](std::uint64_t line, std::string_view text) { dec.feed_line(line, text); });
    if (std::ferror(f) != 0) {
      std::fprintf(stderr, "gfins-can: read error on '%s'\n", src.c_str());
      input_error = true;
    }
    if (f != stdin && std::fclose(f) != 0) input_error = true;
  }
  dec.finish();
  view.finish();
  print_summary(dec.summary(), stderr);
  if (input_error) return kExitInput;
  return dec.summary().total_issues() == 0 ? kExitOk : kExitIssues;
}

std::FILE* open_output(const std::string& path) {
  if (path.empty() || path == "-") return stdout;
  return std::fopen(path.c_str(), "wb");
}

/// Flushes/closes the view's output; false (after a message) when anything written was lost.
bool close_output(std::FILE* f, const std::string& path) {
  const bool write_error = std::ferror(f) != 0;
  if (f == stdout) {
    if (std::fflush(stdout) == 0 && !write_error) return true;
    std::fprintf(stderr, "gfins-can: cannot write to stdout\n");
    return false;
  }
  if (std::fclose(f) != 0 || write_error) {
    std::fprintf(stderr, "gfins-can: cannot write '%s': %s\n", path.c_str(), std::strerror(errno));
    return false;
  }
  return true;
}

int run_decode(const DecodeOptions& o) {
  if (o.sources.empty() && o.iface.empty()) {
    std::fprintf(stderr, "gfins-can: give a candump log, '-' for stdin, or --iface\n");
    return kExitUsage;
  }
  std::FILE* out = open_output(o.output);
  if (out == nullptr) {
    std::fprintf(stderr, "gfins-can: cannot create '%s': %s\n", o.output.c_str(),
                 std::strerror(errno));
    return kExitInput;
  }
  auto view = make_view(parse_view(o.view), out);
  int rc = decode(o, *view);
  view.reset();
  if (!close_output(out, o.output)) rc = kExitInput;
  return rc;
}

int run_plot(const std::string& log, const std::string& png, int node, const std::string& script) {
  namespace fs = std::filesystem;
  std::random_device rd;
  const fs::path csv = fs::temp_directory_path() / ("gfins-can-plot-" + std::to_string(rd()) + "-" +
                                                    std::to_string(rd()) + ".csv");
  DecodeOptions o;
  o.sources = {log};
  o.view = "csv";
  o.output = csv.string();
  o.node = node;
  o.quiet = true;
  const int rc = run_decode(o);
  if (rc == kExitInput || rc == kExitUsage) {
    std::error_code ec;
    fs::remove(csv, ec);
    return rc;
  }
  const fs::path py = script.empty() ? find_script("plot_can.py") : fs::path(script);
  // $GFINS_PYTHON, else Debian's /usr/bin/python3 (python3-matplotlib): a python3 first on PATH
  // (pyenv, venv) often lacks matplotlib.
  const char* env_python = std::getenv("GFINS_PYTHON");
  const std::string python = env_python != nullptr && *env_python != '\0' ? env_python
                             : fs::exists("/usr/bin/python3")             ? "/usr/bin/python3"
                                                                          : "python3";
  const std::vector<std::string> argv{
      python,  py.string(), "--csv",   csv.string(),
      "--out", png,         "--title", fs::path(log).filename().string()};
  std::string detail;
  const Status s = run_without_shell(argv, &detail);
  std::error_code ec;
  fs::remove(csv, ec);
  if (!s.is_ok()) {
    std::fprintf(stderr, "gfins-can plot: %s (%s)\n", s.message(), detail.c_str());
    return kExitPlot;
  }
  std::fprintf(stderr, "gfins-can plot: wrote %s\n", png.c_str());
  return rc;
}

struct CmdOptions {
  std::string iface;
  int node = 0;
  int timeout_ms = 1000;
  int token = -1;
};

int run_cmd(const CmdOptions& o, can::Command c) {
  auto bus = open_live_bus(o.iface);
  if (!bus.is_ok()) {
    std::fprintf(stderr, "gfins-can cmd: cannot open CAN interface '%s': %s\n", o.iface.c_str(),
                 bus.status().message());
    return kExitInput;
  }
  c.token = static_cast<std::uint8_t>(o.token >= 0 ? static_cast<unsigned>(o.token)
                                                   : std::random_device{}() & 0xFFu);
  CommandTimeouts t;
  t.response = std::chrono::milliseconds(o.timeout_ms);
  const CommandOutcome r = run_command(**bus, c, static_cast<std::uint8_t>(o.node), t);
  std::printf("%s\n", r.text.c_str());
  if (r.capture_complete ||
      (c.opcode == can::Opcode::kStartCapture && r.kind == CommandOutcome::Kind::kOk)) {
    std::printf("pose %u, %u samples\nchannel,mean_counts,std_counts,count,saturated,motion\n",
                r.capture.pose, r.capture.samples);
    for (std::size_t ch = 0; ch < 6; ++ch) {
      const auto& cc = r.capture.channels[ch];
      std::printf("%zu,%.4f,%.4f,%u,%d,%d\n", ch + 1, static_cast<double>(cc.mean_counts),
                  static_cast<double>(cc.std_counts), cc.count, cc.saturated ? 1 : 0,
                  cc.motion ? 1 : 0);
    }
  }
  switch (r.kind) {
    case CommandOutcome::Kind::kOk:
      return kExitOk;
    case CommandOutcome::Kind::kRejected:
      return kExitRejected;
    default:
      return kExitTimeout;
  }
}

int main_impl(int argc, char** argv) {
  CLI::App app{"gfins-can: decode, check and plot gfins CAN traffic; send commands to a board"};
  app.footer(kExitCodes);
  app.set_version_flag("--version", gfins::version::version_line("gfins-can"));
  app.require_subcommand(1);

  DecodeOptions d;
  auto* dec = app.add_subcommand("decode", "decode candump logs ('-' = stdin) or a live interface");
  dec->add_option("sources", d.sources, "candump log files, '-' for stdin");
  dec->add_option("--iface", d.iface, "live SocketCAN interface (e.g. can0, vcan0)");
  dec->add_option("--view", d.view, "table | line | csv | json | none")->capture_default_str();
  dec->add_option("-o,--output", d.output, "write the view here instead of stdout");
  dec->add_option("--node", d.node, "show only this node id (0..15)")->check(CLI::Range(0, 15));
  dec->add_option("--max-issues", d.max_issues, "problems printed per kind (all are counted)")
      ->capture_default_str();
  dec->add_option("--duration", d.duration_s, "live: stop after this many seconds");
  dec->add_flag("-q,--quiet", d.quiet, "do not print each problem, only the summary");

  std::string plot_log, plot_png, plot_script;
  int plot_node = -1;
  auto* plot = app.add_subcommand("plot", "plot attitude, rate, velocity, position of a log (PNG)");
  plot->add_option("log", plot_log, "candump log")->required();
  plot->add_option("-o,--output", plot_png, "PNG to write")->required();
  plot->add_option("--node", plot_node, "node id to plot (default: all)")->check(CLI::Range(0, 15));
  plot->add_option("--script", plot_script, "plot script (default: the installed plot_can.py)");

  CmdOptions co;
  auto* cmd = app.add_subcommand("cmd", "send one command and wait for its response");
  cmd->add_option("--iface", co.iface, "SocketCAN interface")->required();
  cmd->add_option("--node", co.node, "node id of the board")->check(CLI::Range(0, 15));
  cmd->add_option("--timeout-ms", co.timeout_ms, "response timeout")->capture_default_str();
  cmd->add_option("--token", co.token, "token (default: random)")->check(CLI::Range(0, 255));
  cmd->require_subcommand(1);
  can::Command c;
  double heading_deg = 0;
  auto* realign = cmd->add_subcommand("realign", "re-align with the given heading");
  realign->add_option("--heading-deg", heading_deg, "heading, degrees")->required();
  auto* reset = cmd->add_subcommand("reset", "reset navigation");
  std::string comp;
  auto* compensator = cmd->add_subcommand("compensator", "switch compensator");
  compensator->add_option("kind", comp, "none | paper | exact")
      ->required()
      ->check(CLI::IsMember({"none", "paper", "exact"}));
  std::string div_msg;
  int divider = 0;
  auto* div = cmd->add_subcommand("divider", "set the output divider of a message");
  std::vector<std::string> data_names;
  for (const auto& m : can::kMessages) {
    if (m.kind == can::MessageKind::kData) data_names.emplace_back(m.name);
  }
  div->add_option("message", div_msg, "message name (GfinsQuaternion, ...)")
      ->required()
      ->check(CLI::IsMember(data_names));
  div->add_option("divider", divider, "divider of the sample rate, 0 = off")
      ->required()
      ->check(CLI::Range(0, 65535));
  auto* calid = cmd->add_subcommand("cal-id", "report the calibration identity");
  int pose = 0, samples = 0;
  auto* capture = cmd->add_subcommand("capture", "start a calibration capture for pose k");
  capture->add_option("--pose", pose, "pose index k")->required()->check(CLI::Range(0, 63));
  capture->add_option("--samples", samples, "N samples")->required()->check(CLI::Range(1, 65535));
  auto* reload = cmd->add_subcommand("reload", "reload the calibration file");

#if GFINS_CAN_HAVE_HIL
  HilOptions ho;
  auto* hil = app.add_subcommand(
      "hil",
      "hardware-in-the-loop replay: stream samples to gfins-fw --board hil, compare its "
      "frames with a host-only core run (docs/hil.md)");
  hil->add_option("--address", ho.address, "the board's IPv4 address")->capture_default_str();
  hil->add_option("--port", ho.port, "the board's replay port")
      ->check(CLI::Range(1, 65535))
      ->capture_default_str();
  auto* hil_src = hil->add_option_group("source");
  hil_src->add_option("--scenario", ho.scenario, "synthetic stream: a scenario name or .toml");
  hil_src->add_option("--recording", ho.recording, "recorded stream: a .gfr file");
  hil_src->require_option(1);
  hil->add_option("--scenario-dir", ho.scenario_dir, "folder of the named scenarios");
  hil->add_option("--duration", ho.duration_s, "scenario: seconds to replay (0 = its duration)")
      ->check(CLI::Range(0.0, 86400.0));
  hil->add_option("--fw-config", ho.fw_config,
                  "the firmware's configuration file (calibration, dividers, heading)");
  hil->add_option("--window", ho.window, "samples in flight before an acknowledgement")
      ->check(CLI::Range(1, 4096))
      ->capture_default_str();
  hil->add_option("--timeout-ms", ho.timeout_ms, "longest silence of the board")
      ->check(CLI::Range(1, 600000))
      ->capture_default_str();
  hil->add_option("--abort-after", ho.abort_after,
                  "test: reset the connection after sending N samples")
      ->check(CLI::NonNegativeNumber);
  hil->add_option("--corrupt-at", ho.corrupt_at, "test: send sample N with a corrupted CRC")
      ->check(CLI::NonNegativeNumber);
#endif

  std::uint8_t dbc_node = 0;
  std::string dbc_out;
  auto* dbc = app.add_subcommand("dbc", "print the DBC generated from the message table");
  dbc->add_option("--node", dbc_node, "node id")->check(CLI::Range(0, 15));
  dbc->add_option("-o,--output", dbc_out, "write here instead of stdout");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);
    return rc == 0 ? kExitOk : kExitUsage;
  }

  if (dec->parsed()) return run_decode(d);
#if GFINS_CAN_HAVE_HIL
  if (hil->parsed()) return run_hil(ho, std::cout, std::cerr);
#endif
  if (plot->parsed()) return run_plot(plot_log, plot_png, plot_node, plot_script);
  if (dbc->parsed()) {
    std::FILE* out = open_output(dbc_out);
    if (out == nullptr) {
      std::fprintf(stderr, "gfins-can: cannot create '%s': %s\n", dbc_out.c_str(),
                   std::strerror(errno));
      return kExitInput;
    }
    const std::string text = generate_dbc(dbc_node);
    const bool written = std::fwrite(text.data(), 1, text.size(), out) == text.size();
    return close_output(out, dbc_out) && written ? kExitOk : kExitInput;
  }
  if (realign->parsed()) {
    c.opcode = can::Opcode::kRealign;
    c.heading_rad =
        static_cast<float>(std::remainder(heading_deg, 360.0) * std::numbers::pi / 180.0);
  } else if (reset->parsed()) {
    c.opcode = can::Opcode::kResetNavigation;
  } else if (compensator->parsed()) {
    c.opcode = can::Opcode::kSetCompensator;
    c.compensator = comp == "none"    ? nav::CompensatorKind::kNone
                    : comp == "paper" ? nav::CompensatorKind::kPaper
                                      : nav::CompensatorKind::kExact;
  } else if (div->parsed()) {
    c.opcode = can::Opcode::kSetDivider;
    for (const auto& m : can::kMessages) {
      if (m.name == div_msg) c.message = m.id;
    }
    c.divider = static_cast<std::uint16_t>(divider);
  } else if (calid->parsed()) {
    c.opcode = can::Opcode::kReportCalibrationId;
  } else if (capture->parsed()) {
    c.opcode = can::Opcode::kStartCapture;
    c.pose = static_cast<std::uint8_t>(pose);
    c.samples = static_cast<std::uint16_t>(samples);
  } else if (reload->parsed()) {
    c.opcode = can::Opcode::kReloadCalibration;
  }
  return run_cmd(co, c);
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return main_impl(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "gfins-can: %s\n", e.what());
    return kExitUsage;
  } catch (...) {
    std::fprintf(stderr, "gfins-can: unexpected error\n");
    return kExitUsage;
  }
}
