// TOML → FwConfig with every key checked (gfins/app/config.hpp). tomlplusplus is used header-only
// here as in firmware/calib_file (same reasons); every toml:: call that can throw is inside the
// try block of parse_config().

#include <algorithm>
#include <cmath>
#include <exception>
#include <set>
#include <sstream>

#include "gfins/app/config.hpp"
#include "gfins/drivers/lnx/text_file.hpp"
#include "gfins/toml/safe_parse.hpp"

namespace gfins::app {

namespace {

struct ConfigError {
  std::string message;
};

// Reads typed values out of the parsed table; every problem throws ConfigError with the file,
// line and key; remembers the keys it knows so the rest can be reported as unknown.
class Reader {
 public:
  Reader(const toml::table& root, const std::string& source) : root_(root), source_(source) {}

  const toml::node* find(const std::string& key) {
    known_.insert(key);
    const toml::node_view<const toml::node> n = root_.at_path(key);
    return n ? n.node() : nullptr;
  }

  [[noreturn]] void fail(const std::string& key, const toml::node* n, const std::string& what) {
    std::ostringstream m;
    m << source_;
    if (n != nullptr && n->source().begin.line > 0) m << ":" << n->source().begin.line;
    m << ": " << key;
    if (n != nullptr) m << " = " << value_text(*n);
    m << ": " << what;
    throw ConfigError{m.str()};
  }

  /// True when the key is in the file.
  bool text(const std::string& key, std::string& s) {
    if (const toml::node* n = find(key)) {
      if (!n->is_string()) fail(key, n, "must be a string");
      s = n->value<std::string>().value_or("");
      return true;
    }
    return false;
  }
  void integer(const std::string& key, int& v, int lo, int hi) {
    if (const toml::node* n = find(key)) {
      const auto* i = n->as_integer();
      if (i == nullptr || i->get() < lo || i->get() > hi) {
        fail(key, n, "must be an integer " + std::to_string(lo) + ".." + std::to_string(hi));
      }
      v = static_cast<int>(i->get());
    }
  }
  void number(const std::string& key, double& x) {
    if (const toml::node* n = find(key)) {
      if (const auto* f = n->as_floating_point()) {
        x = f->get();
      } else if (const auto* i = n->as_integer()) {
        x = static_cast<double>(i->get());
      } else {
        fail(key, n, "must be a number");
      }
    }
  }
  void boolean(const std::string& key, bool& b) {
    if (const toml::node* n = find(key)) {
      if (!n->is_boolean()) fail(key, n, "must be true or false");
      b = n->value<bool>().value_or(false);
    }
  }
  void vec3(const std::string& key, std::array<double, 3>& v) {
    if (const toml::node* n = find(key)) {
      const toml::array* a = n->as_array();
      if (a == nullptr || a->size() != 3) fail(key, n, "must be an array of 3 numbers");
      for (std::size_t k = 0; k < 3; ++k) {
        const toml::node* e = a->get(k);
        if (const auto* f = e->as_floating_point()) {
          v[k] = f->get();
        } else if (const auto* i = e->as_integer()) {
          v[k] = static_cast<double>(i->get());
        } else {
          fail(key, n, "must be an array of 3 numbers");
        }
      }
    }
  }
  // A list of [first, last] CAN identifier pairs (can.reserved_ids).
  void id_ranges(const std::string& key, std::vector<std::array<int, 2>>& out) {
    const toml::node* n = find(key);
    if (n == nullptr) return;
    const char* rule =
        "must be a list of [first, last] pairs of 11-bit identifiers, 0 <= first <= last <= "
        "2047 (0x7FF)";
    const toml::array* a = n->as_array();
    if (a == nullptr) fail(key, n, rule);
    out.clear();
    for (const toml::node& e : *a) {
      const toml::array* pair = e.as_array();
      if (pair == nullptr || pair->size() != 2) fail(key, n, rule);
      const auto* first = pair->get(0)->as_integer();
      const auto* last = pair->get(1)->as_integer();
      if (first == nullptr || last == nullptr || first->get() < 0 || first->get() > last->get() ||
          last->get() > 0x7FF) {
        fail(key, n, rule);
      }
      out.push_back({static_cast<int>(first->get()), static_cast<int>(last->get())});
    }
  }
  // One of `names`; sets `out` to the matching enumerator of `values`.
  template <typename E, std::size_t N>
  void choice(const std::string& key, E& out, const std::array<const char*, N>& names,
              const std::array<E, N>& values) {
    if (const toml::node* n = find(key)) {
      std::string allowed;
      for (std::size_t i = 0; i < N; ++i) {
        allowed +=
            (i == 0 ? "\"" : (i + 1 == N ? " or \"" : ", \"")) + std::string(names[i]) + "\"";
      }
      if (!n->is_string()) fail(key, n, "must be " + allowed);
      const std::string s = n->value<std::string>().value_or("");
      for (std::size_t i = 0; i < N; ++i) {
        if (s == names[i]) {
          out = values[i];
          return;
        }
      }
      fail(key, n, "must be " + allowed);
    }
  }
  // The data-ready line: an offset (integer, or a string of digits) or a line name.
  void line(const std::string& key, std::string& s) {
    if (const toml::node* n = find(key)) {
      if (const auto* i = n->as_integer()) {
        if (i->get() < 0 || i->get() > 1023) fail(key, n, "line offset must be 0..1023");
        s = std::to_string(i->get());
      } else if (n->is_string()) {
        s = n->value<std::string>().value_or("");
      } else {
        fail(key, n, "must be a line offset (integer) or a line name (string)");
      }
    }
  }

