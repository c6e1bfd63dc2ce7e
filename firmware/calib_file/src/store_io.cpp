// Loading and saving the calibration file through a hal::ParameterStore: the bytes come from and
// go to the store (on the board, lnx::FileParameterStore with its atomic save); this file only
// turns them into CalibrationData and back, with messages naming the file. No OS calls here.
#include <cstring>
#include <string>

#include "fields.hpp"
#include "gfins/calib_file/calibration_file.hpp"

namespace gfins::calib_file {
namespace {

// "<what>: <store message>[: strerror]" — the store's static message plus the OS reason.
std::string store_text(const Status& s) {
  std::string out = s.message();
  if (s.os_error() != 0) {
    out += ": ";
    out += std::strerror(s.os_error());
  }
  return out;
}

}  // namespace

FileResult<CalibrationData> load_calibration(hal::ParameterStore& store, std::string_view name) {
  // A calibration file is ~5 kB; the store's limit (64 kB) is far above any real one.
  std::string text(hal::ParameterStore::kMaxBytes, '\0');
  const Result<std::size_t> n = store.load(std::span<char>(text.data(), text.size()));
  if (!n.is_ok()) {
    const Status& s = n.status();
    if (s.code() == ErrorCode::kResourceExhausted) {
      return FileStatus(ErrorCode::kInvalidArgument,
                        detail::file_prefix(name) + "larger than 64 kB: not a calibration file");
    }
    return FileStatus(ErrorCode::kIoError,
                      detail::file_prefix(name) + "cannot read: " + store_text(s));
  }
  text.resize(n.value());
  return parse_calibration_text(text, name);
}

FileStatus save_calibration(hal::ParameterStore& store, const CalibrationData& data,
                            std::string_view name) {
  const Problem problem = validate(data);
  if (problem.found()) {
    return FileStatus(ErrorCode::kOutOfRange, detail::file_prefix(name) + "not saved: " +
                                                  problem.key + " " + problem.problem);
  }
  const std::string text = to_toml_text(data);
  const Status s = store.save(std::span<const char>(text.data(), text.size()));
  if (!s.is_ok()) return FileStatus(s.code(), detail::file_prefix(name) + store_text(s));
  return FileStatus::ok();
}

}  // namespace gfins::calib_file
