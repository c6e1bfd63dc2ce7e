// The value rules of the configuration (gfins/app/config.hpp, check()): ranges, enumerations,
// rules between keys, and every rule the board's backends apply to a value when the run opens
// them, so that a configuration check() accepts is not refused later for its values.
#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <string>

#include "gfins/app/config.hpp"
#include "gfins/app/publisher_sink.hpp"

namespace gfins::app {

std::string hex_id(int id) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%03X", static_cast<unsigned>(id));
  return buf;
}

namespace {

// Linux interface names: 1..15 bytes (IFNAMSIZ 16 with the NUL), no '/', no whitespace.
bool valid_ifname(const std::string& s) {
  return !s.empty() && s.size() <= 15 && std::all_of(s.begin(), s.end(), [](char ch) {
    return ch > 0x20 && ch < 0x7F && ch != '/' && ch != ':';
  });
}

// A dotted-quad IPv4 address, as inet_pton(AF_INET) accepts it: four decimal numbers 0..255.
bool valid_ipv4(const std::string& s) {
  int parts = 0;
  std::size_t i = 0;
  while (i <= s.size()) {
    std::size_t j = i;
    while (j < s.size() && s[j] >= '0' && s[j] <= '9') ++j;
    if (j == i || j - i > 3 || std::stoi(s.substr(i, j - i)) > 255) return false;
    // inet_pton accepts no leading zero ("01" is refused as possibly octal)
    if (j - i > 1 && s[i] == '0') return false;
    ++parts;
    if (j == s.size()) break;
    if (s[j] != '.' || parts == 4) return false;
    i = j + 1;
  }
  return parts == 4;
}

// The identifier groups (docs/can-interface.md, "Identifiers"): each within 11 bits, none over
// another or over a range the bus's other equipment uses (can.reserved_ids).
std::optional<ConfigProblem> id_problem(const FwConfig& c) {
  using P = ConfigProblem;
  const auto range = [&](std::size_t g) {
    const int first = c.id_bases[g];
    return std::array<int, 2>{first, first + static_cast<int>(can::id_span(g)) - 1};
  };
  const auto shown = [](const std::array<int, 2>& r) { return hex_id(r[0]) + ".." + hex_id(r[1]); };
  // The groups checked so far, at their bases (each within 0..0x7FF once it passed the first
  // test below): overlaps are the message table's rule (can::id_group_overlaps), the one the
  // board applies to SetIdBase.
  can::IdBases ids{};
  for (std::size_t g = 0; g < can::kIdGroupCount; ++g) {
    const std::string key(kIdBaseKeys[g]);
    const std::array<int, 2> r = range(g);
    if (c.id_bases[g] < 0 || r[1] > 0x7FF) {
      return P{key, hex_id(c.id_bases[g]),
               "the group takes " + std::to_string(can::id_span(g)) +
                   " identifiers (every message of it for node ids 0..15): its base must be 0.." +
                   hex_id(0x800 - static_cast<int>(can::id_span(g)))};
    }
    ids.base[g] = static_cast<std::uint16_t>(c.id_bases[g]);
    const auto first = static_cast<std::uint32_t>(r[0]);
    const auto last = static_cast<std::uint32_t>(r[1]);
    for (std::size_t h = 0; h < g; ++h) {
      if (can::id_group_overlaps(ids, h, first, last)) {
        // Named after the group that was moved: the one off its default, the later one if both
        // or neither are (a file that moves only the data group onto the commands' stock
        // identifiers hears about data_id_base, the key it set, with its line).
        const bool blame_h =
            c.id_bases[g] == can::kDefaultIdBases[g] && c.id_bases[h] != can::kDefaultIdBases[h];
        const std::size_t a = blame_h ? h : g, b = blame_h ? g : h;
        return P{std::string(kIdBaseKeys[a]), hex_id(c.id_bases[a]),
                 "its identifiers " + shown(range(a)) + " overlap " + std::string(kIdBaseKeys[b]) +
                     "'s " + shown(range(b))};
      }
    }
    // The configuration's reader admits 0 <= first <= last <= 0x7FF only (can.reserved_ids).
    for (const std::array<int, 2>& res : c.reserved_ids) {
      if (can::id_group_overlaps(ids, g, static_cast<std::uint32_t>(res[0]),
                                 static_cast<std::uint32_t>(res[1]))) {
        return P{key, hex_id(c.id_bases[g]),
                 "its identifiers " + shown(r) + " overlap the reserved range " + shown(res) +
                     " of can.reserved_ids"};
      }
    }
  }
  return std::nullopt;
}

// The data-ready line as gfins-fw opens it (open_drdy): all digits = a line offset, anything
// else a line name; a sign in front of digits is a mistyped offset, not a name.
std::string drdy_line_problem(const std::string& s) {
  constexpr int kMaxLineOffset = 1023;  // = the TOML integer form's bound (Reader::line)
  const std::size_t digits_from = !s.empty() && (s[0] == '-' || s[0] == '+') ? 1 : 0;
  if (s.size() > digits_from &&
      s.find_first_not_of("0123456789", digits_from) == std::string::npos) {
    if (digits_from == 1 || s.size() > 4 || std::stoi(s) > kMaxLineOffset) {
      return "line offset must be 0.." + std::to_string(kMaxLineOffset);
    }
    return "";
  }
  if (s.empty() || s.size() > 31 ||
      !std::all_of(s.begin(), s.end(), [](char ch) { return ch > 0x20 && ch < 0x7F; })) {
    return "must be a line offset 0..1023 or a line name of 1..31 printable ASCII characters "
           "without spaces";
  }
  return "";
}

// The shortest text that reads back as x (std::to_chars): 1000.0000001 is not shown as "1000",
// which an ostream's default six digits made of it (a refusal of a value the message called valid).
std::string num(double x) {
  std::array<char, 32> buf{};
  const auto r = std::to_chars(buf.data(), buf.data() + buf.size(), x);
  return std::string(buf.data(), r.ptr);
}

constexpr const char* kPathRule = "must be a path of valid UTF-8 without control characters";

// The first rule `c` breaks: which key, its value as shown, and what is allowed.
}  // namespace

