// gfins-fw command line (CLI11): a configuration file, then overrides of its keys. The help text
// names the configuration key each option overrides.
#include <CLI/CLI.hpp>

#include <sstream>

#include "gfins/app/config.hpp"
#include "gfins/drivers/lnx/output_paths.hpp"
#include "gfins/version/version.hpp"

namespace gfins::app {
namespace {

template <typename E, std::size_t N>
E pick(const std::string& s, const std::array<const char*, N>& names,
       const std::array<E, N>& values) {
  for (std::size_t i = 0; i < N; ++i) {
    if (s == names[i]) return values[i];
  }
  return values[0];  // unreachable: CLI::IsMember checked the text
}

}  // namespace

CliResult parse_command_line(int argc, const char* const* argv) {
  CliResult out;
  CLI::App app{
      "gfins-fw: the gyro-free INS firmware. Reads the ADC on every data-ready edge, navigates and "
      "publishes on CAN; --sim runs the same program on the simulated board.",
      "gfins-fw"};
  std::string config_file, board, spi, chip, line, can_if, can_log, compensator, calib, gravity,
      watchdog, wd_device, level, scenario, scenario_dir, pacing, hil_address, hil_port_file,
      record, replay, settings_file;
  int hil_port = 0;
  double rate = 0, g = 0, lat = 0, height = 0, heading = 0, align = 0, duration = 0;
  std::vector<double> position;
  std::vector<std::string> dividers;
  int node = 0, prio = 0;
  bool no_mlock = false, print_default = false, aiding = false;

  auto* o_config =
      app.add_option("-c,--config", config_file, "configuration file (TOML); default: built-in")
          ->check(CLI::ExistingFile);
  auto* o_sim = app.add_option("--sim", scenario,
                               "run on the simulated board with this scenario (name or .toml; "
                               "sets board.kind = \"sim\" and sim.scenario)");
  auto* o_replay =
      app.add_option("--replay", replay,
                     "replay a raw-sample recording (.gfr, e.g. one of --record) through the same "
                     "loop on the simulated board (sets board.kind = \"sim\" and sim.recording)")
          ->excludes(o_sim);
  auto* o_record = app.add_option("--record", record,
                                  "record.file: every sample and received CAN frame, for --replay");
  auto* o_board =
      app.add_option("--board", board, "board.kind")->check(CLI::IsMember({"linux", "sim", "hil"}));
  auto* o_hil_addr = app.add_option("--hil-address", hil_address, "hil.address");
  auto* o_hil_port = app.add_option("--hil-port", hil_port, "hil.port (0: ephemeral)")
                         ->check(CLI::Range(0, 65535));
  auto* o_hil_file = app.add_option("--hil-port-file", hil_port_file, "hil.port_file");
  auto* o_spi = app.add_option("--spi-device", spi, "adc.spi_device");
  auto* o_chip = app.add_option("--gpio-chip", chip, "adc.gpio_chip");
  auto* o_line = app.add_option("--drdy-line", line, "adc.drdy_line (offset or name)");
  auto* o_rate = app.add_option("--sample-rate", rate, "adc.sample_rate_hz");
  auto* o_can = app.add_option("--can", can_if, "can.interface");
  auto* o_log =
      app.add_option("--can-log", can_log, "can.log_file (candump log instead of an interface)");
  auto* o_node = app.add_option("--node-id", node, "can.node_id");
  auto* o_settings = app.add_option(
      "--settings-file", settings_file,
      "can.settings_file: where settings changed over CAN are kept (\"\" = not kept)");
  auto* o_div = app.add_option("--divider", dividers,
                               "output.NAME = N (repeatable), NAME a message of [output]: epoch "
                               "status quaternion euler rate angular_accel accel velocity "
                               "position_ne position_d health_adc health_system sensors_a "
                               "sensors_b");
  auto* o_comp = app.add_option("--compensator", compensator, "navigation.compensator")
                     ->check(CLI::IsMember({"calibration", "none", "paper", "exact"}));
  auto* o_cal = app.add_option("--calibration", calib, "calibration.file");
  auto* o_grav = app.add_option("--gravity", gravity, "navigation.gravity")
                     ->check(CLI::IsMember({"calibration", "standard", "constant", "normal"}));
  auto* o_g = app.add_option("--gravity-mps2", g, "navigation.gravity_mps2");
  auto* o_lat = app.add_option("--latitude-deg", lat, "navigation.latitude_deg");
  auto* o_h = app.add_option("--height-m", height, "navigation.height_m");
  auto* o_head = app.add_option("--heading-deg", heading, "navigation.heading_deg");
  auto* o_pos = app.add_option("--position-m", position, "navigation.position_m (3 numbers, NED)")
                    ->expected(3)
                    ->delimiter(',');
  auto* o_align = app.add_option("--alignment-s", align, "navigation.alignment_s");
  auto* o_prio = app.add_option("--rt-priority", prio, "realtime.priority (0 = no SCHED_FIFO)");
  app.add_flag("--no-mlock", no_mlock, "realtime.lock_memory = false");
  app.add_flag("--aiding", aiding, "aiding.enabled = true (standstill updates, filter accuracy)");
  auto* o_wd = app.add_option("--watchdog", watchdog, "watchdog.kind")
                   ->check(CLI::IsMember({"none", "systemd", "device"}));
  auto* o_wdd = app.add_option("--watchdog-device", wd_device, "watchdog.device");
  auto* o_level = app.add_option("--log-level", level, "log.level");
  auto* o_pacing = app.add_option("--pacing", pacing, "sim.pacing")
                       ->check(CLI::IsMember({"fast", "realtime", "gpio"}));
  auto* o_dur = app.add_option("--duration", duration, "sim.duration_s (0 = the scenario's)");
  auto* o_sdir = app.add_option("--scenario-dir", scenario_dir, "sim.scenario_dir");
  auto* o_check = app.add_flag("--check-config", out.check_only,
                               "validate the configuration (values, scenario, output folders) "
                               "and exit");
  auto* o_latency =
      app.add_option("--latency-csv", out.latency_csv,
                     "benchmark: write the data-ready → CAN latency histogram (us,count) here");
  app.add_flag("--print-default-config", print_default, "print the commented default and exit");

  app.footer(
      "Exit codes: 0 stopped normally (end of a --sim run, SIGINT/SIGTERM), or --help, --version, "
      "--print-default-config, --check-config done; 1 the board could not be set up or the run "
      "failed; 2 command line or configuration rejected.\n"
      "Environment: GFINS_SCENARIO_DIR (the built-in scenarios of --sim; default "
      "../share/gfins/scenarios, then ../share/gfins-fw/scenarios next to this program).");
  app.set_version_flag("--version", version::version_line("gfins-fw"));
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    std::ostringstream o, err;
    // CLI11's own codes (100+) become the documented 2; --help and --version stay 0.
    out.exit_code = app.exit(e, o, err) == 0 ? 0 : 2;
    out.message = o.str() + err.str();
    return out;
  }
  if (print_default) {
    out.message = default_config_text();
    return out;
  }

