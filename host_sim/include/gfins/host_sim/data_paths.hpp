// Where the installed programs find their data (scenarios, plot scripts, examples): relative to
// their own executable, never through a path of the source or build tree compiled into them
// (docs/install.md, "Where the programs find their data"). The same library holds the other
// setting the host programs read from the environment (progress_interval.hpp).
//
// Search order for a data folder `sub` (e.g. "scenarios"):
//   1. the environment variable named for it (GFINS_SCENARIO_DIR, GFINS_SCRIPTS_DIR,
//      GFINS_EXAMPLES_DIR), used as given: a wrong override is an error, not a fallback;
//   2. PREFIX/share/<package>/<sub> for PREFIX = the executable's folder's parent, and up to two
//      more levels up, package = each of `packages` in turn. An installed program in P/bin finds
//      P/share/gfins/<sub>; a program in the build tree (build/<preset>/<folder>/<program>)
//      finds build/<preset>/share/gfins/<sub>, which the configure step links to the sources.
//
// The executable's location comes from /proc/self/exe at run time. std only (no OS headers).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace gfins::paths {

struct DataLookup {
  std::filesystem::path dir;       // the folder found; empty when none was
  std::vector<std::string> tried;  // where it looked, in order (for the error message)

  [[nodiscard]] bool found() const { return !dir.empty(); }
  /// "no <what> folder: looked in A, B, C; <hint>" (for an error message).
  [[nodiscard]] std::string explain(const std::string& what, const std::string& hint) const;
};

/// The environment variables that override the data folders (docs/install.md).
inline constexpr const char* kScenarioEnv = "GFINS_SCENARIO_DIR";
inline constexpr const char* kScriptsEnv = "GFINS_SCRIPTS_DIR";
inline constexpr const char* kExamplesEnv = "GFINS_EXAMPLES_DIR";

/// The running program's path (/proc/self/exe); empty if it cannot be read.
std::filesystem::path executable_path();

/// Finds the data folder `sub` as described at the top of this file. `env_var` may be null.
/// `packages` are the share/ subfolders to try, in order (default: "gfins").
DataLookup find_data_dir(const std::string& sub, const char* env_var,
                         const std::vector<std::string>& packages = {"gfins"});

/// Same, searching from `exe` instead of the running program (tests).
DataLookup find_data_dir_from(const std::filesystem::path& exe, const std::string& sub,
                              const char* env_var, const std::vector<std::string>& packages);

/// The scenarios: GFINS_SCENARIO_DIR, share/gfins/scenarios (gfins-tools package, or
/// `cmake --install`), then share/gfins-fw/scenarios (the gfins-fw package's own copy).
DataLookup scenario_dir();
/// The plot scripts: GFINS_SCRIPTS_DIR, then share/gfins/scripts (gfins-tools package).
DataLookup scripts_dir();
/// Example inputs (a calibration CSV, a candump log): GFINS_EXAMPLES_DIR, then
/// share/gfins/examples (gfins-tools package).
DataLookup examples_dir();

}  // namespace gfins::paths
