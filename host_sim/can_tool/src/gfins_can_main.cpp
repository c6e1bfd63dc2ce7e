// gfins-can: decode gfins CAN traffic (candump logs, stdin, a live SocketCAN interface), check
// it end to end, plot it, and send commands to a board. docs/can-interface.md describes the
// frames; `gfins-can --help` the exit codes.
#include <CLI/CLI.hpp>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <numbers>
#include <optional>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "capture_sequence.hpp"
#include "command_client.hpp"
#include "csv.hpp"
#include "decode_session.hpp"
#include "decoder.hpp"
#include "generate.hpp"
#include "gfins/app/config.hpp"
#include "gfins/app/publisher_sink.hpp"
#include "gfins/drivers/lnx/candump.hpp"
#include "gfins/drivers/lnx/error_text.hpp"
#include "gfins/drivers/lnx/file_parameter_store.hpp"
#include "gfins/drivers/lnx/text_file.hpp"
#include "gfins/host_sim/scenario.hpp"
#include "gfins/version/version.hpp"
#include "gnss_log.hpp"
#include "host_io.hpp"
#include "id_base_option.hpp"
#include "views.hpp"
#if GFINS_CAN_HAVE_HIL
#include "hil.hpp"
#endif

namespace {

using namespace gfins;
using namespace gfins::can_tool;

enum Exit : int {
  kExitOk = 0,
  kExitUsage = 1,
  kExitInput = 2,      // a file, stdin or interface could not be read / output not written
  kExitIssues = 3,     // decoded to the end, but problems were found (see the summary)
  kExitRejected = 4,   // cmd: the board answered with an error result
  kExitTimeout = 5,    // cmd: no response in time, or the command could not be sent
  kExitPlot = 6,       // plot: the plot script could not be run or failed
  kExitNoFrames = 7,   // decode, plot: readable, no problem, but not one frame arrived
  kExitHilDiffer = 8,  // hil: frames differ from the host-only core run, or incomplete stream
};

#if GFINS_CAN_HAVE_HIL
static_assert(kHilExitBadInput == kExitInput && kHilExitDifferent == kExitHilDiffer,
              "gfins-can hil's exit codes are the ones --help lists");
#endif

constexpr const char* kExitCodes =
    "Exit codes:\n"
    "  0  success (decode: no problem found)\n"
    "  1  command-line error\n"
    "  2  input not readable (file, stdin, interface; hil: scenario, recording, connection) or\n"
    "     output not writable\n"
    "  3  decoded to the end, but problems were found (malformed lines, bad CRCs, drops, ...)\n"
    "  4  cmd: the board rejected the command (error response)\n"
    "  5  cmd: no response before the timeout, the command could not be sent, or a capture\n"
    "     result arrived with frames missing (no statistics are printed then)\n"
    "  6  plot: the plot script could not be started or failed\n"
    "  7  decode, plot: no CAN frame at all (idle or wrong interface, empty log), no problem\n"
    "  8  hil: the board's frames differ from the host-only core run, or the stream ended\n"
    "     early (INCOMPLETE)\n";

struct DecodeOptions {
  std::vector<std::string> sources;
  std::string iface;
  std::string view = "line";
  std::string output;
  int node = -1;
  std::size_t max_issues = 20;  // printed per kind; all are counted
  bool quiet = false;
  double duration_s = 0.0;  // live: stop after this long (0 = until interrupted)
  std::string config;       // --config: the boards' identifier groups from this file
  can::IdBases ids;
};

/// --config FILE of decode, plot, cmd, calibrate, gnss and dbc: the identifier groups
/// (can.*_id_base) of a board from its gfins-fw configuration, and its can.node_id where `node` is
/// not given on the command line (`node_given` false); then the groups of --id-base (`moved`) on
/// top. `sub` is the subcommand: a --config it was given is loaded even when empty (and refused
/// then). `loaded`, when not null, receives the configuration a file gave. False, after saying
/// why, when the file does not load or the groups do not fit.
bool board_from_config(const char* who, const CLI::App* sub, const std::string& path,
                       const std::vector<std::string>& moved, bool node_given, int& node,
                       can::IdBases& ids, std::optional<app::FwConfig>* loaded = nullptr) {
  if (sub->count("--config") != 0) {
    const app::ConfigResult r = app::load_config(path);
    if (!r.ok()) {
      std::fprintf(stderr, "gfins-can %s: --config: %s\n", who, r.error.c_str());
      return false;
    }
    ids = app::id_bases(*r.config);
    if (!node_given) node = r.config->node_id;
    if (loaded != nullptr) *loaded = *r.config;
  }
  if (const std::string p = apply_id_bases(moved, ids); !p.empty()) {
    std::fprintf(stderr, "gfins-can %s: --id-base: %s\n", who, p.c_str());
    return false;
  }
  return true;
}

/// --id-base GROUP=0xBASE of the subcommands that take --config: a group as a SetIdBase command
/// moved it on the board (kept there across restarts), for a board whose configuration file does
/// not say so. Repeatable; applied after --config.
void add_id_base_option(CLI::App* sub, std::vector<std::string>& moved) {
  sub->add_option("--id-base", moved,
                  "GROUP=0xBASE: that identifier group (data, input, command, response) starts "
                  "at BASE (hexadecimal with its 0x), as `cmd id-base` moved it on the board; "
                  "repeatable, on top of --config")
      // One value per --id-base (a file name after it stays a file name), every one kept.
      ->expected(1)
      ->allow_extra_args(false)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll)
      ->check(CLI::Validator(
          [](const std::string& t) {
            std::size_t g = 0;
            std::uint16_t b = 0;
            const std::string p = parse_id_base(t, g, b);
            return p.empty() ? p : p + ", not " + app::quote_text(t).substr(0, 40);
          },
          "GROUP=0xBASE"));
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
  dec.set_id_bases(o.ids);
  dec.set_input_sink([&](const DecodedInput& in) {
    if (o.node < 0 || in.node_id == o.node) view.input(in);
  });
  dec.set_notice_sink([&](const Notice& nt) {
    if (!o.quiet) {
      std::fprintf(stderr, "%s:%llu: note: %s\n", current.c_str(),
                   static_cast<unsigned long long>(nt.line), nt.text.c_str());
    }
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
    const auto keep_going = [&] {
      return o.duration_s <= 0 ||
             std::chrono::steady_clock::now() - start < std::chrono::duration<double>(o.duration_s);
    };
    const auto now_us = [] {
      return static_cast<std::int64_t>(std::chrono::duration_cast<std::chrono::microseconds>(
                                           std::chrono::system_clock::now().time_since_epoch())
                                           .count());
    };
    constexpr std::int64_t kPollNs = 100'000'000;  // --duration is honoured within 0.1 s
    feed_live(**bus, dec, keep_going, now_us, kPollNs);
  }
  for (const std::string& src : o.sources) {
    current = src == "-" ? std::string("-") : display_name(src);
    const std::string error = decode_log(src, dec);
    if (!error.empty()) {
      std::fprintf(stderr, "gfins-can: %s\n", error.c_str());
      input_error = true;
    }
  }
  dec.finish();
  view.finish();
  print_summary(dec.summary(), stderr);
  switch (decode_end(dec.summary(), input_error, o.node)) {
    case DecodeEnd::kInputError:
      return kExitInput;
    case DecodeEnd::kProblems:
      return kExitIssues;
    case DecodeEnd::kNoFrames:
      if (dec.summary().frames != 0) {
        std::fprintf(stderr, "gfins-can: no epoch of node %d (--node); nodes seen: %s\n", o.node,
                     node_list(dec.summary().nodes_seen).c_str());
      } else {
        std::fprintf(stderr, "gfins-can: no CAN frame %s\n",
                     o.iface.empty() ? "in the input" : "arrived on the interface");
      }
      return kExitNoFrames;
    case DecodeEnd::kOk:
      break;
  }
  return kExitOk;
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

struct GnssOptions {
  std::string scenario;
  std::string scenario_dir;
  std::string output;
  std::string iface;
  int node = 0;
  double duration_s = 0.0;
  double log_start_s = static_cast<double>(drivers::lnx::kSimulatedLogEpochS);
  std::string config;
  can::IdBases ids;
};

/// gfins-can gnss: the scenario's [gnss] receiver as input frames.
int run_gnss(const GnssOptions& o) {
  const auto sc = o.scenario_dir.empty() ? sim::load_scenario(o.scenario)
                                         : sim::load_scenario(o.scenario, o.scenario_dir);
  if (!sc.is_ok()) {
    std::fprintf(stderr, "gfins-can: %s\n", sc.error().message.c_str());
    return kExitInput;
  }
  if (!sc->gnss) {
    std::fprintf(stderr, "gfins-can: scenario '%s' has no [gnss] table\n", sc->name.c_str());
    return kExitInput;
  }
  const auto traj = sim::make_trajectory(sc->trajectory);
  if (!traj.is_ok()) {
    std::fprintf(stderr, "gfins-can: %s\n", traj.error().message.c_str());
    return kExitInput;
  }
  const sim::GnssModel model(*sc->gnss, *traj.value());
  const auto fixes = model.fixes(o.duration_s > 0.0 ? o.duration_s : sc->duration_s);
  const auto node = static_cast<std::uint8_t>(o.node);
  if (!o.iface.empty()) {
    auto bus = open_live_bus(o.iface);
    if (!bus.is_ok()) {
      std::fprintf(stderr, "gfins-can: cannot open CAN interface '%s': %s\n", o.iface.c_str(),
                   bus.status().message());
      return kExitInput;
    }
    const std::uint64_t refused = send_gnss_live(**bus, fixes, *sc->gnss, node, o.ids);
    std::fprintf(stderr, "gfins-can: %zu fixes sent, %llu frames refused by the bus\n",
                 fixes.size(), static_cast<unsigned long long>(refused));
    return refused == 0 ? kExitOk : kExitInput;
  }
  std::FILE* out = open_output(o.output);
  if (out == nullptr) {
    std::fprintf(stderr, "gfins-can: cannot create '%s': %s\n", o.output.c_str(),
                 std::strerror(errno));
    return kExitInput;
  }
  const bool written = write_gnss_log(out, fixes, *sc->gnss, node, o.log_start_s, "can0", o.ids);
  return close_output(out, o.output) && written ? kExitOk : kExitInput;
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

/// Whether `path` can be written, checked by opening it for appending (which neither truncates
/// an existing file nor leaves a new one behind); the reason when not.
std::string output_unwritable(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::is_directory(path, ec)) return "is a directory";
  const bool existed = fs::exists(path, ec);
  std::FILE* f = std::fopen(path.c_str(), "ab");
  if (f == nullptr) return std::strerror(errno);
  (void)std::fclose(f);  // nothing was written: a close error says nothing about the figure
  if (!existed) (void)fs::remove(path, ec);  // the probe's own file: best effort
  return {};
}

int run_plot(const std::string& log, const std::string& png, int node, const std::string& script,
             const can::IdBases& ids) {
  namespace fs = std::filesystem;
  // Checked before the decode: a figure that cannot be written is a one-line error naming it,
  // not a traceback of the plot script after the work.
  if (png.empty()) {
    std::fprintf(stderr, "gfins-can plot: -o is empty: give the PNG file to write\n");
    return kExitInput;
  }
  if (const std::string why = output_unwritable(png); !why.empty()) {
    std::fprintf(stderr, "gfins-can plot: cannot write the figure '%s': %s\n", png.c_str(),
                 why.c_str());
    return kExitInput;
  }
  std::random_device rd;
  const fs::path csv = fs::temp_directory_path() / ("gfins-can-plot-" + std::to_string(rd()) + "-" +
                                                    std::to_string(rd()) + ".csv");
  DecodeOptions o;
  o.sources = {log};
  o.view = "csv";
  o.output = csv.string();
  o.node = node;
  o.ids = ids;
  o.quiet = true;
  const int rc = run_decode(o);
  if (rc == kExitInput || rc == kExitUsage || rc == kExitNoFrames) {  // nothing to plot
    std::error_code ec;
    (void)fs::remove(csv, ec);  // a temporary file: best effort
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
  (void)fs::remove(csv, ec);  // a temporary file: best effort
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
  int sequence = -1;        // -1: 1, and the board's next one when it answers Replayed
  double rate_hz = 1000.0;  // the board's sample rate: sizes a capture's wait (N / rate + 5 s)
  std::string config;
  can::IdBases ids;
};

// The longest response wait a command line may ask for (10 min): longer is a typo, not a board.
constexpr int kMaxTimeoutMs = 600000;

/// A heading given in degrees: finite and within one turn either way (it is then wrapped to
/// [-180, 180]). CLI::Range alone lets NaN through (every comparison with NaN is false).
CLI::Validator heading_deg_check() {
  return CLI::Validator(
      [](const std::string& text) -> std::string {
        double v = 0;
        try {
          std::size_t used = 0;
          v = std::stod(text, &used);
          if (used != text.size()) return "'" + text + "' is not a number of degrees";
        } catch (const std::exception&) {
          return "'" + text + "' is not a number of degrees";
        }
        if (!std::isfinite(v) || std::abs(v) > 360.0) {
          return "heading '" + text + "' must be a finite number of degrees in [-360, 360]";
        }
        return {};
      },
      "DEGREES in [-360, 360]");
}

int run_cmd(const CmdOptions& o, can::Command c) {
  auto bus = open_live_bus(o.iface);
  if (!bus.is_ok()) {
    std::fprintf(stderr, "gfins-can cmd: cannot open CAN interface '%s': %s\n", o.iface.c_str(),
                 bus.status().message());
    return kExitInput;
  }
  if (o.sequence >= 0 && !can::carries_sequence(c.opcode)) {
    std::fprintf(stderr,
                 "gfins-can cmd: --sequence: %s carries no sequence number (it changes "
                 "nothing on the board)\n",
                 can::to_string(c.opcode));
    return kExitUsage;
  }
  c.token = static_cast<std::uint8_t>(o.token >= 0 ? static_cast<unsigned>(o.token)
                                                   : std::random_device{}() & 0xFFu);
  CommandTimeouts t;
  t.response = std::chrono::milliseconds(o.timeout_ms);
  t.sample_rate_hz = o.rate_hz;
  const auto node = static_cast<std::uint8_t>(o.node);
  CommandOutcome r;
  if (o.sequence >= 0) {
    c.sequence = static_cast<std::uint16_t>(o.sequence);
    r = run_command(**bus, c, node, t, o.ids);
  } else {
    std::string note;
    r = run_command_next_sequence(**bus, c, node, t, &note, o.ids);
    if (!note.empty()) std::fprintf(stderr, "gfins-can cmd: %s\n", note.c_str());
  }
  if (r.kind == CommandOutcome::Kind::kIncomplete) {
    // Missing statistics are not zeros: print none of them (gfins-can calibrate refuses such a
    // pose too, capture_sequence.cpp).
    std::fprintf(stderr, "gfins-can cmd: %s\n", r.text.c_str());
    return kExitTimeout;
  }
  std::printf("%s\n", r.text.c_str());
  if (r.capture_complete) {
    std::printf("pose %u, %u samples\nchannel,mean_counts,std_counts,count,saturated,motion\n",
                r.capture.pose, r.capture.samples);
    for (std::size_t ch = 0; ch < 6; ++ch) {
      const auto& cc = r.capture.channels[ch];
      std::printf("%zu,%.4f,%.4f,%u,%d,%d\n", ch + 1, static_cast<double>(cc.mean_counts),
                  static_cast<double>(cc.std_counts), cc.count, cc.saturated ? 1 : 0,
                  cc.motion ? 1 : 0);
    }
    // A pose that moved or saturated is not a measurement (docs/calibration.md, step 3).
    std::string sat, moved;
    for (std::size_t ch = 0; ch < 6; ++ch) {
      const std::string name = "a" + std::to_string(ch + 1);
      if (r.capture.channels[ch].saturated) sat += (sat.empty() ? "" : ", ") + name;
      if (r.capture.channels[ch].motion) moved += (moved.empty() ? "" : ", ") + name;
    }
    if (!sat.empty() || !moved.empty()) {
      std::fprintf(stderr, "gfins-can cmd: pose %u refused:%s%s\n", r.capture.pose,
                   sat.empty() ? ""
                               : (" channel(s) " + sat +
                                  " saturated (a code at full scale during the capture);")
                                     .c_str(),
                   moved.empty() ? ""
                                 : (" channel(s) " + moved +
                                    " moved (standard deviation above the firmware's still "
                                    "limit, 2 mg of the scale factor)")
                                       .c_str());
      return kExitRejected;
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

struct SequenceCliOptions {
  std::string iface;
  int node = 0;
  int samples = 2000;
  double adc_lsb = 0.0;
  double rate_hz = 1000.0;
  std::vector<double> nominal_sf;
  double tolerance_g = 0.2;
  std::string poses;
  std::string layout = "auto";
  std::string output;
  std::string poses_out;
  std::string rate_table;  // a rate-table plan: location runs instead of poses
  bool auto_wait = false;
  int probe_samples = 200;
  double pose_timeout_s = 60.0;
  int retries = 3;
  int timeout_ms = 1000;
  std::string config;
  can::IdBases ids;
};

/// The whole file under a temporary name, then renamed over the target
/// (lnx::save_file_atomically: a reader (gfins-calibrate) never sees half a file, a failed run
/// leaves the previous one intact, a device node, FIFO or link at the path is refused and left
/// alone). Says what went wrong; false then.
bool write_output(const std::string& path, const std::string& text) {
  const Status saved = drivers::lnx::save_file_atomically(path, {text.data(), text.size()});
  if (saved.is_ok()) return true;
  std::fprintf(stderr, "gfins-can calibrate: %s\n",
               drivers::lnx::describe("'" + path + "'", saved).c_str());
  return false;
}

/// gfins-can calibrate --rate-table: one capture of whole revolutions per run of the plan, the
/// rows of gfins-calibrate --location-runs (docs/calibration.md, location runs).
int run_rate_table_sequence(const SequenceCliOptions& o, const SequenceOptions& so) {
  if (!o.poses.empty() || !o.poses_out.empty() || o.layout != "auto") {
    std::fprintf(stderr,
                 "gfins-can calibrate: --rate-table captures location runs; --poses, "
                 "--poses-out and --layout are for the orientation poses\n");
    return kExitUsage;
  }
  std::string text;
  const Status read =
      drivers::lnx::read_text_file(o.rate_table.c_str(), drivers::lnx::kMaxTableBytes, text);
  if (!read.is_ok()) {
    std::fprintf(stderr, "gfins-can calibrate: %s\n",
                 drivers::lnx::text_file_error(o.rate_table, read, drivers::lnx::kMaxTableBytes,
                                               "a rate-table plan")
                     .c_str());
    return kExitInput;
  }
  std::string error;
  const std::vector<RateTableRun> plan = rate_table_plan(text, error);
  if (plan.empty()) {
    std::fprintf(stderr, "gfins-can calibrate: %s: %s\n", o.rate_table.c_str(), error.c_str());
    return kExitUsage;
  }
  auto bus = open_live_bus(o.iface);
  if (!bus.is_ok()) {
    std::fprintf(stderr, "gfins-can calibrate: cannot open CAN interface '%s': %s\n",
                 o.iface.c_str(), bus.status().message());
    return kExitInput;
  }
  std::string csv = location_runs_header();
  std::uint8_t token = so.first_token;
  for (std::size_t i = 0; i < plan.size(); ++i) {
    const RateTableRun& run = plan[i];
    for (int attempt = 0;; ++attempt) {
      if (!o.auto_wait) {
        std::fprintf(stderr,
                     "%s run %zu of %zu: mounting %d, body axis (%+.3f, %+.3f, %+.3f) up on the "
                     "table, table at %g rad/s and steady, then press Enter (q Enter stops)\n",
                     attempt > 0 ? "REPEAT" : "next:", i + 1, plan.size(), run.mounting,
                     run.up_b[0], run.up_b[1], run.up_b[2], run.rate_rad_s);
        std::string line;
        if (!std::getline(std::cin, line) || line == "q") {
          std::fprintf(stderr, "gfins-can calibrate: stopped before run %zu\n", i + 1);
          return kExitTimeout;
        }
      }
      const RateTableCapture c = capture_rate_table_run(**bus, run, so, token);
      if (c.ok) {
        if (!c.note.empty()) std::fprintf(stderr, "note: %s\n", c.note.c_str());
        std::fprintf(stderr, "run %zu: captured %u samples (whole turns)\n", i + 1, c.samples);
        csv += c.row;
        break;
      }
      std::fprintf(stderr, "%s\n", c.error.c_str());
      if (attempt >= o.retries) {
        std::fprintf(stderr, "gfins-can calibrate: run %zu given up after %d attempts\n", i + 1,
                     attempt + 1);
        return kExitRejected;
      }
    }
  }
  if (!write_output(o.output, csv)) return kExitInput;
  std::fprintf(stderr, "gfins-can calibrate: wrote %s (%zu rate-table runs)\n", o.output.c_str(),
               plan.size());
  return kExitOk;
}

int run_calibrate_sequence(const SequenceCliOptions& o) {
  std::vector<PlanPose> plan = tables23_plan();
  if (!o.poses.empty()) {
    const auto rows = tools::read_poses(o.poses);
    if (!rows.is_ok()) {
      std::fprintf(stderr, "gfins-can calibrate: %s\n", rows.error().message.c_str());
      return kExitUsage;
    }
    std::vector<std::pair<int, std::array<double, 3>>> r;
    for (const auto& p : rows.value()) r.emplace_back(p.attitude, p.f_b_g);
    std::string error;
    plan = plan_from_rows(r, error);
    if (plan.empty()) {
      std::fprintf(stderr, "gfins-can calibrate: %s: %s\n", o.poses.c_str(), error.c_str());
      return kExitUsage;
    }
  }
  const bool paper = o.layout == "paper" || (o.layout == "auto" && o.poses.empty());
  if (paper && !o.poses.empty()) {
    std::fprintf(stderr,
                 "gfins-can calibrate: --layout paper is the Tables 2/3 plan's; with --poses the "
                 "means are written for every sensor (--layout all)\n");
    return kExitUsage;
  }
  SequenceOptions so;
  so.node_id = static_cast<std::uint8_t>(o.node);
  so.ids = o.ids;
  so.samples = static_cast<std::uint16_t>(o.samples);
  so.sample_rate_hz = o.rate_hz;
  so.adc_lsb_v = o.adc_lsb;
  if (o.nominal_sf.size() == 1) so.nominal_sf_v_per_g.fill(o.nominal_sf[0]);
  if (o.nominal_sf.size() == 6) std::copy_n(o.nominal_sf.begin(), 6, so.nominal_sf_v_per_g.begin());
  if (!o.nominal_sf.empty() && o.nominal_sf.size() != 1 && o.nominal_sf.size() != 6) {
    std::fprintf(stderr, "gfins-can calibrate: --nominal-sf takes 1 or 6 values (V/g)\n");
    return kExitUsage;
  }
  so.pose_tolerance_g = o.tolerance_g;
  so.wait = o.auto_wait ? WaitMode::kAuto : WaitMode::kHook;
  so.probe_samples = static_cast<std::uint16_t>(o.probe_samples);
  so.pose_timeout_s = o.pose_timeout_s;
  so.retries = o.retries;
  so.first_token = static_cast<std::uint8_t>(std::random_device{}() & 0xFFu);
  so.timeouts.response = std::chrono::milliseconds(o.timeout_ms);
  if (!o.rate_table.empty()) return run_rate_table_sequence(o, so);

  auto bus = open_live_bus(o.iface);
  if (!bus.is_ok()) {
    std::fprintf(stderr, "gfins-can calibrate: cannot open CAN interface '%s': %s\n",
                 o.iface.c_str(), bus.status().message());
    return kExitInput;
  }
  SequenceIo io;
  io.note = [](const std::string& s) { std::fprintf(stderr, "%s\n", s.c_str()); };
  io.await_pose = [](const PlanPose& p, std::size_t i, std::size_t n, bool repeat) {
    std::fprintf(stderr,
                 "%s pose %d (%s), %zu of %zu: turn the board so that it senses f = (%+.3f, "
                 "%+.3f, %+.3f) g (body axes; at rest f points up), keep it still, then press "
                 "Enter (q Enter stops)\n",
                 repeat ? "REPEAT" : "next:", p.attitude, p.label.c_str(), i + 1, n, p.f_b_g[0],
                 p.f_b_g[1], p.f_b_g[2]);
    std::string line;
    if (!std::getline(std::cin, line)) return false;
    return line != "q";
  };
  const SequenceResult r = run_capture_sequence(**bus, plan, so, io);
  if (!r.ok) {
    std::fprintf(stderr, "gfins-can calibrate: %s\n", r.error.c_str());
    return r.stop == SequenceResult::Stop::kRefused ? kExitRejected : kExitTimeout;
  }
  if (!write_output(o.output, means_csv(r.captures, o.adc_lsb, paper))) return kExitInput;
  std::fprintf(
      stderr, "gfins-can calibrate: wrote %s (%zu poses, %s layout, %d refused on the way)\n",
      o.output.c_str(), r.captures.size(), paper ? "paper Tables 4/5" : "all sensors", r.refused);
  if (!o.poses_out.empty()) {
    if (!write_output(o.poses_out, poses_csv(plan))) return kExitInput;
    std::fprintf(stderr, "gfins-can calibrate: wrote %s\n", o.poses_out.c_str());
  }
  return kExitOk;
}

int main_impl(int argc, char** argv) {
  CLI::App app{"gfins-can: decode, check and plot gfins CAN traffic; send commands to a board"};
  app.footer(kExitCodes);
  app.set_version_flag("--version", gfins::version::version_line("gfins-can"));
  app.require_subcommand(1);

  DecodeOptions d;
  // --id-base of every subcommand that takes --config: one subcommand runs, so one list.
  std::vector<std::string> id_base_moved;
  auto* dec = app.add_subcommand("decode", "decode candump logs ('-' = stdin) or a live interface");
  dec->add_option("sources", d.sources, "candump log files, '-' for stdin");
  dec->add_option("--iface", d.iface, "live SocketCAN interface (e.g. can0, vcan0)");
  dec->add_option("--view", d.view, "table | line | csv | json | none")->capture_default_str();
  dec->add_option("-o,--output", d.output, "write the view here instead of stdout");
  dec->add_option("--node", d.node, "show only this node id (0..15)")->check(CLI::Range(0, 15));
  dec->add_option("--max-issues", d.max_issues, "problems printed per kind (all are counted)")
      ->capture_default_str();
  dec->add_option("--duration", d.duration_s, "live: stop after this many seconds");
  add_id_base_option(dec, id_base_moved);
  dec->add_option("--config", d.config,
                  "a gfins-fw configuration file: the identifier groups (can.*_id_base) of the "
                  "boards on the bus");
  dec->add_flag("-q,--quiet", d.quiet, "do not print each problem, only the summary");

  std::string plot_log, plot_png, plot_script;
  int plot_node = -1;
  auto* plot = app.add_subcommand("plot", "plot attitude, rate, velocity, position of a log (PNG)");
  plot->add_option("log", plot_log, "candump log")->required();
  plot->add_option("-o,--output", plot_png, "PNG to write")->required();
  plot->add_option("--node", plot_node, "node id to plot (default: all)")->check(CLI::Range(0, 15));
  plot->add_option("--script", plot_script, "plot script (default: the installed plot_can.py)");
  std::string plot_config;
  add_id_base_option(plot, id_base_moved);
  plot->add_option("--config", plot_config,
                   "a gfins-fw configuration file: the identifier groups (can.*_id_base) of the "
                   "boards in the log");

  CmdOptions co;
  auto* cmd = app.add_subcommand("cmd", "send one command and wait for its response");
  cmd->add_option("--iface", co.iface, "SocketCAN interface")->required();
  cmd->add_option("--node", co.node, "node id of the board")->check(CLI::Range(0, 15));
  cmd->add_option("--timeout-ms", co.timeout_ms, "response timeout, ms")
      ->check(CLI::Range(1, kMaxTimeoutMs))
      ->capture_default_str();
  cmd->add_option("--token", co.token, "token (default: random)")->check(CLI::Range(0, 255));
  cmd->add_option("--sequence", co.sequence,
                  "sequence number of a configuration-changing command (default: the board's "
                  "last one, read first with ReportCalibrationId, plus 1)")
      ->check(CLI::Range(1, 65535));
  add_id_base_option(cmd, id_base_moved);
  cmd->add_option("--config", co.config,
                  "the board's gfins-fw configuration file: its identifier groups "
                  "(can.*_id_base) and, unless --node is given, its can.node_id");
  cmd->add_option("--rate", co.rate_hz,
                  "the board's sample rate, Hz (capture: wait N / rate + 5 s for the result)")
      ->check(CLI::Range(1.0, 100000.0))
      ->capture_default_str();
  cmd->require_subcommand(1);
  can::Command c;
  double heading_deg = 0;
  auto* realign = cmd->add_subcommand("realign", "re-align with the given heading");
  realign->add_option("--heading-deg", heading_deg, "heading, degrees in [-360, 360]")
      ->required()
      ->check(heading_deg_check());
  bool realign_force = false;
  realign->add_flag("--force", realign_force,
                    "carry it out even while the board moves (refused while moving otherwise)");
  auto* reset = cmd->add_subcommand("reset", "reset navigation");
  bool reset_force = false;
  reset->add_flag("--force", reset_force,
                  "carry it out even while the board moves (refused while moving otherwise)");
  std::string comp;
  auto* compensator = cmd->add_subcommand("compensator", "switch compensator");
  compensator->add_option("kind", comp, "none | paper | exact")
      ->required()
      ->check(CLI::IsMember({"none", "paper", "exact"}));
  std::string div_msg;
  int divider = 0;
  auto* div = cmd->add_subcommand("divider", "set the output divider of a message");
  // GfinsStatus is not offered: its divider follows GfinsEpoch's (the board refuses it alone,
  // docs/can-interface.md, "Rates, dividers and bus load").
  std::vector<std::string> data_names;
  for (const auto& m : can::kMessages) {
    if (m.kind == can::MessageKind::kData && m.id != can::MessageId::kStatus) {
      data_names.emplace_back(m.name);
    }
  }
  div->add_option("message", div_msg,
                  "message name (GfinsQuaternion, ...; GfinsStatus follows GfinsEpoch)")
      ->required()
      ->check(CLI::IsMember(data_names));
  div->add_option("divider", divider, "divider of the sample rate, 0 = off")
      ->required()
      ->check(CLI::Range(0, int{can::kMaxDivider}));
  auto* calid = cmd->add_subcommand("cal-id", "report the calibration identity");
  int pose = 0, samples = 0;
  auto* capture = cmd->add_subcommand("capture", "start a calibration capture for pose k");
  capture->add_option("--pose", pose, "pose index k")->required()->check(CLI::Range(0, 63));
  capture->add_option("--samples", samples, "N samples")->required()->check(CLI::Range(1, 65535));
  auto* reload = cmd->add_subcommand("reload", "reload the calibration file");
  bool reload_force = false;
  reload->add_flag("--force", reload_force,
                   "take the file even when its device_id is not the one of the calibration in "
                   "use (refused as OtherDevice otherwise)");
  int new_node = 0;
  auto* node_id = cmd->add_subcommand(
      "node-id", "set the node id the board takes at its next start (kept across restarts)");
  node_id->add_option("id", new_node, "node id 0..15")->required()->check(CLI::Range(0, 15));
  std::string id_group_name;
  std::string new_base_text;
  auto* id_base = cmd->add_subcommand(
      "id-base",
      "move an identifier group from the board's next start (kept across restarts; refused when "
      "it would overlap another group or can.reserved_ids)");
  id_base->add_option("group", id_group_name, "data | input | command | response")
      ->required()
      ->check(CLI::IsMember({"data", "input", "command", "response"}));
  // Hexadecimal with its 0x, as candump and the ICD write identifiers: a bare "300" would be
  // decimal to strtoll and "0300" octal, and a base that collides with nothing is accepted and
  // taken at the next start.
  id_base
      ->add_option("base", new_base_text,
                   "the group's first identifier, 0x000..0x7FF (hexadecimal, with 0x)")
      ->required()
      ->check(CLI::Validator(
          [](const std::string& t) -> std::string {
            const std::string p = hex_id_problem(t);
            return p.empty() ? p
                             : p + " (as candump writes it without), not " +
                                   app::quote_text(t).substr(0, 40);
          },
          "0x000..0x7FF"));
  auto* restore = cmd->add_subcommand(
      "restore-defaults",
      "forget the settings kept across restarts: the configuration's dividers at once, its node "
      "id from the next start");

  SequenceCliOptions so;
  auto* calibrate = app.add_subcommand(
      "calibrate",
      "orientation calibration through the firmware: capture every pose of a plan (Tables 2/3, "
      "or --poses), refuse poses that moved, saturated or are not the expected one, write the "
      "means CSV of gfins-calibrate (docs/calibration.md)");
  calibrate->add_option("--iface", so.iface, "SocketCAN interface")->required();
  calibrate->add_option("--node", so.node, "node id of the board")->check(CLI::Range(0, 15));
  calibrate->add_option("--adc-lsb", so.adc_lsb, "ADC LSB at the sensor, V/count")
      ->required()
      ->check(CLI::Range(1e-12, 1.0));
  calibrate->add_option("--samples", so.samples, "N samples per pose")
      ->check(CLI::Range(2, 65535))
      ->capture_default_str();
  calibrate->add_option("--rate", so.rate_hz, "the board's sample rate, Hz")
      ->check(CLI::Range(1.0, 100000.0))
      ->capture_default_str();
  calibrate->add_option("--nominal-sf", so.nominal_sf,
                        "nominal scale factor(s), V/g, 1 or 6 values (default 1.33)");
  calibrate
      ->add_option("--tolerance-g", so.tolerance_g,
                   "largest difference of a channel from the pose's expected output, g")
      ->check(CLI::Range(0.01, 0.5))
      ->capture_default_str();
  calibrate
      ->add_option("--poses", so.poses,
                   "plan: CSV attitude,fx_g,fy_g,fz_g (default: the 12 poses of Tables 2/3)")
      ->check(CLI::ExistingFile);
  calibrate
      ->add_option("--layout", so.layout,
                   "paper (Tables 4/5: each sensor in its table's poses; default for the "
                   "Tables 2/3 plan) or all (every sensor in every pose, with --poses-out)")
      ->check(CLI::IsMember({"auto", "paper", "all"}));
  calibrate->add_option("-o,--output", so.output, "means CSV to write")->required();
  calibrate->add_option("--poses-out", so.poses_out, "also write the plan as a poses CSV");
  calibrate
      ->add_option("--rate-table", so.rate_table,
                   "location runs instead of poses: plan CSV mounting,axis_x,axis_y,axis_z,"
                   "rate_rad_s (body axis up, table rate); -o gets the rows of gfins-calibrate "
                   "--location-runs, each a capture of the whole turns nearest --samples")
      ->check(CLI::ExistingFile);
  calibrate->add_flag("--auto", so.auto_wait,
                      "do not prompt: probe until the board is still in the expected pose "
                      "(index table, simulated board)");
  calibrate->add_option("--probe-samples", so.probe_samples, "--auto: samples per probe")
      ->check(CLI::Range(2, 65535))
      ->capture_default_str();
  calibrate
      ->add_option("--pose-timeout-s", so.pose_timeout_s,
                   "--auto: give up on a pose after probing this long")
      ->check(CLI::Range(0.1, 86400.0))
      ->capture_default_str();
  calibrate->add_option("--retries", so.retries, "refused captures of a pose before giving up")
      ->check(CLI::Range(0, 100))
      ->capture_default_str();
  add_id_base_option(calibrate, id_base_moved);
  calibrate->add_option("--config", so.config,
                        "the board's gfins-fw configuration file: its identifier groups "
                        "(can.*_id_base) and, unless --node is given, its can.node_id");
  calibrate->add_option("--timeout-ms", so.timeout_ms, "response timeout, ms")
      ->check(CLI::Range(1, kMaxTimeoutMs))
      ->capture_default_str();

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
  hil->add_option("--drop-frame", ho.drop_frame,
                  "test: leave aiding frame N off the link (the host-only run applies it)")
      ->check(CLI::NonNegativeNumber);
#endif

  GnssOptions go;
  auto* gnss = app.add_subcommand(
      "gnss",
      "play a scenario's simulated GNSS receiver ([gnss] table) as GNSS input frames: a candump "
      "log, or onto a live bus at the fixes' times");
  gnss->add_option("scenario", go.scenario, "a scenario name or .toml with a [gnss] table")
      ->required();
  gnss->add_option("--scenario-dir", go.scenario_dir, "folder of the named scenarios");
  gnss->add_option("-o,--output", go.output, "candump log to write (default stdout)");
  gnss->add_option("--iface", go.iface, "send on this SocketCAN interface instead, in real time");
  gnss->add_option("--node", go.node, "node id of the board to aid")->check(CLI::Range(0, 15));
  gnss->add_option("--duration", go.duration_s, "seconds of fixes (0 = the scenario's duration)")
      ->check(CLI::Range(0.0, 86400.0));
  add_id_base_option(gnss, id_base_moved);
  gnss->add_option("--config", go.config,
                   "the aided board's gfins-fw configuration file: its identifier groups "
                   "(can.*_id_base) and, unless --node is given, its can.node_id");
  gnss->add_option("--log-start", go.log_start_s,
                   "log time of scenario time 0, s (default 1700000000, the epoch of every "
                   "simulated log)")
      ->check(CLI::Range(0.0, 4.0e9));

  std::uint8_t dbc_node = can::kDefaultNodeId;
  std::string dbc_out;
  auto* dbc = app.add_subcommand("dbc", "print the DBC generated from the message table");
  dbc->add_option("--node", dbc_node, "node id (default 1, a stock board)")
      ->check(CLI::Range(0, 15));
  dbc->add_option("-o,--output", dbc_out, "write here instead of stdout");
  std::string dbc_config;
  add_id_base_option(dbc, id_base_moved);
  dbc->add_option(
      "--config", dbc_config,
      "a gfins-fw configuration file: the DBC of that board (its can.node_id unless --node "
      "is given; identifiers from its can.*_id_base; cycle times from its adc.sample_rate_hz and "
      "[output] dividers)");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);
    return rc == 0 ? kExitOk : kExitUsage;
  }

  if (dec->parsed()) {
    int unused_node = 0;
    if (!board_from_config("decode", dec, d.config, id_base_moved, true, unused_node, d.ids))
      return kExitInput;
    return run_decode(d);
  }
  if (calibrate->parsed()) {
    if (!board_from_config("calibrate", calibrate, so.config, id_base_moved,
                           calibrate->count("--node") != 0, so.node, so.ids)) {
      return kExitInput;
    }
    return run_calibrate_sequence(so);
  }
#if GFINS_CAN_HAVE_HIL
  if (hil->parsed()) return run_hil(ho, std::cout, std::cerr);
#endif
  if (plot->parsed()) {
    int unused_node = 0;
    can::IdBases plot_ids;
    if (!board_from_config("plot", plot, plot_config, id_base_moved, true, unused_node, plot_ids))
      return kExitInput;
    return run_plot(plot_log, plot_png, plot_node, plot_script, plot_ids);
  }
  if (gnss->parsed()) {
    if (!board_from_config("gnss", gnss, go.config, id_base_moved, gnss->count("--node") != 0,
                           go.node, go.ids)) {
      return kExitInput;
    }
    return run_gnss(go);
  }
  if (dbc->parsed()) {
    // The configuration first: a file that does not load leaves the output untouched.
    DbcRates rates;
    can::IdBases dbc_ids;
    int node = dbc_node;
    std::optional<app::FwConfig> loaded;
    if (!board_from_config("dbc", dbc, dbc_config, id_base_moved, dbc->count("--node") != 0, node,
                           dbc_ids, &loaded)) {
      return kExitInput;
    }
    dbc_node = static_cast<std::uint8_t>(node);  // 0..15: --node's range or the file's checked one
    if (loaded) {
      rates.sample_rate_hz = loaded->sample_rate_hz;
      rates.dividers = app::bus_dividers(*loaded);
    }
    std::FILE* out = open_output(dbc_out);
    if (out == nullptr) {
      std::fprintf(stderr, "gfins-can: cannot create '%s': %s\n", dbc_out.c_str(),
                   std::strerror(errno));
      return kExitInput;
    }
    const std::string text = generate_dbc(dbc_node, rates, dbc_ids);
    const bool written = std::fwrite(text.data(), 1, text.size(), out) == text.size();
    return close_output(out, dbc_out) && written ? kExitOk : kExitInput;
  }
  if (realign->parsed()) {
    c.opcode = can::Opcode::kRealign;
    c.heading_rad =
        static_cast<float>(std::remainder(heading_deg, 360.0) * std::numbers::pi / 180.0);
    c.forced = realign_force;
  } else if (reset->parsed()) {
    c.opcode = can::Opcode::kResetNavigation;
    c.forced = reset_force;
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
    c.forced = reload_force;
  } else if (node_id->parsed()) {
    c.opcode = can::Opcode::kSetNodeId;
    c.node_id = static_cast<std::uint8_t>(new_node);
  } else if (id_base->parsed()) {
    c.opcode = can::Opcode::kSetIdBase;
    c.id_group = static_cast<can::IdGroup>(id_group_index(id_group_name));
    const std::optional<std::uint16_t> base = hex_id_value(new_base_text);
    if (!base) {  // the option's validator refuses it first
      std::fprintf(stderr, "gfins-can cmd id-base: BASE must be %s\n",
                   hex_id_problem(new_base_text).c_str());
      return kExitUsage;
    }
    c.id_base = *base;
  } else if (restore->parsed()) {
    c.opcode = can::Opcode::kRestoreDefaults;
  }
  if (!board_from_config("cmd", cmd, co.config, id_base_moved, cmd->count("--node") != 0, co.node,
                         co.ids)) {
    return kExitInput;
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
