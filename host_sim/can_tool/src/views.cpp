#include "views.hpp"

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <numbers>
#include <stdexcept>
#include <utility>

#include "gfins/can/message_table.hpp"

namespace gfins::can_tool {
namespace {

constexpr double kRadToDeg = 180.0 / std::numbers::pi;

double col(const DecodedEpoch& e, const char* name) {
  const int i = column_index(name);
  return i < 0 ? std::nan("") : e.values[static_cast<std::size_t>(i)];
}

std::string mode_name(double v) {
  if (std::isnan(v)) return "?";
  for (const can::ValueName& m : can::kModeValues) {
    if (m.raw == static_cast<std::int64_t>(v)) return std::string(m.name);
  }
  return std::to_string(static_cast<int>(v));
}

/// A group of signals of one message in the line view: "(v v v)" scaled by `scale` with
/// `decimals` decimals; "-" when the message was not sent in this epoch; "n/a" for a value sent
/// as not available.
std::string group(const DecodedEpoch& e, std::initializer_list<const char*> names, double scale,
                  int decimals) {
  std::string out = "(";
  bool any = false;
  for (const char* name : names) {
    const int i = column_index(name);
    if (i >= 0 && e.present[static_cast<std::size_t>(i)]) any = true;
  }
  if (!any) return "-";
  if (names.size() == 1) out.clear();
  for (const char* name : names) {
    if (out.size() > 1) out += ' ';
    const double v = col(e, name);
    if (std::isnan(v)) {
      out += "n/a";
      continue;
    }
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.*f", decimals, v * scale);
    out += buf;
  }
  return names.size() == 1 ? out : out + ")";
}

/// The values of a decoded input by the names of its signals (message_table.hpp), in table
/// order: what the line and json views print.
std::vector<std::pair<const char*, double>> input_values(const DecodedInput& in) {
  std::vector<std::pair<const char*, double>> v;
  if (in.event.kind == can::InputEventKind::kGnssFix) {
    const can::GnssFix& g = in.event.gnss;
    const double na = std::nan("");
    v.emplace_back("FixId", g.fix_id);
    v.emplace_back("GnssPosN", g.has_position ? g.r_n_m[0] : na);
    v.emplace_back("GnssPosE", g.has_position ? g.r_n_m[1] : na);
    v.emplace_back("GnssPosD", g.has_position ? g.r_n_m[2] : na);
    v.emplace_back("GnssSigmaPosH", g.has_position ? g.sigma_pos_h_m : na);
    v.emplace_back("GnssSigmaPosV", g.has_position ? g.sigma_pos_v_m : na);
    v.emplace_back("GnssVelN", g.has_velocity ? g.v_n_mps[0] : na);
    v.emplace_back("GnssVelE", g.has_velocity ? g.v_n_mps[1] : na);
    v.emplace_back("GnssVelD", g.has_velocity ? g.v_n_mps[2] : na);
    v.emplace_back("GnssSigmaVel", g.has_velocity ? g.sigma_vel_mps : na);
    v.emplace_back("GnssFixAge", g.age_s);
    v.emplace_back("GnssContent", (g.has_position ? 1 : 0) + (g.has_velocity ? 2 : 0));
  } else {
    const can::HeadingFix& h = in.event.heading;
    v.emplace_back("Sequence", h.sequence);
    v.emplace_back("ExtHeading", h.heading_rad);
    v.emplace_back("ExtHeadingSigma", h.sigma_rad);
    v.emplace_back("ExtHeadingAge", h.age_s);
  }
  return v;
}

const char* input_name(const DecodedInput& in) {
  return in.event.kind == can::InputEventKind::kGnssFix ? "GnssFix" : "Heading";
}

/// One line per epoch; a message not sent in the epoch (its divider skipped it) shows as "-".
class LineView final : public View {
 public:
  explicit LineView(std::FILE* out) : out_(out) {}
  void input(const DecodedInput& in) override {
    std::fprintf(out_, "node %u input %s", in.node_id, input_name(in));
    for (const auto& [name, v] : input_values(in)) {
      std::fprintf(out_, " %s=%s", name, std::isnan(v) ? "n/a" : format_value(v).c_str());
    }
    std::putc('\n', out_);
  }
  void epoch(const DecodedEpoch& e) override {
    const double flags = col(e, "StatusFlags");
    std::fprintf(out_, "node %u t=%s s seq=%s %s rpy=%s deg w=%s rad/s v=%s m/s r=%s m flags=%s\n",
                 e.node_id, group(e, {"TimeUs"}, 1e-6, 6).c_str(),
                 format_value(col(e, "SampleCount")).c_str(), mode_name(col(e, "Mode")).c_str(),
                 group(e, {"Roll", "Pitch", "Yaw"}, kRadToDeg, 3).c_str(),
                 group(e, {"RateX", "RateY", "RateZ"}, 1.0, 4).c_str(),
                 group(e, {"VelN", "VelE", "VelD"}, 1.0, 2).c_str(),
                 group(e, {"PosN", "PosE", "PosD"}, 1.0, 2).c_str(),
                 std::isnan(flags) ? "-" : hex_flags(flags).c_str());
  }

