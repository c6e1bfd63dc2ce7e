// FileParameterStore on real files in a temporary folder: the atomic save survives a failure at
// every step (the kernel's calls, failed one at a time through lnx::Os), loads report what is
// wrong, and the real kernel's refusals (missing folder, sysfs) come through with errno.
#include "gfins/drivers/lnx/file_parameter_store.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <stdlib.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/un.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "drivers_linux/failing_os.hpp"
#include "gfins/drivers/lnx/error_text.hpp"
#include "support/temp_dir.hpp"

namespace gfins::drivers::lnx {
namespace {

using testing::FailingOs;
using ::testing::HasSubstr;

/// A temporary folder named for these tests (tests/support/temp_dir.hpp).
class TempDir : public gfins::testing::TempDir {
 public:
  TempDir() : gfins::testing::TempDir("gfins-store") {}
};
using gfins::testing::read_text;

std::size_t count_entries(const std::filesystem::path& dir) {
  std::size_t n = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir)) n += e.exists() ? 1 : 0;
  return n;
}

std::span<const char> bytes(const std::string& s) { return {s.data(), s.size()}; }

class AtomicSave : public ::testing::TestWithParam<SaveStep> {
 protected:
  void SetUp() override {
    auto s = FileParameterStore::open(path_.string());
    ASSERT_TRUE(s.is_ok());
    ASSERT_TRUE(s.value()->save(bytes(old_)).is_ok());
  }
  const TempDir dir_;
  const std::filesystem::path path_ = dir_.path() / "cal.toml";
  const std::string old_ = "# the good calibration\nscale = 0.5\n";
  const std::string new_ = "# a newer calibration, longer than the old one\nscale = 0.25\n";
};

TEST_P(AtomicSave, AFailureAtAnyStepLeavesAWholeFileAndNoTemporaryBehind) {
  const SaveStep step = GetParam();
  FailingOs os(step, EIO);
  auto store = FileParameterStore::open(path_.string(), os);
  ASSERT_TRUE(store.is_ok());
  // When the OS fails this step with EIO
  const Status s = store.value()->save(bytes(new_));
  // Then the save reports the step and errno
  ASSERT_FALSE(s.is_ok());
  EXPECT_EQ(s.code(), ErrorCode::kIoError);
  EXPECT_EQ(s.os_error(), EIO);
  EXPECT_EQ(store.value()->last_failed_step(), step);
  EXPECT_THAT(s.message(), HasSubstr(to_string(step)));
  // And the target holds one whole version: the old one before the commit point, the new after
  if (step == SaveStep::kSyncDir) {
    EXPECT_THAT(s.message(), HasSubstr("new file is in place"));
    EXPECT_EQ(read_text(path_), new_);
  } else {
    EXPECT_THAT(s.message(), HasSubstr("previous file is unchanged"));
    EXPECT_EQ(read_text(path_), old_);
  }
  EXPECT_EQ(count_entries(dir_.path()), 1u);
}

INSTANTIATE_TEST_SUITE_P(EveryStep, AtomicSave,
                         ::testing::Values(SaveStep::kCheckTarget, SaveStep::kCreateTemp,
                                           SaveStep::kWrite, SaveStep::kSyncFile,
                                           SaveStep::kCloseFile, SaveStep::kRename,
                                           SaveStep::kSyncDir));

