// Scenario files (TOML, tomlplusplus) → gfins::sim::Scenario, and the trajectories they name.
// Every error message has the form "FILE:LINE: key 'table.key': what is wrong".
#include "gfins/host_sim/scenario.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>

#include "gfins/drivers/lnx/printable.hpp"
#include "gfins/host_sim/chip/simulated_adc.hpp"
#include "gfins/nav_core/math.hpp"
#include "gfins/nav_core/paper_table6.hpp"
#include "gfins/toml/safe_parse.hpp"

namespace gfins::sim {

namespace {
// [[board.faults]] kind names, in BoardFaultKind order.
constexpr std::array<const char*, 11> kBoardFaultNames = {
    "crc_error", "missed_edges", "extra_edge", "silent_line", "adc_reset", "saturated",
    "stuck",     "can_refuse",   "bus_off",    "read_error",  "adc_dead"};
}  // namespace

const char* to_string(BoardFaultKind k) {
  const auto i = static_cast<std::size_t>(k);
  if (i >= kBoardFaultNames.size()) return "unknown";
  const char* name = kBoardFaultNames.at(i);
  return name;
}

namespace {

constexpr double kDegToRad = M_PI / 180.0;

/// Thrown inside the parser only; parse_scenario turns it into a HostError.
struct ScenarioParseError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

class Reader {
 public:
  explicit Reader(std::string source) : source_(std::move(source)) {}

  [[noreturn]] void fail(const toml::node* node, const std::string& key,
                         const std::string& what) const {
    std::ostringstream os;
    os << source_;
    if (node != nullptr && node->source().begin.line > 0) os << ":" << node->source().begin.line;
    os << ": key '" << key << "': " << what;
    throw ScenarioParseError(os.str());
  }

  /// The sub-table `name` of the root; null when absent and not required.
  const toml::table* table(const toml::table& root, const std::string& name, bool required) const {
    const toml::node* n = root.get(name);
    if (n == nullptr) {
      if (required) fail(&root, name, "missing table [" + name + "]");
      return nullptr;
    }
    if (!n->is_table()) fail(n, name, "expected a table, got " + type_name(*n));
    return n->as_table();
  }

  /// Rejects keys not in `allowed` (typos would otherwise be silently ignored).
  void only(const toml::table& t, const std::string& prefix,
            std::initializer_list<const char*> allowed) const {
    for (const auto& [k, v] : t) {
      const std::string key(k.str());
      if (std::none_of(allowed.begin(), allowed.end(), [&](const char* a) { return key == a; })) {
        std::string list;
        for (const char* a : allowed) list += std::string(list.empty() ? "" : ", ") + a;
        fail(&v, prefix + key, "unknown key (allowed: " + list + ")");
      }
    }
  }

  double number(const toml::table& t, const std::string& prefix, const char* key,
                std::optional<double> fallback, double lo, double hi) const {
    const std::string full = prefix + key;
    const toml::node* n = t.get(key);
    if (n == nullptr) {
      if (!fallback) fail(&t, full, "missing (required number)");
      return *fallback;
    }
    double v = 0;
    if (const auto* f = n->as_floating_point()) {
      v = f->get();
    } else if (const auto* i = n->as_integer()) {
      v = static_cast<double>(i->get());
    } else {
      fail(n, full, "expected a number, got " + type_name(*n));
    }
    if (!std::isfinite(v) || v < lo || v > hi) {
      std::ostringstream os;
      os << "value " << v << " out of range [" << lo << ", " << hi << "]";
      fail(n, full, os.str());
    }
    return v;
  }

  std::uint64_t integer(const toml::table& t, const std::string& prefix, const char* key,
                        std::uint64_t fallback) const {
    const toml::node* n = t.get(key);
    if (n == nullptr) return fallback;
    const auto* i = n->as_integer();
    if (i == nullptr) fail(n, prefix + key, "expected an integer, got " + type_name(*n));
    if (i->get() < 0) fail(n, prefix + key, "value out of range: must be ≥ 0");
    return static_cast<std::uint64_t>(i->get());
  }

  std::string string(const toml::table& t, const std::string& prefix, const char* key,
                     std::optional<std::string> fallback,
                     std::initializer_list<const char*> choices = {}) const {
    const std::string full = prefix + key;
    const toml::node* n = t.get(key);
    if (n == nullptr) {
      if (!fallback) fail(&t, full, "missing (required string)");
      return *fallback;
    }
    const auto* s = n->as_string();
    if (s == nullptr) fail(n, full, "expected a string, got " + type_name(*n));
    std::string v = s->get();  // not const: returned by move
    if (choices.size() > 0 &&
        std::none_of(choices.begin(), choices.end(), [&](const char* c) { return v == c; })) {
      std::string list;
      for (const char* c : choices) list += std::string(list.empty() ? "" : ", ") + c;
      fail(n, full, "unknown value '" + v + "' (expected one of: " + list + ")");
    }
    return v;
  }

  bool boolean(const toml::table& t, const std::string& prefix, const char* key,
               bool fallback) const {
    const toml::node* n = t.get(key);
    if (n == nullptr) return fallback;
    const auto* b = n->as_boolean();
    if (b == nullptr) fail(n, prefix + key, "expected true or false, got " + type_name(*n));
    return b->get();
  }

