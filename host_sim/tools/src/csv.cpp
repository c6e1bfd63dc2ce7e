#include "csv.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <set>
#include <sstream>
#include <string_view>
#include <utility>

#include "gfins/drivers/lnx/printable.hpp"
#include "gfins/drivers/lnx/text_file.hpp"
#include "gfins/host_sim/recording.hpp"

namespace gfins::tools {
namespace {

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t\r");
  return s.substr(b, e - b + 1);
}

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> cells;
  std::string::size_type begin = 0;
  for (;;) {
    const auto comma = line.find(',', begin);
    cells.push_back(trim(line.substr(begin, comma - begin)));
    if (comma == std::string::npos) return cells;
    begin = comma + 1;
  }
}

// A header name or cell from the file as a message shows it: control characters and invalid
// UTF-8 escaped (nothing from the file drives the terminal), cut to 60 characters.
std::string shown(std::string_view text) {
  constexpr std::size_t kMaxShown = 60;
  return drivers::lnx::escape_text(text, false, false, kMaxShown);
}

std::string join(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ", ") + shown(n);
  return out;
}

// Every column of the header must be one of `required` or `optional`, and every required one
// must be there; the message names the offending column and lists the accepted names, so a
// header that differs in one name ("mean" for "mean_v") says what it should be.
HostStatus check_header(const CsvTable& t, const std::vector<std::string>& required,
                        const std::vector<std::string>& optional) {
  std::vector<std::string> accepted = required;
  accepted.insert(accepted.end(), optional.begin(), optional.end());
  const std::string names =
      "accepted columns: " + join(required) +
      (optional.empty() ? "" : " (required), " + join(optional) + " (optional)");
  for (const std::string& h : t.header) {
    bool known = false;
    for (const std::string& a : accepted) known = known || a == h;
    if (!known) {
      std::string msg = t.file + ": header column '" + shown(h) + "' is not a known column; ";
      msg += names;
      msg += "; found: ";
      msg += join(t.header);
      return sim::invalid_argument(msg);
    }
  }
  for (const std::string& r : required) {
    if (t.column(r) < 0) {
      std::string msg = t.file + ": the header has no column '" + r + "'; ";
      msg += names;
      msg += "; found: ";
      msg += join(t.header);
      return sim::invalid_argument(msg);
    }
  }
  return Done{};
}

}  // namespace

int CsvTable::column(const std::string& name) const {
  for (std::size_t i = 0; i < header.size(); ++i) {
    if (header[i] == name) return static_cast<int>(i);
  }
  return -1;
}

std::string CsvTable::where(const CsvRow& row) const {
  return file + ":" + std::to_string(row.line) + ": ";
}

HostResult<double> CsvTable::number(const CsvRow& row, int col) const {
  const std::string& text = row.cells[static_cast<std::size_t>(col)];
  double x = 0.0;
  const auto r = std::from_chars(text.data(), text.data() + text.size(), x);
  if (text.empty() || r.ec != std::errc() || r.ptr != text.data() + text.size() ||
      !std::isfinite(x)) {
    return sim::invalid_argument(where(row) + "column '" +
                                 shown(header[static_cast<std::size_t>(col)]) + "': \"" +
                                 shown(text) + "\" is not a finite number");
  }
  return x;
}

HostResult<std::int64_t> CsvTable::integer(const CsvRow& row, int col, std::int64_t lo,
                                           std::int64_t hi) const {
  const std::string& text = row.cells[static_cast<std::size_t>(col)];
  std::int64_t x = 0;
  const auto r = std::from_chars(text.data(), text.data() + text.size(), x);
  if (text.empty() || r.ec != std::errc() || r.ptr != text.data() + text.size() || x < lo ||
      x > hi) {
    return sim::invalid_argument(where(row) + "column '" +
                                 shown(header[static_cast<std::size_t>(col)]) + "': \"" +
                                 shown(text) + "\" is not an integer in [" + std::to_string(lo) +
                                 ", " + std::to_string(hi) + "]");
  }
  return x;
}

