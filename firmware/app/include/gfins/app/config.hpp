// gfins-fw configuration: a TOML file (docs/firmware.md, "Configuration") overridden by the
// command line. Host/Linux side of the firmware: std::string, exceptions inside (tomlplusplus and
// CLI11 throw) and caught at this interface; every problem comes back as a message naming the
// file (or "command line"), the key and what is allowed.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "gfins/can/message_table.hpp"
#include "gfins/nav_core/compensator.hpp"

namespace gfins::app {

enum class BoardKind : std::uint8_t { kLinux, kSim, kHil };    // kHil: docs/hil.md
enum class Pacing : std::uint8_t { kFast, kRealTime, kGpio };  // simulated board only
/// "calibration" = the local gravity the calibration file was made with (gravity.local_mps2).
enum class GravityChoice : std::uint8_t { kCalibration, kStandard, kConstant, kNormal };
enum class WatchdogKind : std::uint8_t { kNone, kSystemd, kDevice };
/// "calibration" = the compensator the calibration file names.
enum class CompensatorChoice : std::uint8_t { kCalibration, kNone, kPaper, kExact };

/// Output messages whose rate is configurable: the divider of the sample rate per message
/// (0 = off), in the CAN message table's order (docs/can-interface.md; MessageId 0..13). The
/// names are the keys of [output] (and of --divider NAME=N).
inline constexpr std::array<std::string_view, 14> kMessageNames = {
    "epoch",         "status",        "quaternion", "euler",       "rate",
    "angular_accel", "accel",         "velocity",   "position_ne", "position_d",
    "health_adc",    "health_system", "sensors_a",  "sensors_b"};
inline constexpr std::size_t kNumMessages = kMessageNames.size();
/// Defaults of the CAN message table: 100 Hz navigation at 1 kHz (50 Hz Euler angles and angular
/// acceleration), 1 Hz health, raw sensor outputs off; the bus budget is in
/// docs/can-interface.md.
inline constexpr std::array<std::uint16_t, kNumMessages> kDefaultDividers = {
    10, 10, 10, 20, 10, 20, 10, 10, 10, 10, 1000, 1000, 0, 0};
inline constexpr std::uint16_t kMaxDivider = can::kMaxDivider;

/// ADS131M06 output data rates reachable with its 8.192 MHz clock (datasheet §8.4.2.2, OSR
/// 1024..8192 → f_MOD / OSR with f_MOD = 4.096 MHz).
inline constexpr std::array<double, 4> kSampleRatesHz = {500.0, 1000.0, 2000.0, 4000.0};
inline constexpr int kMaxNodeId =
    can::kMaxNodeId;  // 4 bits of the identifier (docs/can-interface.md)
inline constexpr int kMaxRtPriority = 99;
/// CAN bit rates of the common classes (CiA 102 / SAE J1939 / ISO 11898 practice), bit/s.
inline constexpr std::array<int, 9> kCanBitRates = {10000,  20000,  50000,  100000, 125000,
                                                    250000, 500000, 800000, 1000000};
/// The share of the bus the board's periodic frames may take in the worst case (every frame
/// stuffed to its longest): half, leaving the rest to the other nodes and to arbitration.
inline constexpr double kDefaultMaxBusLoadPercent =
    50.0;  // SCHED_FIFO range 1..99 (sched(7)); 0 = do not ask

/// The keys of FwConfig::id_bases, in can::IdGroup order.
inline constexpr std::array<std::string_view, can::kIdGroupCount> kIdBaseKeys = {
    "can.data_id_base", "can.input_id_base", "can.command_id_base", "can.response_id_base"};

struct FwConfig {
  BoardKind board = BoardKind::kLinux;

  // [adc]
  std::string spi_device = "/dev/spidev0.0";
  std::string gpio_chip = "gpiochip0";
  std::string drdy_line = "25";  // line offset (digits only) or line name
  double sample_rate_hz = 1000.0;

