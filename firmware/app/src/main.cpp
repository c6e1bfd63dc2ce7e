// gfins-fw: configuration → calibration → ADC start → static alignment → navigation, on the
// Linux board or on the simulated board (docs/firmware.md).
#include <spdlog/spdlog.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <exception>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include "gfins/app/board.hpp"
#include "gfins/app/can_settings.hpp"
#include "gfins/app/config.hpp"
#include "gfins/app/logger.hpp"
#include "gfins/app/publisher_sink.hpp"
#include "gfins/app/recorder.hpp"
#include "gfins/app/sample_loop.hpp"
#include "gfins/app/service_status.hpp"
#include "gfins/app/startup.hpp"

namespace {

std::atomic<bool> g_stop{false};

extern "C" void on_signal(int) { g_stop.store(true); }

// Writes text whole, NULs and all (fputs would stop at the first), with control characters
// escaped: a message may quote user input. Nothing to do if printing fails: the exit code
// carries the outcome.
void print(std::FILE* to, const std::string& text) {
  const std::string safe = gfins::app::printable_text(text);
  (void)std::fwrite(safe.data(), 1, safe.size(), to);
}

struct FileCloser {
  void operator()(std::FILE* f) const { (void)std::fclose(f); }
};

/// Resident memory of this process in KiB (VmRSS of /proc/self/status), -1 where there is none.
long resident_kib() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("VmRSS:", 0) == 0) return std::strtol(line.c_str() + 6, nullptr, 10);
  }
  return -1;
}

