// A small CSV reader for the calibration tool's inputs: comma-separated, '#' comment lines and
// blank lines skipped, a header row naming the columns, no quoting (every field is a number or
// a short token). Errors name the file and the line.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "gfins/host_sim/error.hpp"

namespace gfins::tools {

// The host's one error type (gfins/host_sim/error.hpp): every reader and every step of the
// calibration returns a HostResult whose HostError message names the file, line and column.
using sim::Done;
using sim::HostError;
using sim::HostResult;
using sim::HostStatus;

struct CsvRow {
  int line = 0;  // 1-based line in the file
  std::vector<std::string> cells;
};

struct CsvTable {
  std::string file;  // as given, control characters escaped: for messages
  std::vector<std::string> header;
  std::vector<CsvRow> rows;

  /// Index of a column, or -1.
  int column(const std::string& name) const;
  /// "file:line: " for messages.
  std::string where(const CsvRow& row) const;
  /// The number in `col` of `row`; fails naming file, line, column and text.
  HostResult<double> number(const CsvRow& row, int col) const;
  /// An integer in [lo, hi].
  HostResult<std::int64_t> integer(const CsvRow& row, int col, std::int64_t lo,
                                   std::int64_t hi) const;
};

HostResult<CsvTable> read_csv(const std::filesystem::path& path);

/// Mean outputs per sensor and attitude (paper Tables 4/5 layout): columns sensor, attitude,
/// mean_v and optionally std_v (sample standard deviation, V) with count (samples averaged).
struct MeanRow {
  int sensor = 0;    // 1..6, Table 1 numbering
  int attitude = 0;  // ≥ 1: Tables 2/3 numbering, or the pose number of a poses file
  double mean_v = 0.0;
  double std_v = 0.0;       // 0 when not given
  std::uint32_t count = 0;  // 0 when not given
  int line = 0;
};
HostResult<std::vector<MeanRow>> read_means(const std::filesystem::path& path);

/// Poses: columns attitude, fx_g, fy_g, fz_g — the specific force sensed in that pose, body
/// axes, in g (at rest: minus gravity, i.e. "up", as in the paper's Tables 2/3).
struct Pose {
  int attitude = 0;
  std::array<double, 3> f_b_g{};
  int line = 0;
};
HostResult<std::vector<Pose>> read_poses(const std::filesystem::path& path);

/// A raw recording, either
///   - a .gfr file (docs/recording-format.md, recognised by its magic): counts × the header's ADC
///     LSB per channel, the header's sample rate, and which samples were not measurements; or
///   - a CSV with six columns v1..v6 (volts, sensors in Table 1 order), other columns (e.g. a
///     time stamp) ignored; the sample rate is given separately.
struct Recording {
  std::vector<std::array<double, 6>> samples_v;
  /// Per sample (.gfr only, else empty): bit j set when channel j sat at the converter's full
  /// scale (code at kAdcCodeMax/kAdcCodeMin, or the sample's kSaturated flag: all channels).
  std::vector<std::uint8_t> saturated_mask;
  /// Per sample (.gfr only, else empty): 1 when the frame's CRC failed (counts not valid).
  std::vector<std::uint8_t> crc_error;
  bool from_gfr = false;
  double rate_hz = 0.0;                     // .gfr header; 0 for CSV
  std::array<double, 6> volts_per_count{};  // .gfr header; zeros for CSV
};
HostResult<Recording> read_recording(const std::filesystem::path& path);

/// One constant-rate rate-table run (location calibration, paper §4.2): the fixture pose
/// ("mounting"), the table axis in body axes pointing UP (the table axis is vertical, so gravity
/// in body axes is −g·axis), the rate and the mean output of each sensor over whole revolutions.
/// CSV columns: mounting, axis_x, axis_y, axis_z, rate_rad_s, mean_v1..mean_v6, std_v1..std_v6,
/// count.
struct LocationRunRow {
  int mounting = 0;  // 0..7, runs of one fixture pose share it
  std::array<double, 3> axis_up_b{};
  double rate_rad_s = 0.0;
  std::array<double, 6> mean_v{};
  std::array<double, 6> std_v{};
  std::uint32_t count = 0;
  int line = 0;
};
HostResult<std::vector<LocationRunRow>> read_location_runs(const std::filesystem::path& path);

}  // namespace gfins::tools