  FwConfig c;
  if (!config_file.empty()) {
    ConfigResult r = load_config(config_file);
    if (!r.ok()) {
      out.exit_code = 2;
      out.message = "gfins-fw: " + r.error + "\n";
      return out;
    }
    c = *r.config;
    out.config_source = config_file;
  }

  if (o_board->count()) {
    c.board =
        board == "sim" ? BoardKind::kSim : (board == "hil" ? BoardKind::kHil : BoardKind::kLinux);
  }
  if (o_hil_addr->count()) c.hil_address = hil_address;
  if (o_hil_port->count()) c.hil_port = hil_port;
  if (o_hil_file->count()) c.hil_port_file = hil_port_file;
  if (o_sim->count()) {
    c.board = BoardKind::kSim;
    c.sim_scenario = scenario;
    c.sim_recording.clear();
  }
  if (o_replay->count()) {
    c.board = BoardKind::kSim;
    c.sim_recording = replay;
  }
  if (o_record->count()) c.record_file = record;
  if (o_spi->count()) c.spi_device = spi;
  if (o_chip->count()) c.gpio_chip = chip;
  if (o_line->count()) c.drdy_line = line;
  if (o_rate->count()) c.sample_rate_hz = rate;
  if (o_can->count()) c.can_interface = can_if;
  if (o_log->count()) c.can_log = can_log;
  if (o_node->count()) {
    c.node_id = node;
    c.node_id_from_cli = true;
  }
  if (o_settings->count()) {
    c.can_settings_file = settings_file;
    c.can_settings_file_given = true;
  }
  for (const std::string& d : dividers) {
    const auto eq = d.find('=');
    const int m = eq == std::string::npos ? -1 : message_index(d.substr(0, eq));
    long n = -1;
    if (m >= 0) {
      try {
        std::size_t used = 0;
        n = std::stol(d.substr(eq + 1), &used);
        if (used != d.size() - eq - 1) n = -1;
      } catch (const std::exception&) {
        n = -1;
      }
    }
    if (m < 0 || n < 0 || n > kMaxDivider) {
      out.exit_code = 2;
      out.message = "gfins-fw: command line: --divider " + d +
                    ": expected NAME=N with NAME a message of [output] and N 0.." +
                    std::to_string(kMaxDivider) + "\n";
      return out;
    }
    c.dividers[static_cast<std::size_t>(m)] = static_cast<std::uint16_t>(n);
    c.dividers_from_cli |= 1u << static_cast<unsigned>(m);
  }
  (void)o_div;
  if (o_comp->count()) {
    c.compensator = pick(
        compensator, std::array<const char*, 4>{"calibration", "none", "paper", "exact"},
        std::array<CompensatorChoice, 4>{CompensatorChoice::kCalibration, CompensatorChoice::kNone,
                                         CompensatorChoice::kPaper, CompensatorChoice::kExact});
  }
  if (o_cal->count()) c.calibration_file = calib;
  if (o_grav->count()) {
    c.gravity =
        pick(gravity, std::array<const char*, 4>{"calibration", "standard", "constant", "normal"},
             std::array<GravityChoice, 4>{GravityChoice::kCalibration, GravityChoice::kStandard,
                                          GravityChoice::kConstant, GravityChoice::kNormal});
  }
  if (o_g->count()) c.gravity_mps2 = g;
  if (o_lat->count()) c.latitude_deg = lat;
  if (o_h->count()) c.height_m = height;
  if (o_head->count()) c.heading_deg = heading;
  if (o_pos->count()) c.position_m = {position[0], position[1], position[2]};
  if (o_align->count()) c.alignment_s = align;
  if (o_prio->count()) c.rt_priority = prio;
  if (no_mlock) c.lock_memory = false;
  if (aiding) c.aiding = true;
  if (o_wd->count()) {
    c.watchdog = pick(watchdog, std::array<const char*, 3>{"none", "systemd", "device"},
                      std::array<WatchdogKind, 3>{WatchdogKind::kNone, WatchdogKind::kSystemd,
                                                  WatchdogKind::kDevice});
  }
  if (o_wdd->count()) c.watchdog_device = wd_device;
  if (o_level->count()) c.log_level = level;
  if (o_pacing->count()) {
    c.pacing = pacing == "realtime" ? Pacing::kRealTime
               : pacing == "gpio"   ? Pacing::kGpio
                                    : Pacing::kFast;
  }
  if (o_dur->count()) c.sim_duration_s = duration;
  if (o_sdir->count()) c.sim_scenario_dir = scenario_dir;