  /// An array of exactly `size` numbers, each within [lo, hi].
  std::vector<double> numbers(const toml::table& t, const std::string& prefix, const char* key,
                              std::size_t size, double lo, double hi, bool required) const {
    const std::string full = prefix + key;
    const toml::node* n = t.get(key);
    if (n == nullptr) {
      if (required) fail(&t, full, "missing (required array)");
      return {};
    }
    const auto* a = n->as_array();
    if (a == nullptr) fail(n, full, "expected an array of numbers, got " + type_name(*n));
    if (size != 0 && a->size() != size) {  // size 0: any length (the caller checks it)
      fail(n, full,
           "expected " + std::to_string(size) + " numbers, got " + std::to_string(a->size()));
    }
    std::vector<double> out;
    for (const auto& e : *a) {
      double v = 0;
      if (const auto* f = e.as_floating_point()) {
        v = f->get();
      } else if (const auto* i = e.as_integer()) {
        v = static_cast<double>(i->get());
      } else {
        fail(&e, full, "expected an array of numbers, found a " + type_name(e));
      }
      if (!std::isfinite(v) || v < lo || v > hi) {
        std::ostringstream os;
        os << "element " << out.size() << " = " << v << " out of range [" << lo << ", " << hi
           << "]";
        fail(&e, full, os.str());
      }
      out.push_back(v);
    }
    return out;
  }

  static std::string type_name(const toml::node& n) {
    switch (n.type()) {
      case toml::node_type::table:
        return "a table";
      case toml::node_type::array:
        return "an array";
      case toml::node_type::string:
        return "a string";
      case toml::node_type::integer:
        return "an integer";
      case toml::node_type::floating_point:
        return "a floating-point number";
      case toml::node_type::boolean:
        return "a boolean";
      default:
        return "a date/time";
    }
  }

