// The version every program prints with --version (docs/install.md, "Versions"): the project
// version from CMakeLists.txt and the git revision the build was made from
// (`git describe --always --dirty` at build time, "unknown" outside a git checkout).
#pragma once

#include <string>

namespace gfins::version {

const char* version();       // "0.1.0"
const char* git_revision();  // "91c268f", "v0.1.0-3-g91c268f-dirty" or "unknown"

/// "<program> <version> (git <revision>)": the one line of `--version`.
inline std::string version_line(const std::string& program) {
  return program + " " + version() + " (git " + git_revision() + ")";
}

}  // namespace gfins::version