  // Only the board itself keeps settings in can.settings_file: the simulated board (also
  // replaying a recording, whose command frames would be carried out again) and the HIL board
  // keep them only in a file named with --settings-file, never in the board's place.
  if (c.board != BoardKind::kLinux && !c.can_settings_file_given) c.can_settings_file.clear();

  // What the configuration is made of, for --check-config's verdict.
  std::size_t overrides = 0;
  for (const CLI::Option* o : app.get_options()) {
    if (o != o_config && o != o_check && o != o_latency) overrides += o->count();
  }
  out.origin = (config_file.empty() ? std::string("built-in defaults") : config_file) +
               (overrides > 0 ? " + command line" : "");

  // The file was valid on its own, so a problem now comes from an option.
  const std::string origin =
      config_file.empty() ? "command line" : "command line (over " + config_file + ")";
  if (std::string problem = validate(c, origin); !problem.empty()) {
    out.exit_code = 2;
    out.message = "gfins-fw: " + problem + "\n";
    return out;
  }
  // The files this run writes: two of them on one path would overwrite each other.
  const drivers::lnx::NamedOutput outputs[] = {
      {"can.log_file (--can-log)", c.can_log},
      {"--latency-csv", out.latency_csv},
      {"hil.port_file (--hil-port-file)", c.hil_port_file},
      {"record.file (--record)", c.record_file},
      {"sim.recording (--replay, read while the run writes)", c.sim_recording},
      {"calibration.file (--calibration, written by the calibrate command)", c.calibration_file},
      {"can.settings_file (--settings-file, written when a command changes a setting)",
       c.can_settings_file},
      {"the configuration file (--config, read)", config_file},
      {"sim.scenario (read)", c.sim_scenario.find('/') != std::string::npos ? c.sim_scenario : ""},
  };
  if (auto clash = drivers::lnx::output_clash(outputs)) {
    out.exit_code = 2;
    out.message = "gfins-fw: " + *clash + "\n";
    return out;
  }
  out.config = std::move(c);
  return out;
}

}  // namespace gfins::app