std::optional<ConfigProblem> check(const FwConfig& c) {
  using P = ConfigProblem;
  if (std::find(kSampleRatesHz.begin(), kSampleRatesHz.end(), c.sample_rate_hz) ==
      kSampleRatesHz.end()) {
    return P{"adc.sample_rate_hz", num(c.sample_rate_hz),
             "must be 500, 1000, 2000 or 4000 (ADS131M06 data rates at 8.192 MHz)"};
  }
  // spidev names its nodes /dev/spidevB.C (bus B, chip select C).
  const std::string spidev = "/dev/spidev";
  const std::string bc =
      c.spi_device.rfind(spidev, 0) == 0 ? c.spi_device.substr(spidev.size()) : "";
  const auto dot = bc.find('.');
  const auto digits = [](const std::string& t) {
    return !t.empty() && t.size() < 4 && t.find_first_not_of("0123456789") == std::string::npos;
  };
  if (dot == std::string::npos || !digits(bc.substr(0, dot)) || !digits(bc.substr(dot + 1))) {
    return P{"adc.spi_device", quote_text(c.spi_device),
             "must be a spidev node /dev/spidevB.C (bus B, chip select C)"};
  }
  if (!valid_path(c.gpio_chip)) {
    return P{"adc.gpio_chip", quote_text(c.gpio_chip),
             "must be a chip name or path of valid UTF-8 without control characters"};
  }
  if (std::string why = drdy_line_problem(c.drdy_line); !why.empty()) {
    return P{"adc.drdy_line", quote_text(c.drdy_line), why};
  }
  // Checked with a log file too: the candump lines carry the interface name.
  if (!valid_ifname(c.can_interface)) {
    return P{"can.interface", quote_text(c.can_interface),
             "must be an interface name of 1..15 characters without '/', ':' or spaces"};
  }
  if (!c.can_log.empty() && !valid_path(c.can_log)) {
    return P{"can.log_file", quote_text(c.can_log),
             std::string(kPathRule) + " (or empty for none)"};
  }
  if (c.node_id < 0 || c.node_id > kMaxNodeId) {
    return P{"can.node_id", std::to_string(c.node_id),
             "must be an integer 0.." + std::to_string(kMaxNodeId)};
  }
  for (std::size_t m = 0; m < kNumMessages; ++m) {
    if (c.dividers[m] > kMaxDivider) {
      return P{"output." + std::string(kMessageNames[m]), std::to_string(c.dividers[m]),
               "must be 0 (off) .. " + std::to_string(kMaxDivider)};
    }
  }
  // The CAN message table's rule: epoch and status open every epoch, so they share a divider
  // (not 0), and every other enabled message is a multiple of it (its frames follow an epoch).
  const std::uint16_t epoch_div = c.dividers[0];
  if (epoch_div == 0) return P{"output.epoch", "0", "must be 1.." + std::to_string(kMaxDivider)};
  if (c.dividers[1] != epoch_div) {
    return P{"output.status", std::to_string(c.dividers[1]),
             "must equal output.epoch (" + std::to_string(epoch_div) + ")"};
  }
  for (std::size_t m = 2; m < kNumMessages; ++m) {
    if (c.dividers[m] % epoch_div != 0) {
      return P{"output." + std::string(kMessageNames[m]), std::to_string(c.dividers[m]),
               "must be 0 (off) or a multiple of output.epoch (" + std::to_string(epoch_div) + ")"};
    }
  }
  if (std::find(kCanBitRates.begin(), kCanBitRates.end(), c.can_bit_rate) == kCanBitRates.end()) {
    return P{"can.bit_rate", std::to_string(c.can_bit_rate),
             "must be one of 10000, 20000, 50000, 100000, 125000, 250000, 500000, 800000, "
             "1000000 bit/s (the bus's, as `ip link set ... bitrate` sets it)"};
  }
  if (auto p = id_problem(c)) return p;
  if (!(c.max_bus_load_percent > 0.0 && c.max_bus_load_percent <= 100.0)) {
    return P{"can.max_bus_load_percent", num(c.max_bus_load_percent), "must be in (0, 100]"};
  }
  // The bus budget (docs/can-interface.md, "Rates, dividers and bus load"): a configuration
  // whose frames would take more than the allowed share in the worst case is refused with the
  // figure, here and by --check-config, before it can crowd the other nodes off the bus.
  if (const double load = worst_case_bus_load(c); !(load * 100.0 <= c.max_bus_load_percent)) {
    char figure[160];
    std::snprintf(figure, sizeof figure,
                  "a worst-case bus load of %.1f %% of %d bit/s at adc.sample_rate_hz = %s",
                  load * 100.0, c.can_bit_rate, num(c.sample_rate_hz).c_str());
    return P{"output", figure,
             "must be at most can.max_bus_load_percent = " + num(c.max_bus_load_percent) +
                 " %: raise the dividers of [output], switch messages off, or raise can.bit_rate"};
  }
  if (!(c.gravity_mps2 >= 9.7 && c.gravity_mps2 <= 9.9)) {
    return P{"navigation.gravity_mps2", num(c.gravity_mps2),
             "must be 9.7..9.9 m/s² (the Earth's surface range is 9.76..9.84)"};
  }
  if (!(std::abs(c.latitude_deg) <= 90.0)) {
    return P{"navigation.latitude_deg", num(c.latitude_deg), "must be -90..90 degrees"};
  }
  if (!(c.height_m >= -500.0 && c.height_m <= 20000.0)) {
    return P{"navigation.height_m", num(c.height_m),
             "must be -500..20000 m (the normal gravity's free-air term is first order)"};
  }
  if (!(c.heading_deg >= -360.0 && c.heading_deg <= 360.0)) {
    return P{"navigation.heading_deg", num(c.heading_deg), "must be -360..360 degrees"};
  }
  for (double p : c.position_m) {
    if (!std::isfinite(p) || std::abs(p) > 1e7) {
      return P{"navigation.position_m", num(p), "components must be finite, |x| <= 1e7 m"};
    }
  }
  // ZYX Euler angles: roll and yaw over a full turn, pitch within ±90° (beyond it the same
  // orientation has another name).
  const std::array<double, 3> mount_limit = {180.0, 90.0, 180.0};
  for (std::size_t i = 0; i < 3; ++i) {
    if (!(std::abs(c.mounting_rpy_deg[i]) <= mount_limit[i])) {
      return P{"navigation.mounting_rpy_deg", num(c.mounting_rpy_deg[i]),
               i == 1 ? "pitch must be -90..90 degrees" : "roll and yaw must be -180..180 degrees"};
    }
  }
  // The aiding's inputs are the board's: a heading input and the track heading are compared with
  // the board's yaw (the track heading takes the board's x axis along the velocity), the lever
  // arm is in the board's axes. A mounted board would take the vehicle's heading for its own.
  if (c.aiding && c.mounting_rpy_deg != std::array<double, 3>{}) {
    return P{"navigation.mounting_rpy_deg",
             "[" + num(c.mounting_rpy_deg[0]) + ", " + num(c.mounting_rpy_deg[1]) + ", " +
                 num(c.mounting_rpy_deg[2]) + "]",
             "a mounting rotation cannot be combined with aiding.enabled = true yet (the aiding's "
             "heading inputs, track heading and lever arm are in the board's axes)"};
  }
  if (!(c.alignment_s >= 0.1 && c.alignment_s <= 600.0)) {
    return P{"navigation.alignment_s", num(c.alignment_s), "must be 0.1..600 s"};
  }
  // [aiding]: σ that are positive, finite and physically sensible (a σ of 0 would make the
  // filter certain of a value it never measured).
  struct Sigma {
    const char* key;
    double value;
    double lo;
    double hi;
    const char* unit;
  };
  for (const Sigma& g :
       {Sigma{"aiding.noise_ug", c.aiding_noise_ug, 0.1, 1e5, "µg"},
        Sigma{"aiding.bias_sigma_ug", c.aiding_bias_sigma_ug, 0.1, 1e6, "µg"},
        Sigma{"aiding.bias_rw_ug_sqrt_s", c.aiding_bias_rw_ug_sqrt_s, 0.0, 1e5, "µg/√s"},
        Sigma{"aiding.zupt_sigma_mps", c.aiding_zupt_sigma_mps, 1e-4, 10.0, "m/s"},
        Sigma{"aiding.zaru_sigma_rps", c.aiding_zaru_sigma_rps, 1e-6, 10.0, "rad/s"},
        Sigma{"aiding.track_heading_sigma_deg", c.aiding_track_heading_sigma_deg, 0.0, 90.0,
              "° (0: off)"}}) {
    if (!(g.value >= g.lo && g.value <= g.hi)) {
      return P{g.key, num(g.value), "must be " + num(g.lo) + ".." + num(g.hi) + " " + g.unit};
    }
  }
  // The antenna sits on the vehicle: a lever arm beyond 100 m is a unit mistake (mm for m).
  for (double l : c.aiding_gnss_lever_arm_m) {
    if (!std::isfinite(l) || std::abs(l) > 100.0) {
      return P{"aiding.gnss_lever_arm_m", num(l), "components must be finite, |x| <= 100 m"};
    }
  }
  if (!c.can_settings_file.empty() && !valid_path(c.can_settings_file)) {
    return P{"can.settings_file", quote_text(c.can_settings_file),
             std::string(kPathRule) + " (or empty: settings changed over CAN are not kept)"};
  }
  if (!c.calibration_file.empty() && !valid_path(c.calibration_file)) {
    return P{"calibration.file", quote_text(c.calibration_file),
             std::string(kPathRule) + " (or empty for none)"};
  }
  if (c.rt_priority < 0 || c.rt_priority > kMaxRtPriority) {
    return P{"realtime.priority", std::to_string(c.rt_priority), "must be 0 (no SCHED_FIFO) .. 99"};
  }
  if (!valid_path(c.watchdog_device)) {
    return P{"watchdog.device", quote_text(c.watchdog_device), kPathRule};
  }
  static constexpr std::array<const char*, 6> kLevels = {"trace", "debug", "info",
                                                         "warn",  "error", "off"};
  if (std::find_if(kLevels.begin(), kLevels.end(),
                   [&](const char* l) { return c.log_level == l; }) == kLevels.end()) {
    return P{"log.level", quote_text(c.log_level),
             "must be \"trace\", \"debug\", \"info\", \"warn\", \"error\" or \"off\""};
  }
  if (!valid_path(c.sim_scenario)) {
    return P{"sim.scenario", quote_text(c.sim_scenario),
             "must be a scenario name or a .toml file (valid UTF-8, no control characters)"};
  }
  if (!c.sim_scenario_dir.empty() && !valid_path(c.sim_scenario_dir)) {
    return P{"sim.scenario_dir", quote_text(c.sim_scenario_dir),
             std::string(kPathRule) + " (or empty for the installed scenarios)"};
  }
  if (!(c.sim_duration_s >= 0.0 && c.sim_duration_s <= 86400.0)) {
    return P{"sim.duration_s", num(c.sim_duration_s), "must be 0 (the scenario's) .. 86400 s"};
  }
  if (!c.sim_recording.empty() && !valid_path(c.sim_recording)) {
    return P{"sim.recording", quote_text(c.sim_recording),
             std::string(kPathRule) + " (or empty for a scenario)"};
  }
  if (!c.record_file.empty() && !valid_path(c.record_file)) {
    return P{"record.file", quote_text(c.record_file),
             std::string(kPathRule) + " (or empty for none)"};
  }
  if (!valid_ipv4(c.hil_address)) {
    return P{"hil.address", quote_text(c.hil_address),
             "must be an IPv4 address a.b.c.d (each 0..255), e.g. \"127.0.0.1\""};
  }
  if (c.hil_port < 0 || c.hil_port > 65535) {
    return P{"hil.port", std::to_string(c.hil_port), "must be 0 (ephemeral) .. 65535"};
  }
  if (!c.hil_port_file.empty() && !valid_path(c.hil_port_file)) {
    return P{"hil.port_file", quote_text(c.hil_port_file),
             std::string(kPathRule) + " (or empty for none)"};
  }
  return std::nullopt;
}

std::string validate(const FwConfig& c, const std::string& origin) {
  const std::optional<ConfigProblem> p = check(c);
  return p ? origin + ": " + p->key + " = " + p->value + ": " + p->allowed : std::string();
}

}  // namespace gfins::app
