// Loading and saving the calibration file (TOML, docs/calibration-file.md).
//
// No exception escapes these functions (tomlplusplus throws; it is caught at this boundary).
// Every failure comes back as a FileStatus whose message names the file, the problem and, where
// there is one, the key and line: "calibration file 'cal.toml': line 12: sensor.3.scale_v_per_g
// = -0.33: must be a positive finite number".
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

#include "gfins/calib_file/calibration_data.hpp"
#include "gfins/hal/parameter_store.hpp"
#include "gfins/status/status.hpp"

namespace gfins::calib_file {

/// gfins::Status with an owned message (host side: messages carry file names and values).
class [[nodiscard]] FileStatus {
 public:
  FileStatus() = default;
  FileStatus(ErrorCode code, std::string message) : code_(code), message_(std::move(message)) {}
  static FileStatus ok() { return FileStatus(); }

  bool is_ok() const { return code_ == ErrorCode::kOk; }
  ErrorCode code() const { return code_; }
  const std::string& message() const { return message_; }

 private:
  ErrorCode code_ = ErrorCode::kOk;
  std::string message_;
};

template <typename T>
class [[nodiscard]] FileResult {
 public:
  FileResult(T value) : value_(std::move(value)) {}             // NOLINT: implicit on purpose
  FileResult(FileStatus status) : status_(std::move(status)) {  // NOLINT: implicit on purpose
    if (status_.is_ok()) status_ = FileStatus(ErrorCode::kFailedPrecondition, "no value");
  }
  bool is_ok() const { return value_.has_value(); }
  const FileStatus& status() const { return status_; }
  const T& value() const& { return *value_; }
  T&& value() && { return std::move(*value_); }

 private:
  std::optional<T> value_;
  FileStatus status_;
};

/// The last line of every file; a file that does not end with it is reported as truncated.
inline constexpr std::string_view kEndMarker = "# end of gfins calibration file";

/// The TOML text of `data` (header comment, values, checksum, end marker). Does not validate:
/// save_calibration_file() does. Tests use it to build files with out-of-range values.
std::string to_toml_text(const CalibrationData& data);

/// Parses and checks a calibration file's text; `file_name` only labels the messages.
/// Checks, in order: end marker (truncation), TOML syntax, format version, presence and type of
/// every key and absence of unknown ones, units, checksum, value ranges.
/// Error codes: kDataLoss (truncated, syntax, checksum), kUnimplemented (other format version),
/// kInvalidArgument (missing/unknown/mistyped key, wrong unit), kOutOfRange (value out of range).
FileResult<CalibrationData> parse_calibration_text(std::string_view text,
                                                   std::string_view file_name);

/// Loads the stored bytes and parses them; `name` labels the messages. A store that cannot be
/// read fails with kIoError (the store's message and the OS reason); more than
/// hal::ParameterStore::kMaxBytes is kInvalidArgument (not a calibration file).
FileResult<CalibrationData> load_calibration(hal::ParameterStore& store, std::string_view name);

/// Validates `data` (kOutOfRange naming the key, nothing stored) and replaces the stored bytes
/// with its TOML text through the store's atomic save. A store failure comes back with the
/// store's code and message (for lnx::FileParameterStore: the step that failed, whether the
/// previous file is unchanged, and the OS reason).
FileStatus save_calibration(hal::ParameterStore& store, const CalibrationData& data,
                            std::string_view name);

/// The same on a file at `path` through lnx::FileParameterStore (drivers/linux): the atomic save
/// writes a temporary file in the same folder, fsyncs it, renames it over `path` and fsyncs the
/// folder; a failure before the rename leaves an existing `path` untouched.
FileResult<CalibrationData> load_calibration_file(const std::filesystem::path& path);
FileStatus save_calibration_file(const std::filesystem::path& path, const CalibrationData& data);

}  // namespace gfins::calib_file
