#include "gfins/drivers/lnx/output_paths.hpp"

#include <sys/stat.h>

#include <filesystem>
#include <system_error>

namespace gfins::drivers::lnx {

const char* non_regular_kind(unsigned st_mode) {
  if (S_ISREG(st_mode)) return nullptr;
  if (S_ISLNK(st_mode)) return "a symbolic link";
  if (S_ISDIR(st_mode)) return "a folder";
  if (S_ISCHR(st_mode) || S_ISBLK(st_mode)) return "a device node";
  if (S_ISFIFO(st_mode)) return "a FIFO";
  if (S_ISSOCK(st_mode)) return "a socket";
  return "a special file";
}

bool same_output_file(const std::string& a, const std::string& b) {
  namespace fs = std::filesystem;
  if (a.empty() || b.empty()) return false;
  std::error_code ea;
  std::error_code eb;
  const fs::file_status sa = fs::status(a, ea);
  const fs::file_status sb = fs::status(b, eb);
  if (!ea && !eb && fs::exists(sa) && fs::exists(sb)) {
    if (fs::is_character_file(sa)) return false;
    std::error_code e;
    return fs::equivalent(a, b, e) && !e;
  }
  const fs::path ca = fs::weakly_canonical(fs::absolute(a, ea), ea);
  const fs::path cb = fs::weakly_canonical(fs::absolute(b, eb), eb);
  return !ea && !eb && ca == cb;
}

std::optional<std::string> output_clash(std::span<const NamedOutput> outputs) {
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    for (std::size_t j = i + 1; j < outputs.size(); ++j) {
      if (!same_output_file(outputs[i].path, outputs[j].path)) continue;
      return std::string(outputs[i].what) + " and " + std::string(outputs[j].what) +
             " name the same file '" + outputs[j].path + "': each output needs a file of its own";
    }
  }
  return std::nullopt;
}

}  // namespace gfins::drivers::lnx
