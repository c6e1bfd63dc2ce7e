// Saving is atomic: a failure at any step leaves the previous file intact and loadable, and no
// temporary file behind.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cerrno>
#include <filesystem>

#include "calib_file/calib_test_data.hpp"
#include "gfins/calib_file/calibration_file.hpp"

namespace gfins::calib_file {
namespace {

using ::testing::HasSubstr;
using testing::read_text;
using testing::table6_data;
using testing::TempDir;

std::size_t count_entries(const std::filesystem::path& dir) {
  std::size_t n = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    (void)e;
    ++n;
  }
  return n;
}

class AtomicSave : public ::testing::TestWithParam<SaveStep> {
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

TEST_P(AtomicSave, AFailureBeforeTheRenameLeavesThePreviousFileIntact) {
  const SaveStep failing = GetParam();
  // When a new calibration is saved and the OS fails one step with EIO
  SaveOptions options;
  options.inject_failure = [failing](SaveStep s) { return s == failing ? EIO : 0; };
  const FileStatus s = save_calibration_file(path_, new_, options);
  // Then the save reports the step and the OS reason
  ASSERT_FALSE(s.is_ok());
  EXPECT_EQ(s.code(), ErrorCode::kIoError);
  EXPECT_THAT(s.message(), HasSubstr(to_string(failing)));
  EXPECT_THAT(s.message(), HasSubstr("Input/output error"));
  EXPECT_THAT(s.message(), HasSubstr("previous file, if any, is unchanged"));
  // And the previous file is byte-identical, still loads with its values, and is alone
  EXPECT_EQ(read_text(path_), old_text_);
  const auto loaded = load_calibration_file(path_);
  ASSERT_TRUE(loaded.is_ok()) << loaded.status().message();
  EXPECT_TRUE(loaded.value() == old_);
  EXPECT_EQ(count_entries(dir_.path()), 1u);
}

INSTANTIATE_TEST_SUITE_P(EveryStepBeforeTheCommitPoint, AtomicSave,
                         ::testing::Values(SaveStep::kCreateTemp, SaveStep::kWrite,
                                           SaveStep::kSyncFile, SaveStep::kCloseFile,
                                           SaveStep::kRename));

TEST(AtomicSaveCommit, ADirectorySyncFailureAfterTheRenameSaysTheNewFileIsInPlace) {
  const TempDir dir;
  const auto path = dir.path() / "cal.toml";
  ASSERT_TRUE(save_calibration_file(path, table6_data()).is_ok());
  CalibrationData next = table6_data();
  next.device_id = "gfins-test-03";
  SaveOptions options;
  options.inject_failure = [](SaveStep s) { return s == SaveStep::kSyncDir ? EIO : 0; };
  // When only the final directory fsync fails
  const FileStatus s = save_calibration_file(path, next, options);
  // Then the error says the rename happened, and the file holds the new values
  ASSERT_FALSE(s.is_ok());
  EXPECT_THAT(s.message(), HasSubstr("new file is in place but may not survive a power cut"));
  const auto loaded = load_calibration_file(path);
  ASSERT_TRUE(loaded.is_ok());
  EXPECT_EQ(loaded.value().device_id, "gfins-test-03");
  EXPECT_EQ(count_entries(dir.path()), 1u);
}

TEST(AtomicSaveCommit, AMissingDirectoryIsARealOsFailureNamingTheStep) {
  const TempDir dir;
  const auto path = dir.path() / "no-such-dir" / "cal.toml";
  const FileStatus s = save_calibration_file(path, table6_data());
  ASSERT_FALSE(s.is_ok());
  EXPECT_EQ(s.code(), ErrorCode::kIoError);
  EXPECT_THAT(s.message(), HasSubstr("calibration file '" + path.string() + "'"));
  EXPECT_THAT(s.message(), HasSubstr("creating the temporary file failed: No such file"));
}

TEST(AtomicSaveCommit, AReadOnlyDirectoryRefusesTheSaveAndKeepsTheOldFile) {
  if (::geteuid() == 0) {
    GTEST_SKIP() << "root ignores directory permissions; the injected failures above cover this";
  }
  const TempDir dir;
  const auto path = dir.path() / "cal.toml";
  ASSERT_TRUE(save_calibration_file(path, table6_data()).is_ok());
  const std::string before = read_text(path);
  std::filesystem::permissions(dir.path(), std::filesystem::perms::owner_write,
                               std::filesystem::perm_options::remove);
  CalibrationData next = table6_data();
  next.device_id = "gfins-test-04";
  const FileStatus s = save_calibration_file(path, next);
  ASSERT_FALSE(s.is_ok());
  EXPECT_THAT(s.message(), HasSubstr("Permission denied"));
  EXPECT_EQ(read_text(path), before);
  EXPECT_TRUE(load_calibration_file(path).is_ok());
}

TEST(AtomicSaveCommit, ADirectoryNobodyMayCreateFilesInIsARealOsFailure) {
  // sysfs refuses file creation even to root, so this runs whoever runs the tests.
  if (!std::filesystem::is_directory("/sys/kernel")) GTEST_SKIP() << "no sysfs mounted";
  const FileStatus s = save_calibration_file("/sys/gfins-cal.toml", table6_data());
  ASSERT_FALSE(s.is_ok());
  EXPECT_EQ(s.code(), ErrorCode::kIoError);
  EXPECT_THAT(s.message(), HasSubstr("creating the temporary file failed"));
  EXPECT_FALSE(std::filesystem::exists("/sys/gfins-cal.toml"));
}

TEST(AtomicSaveCommit, ASavedFileIsWorldReadable) {
  const TempDir dir;
  const auto path = dir.path() / "cal.toml";
  ASSERT_TRUE(save_calibration_file(path, table6_data()).is_ok());
  const auto perms = std::filesystem::status(path).permissions();
  EXPECT_NE(perms & std::filesystem::perms::others_read, std::filesystem::perms::none);
}

}  // namespace
}  // namespace gfins::calib_file
