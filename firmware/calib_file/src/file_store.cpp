// The path-based entry points: a lnx::FileParameterStore (drivers/linux, which holds the POSIX
// calls and the atomic save) under load_calibration() / save_calibration().
#include <string>

#include "gfins/calib_file/calibration_file.hpp"
#include "gfins/drivers/lnx/error_text.hpp"
#include "gfins/drivers/lnx/file_parameter_store.hpp"

namespace gfins::calib_file {

FileResult<CalibrationData> load_calibration_file(const std::filesystem::path& path) {
  auto store = drivers::lnx::FileParameterStore::open(path.string());
  if (!store.is_ok()) {
    return FileStatus(
        store.status().code(),
        drivers::lnx::describe("calibration file '" + path.string() + "'", store.status()));
  }
  return load_calibration(*store.value(), path.string());
}

FileStatus save_calibration_file(const std::filesystem::path& path, const CalibrationData& data) {
  auto store = drivers::lnx::FileParameterStore::open(path.string());
  if (!store.is_ok()) {
    return FileStatus(
        store.status().code(),
        drivers::lnx::describe("calibration file '" + path.string() + "'", store.status()));
  }
  return save_calibration(*store.value(), data, path.string());
}

}  // namespace gfins::calib_file