 private:
  static std::string hex_flags(double v) {
    char buf[16];
    std::snprintf(buf, sizeof buf, "0x%05X", static_cast<unsigned>(v));
    return buf;
  }
  std::FILE* out_;
};

class CsvView final : public View {
 public:
  explicit CsvView(std::FILE* out) : out_(out) {
    std::fprintf(out_, "node,line,log_time_s");
    for (const Column& c : columns()) std::fprintf(out_, ",%s", c.header.c_str());
    std::putc('\n', out_);
  }
  void epoch(const DecodedEpoch& e) override {
    std::fprintf(out_, "%u,%llu,%.6f", e.node_id, static_cast<unsigned long long>(e.line),
                 static_cast<double>(e.log_time_us) * 1e-6);
    for (double v : e.values) {
      std::putc(',', out_);
      if (!std::isnan(v)) std::fprintf(out_, "%.10g", v);
    }
    std::putc('\n', out_);
  }

 private:
  std::FILE* out_;
};

class JsonView final : public View {
 public:
  explicit JsonView(std::FILE* out) : out_(out) {}
  void input(const DecodedInput& in) override {
    std::fprintf(out_, "{\"node\":%u,\"line\":%llu,\"log_time_s\":%.6f,\"input\":\"%s\"",
                 in.node_id, static_cast<unsigned long long>(in.line),
                 static_cast<double>(in.log_time_us) * 1e-6, input_name(in));
    for (const auto& [name, v] : input_values(in)) {
      if (std::isnan(v)) {
        std::fprintf(out_, ",\"%s\":null", name);
      } else {
        std::fprintf(out_, ",\"%s\":%.10g", name, v);
      }
    }
    std::fprintf(out_, "}\n");
  }
  void epoch(const DecodedEpoch& e) override {
    std::fprintf(out_, "{\"node\":%u,\"line\":%llu,\"log_time_s\":%.6f", e.node_id,
                 static_cast<unsigned long long>(e.line),
                 static_cast<double>(e.log_time_us) * 1e-6);
    const auto& cols = columns();
    for (std::size_t i = 0; i < cols.size(); ++i) {
      const std::string name(cols[i].signal->name);
      if (std::isnan(e.values[i])) {
        std::fprintf(out_, ",\"%s\":null", name.c_str());
      } else {
        std::fprintf(out_, ",\"%s\":%.10g", name.c_str(), e.values[i]);
      }
    }
    std::fprintf(out_, "}\n");
  }

 private:
  std::FILE* out_;
};

/// Redraws at most every kRefresh of wall-clock time (and once at the end), so a fast log or a
/// 100 Hz bus does not flood the terminal. Every signal shows its latest value, with its age
/// (device time since the epoch that carried it) when that was not the latest epoch: messages
/// on slower dividers (Euler, health counters) stay readable between their frames.
class TableView final : public View {
 public:
  explicit TableView(std::FILE* out) : out_(out) {
    const auto& cols = columns();
    values_.assign(cols.size(), std::nan(""));
    seen_at_us_.assign(cols.size(), -1);
    for (const Column& c : cols) name_width_ = std::max(name_width_, c.signal->name.size());
  }
  void epoch(const DecodedEpoch& e) override {
    latest_ = e;
    have_ = true;
    now_us_ = epoch_time_us(e);
    for (std::size_t i = 0; i < e.values.size(); ++i) {
      if (!e.present[i]) continue;
      values_[i] = e.values[i];
      seen_at_us_[i] = now_us_;
    }
    const auto now = std::chrono::steady_clock::now();
    if (now - last_draw_ >= kRefresh) {
      draw();
      last_draw_ = now;
    }
  }
  void finish() override {
    if (have_) draw();
  }

