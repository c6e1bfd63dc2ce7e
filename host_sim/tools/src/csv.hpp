// A small CSV reader for the calibration tool's inputs: comma-separated, '#' comment lines and
// blank lines skipped, a header row naming the columns, no quoting (every field is a number or
// a short token). Errors name the file and the line.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "gfins/calib_file/calibration_file.hpp"

namespace gfins::tools {

using calib_file::FileResult;
using calib_file::FileStatus;

struct CsvRow {
  int line = 0;  // 1-based line in the file
  std::vector<std::string> cells;
};

struct CsvTable {
  std::string file;  // as given, for messages
  std::vector<std::string> header;
  std::vector<CsvRow> rows;

  /// Index of a column, or -1.
  int column(const std::string& name) const;
  /// "file:line: " for messages.
  std::string where(const CsvRow& row) const;
  /// The number in `col` of `row`; fails naming file, line, column and text.
  FileResult<double> number(const CsvRow& row, int col) const;
  /// An integer in [lo, hi].
  FileResult<std::int64_t> integer(const CsvRow& row, int col, std::int64_t lo,
                                   std::int64_t hi) const;
};

FileResult<CsvTable> read_csv(const std::filesystem::path& path);

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
FileResult<std::vector<MeanRow>> read_means(const std::filesystem::path& path);

/// Poses: columns attitude, fx_g, fy_g, fz_g — the specific force sensed in that pose, body
/// axes, in g (at rest: minus gravity, i.e. "up", as in the paper's Tables 2/3).
struct Pose {
  int attitude = 0;
  std::array<double, 3> f_b_g{};
  int line = 0;
};
FileResult<std::vector<Pose>> read_poses(const std::filesystem::path& path);

/// A raw recording: six columns v1..v6 (volts, sensors in Table 1 order), other columns (e.g. a
/// time stamp) ignored; the sample rate is given separately.
struct Recording {
  std::vector<std::array<double, 6>> samples_v;
};
FileResult<Recording> read_recording(const std::filesystem::path& path);

}  // namespace gfins::tools