 private:
  std::string source_;
};

Vec3d vec3(const std::vector<double>& v) { return Vec3d(v[0], v[1], v[2]); }

/// The [trajectory] keys each kind reads (docs/simulation.md, "Scenario format"). A key of
/// another kind would be silently ignored, so it is an error naming the kind and its keys.
std::vector<std::string> trajectory_keys_of(const std::string& kind) {
  if (kind == "rest") return {"kind", "euler_deg"};
  if (kind == "constant_acceleration") return {"kind", "euler_deg", "accel_mps2"};
  if (kind == "spin" || kind == "rate_table") return {"kind", "euler_deg", "axis_b", "rate_dps"};
  if (kind == "coning") return {"kind", "euler_deg", "half_angle_deg", "cone_rate_hz"};
  if (kind == "maneuver") return {"kind", "scale"};
  if (kind == "drive") return {"kind", "speed_mps", "turn_amplitude_m", "turn_period_s"};
  if (kind == "stop_and_go") {
    return {"kind",   "speed_mps",      "accel_s",           "cruise_s",
            "stop_s", "initial_stop_s", "weave_amplitude_m", "weave_length_m"};
  }
  if (kind == "calibration_poses")
    return {"kind", "poses", "dwell_s", "transition_s", "extra_poses_g"};
  return {"kind"};
}

void check_trajectory_keys(const toml::table& tr, const Reader& rd, const std::string& kind) {
  const std::vector<std::string> keys = trajectory_keys_of(kind);
  for (const auto& [k, v] : tr) {
    const std::string key(k.str());
    if (std::find(keys.begin(), keys.end(), key) != keys.end()) continue;
    std::string list;
    for (const auto& a : keys) list += (list.empty() ? "" : ", ") + a;
    std::string what = "does not apply to trajectory kind \"";
    what += kind;
    what += "\" (its keys: ";
    what += list;
    what += ")";
    rd.fail(&v, "trajectory." + key, what);
  }
}

constexpr double kBig = 1e9;

/// Checks the scenario's name where it came from: the [scenario] name key (its line), or the
/// file name's stem when the key is absent.
void check_name(const toml::table& sc, const Reader& rd, const std::string& name) {
  const std::string problem = scenario_name_problem(name);
  if (problem.empty()) return;
  if (const toml::node* n = sc.get("name"); n != nullptr) rd.fail(n, "scenario.name", problem);
  rd.fail(nullptr, "scenario.name",
          problem + " (the name is the file's stem when [scenario] has no name key: set one)");
}

/// The description is printed to the terminal and into summary.txt: one line of text, without
/// the control characters (C0, DEL, C1) a TOML escape can put there and a terminal would obey
/// (ESC [2J clears the screen; a newline would forge a line of the report).
void check_description(const toml::table& sc, const Reader& rd, const std::string& text) {
  std::size_t chars = 0;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if ((c & 0xC0U) != 0x80U) ++chars;  // a character starts here (not a continuation byte)
    unsigned code = c;
    if (c == 0xC2 && i + 1 < text.size()) code = static_cast<unsigned char>(text[i + 1]);
    const bool c1 = c == 0xC2 && code >= 0x80 && code <= 0x9F;
    if (c < 0x20 || c == 0x7F || c1) {
      char buf[160];
      std::snprintf(buf, sizeof buf,
                    "control character U+%04X at character %zu: a description is one line of "
                    "printable text",
                    code, chars);
      rd.fail(sc.get("description"), "scenario.description", buf);
    }
  }
}

/// [gnss]: the simulated receiver (GnssSpec). Outages are [[start_s, end_s], ...].
GnssSpec parse_gnss(const toml::table& g, const Reader& rd) {
  const std::string p = "gnss.";
  rd.only(
      g, p,
      {"rate_hz", "sigma_pos_m", "sigma_vel_mps", "latency_s", "lever_arm_m", "outages", "seed"});
  GnssSpec spec;
  spec.rate_hz = rd.number(g, p, "rate_hz", spec.rate_hz, 0.01, 100.0);
  if (const auto sp = rd.numbers(g, p, "sigma_pos_m", 2, 0.0, 1e4, false); !sp.empty()) {
    spec.sigma_pos_h_m = sp[0];
    spec.sigma_pos_v_m = sp[1];
  }
  spec.sigma_vel_mps = rd.number(g, p, "sigma_vel_mps", spec.sigma_vel_mps, 0.0, 100.0);
  spec.latency_s = rd.number(g, p, "latency_s", spec.latency_s, 0.0, 8.0);
  if (const auto l = rd.numbers(g, p, "lever_arm_m", 3, -100.0, 100.0, false); !l.empty()) {
    spec.lever_arm_b_m = Vec3d(l[0], l[1], l[2]);
  }
  if (const toml::node* n = g.get("outages"); n != nullptr) {
    const auto* a = n->as_array();
    if (a == nullptr) rd.fail(n, p + "outages", "expected [[start_s, end_s], ...]");
    for (const toml::node& e : *a) {
      const auto* pair = e.as_array();
      const auto num = [&](std::size_t i) -> std::optional<double> {
        if (pair == nullptr || pair->size() != 2) return std::nullopt;
        if (const auto* f = (*pair)[i].as_floating_point()) return f->get();
        if (const auto* k = (*pair)[i].as_integer()) return static_cast<double>(k->get());
        return std::nullopt;
      };
      const auto start = num(0);
      const auto end = num(1);
      if (!start || !end || !std::isfinite(*start) || !std::isfinite(*end) || *start < 0.0 ||
          *end <= *start) {
        rd.fail(&e, p + "outages", "each outage is [start_s, end_s] with 0 <= start_s < end_s");
      }
      spec.outages.emplace_back(*start, *end);
    }
  }
  spec.seed = rd.integer(g, p, "seed", spec.seed);
  return spec;
}

// [aiding] (AidingSpec).
void parse_aiding(const toml::table& root, const Reader& rd, AidingSpec& a) {
  const toml::table* t = rd.table(root, "aiding", false);
  if (t == nullptr) return;
  const std::string p = "aiding.";
  rd.only(*t, p,
          {"enabled", "decimation", "standstill", "window", "false_alarm", "zupt_sigma_mps",
           "zaru_sigma_rps", "bias_sigma_ug", "bias_rw_ug_sqrt_s", "track_heading_sigma_deg"});
  a.enabled = rd.boolean(*t, p, "enabled", true);
  a.decimation = static_cast<std::uint32_t>(rd.number(*t, p, "decimation", 10.0, 1.0, 10000.0));
  a.standstill = rd.boolean(*t, p, "standstill", a.standstill);
  a.window = static_cast<std::uint32_t>(rd.number(*t, p, "window", 100.0, 2.0, 100000.0));
  a.false_alarm = rd.number(*t, p, "false_alarm", a.false_alarm, 1e-9, 0.5);
  a.zupt_sigma_mps = rd.number(*t, p, "zupt_sigma_mps", a.zupt_sigma_mps, 1e-6, 10.0);
  a.zaru_sigma_rps = rd.number(*t, p, "zaru_sigma_rps", a.zaru_sigma_rps, 1e-9, 10.0);
  a.bias_sigma_ug = rd.number(*t, p, "bias_sigma_ug", a.bias_sigma_ug, 1e-3, 1e6);
  a.bias_rw_ug_sqrt_s = rd.number(*t, p, "bias_rw_ug_sqrt_s", a.bias_rw_ug_sqrt_s, 0.0, 1e6);
  a.track_heading_sigma_deg =
      rd.number(*t, p, "track_heading_sigma_deg", a.track_heading_sigma_deg, 0.0, 90.0);
}

/// [[sensors.failures]]: one table per failure, `kind`, `sensor` (1-6, the paper's numbering),
/// `start_s` within the run and the kind's magnitude (sensor_model.hpp, ChannelFailure).
std::vector<ChannelFailure> read_failures(const Reader& rd, const toml::table& sensors,
                                          double duration_s) {
  std::vector<ChannelFailure> out;
  const toml::node* n = sensors.get("failures");
  if (n == nullptr) return out;
  const auto* a = n->as_array();
  if (a == nullptr) {
    rd.fail(n, "sensors.failures", "expected an array of tables ([[sensors.failures]])");
  }
  for (std::size_t i = 0; i < a->size(); ++i) {
    const std::string p = "sensors.failures[" + std::to_string(i) + "].";
    const auto* t = (*a)[i].as_table();
    if (t == nullptr) rd.fail(&(*a)[i], p, "expected a table ([[sensors.failures]])");
    const std::string kind = rd.string(*t, p, "kind", std::nullopt,
                                       {"bias", "ramp", "noise", "saturation", "stuck", "dead"});
    ChannelFailure f;
    f.sensor = static_cast<std::size_t>(rd.number(*t, p, "sensor", std::nullopt, 1, 6)) - 1;
    if (const toml::node* sn = t->get("sensor"); sn->as_integer() == nullptr) {
      rd.fail(sn, p + "sensor", "expected an integer sensor number 1-6");
    }
    f.start_s = rd.number(*t, p, "start_s", std::nullopt, 0.0, duration_s);
    if (kind == "bias") {
      rd.only(*t, p, {"kind", "sensor", "start_s", "bias_mg"});
      f.kind = ChannelFailureKind::kBias;
      f.value = rd.number(*t, p, "bias_mg", std::nullopt, -6e4, 6e4) * 1e-3;
    } else if (kind == "ramp") {
      rd.only(*t, p, {"kind", "sensor", "start_s", "rate_mg_per_s"});
      f.kind = ChannelFailureKind::kRamp;
      f.value = rd.number(*t, p, "rate_mg_per_s", std::nullopt, -6e4, 6e4) * 1e-3;
    } else if (kind == "noise") {
      rd.only(*t, p, {"kind", "sensor", "start_s", "factor"});
      f.kind = ChannelFailureKind::kNoise;
      f.value = rd.number(*t, p, "factor", std::nullopt, 0.0, 1e4);
    } else if (kind == "saturation") {
      rd.only(*t, p, {"kind", "sensor", "start_s", "limit_g"});
      f.kind = ChannelFailureKind::kSaturation;
      f.value = rd.number(*t, p, "limit_g", std::nullopt, 0.0, 60.0);
    } else {
      rd.only(*t, p, {"kind", "sensor", "start_s"});
      f.kind = kind == "stuck" ? ChannelFailureKind::kStuck : ChannelFailureKind::kDead;
    }
    out.push_back(f);
  }
  return out;
}

/// [[board.faults]]: one table per fault, `kind` and `at_s` within the run, then the kind's own
/// keys (scenario.hpp, BoardFault). Two faults of one kind may not overlap, and a fault with a
/// duration must end within the run.
std::vector<BoardFault> read_board_faults(const Reader& rd, const toml::table& board,
                                          double duration_s) {
  std::vector<BoardFault> out;
  const toml::node* n = board.get("faults");
  const auto* a = n == nullptr ? nullptr : n->as_array();
  if (n != nullptr && a == nullptr) {
    rd.fail(n, "board.faults", "expected an array of tables ([[board.faults]])");
  }
  if (a == nullptr) return out;
  for (std::size_t i = 0; i < a->size(); ++i) {
    const std::string p = "board.faults[" + std::to_string(i) + "].";
    const auto* t = (*a)[i].as_table();
    if (t == nullptr) rd.fail(&(*a)[i], p, "expected a table ([[board.faults]])");
    const std::string kind = rd.string(*t, p, "kind", std::nullopt);
    BoardFault f;
    const auto named = std::find(kBoardFaultNames.begin(), kBoardFaultNames.end(), kind);
    if (named == kBoardFaultNames.end()) {
      std::string what = "unknown value '" + kind + "' (expected one of: ";
      for (std::size_t k = 0; k < kBoardFaultNames.size(); ++k) {
        what += k == 0 ? "" : ", ";
        what += kBoardFaultNames[k];
      }
      what += ")";
      rd.fail(t->get("kind"), p + "kind", what);
    }
    f.kind = static_cast<BoardFaultKind>(named - kBoardFaultNames.begin());
    // After the first sample (the loop's reference) and before the last.
    f.at_s = rd.number(*t, p, "at_s", std::nullopt, 0.001, duration_s);
    switch (f.kind) {
      case BoardFaultKind::kMissedEdges:
      case BoardFaultKind::kSilentLine:
      case BoardFaultKind::kReadError:
        rd.only(*t, p, {"kind", "at_s", "count"});
        f.count = static_cast<std::uint32_t>(rd.number(*t, p, "count", std::nullopt, 1, 1000));
        if (t->get("count")->as_integer() == nullptr) {
          rd.fail(t->get("count"), p + "count", "expected an integer 1-1000");
        }
        break;
      case BoardFaultKind::kSaturated:
      case BoardFaultKind::kStuck:
        rd.only(*t, p, {"kind", "at_s", "sensor", "duration_s"});
        f.channel = static_cast<std::size_t>(rd.number(*t, p, "sensor", std::nullopt, 1, 6)) - 1;
        if (t->get("sensor")->as_integer() == nullptr) {
          rd.fail(t->get("sensor"), p + "sensor", "expected an integer sensor number 1-6");
        }
        [[fallthrough]];
      case BoardFaultKind::kCanRefuse:
      case BoardFaultKind::kBusOff:
      case BoardFaultKind::kAdcDead:
        if (f.kind != BoardFaultKind::kSaturated && f.kind != BoardFaultKind::kStuck) {
          rd.only(*t, p, {"kind", "at_s", "duration_s"});
        }
        f.duration_s = rd.number(*t, p, "duration_s", std::nullopt, 0.001, duration_s - f.at_s);
        break;
      default:
        rd.only(*t, p, {"kind", "at_s"});
        break;
    }
    for (const BoardFault& e : out) {
      const double end = e.at_s + std::max(e.duration_s, 1e-3 * e.count);
      if (e.kind == f.kind && f.at_s < end &&
          e.at_s < f.at_s + std::max(f.duration_s, 1e-3 * f.count)) {
        rd.fail(t->get("at_s"), p + "at_s",
                "overlaps an earlier " + kind + " fault (at " + std::to_string(e.at_s) +
                    " s): faults of one kind follow each other");
      }
    }
    out.push_back(f);
  }
  std::sort(out.begin(), out.end(),
            [](const BoardFault& x, const BoardFault& y) { return x.at_s < y.at_s; });
  return out;
}

Scenario parse_root(const toml::table& root, const Reader& rd, const std::string& source) {
  Scenario s;
  s.source = source;
  s.name = std::filesystem::path(source).stem().string();
  rd.only(root, "",
          {"scenario", "gravity", "trajectory", "sensors", "compensator", "calibration", "gnss",
           "aiding", "board"});

  // [scenario]
  const toml::table& sc = *rd.table(root, "scenario", true);
  rd.only(sc, "scenario.", {"name", "description", "duration_s", "rate_hz", "rho_m", "seed"});
  s.name = rd.string(sc, "scenario.", "name", s.name);
  check_name(sc, rd, s.name);
  s.description = rd.string(sc, "scenario.", "description", std::string());
  check_description(sc, rd, s.description);
  s.duration_s = rd.number(sc, "scenario.", "duration_s", std::nullopt, 1e-3, 1e6);
  s.rate_hz = rd.number(sc, "scenario.", "rate_hz", std::nullopt, 1.0, 1e5);
  if (sample_count(s) < 2) {
    char buf[256];
    std::snprintf(buf, sizeof buf,
                  "duration_s %g x rate_hz %g = %.3g sample periods: a run needs at least 2 "
                  "samples, t = 0 and one period later (duration_s >= %g s at this rate)",
                  s.duration_s, s.rate_hz, s.duration_s * s.rate_hz, 1.0 / s.rate_hz);
    rd.fail(sc.get("duration_s"), "scenario.duration_s", buf);
  }
  s.rho_m = rd.number(sc, "scenario.", "rho_m", 0.1, 1e-3, 10.0);
  s.seed = rd.integer(sc, "scenario.", "seed", 1);

  // [gravity]
  if (const toml::table* g = rd.table(root, "gravity", false)) {
    rd.only(*g, "gravity.", {"model", "magnitude_mps2", "latitude_deg", "height_m"});
    const std::string model =
        rd.string(*g, "gravity.", "model", std::string("down"), {"down", "up", "normal"});
    s.gravity = model == "up"     ? ScenarioGravity::kUp
                : model == "down" ? ScenarioGravity::kDown
                                  : ScenarioGravity::kNormal;
    s.gravity_mps2 = rd.number(*g, "gravity.", "magnitude_mps2", nav::kStandardGravity, 0.0, 30.0);
    s.latitude_rad = rd.number(*g, "gravity.", "latitude_deg", 0.0, -90.0, 90.0) * kDegToRad;
    s.height_m = rd.number(*g, "gravity.", "height_m", 0.0, -1e4, 1e5);
  }

  // [trajectory]
  const toml::table& tr = *rd.table(root, "trajectory", true);
  const std::string p = "trajectory.";
  rd.only(tr, p,
          {"kind",           "euler_deg",    "accel_mps2", "axis_b",         "rate_dps",
           "half_angle_deg", "cone_rate_hz", "scale",      "speed_mps",      "turn_amplitude_m",
           "turn_period_s",  "poses",        "dwell_s",    "transition_s",   "extra_poses_g",
           "accel_s",        "cruise_s",     "stop_s",     "initial_stop_s", "weave_amplitude_m",
           "weave_length_m"});
  TrajectorySpec& t = s.trajectory;
  t.kind = rd.string(tr, p, "kind", std::nullopt,
                     {"rest", "constant_acceleration", "spin", "rate_table", "coning", "maneuver",
                      "drive", "stop_and_go", "calibration_poses"});
  check_trajectory_keys(tr, rd, t.kind);
  if (const auto e = rd.numbers(tr, p, "euler_deg", 3, -360.0, 360.0, false); !e.empty()) {
    t.euler0_rad = vec3(e) * kDegToRad;
  }
  const bool spin = t.kind == "spin" || t.kind == "rate_table";
  if (t.kind == "constant_acceleration") {
    t.accel_n_mps2 = vec3(rd.numbers(tr, p, "accel_mps2", 3, -1e3, 1e3, true));
  }
  if (spin) {
    const auto ax = rd.numbers(tr, p, "axis_b", 3, -kBig, kBig, t.kind == "spin");
    if (!ax.empty()) t.axis_b = vec3(ax);
    if (!(t.axis_b.norm() > 0)) rd.fail(tr.get("axis_b"), p + "axis_b", "must not be zero");
    t.rate_rps = rd.number(tr, p, "rate_dps", std::nullopt, -3600.0, 3600.0) * kDegToRad;
  }
  if (t.kind == "coning") {
    t.half_angle_rad = rd.number(tr, p, "half_angle_deg", std::nullopt, 0.0, 89.0) * kDegToRad;
    t.cone_rate_rps = rd.number(tr, p, "cone_rate_hz", std::nullopt, 0.0, 100.0) * 2.0 * M_PI;
  }
  if (t.kind == "maneuver") t.scale = rd.number(tr, p, "scale", 1.0, 0.0, 100.0);
  if (t.kind == "drive") {
    t.speed_mps = rd.number(tr, p, "speed_mps", 10.0, 0.1, 100.0);
    t.turn_amplitude_m = rd.number(tr, p, "turn_amplitude_m", 20.0, 0.0, 1e4);
    t.turn_period_s = rd.number(tr, p, "turn_period_s", 20.0, 1.0, 1e5);
  }
  if (t.kind == "stop_and_go") {
    StopAndGoSpec& g = t.stop_and_go;
    g.speed_mps = rd.number(tr, p, "speed_mps", g.speed_mps, 0.1, 100.0);
    g.accel_s = rd.number(tr, p, "accel_s", g.accel_s, 0.1, 1e3);
    g.cruise_s = rd.number(tr, p, "cruise_s", g.cruise_s, 0.0, 1e5);
    g.stop_s = rd.number(tr, p, "stop_s", g.stop_s, 0.0, 1e5);
    g.initial_stop_s = rd.number(tr, p, "initial_stop_s", g.initial_stop_s, 0.0, 1e5);
    g.weave_amplitude_m = rd.number(tr, p, "weave_amplitude_m", g.weave_amplitude_m, 0.0, 1e4);
    g.weave_length_m = rd.number(tr, p, "weave_length_m", g.weave_length_m, 1.0, 1e6);
  }
  if (t.kind == "calibration_poses") {
    t.poses = rd.string(tr, p, "poses", std::string("both"), {"table2", "table3", "both"});
    t.dwell_s = rd.number(tr, p, "dwell_s", 10.0, 1e-2, 1e5);
    t.transition_s = rd.number(tr, p, "transition_s", 2.0, 1e-2, 1e4);
    const auto extra = rd.numbers(tr, p, "extra_poses_g", 0, -1.5, 1.5, false);
    if (extra.size() % 3 != 0) {
      rd.fail(tr.get("extra_poses_g"), p + "extra_poses_g",
              "takes three numbers (fx, fy, fz in g) per pose");
    }
    for (std::size_t i = 0; i + 2 < extra.size(); i += 3) {
      const Vec3d f(extra[i], extra[i + 1], extra[i + 2]);
      if (!(f.norm() > 0.5)) {
        rd.fail(tr.get("extra_poses_g"), p + "extra_poses_g",
                "a pose's specific force must be about 1 g (at rest: minus gravity, body axes)");
      }
      t.extra_poses_g.push_back(f);
    }
  }

  // [sensors]
  if (const toml::table* se = rd.table(root, "sensors", false)) {
    const std::string q = "sensors.";
    rd.only(*se, q,
            {"orientation", "beta_deg", "alpha_deg", "location_error_mm", "bias_mps2", "noise_mps2",
             "noise_mg", "noise_distribution", "model", "temperature_c", "adc", "scale_v_per_g",
             "failures"});
    const std::string orient =
        rd.string(*se, q, "orientation", std::string("none"), {"none", "paper_table6", "custom"});
    if (orient == "paper_table6") {
      s.misalignment.orientation = nav::paper_table6::misalignment<double>().orientation;
    }
    if (orient == "custom") {
      // Bounded by the compensator's small-angle limit (0.2 rad = 11.5°).
      const auto b = rd.numbers(*se, q, "beta_deg", 6, -11.0, 11.0, true);
      const auto a = rd.numbers(*se, q, "alpha_deg", 6, -11.0, 11.0, true);
      for (std::size_t i = 0; i < 6; ++i) {
        s.misalignment.orientation.beta[i] = b[i] * kDegToRad;
        s.misalignment.orientation.alpha[i] = a[i] * kDegToRad;
      }
    } else if (se->get("beta_deg") != nullptr || se->get("alpha_deg") != nullptr) {
      rd.fail(se->get("beta_deg") != nullptr ? se->get("beta_deg") : se->get("alpha_deg"),
              q + "beta_deg/alpha_deg", "given, but orientation is not \"custom\"");
    }
    if (const auto l = rd.numbers(*se, q, "location_error_mm", 18, -100.0, 100.0, false);
        !l.empty()) {
      for (std::size_t j = 0; j < 6; ++j) {
        s.misalignment.drho_b[j] = Vec3d(l[3 * j], l[3 * j + 1], l[3 * j + 2]) * 1e-3;
      }
    }
    if (const auto b = rd.numbers(*se, q, "bias_mps2", 6, -100.0, 100.0, false); !b.empty()) {
      std::copy(b.begin(), b.end(), s.bias_mps2.begin());
    }
    if (se->get("noise_mps2") != nullptr && se->get("noise_mg") != nullptr) {
      rd.fail(se->get("noise_mg"), q + "noise_mg", "give noise_mps2 or noise_mg, not both");
    }
    s.noise_mps2 = rd.number(*se, q, "noise_mps2", 0.0, 0.0, 100.0);
    if (se->get("noise_mg") != nullptr) {
      s.noise_mps2 = rd.number(*se, q, "noise_mg", 0.0, 0.0, 1e4) * 1e-3 * nav::kStandardGravity;
    }
    s.qa1100 = rd.string(*se, q, "model", std::string("paper"), {"paper", "qa1100"}) == "qa1100";
    s.temperature_c = rd.number(*se, q, "temperature_c", 25.0, -55.0, 125.0);
    s.noise_uniform = rd.string(*se, q, "noise_distribution", std::string("gaussian"),
                                {"gaussian", "uniform"}) == "uniform";
    s.adc = rd.boolean(*se, q, "adc", true);
    if (const auto sf = rd.numbers(*se, q, "scale_v_per_g", 6, 0.1, 10.0, false); !sf.empty()) {
      std::copy(sf.begin(), sf.end(), s.scale_v_per_g.begin());
      if (!s.adc) rd.fail(se->get("scale_v_per_g"), q + "scale_v_per_g", "needs adc = true");
    }
    s.failures = read_failures(rd, *se, s.duration_s);
    if (!s.adc && s.qa1100) {
      rd.fail(se->get("adc"), q + "adc",
              "false (the paper's §6.3 m/s² setting) needs model = \"paper\", not \"qa1100\"");
    }
  }

  // The converter model makes at most 32 kHz (SimulatedAdc::kMaxSampleRateHz): refused while the
  // scenario is read, before any command creates its output.
  if (s.adc && s.rate_hz > SimulatedAdc::kMaxSampleRateHz) {
    char buf[200];
    std::snprintf(buf, sizeof buf,
                  "%g Hz is beyond what the ADS131M06 model converts (at most %g Hz: CLKIN 8.192 "
                  "MHz / (2 x OSR 128)); set [sensors] adc = false for a faster rate",
                  s.rate_hz, SimulatedAdc::kMaxSampleRateHz);
    rd.fail(sc.get("rate_hz"), "scenario.rate_hz", buf);
  }

  // [compensator]
  if (const toml::table* c = rd.table(root, "compensator", false)) {
    rd.only(*c, "compensator.", {"kind", "misalignment"});
    const std::string k =
        rd.string(*c, "compensator.", "kind", std::string("paper"), {"none", "paper", "exact"});
    s.compensator = k == "none"    ? nav::CompensatorKind::kNone
                    : k == "paper" ? nav::CompensatorKind::kPaper
                                   : nav::CompensatorKind::kExact;
    s.misalignment_source = rd.string(*c, "compensator.", "misalignment", std::string("true"),
                                      {"true", "calibrated"}) == "true"
                                ? MisalignmentSource::kTrue
                                : MisalignmentSource::kCalibrated;
  }

  // [calibration]
  if (const toml::table* c = rd.table(root, "calibration", false)) {
    rd.only(*c, "calibration.", {"mean_noise_g", "scale_v_per_g", "seed"});
    s.calibration.mean_noise_g = rd.number(*c, "calibration.", "mean_noise_g", 1e-3, 0.0, 0.1);
    s.calibration.scale_v_per_g = rd.number(*c, "calibration.", "scale_v_per_g", 1.0, 1e-3, 1e3);
    s.calibration.seed = rd.integer(*c, "calibration.", "seed", 7);
  }

  if (const toml::table* g = rd.table(root, "gnss", false)) s.gnss = parse_gnss(*g, rd);
  parse_aiding(root, rd, s.aiding);
  if (const toml::table* b = rd.table(root, "board", false)) {
    rd.only(*b, "board.", {"faults"});
    s.board_faults = read_board_faults(rd, *b, s.duration_s);
  }
  return s;
}

class DriveTrajectory final : public JetTrajectory {
 public:
  DriveTrajectory(double v, double a, double period) : v_(v), a_(a), w_(2.0 * M_PI / period) {}
  void pose(const JetD& t, JetVec3& r_n, JetQuat& q_nb) const override {
    JetD s;
    JetD c;
    sin_cos(w_ * t, s, c);
    r_n = {v_ * t, a_ * (1.0 - c), JetD(0.0)};
    // Heading along the velocity: tan ψ = ẏ/ẋ = A Ω sin Ωt / v, written over jets so that ψ̇
    // and ψ̈ follow exactly. Bank of a coordinated turn: tan φ = v ψ̇ / g.
    const JetD psi = atan(s * (a_ * w_ / v_));
    const double k = a_ * w_ / v_;
    // ψ̇ = k Ω cos Ωt / (1 + k² sin² Ωt), written over jets as well.
    const JetD psi_dot = (k * w_) * c / (1.0 + (k * k) * s * s);
    const JetD phi = atan(psi_dot * (v_ / nav::kStandardGravity));
    q_nb = jet_rot_z(psi) * jet_rot_x(phi);
  }
  std::string name() const override { return "drive"; }