// What a rename would replace with a regular file: each is refused before anything is written
// and is still what it was afterwards (a device node only where mknod is allowed: as root, which
// CI and the board are).
TEST(FileParameterStore, AnythingButARegularFileAtThePathIsRefusedAndLeftAsItWas) {
  const TempDir dir;
  struct Kind {
    const char* name;
    std::filesystem::file_type type;
    const char* said;
  };
  const std::array<Kind, 5> kinds{{
      {"fifo", std::filesystem::file_type::fifo, "is a FIFO"},
      {"sock", std::filesystem::file_type::socket, "is a socket"},
      {"folder", std::filesystem::file_type::directory, "is a folder"},
      {"link", std::filesystem::file_type::symlink, "is a symbolic link"},
      {"null", std::filesystem::file_type::character, "is a device node"},
  }};
  const auto target = dir.path() / "target.toml";
  { std::ofstream(target) << "kept\n"; }
  int made = 0;
  for (const Kind& k : kinds) {
    SCOPED_TRACE(k.name);
    const auto p = dir.path() / k.name;
    int rc = 0;
    switch (k.type) {
      case std::filesystem::file_type::fifo:
        rc = ::mkfifo(p.c_str(), 0600);
        break;
      case std::filesystem::file_type::socket: {
        const int fd = ::socket(AF_UNIX, SOCK_STREAM, 0);
        ASSERT_GE(fd, 0);
        sockaddr_un addr{};
        addr.sun_family = AF_UNIX;
        ASSERT_LT(p.string().size(), sizeof addr.sun_path);
        std::memcpy(addr.sun_path, p.c_str(), p.string().size());
        rc = ::bind(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof addr);
        ::close(fd);
        break;
      }
      case std::filesystem::file_type::directory:
        rc = std::filesystem::create_directory(p) ? 0 : -1;
        break;
      case std::filesystem::file_type::symlink:
        std::filesystem::create_symlink(target, p);
        break;
      default:
        rc = ::mknod(p.c_str(), S_IFCHR | 0600, ::makedev(1, 3));  // /dev/null's numbers
        if (rc != 0 && errno == EPERM) continue;                   // not root: nothing to test
        break;
    }
    ASSERT_EQ(rc, 0) << std::strerror(errno);
    ++made;
    auto store = FileParameterStore::open(p.string());
    ASSERT_TRUE(store.is_ok());
    const Status s = store.value()->save(bytes("replaced = true\n"));
    EXPECT_EQ(s.code(), ErrorCode::kInvalidArgument);
    EXPECT_THAT(s.message(), HasSubstr(k.said));
    EXPECT_THAT(s.message(), HasSubstr("nothing was replaced"));
    EXPECT_EQ(store.value()->last_failed_step(), SaveStep::kCheckTarget);
    EXPECT_EQ(std::filesystem::symlink_status(p).type(), k.type);
  }
  EXPECT_GE(made, 4);
  EXPECT_EQ(read_text(target), "kept\n");  // through the link: not written either
  // Nothing else appeared: the five paths (four without root) and the target
  EXPECT_EQ(count_entries(dir.path()), static_cast<std::size_t>(made) + 1);
}

TEST(FileParameterStore, SaveThenLoadRoundTripsTheBytesAndTheFileIsWorldReadable) {
  const TempDir dir;
  const auto path = dir.path() / "cal.toml";
  auto store = FileParameterStore::open(path.string());
  ASSERT_TRUE(store.is_ok());
  const std::string blob = "a = 1\n\0b = 2\n";  // bytes, not a C string
  ASSERT_TRUE(store.value()->save(bytes(blob)).is_ok());
  std::array<char, 64> buf{};
  const auto n = store.value()->load(buf);
  ASSERT_TRUE(n.is_ok());
  EXPECT_EQ(std::string(buf.data(), n.value()), blob);
  const auto perms = std::filesystem::status(path).permissions();
  EXPECT_NE(perms & std::filesystem::perms::others_read, std::filesystem::perms::none);
}

TEST(FileParameterStore, AFileThatFillsTheBufferExactlyLoadsAndOneByteMoreDoesNot) {
  const TempDir dir;
  auto store = FileParameterStore::open((dir.path() / "p").string());
  ASSERT_TRUE(store.is_ok());
  ASSERT_TRUE(store.value()->save(bytes("12345678")).is_ok());
  std::array<char, 8> exact{};
  EXPECT_EQ(store.value()->load(exact).value(), 8u);
  std::array<char, 7> small{};
  EXPECT_EQ(store.value()->load(small).status().code(), ErrorCode::kResourceExhausted);
}

TEST(FileParameterStore, NothingStoredIsUnavailableWithENOENT) {
  const TempDir dir;
  const auto path = (dir.path() / "absent.toml").string();
  auto store = FileParameterStore::open(path);
  ASSERT_TRUE(store.is_ok());
  std::array<char, 16> buf{};
  const auto r = store.value()->load(buf);
  EXPECT_EQ(r.status().code(), ErrorCode::kUnavailable);
  EXPECT_EQ(r.status().os_error(), ENOENT);
  EXPECT_EQ(describe(path, r.status()),
            path + ": parameter store: no file: No such file or directory (errno 2)");
}

