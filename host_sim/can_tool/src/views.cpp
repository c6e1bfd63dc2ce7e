#include "views.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>

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

class LineView final : public View {
 public:
  explicit LineView(std::FILE* out) : out_(out) {}
  void epoch(const DecodedEpoch& e) override {
    std::fprintf(
        out_,
        "node %u t=%.6f s seq=%s %s rpy=(%.3f %.3f %.3f) deg w=(%.4f %.4f %.4f) rad/s "
        "v=(%.2f %.2f %.2f) m/s r=(%.2f %.2f %.2f) m flags=0x%05X\n",
        e.node_id, col(e, "TimeUs") * 1e-6, format_value(col(e, "SampleCount")).c_str(),
        mode_name(col(e, "Mode")).c_str(), col(e, "Roll") * kRadToDeg, col(e, "Pitch") * kRadToDeg,
        col(e, "Yaw") * kRadToDeg, col(e, "RateX"), col(e, "RateY"), col(e, "RateZ"),
        col(e, "VelN"), col(e, "VelE"), col(e, "VelD"), col(e, "PosN"), col(e, "PosE"),
        col(e, "PosD"),
        std::isnan(col(e, "StatusFlags")) ? 0u : static_cast<unsigned>(col(e, "StatusFlags")));
  }

 private:
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
/// 100 Hz bus does not flood the terminal.
class TableView final : public View {
 public:
  explicit TableView(std::FILE* out) : out_(out) {}
  void epoch(const DecodedEpoch& e) override {
    latest_ = e;
    have_ = true;
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
  void draw() {
    std::fprintf(out_, "\x1b[H\x1b[2J");  // cursor home, clear screen (ANSI)
    std::fprintf(out_, "gfins-can  node %u  epoch counter %u  line %llu  log time %.6f s\n\n",
                 latest_.node_id, latest_.counter, static_cast<unsigned long long>(latest_.line),
                 static_cast<double>(latest_.log_time_us) * 1e-6);
    const auto& cols = columns();
    const can::MessageDef* last = nullptr;
    for (std::size_t i = 0; i < cols.size(); ++i) {
      if (cols[i].message != last) {
        last = cols[i].message;
        std::fprintf(out_, "%s\n", std::string(last->name).c_str());
      }
      const std::string v = latest_.present[i] ? format_value(latest_.values[i]) : std::string("-");
      std::fprintf(out_, "  %-14s %16s %s\n", std::string(cols[i].signal->name).c_str(),
                   v.empty() ? "n/a" : v.c_str(), std::string(cols[i].signal->unit).c_str());
    }
    // A failed write shows again in ferror() when the output is closed (close_output).
    static_cast<void>(std::fflush(out_));
  }
  std::FILE* out_;
  DecodedEpoch latest_;
  bool have_ = false;
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
