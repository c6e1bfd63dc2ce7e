// A fresh empty directory for a test, and reading/writing a whole file: one helper for every
// test folder (they had four copies).
#pragma once

#include <stdlib.h>  // mkdtemp (POSIX)

#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>

namespace gfins::testing {

/// A new empty directory under the system temp dir (`<prefix>-XXXXXX`, made by mkdtemp so two
/// tests never share it), removed with its contents on destruction, even where a test took the
/// owner's permissions away.
class TempDir {
 public:
  explicit TempDir(std::string_view prefix = "gfins-test") {
    std::string t =
        (std::filesystem::temp_directory_path() / (std::string(prefix) + "-XXXXXX")).string();
    if (::mkdtemp(t.data()) == nullptr) {
      throw std::runtime_error("TempDir: mkdtemp failed for " + t);
    }
    path_ = t;
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  ~TempDir() {
    std::error_code ec;
    std::filesystem::permissions(path_, std::filesystem::perms::owner_all,
                                 std::filesystem::perm_options::add, ec);
    std::filesystem::remove_all(path_, ec);
  }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

/// The whole file, bytes as they are ("" when it cannot be opened).
inline std::string read_text(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// Replaces the file's contents with `text`.
inline void write_text(const std::filesystem::path& p, const std::string& text) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out << text;
}

}  // namespace gfins::testing