  // [can]
  std::string can_interface = "can0";
  std::string can_log;  // non-empty: write a candump log file instead of using an interface
  int node_id = can::kDefaultNodeId;
  int can_bit_rate = static_cast<int>(can::kDefaultBitRate);  // bit/s of the bus (ip link's)
  double max_bus_load_percent = kDefaultMaxBusLoadPercent;    // the board's worst-case share
  /// First identifier of each group (can::IdGroup order: data, input, command, response):
  /// can.data_id_base, can.input_id_base, can.command_id_base, can.response_id_base.
  std::array<int, can::kIdGroupCount> id_bases = {can::kDefaultIdBases[0], can::kDefaultIdBases[1],
                                                  can::kDefaultIdBases[2], can::kDefaultIdBases[3]};
  /// Identifier ranges other equipment on the bus uses (can.reserved_ids, [first, last] each):
  /// no group may overlap one.
  std::vector<std::array<int, 2>> reserved_ids;
  /// Where settings changed over CAN (node id, dividers) are kept across restarts; "" = not kept.
  std::string can_settings_file = "/var/lib/gfins/can-settings.toml";
  /// can.settings_file was given on the command line (--settings-file): the simulated and the
  /// HIL boards keep settings only then, never in the board's place.
  bool can_settings_file_given = false;
  /// The command line gave can.node_id (--node-id) / these [output] dividers (--divider, bit m =
  /// message m): they win over the stored settings (docs/can-interface.md, "Stored settings").
  bool node_id_from_cli = false;
  std::uint32_t dividers_from_cli = 0;

  // [output]
  std::array<std::uint16_t, kNumMessages> dividers = kDefaultDividers;

  // [navigation]
  CompensatorChoice compensator = CompensatorChoice::kCalibration;
  GravityChoice gravity = GravityChoice::kCalibration;
  double gravity_mps2 = 9.80665;       // kConstant
  double latitude_deg = 0.0;           // kNormal
  double height_m = 0.0;               // kNormal
  double heading_deg = 0.0;            // initial heading (nothing on board senses it)
  std::array<double, 3> position_m{};  // initial position, NED from the alignment point
  // The board's orientation in the vehicle frame (FRD: x forward, y right, z down): roll, pitch,
  // yaw in degrees, the ZYX (yaw, then pitch, then roll) rotation of the vehicle's axes onto the
  // board's. Non-zero: the published attitude, rates and accelerations are the vehicle's.
  std::array<double, 3> mounting_rpy_deg{};
  double alignment_s = 1.0;  // time at rest averaged by the static alignment

  // [aiding] the error-state filter with standstill updates (docs/firmware.md, "Aiding")
  bool aiding = false;
  bool aiding_standstill = true;           // ZUPT + ZARU while the array says "at rest"
  int aiding_decimation = 10;              // filter propagation every N samples
  double aiding_noise_ug = 70.0;           // white noise per sensor and sample (QA-1100: 70 µg)
  double aiding_bias_sigma_ug = 500.0;     // per-sensor bias prior, 1σ
  double aiding_bias_rw_ug_sqrt_s = 10.0;  // per-sensor bias random walk
  double aiding_zupt_sigma_mps = 0.01;     // 1σ of the zero-velocity update
  double aiding_zaru_sigma_rps = 0.001;    // 1σ of the zero-rate update
  bool aiding_inputs = true;  // GNSS / heading input frames of can.node_id feed the filter
  std::array<double, 3> aiding_gnss_lever_arm_m{};  // GNSS antenna from the array centre, FRD, m
  double aiding_track_heading_sigma_deg = 0.0;      // > 0: heading from the GNSS track (a vehicle)

  // [calibration]
  std::string calibration_file = "/var/lib/gfins/calibration.toml";

  // [realtime]
  int rt_priority = 80;
  bool lock_memory = true;

  // [watchdog]
  WatchdogKind watchdog = WatchdogKind::kSystemd;
  std::string watchdog_device = "/dev/watchdog";

  // [log]
  std::string log_level = "info";  // trace debug info warn error off

  // [sim]
  std::string sim_scenario = "rest";
  std::string sim_scenario_dir;  // empty: the installed scenarios next to the binary
  Pacing pacing = Pacing::kFast;
  double sim_duration_s = 0.0;  // 0 = the scenario's duration
  std::string sim_recording;    // non-empty: replay this raw-sample recording instead of a scenario

  // [record] the raw-sample recorder (docs/replay.md, "Recording on the board")
  std::string record_file;  // non-empty: every sample and received frame is recorded here