int run(const gfins::app::BoardTable& boards, gfins::app::FwConfig cfg,
        const std::string& latency_csv) {
  using namespace gfins::app;
  gfins::app::init_spdlog(cfg.log_level);
  // Settings changed over CAN by an earlier run replace the configuration's node id and dividers
  // (RestoreDefaults returns to the configuration's). Checked by the configuration's rules; a
  // file that is not right is ignored and the bus says so (SettingsSource).
  const std::array<std::uint16_t, kNumMessages> config_dividers = cfg.dividers;
  const auto config_node_id = static_cast<std::uint8_t>(cfg.node_id);
  const gfins::can::IdBases config_ids = id_bases(cfg);
  const StartupSettings stored = load_stored_settings(cfg);
  if (stored.source == SettingsSource::kStoredCorrupt) {
    spdlog::error("{}", printable_text(stored.message));
  } else if (!stored.message.empty()) {
    spdlog::info("{}", printable_text(stored.message));
  }
  std::unique_ptr<SettingsWriter> settings_writer;
  if (!cfg.can_settings_file.empty()) {
    settings_writer = std::make_unique<SettingsWriter>(cfg.can_settings_file, stored.source);
  }
  spdlog::info("gfins-fw: board {}, {} Hz, node {}, compensator {}", to_string(cfg.board),
               cfg.sample_rate_hz, cfg.node_id, to_string(cfg.compensator));

  // Output files are opened before any work: a run never ends with "cannot write" (the CAN log
  // is opened with the board below, also before the loop).
  std::unique_ptr<std::FILE, FileCloser> latency_file;
  if (!latency_csv.empty()) {
    latency_file.reset(std::fopen(latency_csv.c_str(), "w"));
    if (!latency_file) {
      spdlog::critical("--latency-csv {}: cannot be created: {}", quote_text(latency_csv),
                       std::strerror(errno));
      return 1;
    }
  }

  BoardResult made = make_board(boards, cfg);
  if (!made.board) {
    spdlog::critical("board set-up failed: {}", printable_text(made.error));
    return 1;
  }
  Board& board = *made.board;

  const StartupCalibration cal =
      load_calibration(cfg, board.defaults, board.factory ? &*board.factory : nullptr);
  if (cal.from_file) {
    spdlog::info("{}", printable_text(cal.message));
  } else {
    spdlog::warn("**************************************************************************");
    spdlog::warn("{}", printable_text(cal.message));
    spdlog::warn("**************************************************************************");
  }

  auto log_queue = std::make_unique<FwLogQueue>();
  LogDrain drain(*log_queue);
  drain.start();
  ReloadWorker reload(calibration_reloader(cfg, converter_lsb(board.defaults), cal.device_id));

  // The recorder (record.file): its header says how the samples were made (rate, the chain's
  // LSB, the configured nominal geometry); opened before the loop, as every output is.
  std::unique_ptr<Recorder> recorder;
  if (!cfg.record_file.empty()) {
    gfins::recording::Header h;
    h.sample_rate_hz = cfg.sample_rate_hz;
    h.volts_per_count.fill(board.source->volts_per_count());
    h.geometry = cal.set.config.nominal.cast<double>();
    Recorder::Opened opened = Recorder::open(cfg.record_file, h);
    if (!opened.recorder) {
      spdlog::critical("record.file {}: {}", quote_text(cfg.record_file),
                       printable_text(opened.error));
      return 1;
    }
    recorder = std::move(opened.recorder);
    recorder->start();
  }

  auto loop = std::make_unique<SampleLoop>(*board.source, *board.bus, *board.sink, *board.clock,
                                           *log_queue);
  // The simulated board in fast pacing keeps no real time: it waits for the recorder's writer
  // rather than lose records when the machine is busy.
  if (recorder) {
    loop->set_recorder(&recorder->queue(),
                       cfg.board == BoardKind::kSim && cfg.pacing == Pacing::kFast);
  }
  loop->set_commands(board.commands);
  loop->set_watchdog(board.watchdog.get());
  loop->set_reload_worker(&reload);
  loop->set_settings_port(settings_writer.get());
  // The service status line (systemd STATUS=): the loop leaves its mode and health counters on
  // the board each cycle; the reporter thread formats and sends them, never the loop.
  StatusBoard status_board;
  loop->set_status_board(&status_board);
  std::unique_ptr<StatusReporter> status_reporter;
  if (board.watchdog) {
    status_reporter =
        std::make_unique<StatusReporter>(*board.watchdog, status_board, cfg.sample_rate_hz);
  }
  LoopOptions options = loop_options(cfg);
  options.stored = stored.stored;
  options.config_dividers = config_dividers;
  options.config_node_id = config_node_id;
  options.config_ids = config_ids;
  if (const gfins::Status s = loop->configure(cal.set, options); !s.is_ok()) {
    spdlog::critical("navigation core rejected the configuration: {}", s.message());
    return 1;
  }
  // Every helper thread (log drain, reload worker, status reporter) starts before the loop's
  // thread takes SCHED_FIFO: a thread inherits its creator's policy, and none of them may
  // compete with the loop at its priority (the virtual board's check fw-realtime asserts it).
  if (status_reporter) status_reporter->start();
  if (const std::string warn = board.enter_realtime(cfg); !warn.empty()) spdlog::warn("{}", warn);
  if (board.watchdog) (void)board.watchdog->notify_ready();
  spdlog::info("sample loop running (alignment: keep the board still for {} s)", cfg.alignment_s);

  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  // Resident memory at the loop's start and end: a loop that allocates nothing keeps it flat
  // (the soak test bounds the difference over a simulated hour).
  const long rss0_kib = resident_kib();
  const std::clock_t cpu0 = std::clock();
  const auto wall0 = std::chrono::steady_clock::now();
  // A board with a known end (the simulated board, fast) reports how far it got: a line every
  // interval of wall-clock time, looked at every 4096 cycles (a clock read per cycle would cost
  // the loop more than the line is worth).
  const auto interval = std::chrono::duration<double>(board.progress_interval_s);
  auto next = wall0 + interval;
  for (std::uint32_t n = 1; !g_stop.load(std::memory_order_relaxed) && !board.finished(); ++n) {
    loop->step();
    if (!board.progress || (n & 4095U) != 0 || std::chrono::steady_clock::now() < next) continue;
    next += interval;
    const BoardProgress p = board.progress();
    spdlog::info("progress: {:.0f} % (t = {:.1f} of {:.1f} s of the scenario)", 100.0 * p.fraction,
                 p.fraction * p.duration_s, p.duration_s);
  }
  const double cpu_s = static_cast<double>(std::clock() - cpu0) / CLOCKS_PER_SEC;
  const long rss1_kib = resident_kib();
  const double wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();

  // A settings change the writer could not take in the loop's last cycle is handed over now;
  // the writer saves it before it stops.
  loop->flush_settings();
  if (status_reporter) {
    status_reporter->stop();
    (void)board.watchdog->notify_status("stopping");
  }
  drain.stop();
  const HealthCounters& h = loop->health();
  const auto& st = loop->pipeline().state();
  spdlog::info("stopped after {} samples; mode {}, calibration id {:08x}{}", h.samples,
               static_cast<int>(loop->mode()), loop->cal_id(),
               loop->calibrated() ? "" : " (UNCALIBRATED)");
  spdlog::info(
      "health: missed edges {}, extra edges {}, data-ready timeouts {}, CRC errors {}, "
      "ADC resets {}, saturated {}, stuck events {} (mask {:#x}), CAN dropped {}, "
      "bus-off {}, overruns {}, log dropped {}",
      h.missed_edges, h.extra_edges, h.drdy_timeouts, h.crc_errors, h.adc_resets,
      h.saturated_samples, h.stuck_events, h.stuck_mask, h.can_tx_dropped, h.bus_off_events,
      h.loop_overruns, h.log_dropped);
  spdlog::info("memory: resident {} KiB at the loop's start, {} KiB at its end", rss0_kib,
               rss1_kib);
  spdlog::info(
      "final state t {:.3f} s: v_n [{:.4f} {:.4f} {:.4f}] m/s, r_n [{:.4f} {:.4f} {:.4f}] m",
      static_cast<double>(st.t_ns) * 1e-9, st.v_n.x(), st.v_n.y(), st.v_n.z(), st.r_n.x(),
      st.r_n.y(), st.r_n.z());
  // Latency and CPU use mean something only against the wall clock (not in fast pacing).
  if (loop->latency().count() > 0 && cfg.board != BoardKind::kHil &&
      !(cfg.board == BoardKind::kSim && cfg.pacing == Pacing::kFast)) {
    spdlog::info("latency edge → CAN: p50 {} µs, p99 {} µs, max {:.1f} µs over {} epochs",
                 loop->latency().quantile_us(0.5), loop->latency().quantile_us(0.99),
                 static_cast<double>(loop->latency().max_ns()) * 1e-3, loop->latency().count());
    spdlog::info(
        "CPU use {:.2f} % of one core over {:.1f} s ({:.3f} s of CPU; the whole process, "
        "including on the simulated board its sensor and chip models)",
        100.0 * cpu_s / wall_s, wall_s, cpu_s);
  }
  int status = 0;
  if (latency_file) {
    std::FILE* f = latency_file.get();
    bool ok = std::fprintf(f, "latency_us,count\n") > 0;
    for (std::size_t b = 0; b < LatencyHistogram::kBins; ++b) {
      if (loop->latency().bin(b) != 0) {
        ok = std::fprintf(f, "%zu,%u\n", b, loop->latency().bin(b)) > 0 && ok;
      }
    }
    if (std::fclose(latency_file.release()) != 0 || !ok) {
      spdlog::error("--latency-csv {}: write error: {}", quote_text(latency_csv),
                    std::strerror(errno));
      status = 1;
    }
  }
  if (recorder) {
    if (const std::string e = recorder->stop(); !e.empty()) {
      spdlog::error("record.file {}: {}", quote_text(cfg.record_file), printable_text(e));
      status = 1;
    } else {
      spdlog::info("recorded {} records ({} samples and the frames received) to {}",
                   recorder->records_written(), h.samples, quote_text(cfg.record_file));
    }
  }
  board.close();
  // A CAN log that lost frames is a failed run: its file is not the run's output (a log on a
  // full disk, /dev/full, must not end with exit 0 and every frame dropped).
  if (const std::string lost = board.finish_output(); !lost.empty()) {
    spdlog::error("{}", lost);
    status = 1;
  }
  return status;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const gfins::app::CliResult cli = gfins::app::parse_command_line(argc, argv);
    if (!cli.config) {
      print(cli.exit_code == 0 ? stdout : stderr, cli.message);
      return cli.exit_code;
    }
    // The boards this build runs on: the firmware's own and the plug-ins linked in.
    gfins::app::BoardTable boards;
    gfins::app::add_firmware_boards(boards);
    gfins::app::add_plugin_boards(boards);
    // The same checks before a run and for --check-config: what one accepts the other does.
    if (std::string problem =
            gfins::app::preflight(*cli.config, boards, cli.origin, cli.latency_csv);
        !problem.empty()) {
      print(stderr, "gfins-fw: " + problem + "\n");
      return 2;
    }
    if (cli.check_only) {
      print(stdout, "gfins-fw: configuration (" + cli.origin + ") is valid\n");
      char load[160];
      std::snprintf(load, sizeof load,
                    "gfins-fw: worst-case bus load %.2f %% of %d bit/s (limit %g %%)\n",
                    100.0 * gfins::app::worst_case_bus_load(*cli.config), cli.config->can_bit_rate,
                    cli.config->max_bus_load_percent);
      print(stdout, load);
      if (const std::string note = gfins::app::calibration_note(*cli.config); !note.empty()) {
        print(stdout, "gfins-fw: note: " + note + "\n");
      }
      gfins::app::FwConfig with_stored = *cli.config;
      if (const auto stored = gfins::app::load_stored_settings(with_stored);
          !stored.message.empty()) {
        print(stdout, "gfins-fw: note: " + stored.message + "\n");
      }
      return 0;
    }
    return run(boards, *cli.config, cli.latency_csv);
  } catch (const std::exception& e) {
    print(stderr, std::string("gfins-fw: ") + e.what() + "\n");
    return 1;
  }
}