HostResult<CsvTable> read_csv(const std::filesystem::path& path) {
  CsvTable t;
  t.file = drivers::lnx::printable_text(path.string());
  std::string text;
  const Status read =
      drivers::lnx::read_text_file(path.c_str(), drivers::lnx::kMaxTableBytes, text);
  if (!read.is_ok()) {
    return HostError{
        ErrorCode::kIoError,
        drivers::lnx::text_file_error(t.file, read, drivers::lnx::kMaxTableBytes, "a CSV table"),
        0};
  }
  // A spreadsheet's "CSV UTF-8" starts with a byte-order mark (EF BB BF): it is not part of the
  // first line (a comment or the header), so it is dropped.
  constexpr std::string_view kBom = "\xEF\xBB\xBF";
  if (std::string_view(text).substr(0, kBom.size()) == kBom) text.erase(0, kBom.size());
  std::istringstream in(text);
  std::string line;
  int n = 0;
  while (std::getline(in, line)) {
    ++n;
    const std::string s = trim(line);
    if (s.empty() || s[0] == '#') continue;
    auto cells = split(s);
    if (t.header.empty()) {
      t.header = std::move(cells);
      continue;
    }
    if (cells.size() != t.header.size()) {
      return sim::invalid_argument(t.file + ":" + std::to_string(n) + ": " +
                                   std::to_string(cells.size()) + " fields, the header has " +
                                   std::to_string(t.header.size()));
    }
    t.rows.push_back(CsvRow{n, std::move(cells)});
  }
  if (in.bad()) return HostError{ErrorCode::kIoError, t.file + ": read error", 0};
  if (t.header.empty()) return sim::invalid_argument(t.file + ": empty (no header row)");
  if (t.rows.empty()) return sim::invalid_argument(t.file + ": no data rows after the header");
  return t;
}

// Largest |mean| and standard deviation of a sensor output accepted, V: ten times the ±10 V a
// load resistor or converter front end gives; beyond it the column is in another unit.
constexpr double kMaxMeanVolts = 100.0;  // the messages say 100 V