  // [hil] hardware-in-the-loop replay (docs/hil.md): samples arrive over TCP from gfins-can hil
  std::string hil_address = "127.0.0.1";  // IPv4 address to listen on
  int hil_port = 7476;                    // 0: an ephemeral port (written to hil_port_file)
  std::string hil_port_file;              // non-empty: the bound port is written here
};

/// The worst-case share (0..1) of can.bit_rate that the board's periodic frames take with the
/// configuration's sample rate and dividers (can::worst_case_bits_per_s; docs/can-interface.md).
double worst_case_bus_load(const FwConfig& c);

/// Outcome of loading: the configuration, or the first problem.
struct ConfigResult {
  std::optional<FwConfig> config;
  std::string error;  // "gfins-fw.toml: can.node_id = 40: must be an integer 0..15"
  bool ok() const { return config.has_value(); }
};

/// Parses TOML text; `source` names it in messages. Keys absent from the text keep their
/// defaults; unknown keys are errors.
ConfigResult parse_config(std::string_view toml_text, const std::string& source,
                          FwConfig base = {});

/// Reads and parses a file.
ConfigResult load_config(const std::string& path, FwConfig base = {});

/// The first rule a configuration breaks: `key` ("can.node_id"), `value` as shown in messages
/// (strings quoted and escaped by quote_text()) and `allowed` (what the key accepts).
struct ConfigProblem {
  std::string key;
  std::string value;
  std::string allowed;
};

/// Checks every field (ranges, enumerations, consistency, and every rule on values the run
/// applies when it opens the board: interface names, line offsets, addresses, paths). Returns
/// the first problem, or nothing when all are valid.
std::optional<ConfigProblem> check(const FwConfig& c);

/// check() as one message "ORIGIN: key = value: allowed"; `origin` names where the values came
/// from. Returns "" when all are valid.
std::string validate(const FwConfig& c, const std::string& origin);

class BoardTable;  // board.hpp

/// Checks against the file system what the run would otherwise find only when it gets there:
/// that `boards` has c.board, that board's own checks (BoardEntry::check: the simulated board's
/// scenario loads and runs at adc.sample_rate_hz) and the output files (can.log_file,
/// hil.port_file on the hil board, `latency_csv` when not empty: the folder exists and the path
/// is not a folder). Devices (SPI, GPIO, CAN interface, watchdog) are not opened: the run reports
/// those at start-up, before the loop starts. Returns "" or "ORIGIN: key = value: problem".
std::string preflight(const FwConfig& c, const BoardTable& boards, const std::string& origin,
                      const std::string& latency_csv = {});

/// For --check-config: "" when the run would navigate with a calibration (calibration.file
/// loads, or it is empty on the simulated board, whose factory calibration is used), else why
/// it would navigate UNCALIBRATED (not an error: the run starts, flagged, docs/firmware.md).
std::string calibration_note(const FwConfig& c);

/// A CAN identifier as the ICD writes it: 0x and three upper-case hexadecimal digits.
std::string hex_id(int id);

/// `s` in double quotes with '"', '\', control characters (C0, DEL, C1) and the bytes of invalid
/// UTF-8 escaped (\uXXXX, \xNN), cut to 60 characters: a value as a message shows it.
std::string quote_text(std::string_view s);

/// `s` with control characters other than '\n' and '\t', and invalid UTF-8, escaped: safe to
/// print.
std::string printable_text(std::string_view s);

/// A non-empty path of at most 4095 bytes of valid UTF-8 without control characters.
bool valid_path(std::string_view s);

/// The commented default configuration (what firmware/app/gfins-fw.toml ships).
std::string default_config_text();

const char* to_string(BoardKind b);
const char* to_string(Pacing p);
const char* to_string(GravityChoice g);
const char* to_string(CompensatorChoice c);
const char* to_string(WatchdogKind w);

/// Index of a message name in kMessageNames, or -1.
int message_index(std::string_view name);

/// The compensator to run given the configuration's choice and the calibration file's.
nav::CompensatorKind resolve_compensator(CompensatorChoice choice, nav::CompensatorKind from_file);

/// Outcome of the command line: a configuration to run with, or an exit (help, error, printed
/// default configuration) with its code.
struct CliResult {
  std::optional<FwConfig> config;
  std::string config_source;  // the file the configuration came from ("" = built-in defaults)
  std::string origin;         // "my.toml", "my.toml + command line", "built-in defaults", ...
  bool check_only = false;    // --check-config: validate and exit
  std::string latency_csv;    // --latency-csv: write the edge→CAN latency histogram (benchmark)
  int exit_code = 0;          // when !config
  std::string message;        // printed when !config (stdout for exit 0, stderr otherwise)
};

/// Parses argv: --config FILE (default: none = built-in defaults) then every override.
CliResult parse_command_line(int argc, const char* const* argv);

}  // namespace gfins::app