 private:
  double v_;
  double a_;
  double w_;
};

}  // namespace

std::uint64_t sample_count(const Scenario& s) {
  const double periods = s.duration_s * s.rate_hz;
  if (!(periods >= 0.0) || !std::isfinite(periods)) return 0;
  return static_cast<std::uint64_t>(std::floor(periods + 1e-9 * std::max(1.0, periods))) + 1;
}

double covered_duration_s(const Scenario& s) {
  const std::uint64_t n = sample_count(s);
  return n < 1 ? 0.0 : static_cast<double>(n - 1) / s.rate_hz;
}

std::string scenario_name_problem(const std::string& name) {
  const auto allowed = [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '.' ||
           c == '_' || c == '-';
  };
  const bool ok = !name.empty() && name.size() <= kMaxScenarioNameChars &&
                  std::all_of(name.begin(), name.end(), allowed) && name.front() != '.' &&
                  name.front() != '-';
  if (ok) return {};
  std::string shown;
  for (const char c : name) {
    // Control characters shown escaped, so a newline in the name cannot split the message.
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) {
      char esc[8];
      std::snprintf(esc, sizeof esc, "\\x%02x",
                    static_cast<unsigned>(static_cast<unsigned char>(c)));
      shown += esc;
    } else {
      shown += c;
    }
  }
  return "\"" + shown + "\" is not a plain name: the scenario's name becomes the output folder " +
         "(sim-out/<name>), so it takes 1 to " + std::to_string(kMaxScenarioNameChars) +
         " letters, digits, '.', '_' and '-', not starting with '.' or '-' (no '/', no spaces)";
}