HostResult<std::vector<MeanRow>> read_means(const std::filesystem::path& path) {
  GFINS_TRY(const CsvTable t, read_csv(path));
  GFINS_TRY_STATUS(check_header(t, {"sensor", "attitude", "mean_v"}, {"std_v", "count"}));
  const int c_sensor = t.column("sensor");
  const int c_attitude = t.column("attitude");
  const int c_mean = t.column("mean_v");
  const int c_std = t.column("std_v");
  const int c_count = t.column("count");
  if ((c_std < 0) != (c_count < 0)) {
    return sim::invalid_argument(
        t.file + ": columns std_v and count go together (σ of a mean = std_v/√count)");
  }
  std::vector<MeanRow> rows;
  std::set<std::pair<int, int>> seen;
  for (const CsvRow& r : t.rows) {
    MeanRow m;
    m.line = r.line;
    GFINS_TRY(const auto sensor, t.integer(r, c_sensor, 1, 6));
    GFINS_TRY(const auto attitude, t.integer(r, c_attitude, 1, 1000));
    GFINS_TRY(const auto mean, t.number(r, c_mean));
    if (std::fabs(mean) > kMaxMeanVolts) {
      return sim::invalid_argument(
          t.where(r) +
          "mean_v must be within ±100 V (a sensor output in volts: millivolts "
          "given as volts?)");
    }
    m.sensor = static_cast<int>(sensor);
    m.attitude = static_cast<int>(attitude);
    m.mean_v = mean;
    if (c_std >= 0) {
      GFINS_TRY(const auto sd, t.number(r, c_std));
      GFINS_TRY(const auto count, t.integer(r, c_count, 1, 1'000'000'000));
      if (sd < 0.0) return sim::invalid_argument(t.where(r) + "std_v must not be negative");
      // Finite is not enough: 1e308 V squares to inf in the σ of the fit, and the file was then
      // refused after a "good" verdict. No output of a sensor varies by more than its range.
      if (sd > kMaxMeanVolts) {
        return sim::invalid_argument(
            t.where(r) +
            "std_v must be at most 100 V (a standard deviation of a sensor output "
            "in volts)");
      }
      m.std_v = sd;
      m.count = static_cast<std::uint32_t>(count);
    }
    if (!seen.insert({m.sensor, m.attitude}).second) {
      return sim::invalid_argument(t.where(r) + "sensor " + std::to_string(m.sensor) +
                                   " attitude " + std::to_string(m.attitude) + " appears twice");
    }
    rows.push_back(m);
  }
  return rows;
}

HostResult<std::vector<Pose>> read_poses(const std::filesystem::path& path) {
  GFINS_TRY(const CsvTable t, read_csv(path));
  GFINS_TRY_STATUS(check_header(t, {"attitude", "fx_g", "fy_g", "fz_g"}, {}));
  const int c_att = t.column("attitude");
  const std::array<int, 3> c_f = {t.column("fx_g"), t.column("fy_g"), t.column("fz_g")};
  std::vector<Pose> poses;
  std::set<int> seen;
  for (const CsvRow& r : t.rows) {
    Pose p;
    p.line = r.line;
    GFINS_TRY(const auto att, t.integer(r, c_att, 1, 1000));
    p.attitude = static_cast<int>(att);
    for (std::size_t k = 0; k < 3; ++k) {
      GFINS_TRY(const auto f, t.number(r, c_f[k]));
      p.f_b_g[k] = f;
    }
    const double norm = std::hypot(p.f_b_g[0], p.f_b_g[1], p.f_b_g[2]);
    // At rest the specific force is 1 g; 10 % covers a local gravity model and rounding.
    if (std::fabs(norm - 1.0) > 0.1) {
      return sim::invalid_argument(
          t.where(r) + "|f| = " + std::to_string(norm) +
          " g: a static pose senses 1 g (give the specific force in g, not m/s²)");
    }
    if (!seen.insert(p.attitude).second) {
      return sim::invalid_argument(t.where(r) + "attitude " + std::to_string(p.attitude) +
                                   " appears twice");
    }
    poses.push_back(p);
  }
  return poses;
}

namespace {

bool has_gfr_magic(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::array<char, 8> magic{};
  in.read(magic.data(), static_cast<std::streamsize>(magic.size()));
  return in.gcount() == static_cast<std::streamsize>(magic.size()) && magic == sim::kRecordingMagic;
}

HostResult<Recording> read_gfr(const std::filesystem::path& path) {
  auto file = sim::read_recording(path.string());
  if (!file.is_ok()) {
    return HostError{file.error().code, path.string() + ": " + file.error().message,
                     file.error().byte_offset};
  }
  const sim::Recording& r = file.value();
  Recording rec;
  rec.from_gfr = true;
  rec.rate_hz = r.header.sample_rate_hz;
  rec.volts_per_count = r.header.volts_per_count;
  rec.samples_v.reserve(r.samples.size());
  rec.saturated_mask.reserve(r.samples.size());
  rec.crc_error.reserve(r.samples.size());
  for (const RawSample& smp : r.samples) {
    std::array<double, 6> v{};
    for (std::size_t j = 0; j < 6; ++j) {
      v[j] = static_cast<double>(smp.counts[j]) * rec.volts_per_count[j];
    }
    std::uint8_t sat = rail_mask(smp.counts);
    // The flag says some channel saturated; the codes say which. A flag without a code at full
    // scale (the driver saw it, the code was then clamped) marks every channel.
    if ((smp.flags & sample_flags::kSaturated) != 0 && sat == 0) sat = 0x3F;
    rec.samples_v.push_back(v);
    rec.saturated_mask.push_back(sat);
    rec.crc_error.push_back((smp.flags & sample_flags::kCrcError) != 0 ? 1 : 0);
  }
  if (rec.samples_v.empty())
    return sim::invalid_argument(path.string() + ": the recording holds no samples");
  return rec;
}

}  // namespace

HostResult<Recording> read_recording(const std::filesystem::path& path) {
  if (has_gfr_magic(path)) return read_gfr(path);
  GFINS_TRY(const CsvTable t, read_csv(path));
  std::array<int, 6> c{};
  for (std::size_t j = 0; j < 6; ++j) {
    c[j] = t.column("v" + std::to_string(j + 1));
    if (c[j] < 0) {
      return sim::invalid_argument(
          t.file + ": the header has no column 'v" + std::to_string(j + 1) +
          "'; a CSV recording needs the columns v1, v2, v3, v4, v5, v6 (volts; other "
          "columns such as a time stamp are ignored); found: " +
          join(t.header));
    }
  }
  Recording rec;
  rec.samples_v.reserve(t.rows.size());
  for (const CsvRow& r : t.rows) {
    std::array<double, 6> s{};
    for (std::size_t j = 0; j < 6; ++j) {
      GFINS_TRY(const auto v, t.number(r, c[j]));
      s[j] = v;
    }
    rec.samples_v.push_back(s);
  }
  return rec;
}

}  // namespace gfins::tools

namespace gfins::tools {

HostResult<std::vector<LocationRunRow>> read_location_runs(const std::filesystem::path& path) {
  GFINS_TRY(const CsvTable t, read_csv(path));
  std::vector<std::string> required = {"mounting", "axis_x", "axis_y", "axis_z", "rate_rad_s"};
  for (int j = 1; j <= 6; ++j) required.push_back("mean_v" + std::to_string(j));
  for (int j = 1; j <= 6; ++j) required.push_back("std_v" + std::to_string(j));
  required.push_back("count");
  GFINS_TRY_STATUS(check_header(t, required, {}));
  std::vector<LocationRunRow> rows;
  for (const CsvRow& r : t.rows) {
    LocationRunRow run;
    run.line = r.line;
    GFINS_TRY(const auto m, t.integer(r, t.column("mounting"), 0, 7));
    run.mounting = static_cast<int>(m);
    for (std::size_t k = 0; k < 3; ++k) {
      GFINS_TRY(const auto a, t.number(r, t.column(std::string("axis_") + "xyz"[k])));
      run.axis_up_b[k] = a;
    }
    const double norm = std::hypot(run.axis_up_b[0], run.axis_up_b[1], run.axis_up_b[2]);
    if (!(norm > 0.5)) {
      return sim::invalid_argument(
          t.where(r) + "the table axis (axis_x, axis_y, axis_z) has length " +
          std::to_string(norm) + ": give the upward unit axis in body axes");
    }
    GFINS_TRY(const auto rate, t.number(r, t.column("rate_rad_s")));
    run.rate_rad_s = rate;
    for (std::size_t j = 0; j < 6; ++j) {
      GFINS_TRY(const auto mean, t.number(r, t.column("mean_v" + std::to_string(j + 1))));
      GFINS_TRY(const auto sd, t.number(r, t.column("std_v" + std::to_string(j + 1))));
      if (!(sd > 0.0)) {
        return sim::invalid_argument(t.where(r) + "std_v" + std::to_string(j + 1) +
                                     " must be positive (the noise of the samples, V)");
      }
      run.mean_v[j] = mean;
      run.std_v[j] = sd;
    }
    GFINS_TRY(const auto count, t.integer(r, t.column("count"), 1, 1'000'000'000));
    run.count = static_cast<std::uint32_t>(count);
    rows.push_back(run);
  }
  return rows;
}

}  // namespace gfins::tools
