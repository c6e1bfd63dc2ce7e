// The calibration file saved through lnx::FileParameterStore: a failure at any step of the
// atomic save leaves the previous calibration loadable with its values and no temporary file
// behind, and the message names the file, the step and the OS reason. A truncated file is
// caught by the parser, not handed over as a calibration.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cerrno>
#include <filesystem>

#include "calib_file/calib_test_data.hpp"
#include "drivers_linux/failing_os.hpp"
#include "gfins/calib_file/calibration_file.hpp"
#include "gfins/drivers/lnx/file_parameter_store.hpp"

namespace gfins::calib_file {
namespace {

using drivers::lnx::FileParameterStore;
using drivers::lnx::SaveStep;
using drivers::lnx::testing::FailingOs;
using ::testing::HasSubstr;
using testing::read_text;
using testing::table6_data;
using testing::TempDir;
using testing::write_text;

std::size_t count_entries(const std::filesystem::path& dir) {
  std::size_t n = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir)) n += e.exists() ? 1 : 0;
  return n;
}

class AtomicCalibrationSave : public ::testing::TestWithParam<SaveStep> {
 protected:
  void SetUp() override {
    // Given a good file already in place
    ASSERT_TRUE(save_calibration_file(path_, old_).is_ok());
    old_text_ = read_text(path_);
    new_ = old_;
    new_.sensors[1].scale_v_per_g = 0.4;
    new_.device_id = "gfins-test-02";
  }

  const TempDir dir_;
  const std::filesystem::path path_ = dir_.path() / "cal.toml";
  const CalibrationData old_ = table6_data();
  CalibrationData new_;
  std::string old_text_;
};

TEST_P(AtomicCalibrationSave, AFailureAtAnyStepLeavesOneWholeCalibrationThatLoads) {
  const SaveStep failing = GetParam();
  // When a new calibration is saved and the OS fails one step with EIO
  FailingOs os(failing, EIO);
  auto store = FileParameterStore::open(path_.string(), os);
  ASSERT_TRUE(store.is_ok());
  const FileStatus s = save_calibration(*store.value(), new_, path_.string());
  // Then the save reports the file, the step and the OS reason
  ASSERT_FALSE(s.is_ok());
  EXPECT_EQ(s.code(), ErrorCode::kIoError);
  EXPECT_THAT(s.message(), HasSubstr("calibration file '" + path_.string() + "'"));
  EXPECT_THAT(s.message(), HasSubstr(to_string(failing)));
  EXPECT_THAT(s.message(), HasSubstr("Input/output error"));
  // And the file is one whole calibration: the previous one before the rename, the new after
  const auto loaded = load_calibration_file(path_);
  ASSERT_TRUE(loaded.is_ok()) << loaded.status().message();
  if (failing == SaveStep::kSyncDir) {
    EXPECT_THAT(s.message(), HasSubstr("new file is in place but may not survive a power cut"));
    EXPECT_TRUE(loaded.value() == new_);
  } else {
    EXPECT_THAT(s.message(), HasSubstr("previous file is unchanged"));
    EXPECT_EQ(read_text(path_), old_text_);
    EXPECT_TRUE(loaded.value() == old_);
  }
  EXPECT_EQ(count_entries(dir_.path()), 1u);
}

INSTANTIATE_TEST_SUITE_P(EveryStep, AtomicCalibrationSave,
                         ::testing::Values(SaveStep::kCreateTemp, SaveStep::kWrite,
                                           SaveStep::kSyncFile, SaveStep::kCloseFile,
                                           SaveStep::kRename, SaveStep::kSyncDir));

TEST(CalibrationSaveOnDisk, AMissingDirectoryIsARealOsFailureNamingTheStep) {
  const TempDir dir;
  const auto path = dir.path() / "no-such-dir" / "cal.toml";
  const FileStatus s = save_calibration_file(path, table6_data());
  ASSERT_FALSE(s.is_ok());
  EXPECT_EQ(s.code(), ErrorCode::kIoError);
  EXPECT_THAT(s.message(), HasSubstr("calibration file '" + path.string() + "'"));
  EXPECT_THAT(s.message(), HasSubstr("creating the temporary file failed"));
  EXPECT_THAT(s.message(), HasSubstr("No such file or directory"));
}

TEST(CalibrationSaveOnDisk, AReadOnlyDirectoryRefusesTheSaveAndKeepsTheOldFile) {
  const TempDir dir;
  const auto path = dir.path() / "cal.toml";
  ASSERT_TRUE(save_calibration_file(path, table6_data()).is_ok());
  const std::string before = read_text(path);
  std::filesystem::permissions(dir.path(), std::filesystem::perms::owner_write,
                               std::filesystem::perm_options::remove);
  if (::access(dir.path().c_str(), W_OK) == 0) {
    GTEST_SKIP() << "root ignores directory permissions; sysfs below and the injected failures "
                    "above cover this";
  }
  CalibrationData next = table6_data();
  next.device_id = "gfins-test-04";
  const FileStatus s = save_calibration_file(path, next);
  ASSERT_FALSE(s.is_ok());
  EXPECT_THAT(s.message(), HasSubstr("Permission denied"));
  EXPECT_EQ(read_text(path), before);
  EXPECT_TRUE(load_calibration_file(path).is_ok());
}

TEST(CalibrationSaveOnDisk, ADirectoryNobodyMayCreateFilesInIsARealOsFailure) {
  // sysfs refuses file creation even to root, so this runs whoever runs the tests.
  if (!std::filesystem::is_directory("/sys/kernel")) GTEST_SKIP() << "no sysfs mounted";
  const FileStatus s = save_calibration_file("/sys/gfins-cal.toml", table6_data());
  ASSERT_FALSE(s.is_ok());
  EXPECT_EQ(s.code(), ErrorCode::kIoError);
  EXPECT_THAT(s.message(), HasSubstr("creating the temporary file failed"));
  EXPECT_FALSE(std::filesystem::exists("/sys/gfins-cal.toml"));
}

TEST(CalibrationSaveOnDisk, ATruncatedFileInTheStoreIsDataLossNotACalibration) {
  const TempDir dir;
  const auto path = dir.path() / "cal.toml";
  ASSERT_TRUE(save_calibration_file(path, table6_data()).is_ok());
  const std::string whole = read_text(path);
  write_text(path, whole.substr(0, whole.size() - 40));  // power cut during a non-atomic copy
  auto store = FileParameterStore::open(path.string());
  ASSERT_TRUE(store.is_ok());
  const auto r = load_calibration(*store.value(), path.string());
  ASSERT_FALSE(r.is_ok());
  EXPECT_EQ(r.status().code(), ErrorCode::kDataLoss);
  EXPECT_THAT(r.status().message(), HasSubstr("calibration file '" + path.string() + "'"));
}

TEST(CalibrationSaveOnDisk, ASavedFileIsWorldReadable) {
  const TempDir dir;
  const auto path = dir.path() / "cal.toml";
  ASSERT_TRUE(save_calibration_file(path, table6_data()).is_ok());
  const auto perms = std::filesystem::status(path).permissions();
  EXPECT_NE(perms & std::filesystem::perms::others_read, std::filesystem::perms::none);
}

}  // namespace
}  // namespace gfins::calib_file