HostResult<Scenario> parse_scenario(std::string_view toml_text, const std::string& source) {
  try {
    const toml::table root = toml_text::safe_parse(toml_text, source);
    HostResult<Scenario> r = parse_root(root, Reader(source), source);
    if (r.is_ok()) return r;
    // Messages quote the file's values (an unknown kind, a name): escaped for the terminal.
    HostError e = std::move(r).take_error();
    e.message = drivers::lnx::printable_text(e.message);
    return e;
  } catch (const toml::parse_error& e) {
    std::ostringstream os;
    // The parser's description quotes the offending character raw: escaped for the terminal.
    os << source << ":" << e.source().begin.line
       << ": TOML syntax error: " << drivers::lnx::printable_text(e.description());
    return HostError{ErrorCode::kInvalidArgument, os.str()};
  } catch (const ScenarioParseError& e) {
    return HostError{ErrorCode::kInvalidArgument, drivers::lnx::printable_text(e.what())};
  }
}

std::vector<Vec3d> calibration_pose_vectors(const TrajectorySpec& spec) {
  std::vector<Vec3d> out;
  const auto add = [&out](const std::array<std::array<double, 3>, 6>& table) {
    for (const auto& a : table) out.emplace_back(a[0], a[1], a[2]);
  };
  if (spec.poses != "table3") add(calib::table2_attitudes<double>());
  if (spec.poses != "table2") add(calib::table3_attitudes<double>());
  out.insert(out.end(), spec.extra_poses_g.begin(), spec.extra_poses_g.end());
  return out;
}