TEST(FileParameterStore, AMissingFolderFailsTheFirstStepWithENOENT) {
  const TempDir dir;
  auto store = FileParameterStore::open((dir.path() / "no-such-dir" / "cal.toml").string());
  ASSERT_TRUE(store.is_ok());
  const Status s = store.value()->save(bytes("x"));
  EXPECT_EQ(s.code(), ErrorCode::kIoError);
  EXPECT_EQ(s.os_error(), ENOENT);
  EXPECT_EQ(store.value()->last_failed_step(), SaveStep::kCreateTemp);
}

TEST(FileParameterStore, AFolderNobodyMayWriteRefusesTheSaveAndKeepsTheOldFile) {
  const TempDir dir;
  const auto path = dir.path() / "cal.toml";
  auto store = FileParameterStore::open(path.string());
  ASSERT_TRUE(store.is_ok());
  ASSERT_TRUE(store.value()->save(bytes("old\n")).is_ok());
  std::filesystem::permissions(dir.path(), std::filesystem::perms::owner_write,
                               std::filesystem::perm_options::remove);
  if (::access(dir.path().c_str(), W_OK) == 0) {
    GTEST_SKIP() << "running as root (permissions ignored); the read-only case below uses sysfs";
  }
  const Status s = store.value()->save(bytes("new\n"));
  EXPECT_EQ(s.os_error(), EACCES);
  EXPECT_EQ(read_text(path), "old\n");
}

TEST(FileParameterStore, AReadOnlyFolderEvenForRootIsARealOsFailure) {
  // sysfs refuses file creation to everybody, root included.
  if (!std::filesystem::is_directory("/sys/kernel")) GTEST_SKIP() << "no sysfs mounted";
  auto store = FileParameterStore::open("/sys/gfins-cal.toml");
  ASSERT_TRUE(store.is_ok());
  const Status s = store.value()->save(bytes("x"));
  EXPECT_EQ(s.code(), ErrorCode::kIoError);
  EXPECT_NE(s.os_error(), 0);
  EXPECT_EQ(store.value()->last_failed_step(), SaveStep::kCreateTemp);
  EXPECT_FALSE(std::filesystem::exists("/sys/gfins-cal.toml"));
}

TEST(FileParameterStore, PathsThatNameNoFileAreRefusedAtOpen) {
  EXPECT_EQ(FileParameterStore::open("").status().code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(FileParameterStore::open("/etc/gfins/").status().code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(FileParameterStore::open("/etc/..").status().code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(FileParameterStore::open(std::string(5000, 'a')).status().code(),
            ErrorCode::kInvalidArgument);
  EXPECT_TRUE(FileParameterStore::open("cal.toml").is_ok());  // relative: the current folder
}

}  // namespace
}  // namespace gfins::drivers::lnx

namespace gfins::drivers::lnx {
namespace {

// remove_file_durably: a regular file goes (its folder synced), nothing there is fine, anything
// else at the path is refused and left, and a failed folder sync is reported with its errno.
TEST(RemoveFileDurably, RemovesARegularFileRefusesAnythingElseAndReportsAFailedSync) {
  const gfins::testing::TempDir dir("gfins-remove");
  const std::filesystem::path file = dir.path() / "can.toml";
  gfins::testing::write_text(file, "x = 1\n");
  EXPECT_TRUE(remove_file_durably(file.string()).is_ok());
  EXPECT_FALSE(std::filesystem::exists(file));
  EXPECT_TRUE(remove_file_durably(file.string()).is_ok()) << "nothing there";
  std::filesystem::create_directory(file);
  const Status folder = remove_file_durably(file.string());
  EXPECT_EQ(folder.code(), ErrorCode::kInvalidArgument);
  EXPECT_TRUE(std::filesystem::is_directory(file)) << "left as it was";
  std::filesystem::remove(file);
  gfins::testing::write_text(file, "x = 1\n");
  // The folder's fsync fails (FailingOs at kSyncDir fails every fsync but a save's temporary's).
  testing::FailingOs os(SaveStep::kSyncDir, EIO);
  const Status sync = remove_file_durably(file.string(), os);
  EXPECT_EQ(sync.code(), ErrorCode::kIoError);
  EXPECT_EQ(sync.os_error(), EIO);
  EXPECT_THAT(std::string(sync.message()), ::testing::HasSubstr("fsync of the folder"));
}

}  // namespace
}  // namespace gfins::drivers::lnx