  // The first key present in the file that no reader asked for.
  // Paths are compared key by key, never as joined text: a key that is not a TOML bare key is
  // shown quoted, so a quoted key with a dot in it ("can.node_id" = 7 is ONE key named
  // can.node_id, not can → node_id) never matches a known path and is reported as unknown.
  void reject_unknown(const toml::table& t, const std::string& prefix) {
    for (const auto& [k, node] : t) {
      const std::string_view name = k.str();
      const bool bare = !name.empty() && std::all_of(name.begin(), name.end(), [](char ch) {
        return (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || (ch >= '0' && ch <= '9') ||
               ch == '_' || ch == '-';
      });
      const std::string shown = bare ? std::string(name) : quote_text(name);
      std::string p = prefix;
      if (!p.empty()) p += '.';
      p += shown;
      if (const toml::table* sub = node.as_table(); sub != nullptr && known_tables_.count(p) != 0) {
        reject_unknown(*sub, p);
      } else if (known_.count(p) == 0) {
        std::ostringstream m;
        m << source_;
        if (node.source().begin.line > 0) m << ":" << node.source().begin.line;
        m << ": unknown key '" << p << "'";
        if (!bare && name.find('.') != std::string_view::npos) {
          m << " (a quoted key is one name, dots included: write the path unquoted, e.g. "
               "can.node_id = 7 or node_id = 7 under [can])";
        }
        throw ConfigError{m.str()};
      }
    }
  }
  void table(const std::string& name) { known_tables_.insert(name); }

 private:
  static std::string value_text(const toml::node& n) {
    std::ostringstream o;
    if (n.is_table()) return "{...}";
    if (n.is_array()) return "[...]";
    if (const auto* v = n.as_string()) return quote_text(v->get());
    if (const auto* v = n.as_integer()) o << v->get();
    if (const auto* v = n.as_floating_point()) o << v->get();
    if (const auto* v = n.as_boolean()) o << (v->get() ? "true" : "false");
    return o.str();
  }

  const toml::table& root_;
  const std::string& source_;
  std::set<std::string> known_;
  std::set<std::string> known_tables_;
};

void read_all(Reader& r, FwConfig& c) {
  for (const char* t : {"board", "adc", "can", "output", "navigation", "aiding", "calibration",
                        "realtime", "watchdog", "log", "sim", "hil", "record"}) {
    r.table(t);
  }
  r.choice("board.kind", c.board, std::array<const char*, 3>{"linux", "sim", "hil"},
           std::array<BoardKind, 3>{BoardKind::kLinux, BoardKind::kSim, BoardKind::kHil});
  r.text("adc.spi_device", c.spi_device);
  r.text("adc.gpio_chip", c.gpio_chip);
  r.line("adc.drdy_line", c.drdy_line);
  r.number("adc.sample_rate_hz", c.sample_rate_hz);
  r.text("can.interface", c.can_interface);
  r.text("can.log_file", c.can_log);
  r.integer("can.node_id", c.node_id, 0, kMaxNodeId);
  r.integer("can.bit_rate", c.can_bit_rate, 1, 1000000);
  r.number("can.max_bus_load_percent", c.max_bus_load_percent);
  for (std::size_t g = 0; g < kIdBaseKeys.size(); ++g) {
    r.integer(std::string(kIdBaseKeys[g]), c.id_bases[g], 0, 0x7FF);
  }
  r.id_ranges("can.reserved_ids", c.reserved_ids);
  r.text("can.settings_file", c.can_settings_file);
  for (std::size_t m = 0; m < kNumMessages; ++m) {
    int d = c.dividers[m];
    r.integer("output." + std::string(kMessageNames[m]), d, 0, kMaxDivider);
    c.dividers[m] = static_cast<std::uint16_t>(d);
  }
  r.choice(
      "navigation.compensator", c.compensator,
      std::array<const char*, 4>{"calibration", "none", "paper", "exact"},
      std::array<CompensatorChoice, 4>{CompensatorChoice::kCalibration, CompensatorChoice::kNone,
                                       CompensatorChoice::kPaper, CompensatorChoice::kExact});
  r.choice("navigation.gravity", c.gravity,
           std::array<const char*, 4>{"calibration", "standard", "constant", "normal"},
           std::array<GravityChoice, 4>{GravityChoice::kCalibration, GravityChoice::kStandard,
                                        GravityChoice::kConstant, GravityChoice::kNormal});
  r.number("navigation.gravity_mps2", c.gravity_mps2);
  r.number("navigation.latitude_deg", c.latitude_deg);
  r.number("navigation.height_m", c.height_m);
  r.number("navigation.heading_deg", c.heading_deg);
  r.vec3("navigation.position_m", c.position_m);
  r.vec3("navigation.mounting_rpy_deg", c.mounting_rpy_deg);
  r.number("navigation.alignment_s", c.alignment_s);
  r.boolean("aiding.enabled", c.aiding);
  r.boolean("aiding.standstill", c.aiding_standstill);
  r.integer("aiding.decimation", c.aiding_decimation, 1, 10000);
  r.number("aiding.noise_ug", c.aiding_noise_ug);
  r.number("aiding.bias_sigma_ug", c.aiding_bias_sigma_ug);
  r.number("aiding.bias_rw_ug_sqrt_s", c.aiding_bias_rw_ug_sqrt_s);
  r.number("aiding.zupt_sigma_mps", c.aiding_zupt_sigma_mps);
  r.number("aiding.zaru_sigma_rps", c.aiding_zaru_sigma_rps);
  r.boolean("aiding.inputs", c.aiding_inputs);
  r.vec3("aiding.gnss_lever_arm_m", c.aiding_gnss_lever_arm_m);
  r.number("aiding.track_heading_sigma_deg", c.aiding_track_heading_sigma_deg);
  r.text("calibration.file", c.calibration_file);
  r.integer("realtime.priority", c.rt_priority, 0, kMaxRtPriority);
  r.boolean("realtime.lock_memory", c.lock_memory);
  r.choice("watchdog.kind", c.watchdog, std::array<const char*, 3>{"none", "systemd", "device"},
           std::array<WatchdogKind, 3>{WatchdogKind::kNone, WatchdogKind::kSystemd,
                                       WatchdogKind::kDevice});
  r.text("watchdog.device", c.watchdog_device);
  r.text("log.level", c.log_level);
  r.text("sim.scenario", c.sim_scenario);
  r.text("sim.scenario_dir", c.sim_scenario_dir);
  // gpio: each conversion waits for a data-ready edge on adc.gpio_chip / adc.drdy_line.
  r.choice("sim.pacing", c.pacing, std::array<const char*, 3>{"fast", "realtime", "gpio"},
           std::array<Pacing, 3>{Pacing::kFast, Pacing::kRealTime, Pacing::kGpio});
  r.number("sim.duration_s", c.sim_duration_s);
  r.text("sim.recording", c.sim_recording);
  r.text("record.file", c.record_file);
  r.text("hil.address", c.hil_address);
  r.integer("hil.port", c.hil_port, 0, 65535);
  r.text("hil.port_file", c.hil_port_file);
}

}  // namespace

ConfigResult parse_config(std::string_view toml_text, const std::string& source, FwConfig base) {
  ConfigResult out;
  std::optional<ConfigProblem> problem;
  int line = 0;  // of the key the problem names, when it is in the text
  try {
    const toml::table root = toml_text::safe_parse(toml_text, source);
    Reader r(root, source);
    read_all(r, base);
    r.reject_unknown(root, "");
    problem = check(base);
    if (problem) {
      if (const toml::node_view<const toml::node> n = root.at_path(problem->key)) {
        line = static_cast<int>(n.node()->source().begin.line);
      }
    }
  } catch (const toml::parse_error& e) {
    std::ostringstream m;
    // The parser's description quotes the offending character raw: escaped for the terminal.
    m << source << ":" << e.source().begin.line
      << ": TOML syntax: " << printable_text(e.description());
    out.error = m.str();
    return out;
  } catch (const ConfigError& e) {
    out.error = e.message;
    return out;
  } catch (const std::exception& e) {
    out.error = source + ": " + e.what();
    return out;
  }
  if (problem) {
    // "file:line: key = value: what is allowed", as the Reader's own messages (the line is
    // missing only when the key is not in the file: a rule between keys broken by a default).
    out.error = source + (line > 0 ? ":" + std::to_string(line) : std::string()) + ": " +
                problem->key + " = " + problem->value + ": " + problem->allowed;
    return out;
  }
  out.config = std::move(base);
  return out;
}

ConfigResult load_config(const std::string& path, FwConfig base) {
  // Bounded: a path that never ends (/dev/zero) or a huge file is refused after 1 MiB.
  std::string text;
  const Status st = drivers::lnx::read_text_file(path.c_str(), drivers::lnx::kMaxConfigBytes, text);
  if (!st.is_ok()) {
    ConfigResult r;
    r.error = drivers::lnx::text_file_error(path, st, drivers::lnx::kMaxConfigBytes,
                                            "a configuration file");
    return r;
  }
  return parse_config(text, path, std::move(base));
}

const char* to_string(BoardKind b) {
  return b == BoardKind::kSim ? "sim" : (b == BoardKind::kHil ? "hil" : "linux");
}
const char* to_string(Pacing p) {
  switch (p) {
    case Pacing::kRealTime:
      return "realtime";
    case Pacing::kGpio:
      return "gpio";
    case Pacing::kFast:
      break;
  }
  return "fast";
}
const char* to_string(GravityChoice g) {
  switch (g) {
    case GravityChoice::kCalibration:
      return "calibration";
    case GravityChoice::kStandard:
      return "standard";
    case GravityChoice::kConstant:
      return "constant";
    case GravityChoice::kNormal:
      return "normal";
  }
  return "?";
}
const char* to_string(CompensatorChoice c) {
  switch (c) {
    case CompensatorChoice::kCalibration:
      return "calibration";
    case CompensatorChoice::kNone:
      return "none";
    case CompensatorChoice::kPaper:
      return "paper";
    case CompensatorChoice::kExact:
      return "exact";
  }
  return "?";
}
const char* to_string(WatchdogKind w) {
  switch (w) {
    case WatchdogKind::kNone:
      return "none";
    case WatchdogKind::kSystemd:
      return "systemd";
    case WatchdogKind::kDevice:
      return "device";
  }
  return "?";
}

int message_index(std::string_view name) {
  for (std::size_t m = 0; m < kNumMessages; ++m) {
    if (kMessageNames[m] == name) return static_cast<int>(m);
  }
  return -1;
}

nav::CompensatorKind resolve_compensator(CompensatorChoice choice, nav::CompensatorKind from_file) {
  switch (choice) {
    case CompensatorChoice::kCalibration:
      return from_file;
    case CompensatorChoice::kNone:
      return nav::CompensatorKind::kNone;
    case CompensatorChoice::kPaper:
      return nav::CompensatorKind::kPaper;
    case CompensatorChoice::kExact:
      return nav::CompensatorKind::kExact;
  }
  return from_file;
}

}  // namespace gfins::app