std::unique_ptr<Trajectory> make_drive(double speed_mps, double amplitude_m, double period_s) {
  return std::make_unique<DriveTrajectory>(speed_mps, amplitude_m, period_s);
}

HostResult<std::unique_ptr<Trajectory>> make_trajectory(const TrajectorySpec& t) {
  const Quatd q0 = nav::quat_from_euler(t.euler0_rad.x(), t.euler0_rad.y(), t.euler0_rad.z());
  if (t.kind == "rest") return make_rest(q0);
  if (t.kind == "calibration_poses") {
    return std::unique_ptr<Trajectory>(
        make_pose_sequence(calibration_pose_vectors(t), t.dwell_s, t.transition_s));
  }
  if (t.kind == "constant_acceleration") return make_constant_acceleration(t.accel_n_mps2, q0);
  if (t.kind == "spin" || t.kind == "rate_table") {
    // make_spin throws on a zero or non-finite axis (host code); here, on the simulated board's
    // path, it is a value.
    const double n = t.axis_b.norm();
    if (!(n > 0.0) || !std::isfinite(n)) {
      return HostError{ErrorCode::kInvalidArgument,
                       "trajectory '" + t.kind + "': the spin axis must be finite and non-zero"};
    }
    return make_spin(t.axis_b, t.rate_rps, q0);
  }
  if (t.kind == "coning") return make_coning(t.half_angle_rad, t.cone_rate_rps, q0);
  if (t.kind == "maneuver") return make_maneuver(t.scale);
  if (t.kind == "drive") return make_drive(t.speed_mps, t.turn_amplitude_m, t.turn_period_s);
  if (t.kind == "stop_and_go") return make_stop_and_go(t.stop_and_go);
  return HostError{ErrorCode::kInvalidArgument, "unknown trajectory kind '" + t.kind + "'"};
}

}  // namespace gfins::sim
