// hal::ParameterStore on a file (the calibration file of the board, /etc/gfins/calibration.toml).
//
// save() is atomic (rename(2) is the commit point): write a temporary file in the same folder
// (mkostemp, so the rename cannot cross filesystems), fsync it, close it (close reports
// deferred write errors on some filesystems), rename it over the target, fsync the folder so
// the rename itself survives a power cut. A failure before the rename removes the temporary
// file and leaves the previous file byte-identical; a failure of the folder fsync is reported
// (kIoError, SaveStep::kSyncDir) with the new file already in place. Only a regular file (or
// nothing) is replaced: a device node, FIFO, socket, folder or symbolic link at the path is
// refused before anything is written (SaveStep::kCheckTarget), since a rename would put a
// regular file in its place (`-o /dev/full` run as root would replace the machine's /dev/full).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

#include "gfins/drivers/lnx/os.hpp"
#include "gfins/hal/parameter_store.hpp"
#include "gfins/status/status.hpp"

namespace gfins::drivers::lnx {

/// Steps of the atomic save, in order.
enum class SaveStep : std::uint8_t {
  kCheckTarget,  // lstat the target: nothing there, or a regular file
  kCreateTemp,   // mkostemp in the target's folder (+ fchmod 0644)
  kWrite,        // write the whole blob
  kSyncFile,     // fsync the temporary file
  kCloseFile,    // close it
  kRename,       // rename over the target: the commit point
  kSyncDir,      // open + fsync the folder
};
const char* to_string(SaveStep step);

class FileParameterStore final : public hal::ParameterStore {
 public:
  /// Checks the path (non-empty, names a file, below PATH_MAX); touches nothing on disk.
  static Result<std::unique_ptr<FileParameterStore>> open(std::string_view path,
                                                          Os& os = real_os());

  const std::string& path() const { return path_; }
  /// The atomic save without the store's kMaxBytes limit (a tool's CSV output).
  [[nodiscard]] Status replace(std::span<const char> blob) { return do_save(blob); }
  /// Removes the file (see remove_file_durably).
  [[nodiscard]] Status remove();
  /// The step of the last failed save (meaningful only after save() failed).
  SaveStep last_failed_step() const { return last_failed_step_; }

 private:
  FileParameterStore(Os& os, std::string path, std::string dir, std::string temp_template);
  Result<std::size_t> do_load(std::span<char> buffer) override;
  Status do_save(std::span<const char> blob) override;
  Status fail(SaveStep step, int err, bool temp_exists);

  Os& os_;
  std::string path_;
  std::string dir_;
  std::string temp_template_;  // "<dir>/.<name>.tmp-XXXXXX"
  std::string temp_;           // mkostemp fills the X's
  SaveStep last_failed_step_ = SaveStep::kCreateTemp;
};

/// `blob` written to `path` with the store's atomic save and its target check, any size.
Status save_file_atomically(std::string_view path, std::span<const char> blob, Os& os = real_os());

/// Removes the regular file at `path` (nothing there is fine) and fsyncs its folder, so that the
/// removal survives a power cut as a save does. A folder, link, FIFO, device or socket at the path
/// is refused (kInvalidArgument) and left alone.
Status remove_file_durably(std::string_view path, Os& os = real_os());

}  // namespace gfins::drivers::lnx