 private:
  static constexpr std::chrono::milliseconds kRefresh{100};
  static constexpr std::int64_t kTimeWrapUs = std::int64_t{1} << 32;  // TimeUs is mod 2^32 µs

  /// Device time of the epoch, unwrapped across the 32-bit wrap; the log time when the epoch
  /// frame carried none.
  std::int64_t epoch_time_us(const DecodedEpoch& e) {
    const double t = col(e, "TimeUs");
    if (std::isnan(t)) return e.log_time_us;
    const auto raw = static_cast<std::int64_t>(t);
    if (have_time_ && raw < last_raw_us_) wraps_ += kTimeWrapUs;
    last_raw_us_ = raw;
    have_time_ = true;
    return raw + wraps_;
  }

  void draw() {
    std::fprintf(out_, "\x1b[H\x1b[2J");  // cursor home, clear screen (ANSI)
    std::fprintf(out_, "gfins-can  node %u  epoch counter %u  line %llu  log time %.6f s\n\n",
                 latest_.node_id, latest_.counter, static_cast<unsigned long long>(latest_.line),
                 static_cast<double>(latest_.log_time_us) * 1e-6);
    const auto& cols = columns();
    const can::MessageDef* last = nullptr;
    const int w = static_cast<int>(name_width_);
    for (std::size_t i = 0; i < cols.size(); ++i) {
      if (cols[i].message != last) {
        last = cols[i].message;
        std::fprintf(out_, "%s\n", std::string(last->name).c_str());
      }
      std::string v = "-";  // never received
      std::string age;
      if (seen_at_us_[i] >= 0) {
        v = std::isnan(values_[i]) ? std::string("n/a") : format_value(values_[i]);
        if (seen_at_us_[i] != now_us_) {
          char buf[40];
          std::snprintf(buf, sizeof buf, "  (%.3f s ago)",
                        static_cast<double>(now_us_ - seen_at_us_[i]) * 1e-6);
          age = buf;
        }
      }
      std::fprintf(out_, "  %-*s %16s %-8s%s\n", w, std::string(cols[i].signal->name).c_str(),
                   v.c_str(), std::string(cols[i].signal->unit).c_str(), age.c_str());
    }
    // A failed write shows again in ferror() when the output is closed (close_output).
    static_cast<void>(std::fflush(out_));
  }
  std::FILE* out_;
  DecodedEpoch latest_;
  bool have_ = false;
  std::vector<double> values_;            // latest value per column
  std::vector<std::int64_t> seen_at_us_;  // device time of the epoch that carried it, -1 never
  std::int64_t now_us_ = 0;
  std::int64_t last_raw_us_ = 0;
  std::int64_t wraps_ = 0;
  bool have_time_ = false;
  std::size_t name_width_ = 0;
  std::chrono::steady_clock::time_point last_draw_{};
};

class NoView final : public View {
 public:
  void epoch(const DecodedEpoch&) override {}
};

}  // namespace

std::string format_value(double v) {
  if (std::isnan(v)) return "";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

ViewKind parse_view(const std::string& name) {
  if (name == "table") return ViewKind::kTable;
  if (name == "line") return ViewKind::kLine;
  if (name == "csv") return ViewKind::kCsv;
  if (name == "json") return ViewKind::kJson;
  if (name == "none") return ViewKind::kNone;
  throw std::invalid_argument("unknown view '" + name + "' (table, line, csv, json, none)");
}

std::unique_ptr<View> make_view(ViewKind kind, std::FILE* out) {
  switch (kind) {
    case ViewKind::kTable:
      return std::make_unique<TableView>(out);
    case ViewKind::kLine:
      return std::make_unique<LineView>(out);
    case ViewKind::kCsv:
      return std::make_unique<CsvView>(out);
    case ViewKind::kJson:
      return std::make_unique<JsonView>(out);
    case ViewKind::kNone:
      break;
  }
  return std::make_unique<NoView>();
}

}  // namespace gfins::can_tool
