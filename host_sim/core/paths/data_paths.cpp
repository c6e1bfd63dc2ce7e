#include "gfins/host_sim/data_paths.hpp"

#include <cstdlib>

namespace gfins::paths {
namespace fs = std::filesystem;

namespace {

// PREFIX candidates above the executable's folder: P/bin/prog -> P (installed); a build-tree
// program sits one or two folders deeper below the build folder (build/<preset>/host_sim/app,
// build/<preset>/tests/host_sim), so three levels cover both and stop well short of /.
constexpr int kPrefixLevels = 3;

}  // namespace

std::string DataLookup::explain(const std::string& what, const std::string& hint) const {
  std::string m = "no " + what + " folder: looked in ";
  for (std::size_t i = 0; i < tried.size(); ++i) m += (i == 0 ? "" : ", ") + tried[i];
  if (tried.empty()) m += "nothing (the program's location is unknown)";
  if (!hint.empty()) m += "; " + hint;
  return m;
}

fs::path executable_path() {
  std::error_code ec;
  fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (ec) return {};
  return exe;
}

DataLookup find_data_dir_from(const fs::path& exe, const std::string& sub, const char* env_var,
                              const std::vector<std::string>& packages) {
  DataLookup out;
  std::error_code ec;
  if (env_var != nullptr) {
    const char* env = std::getenv(env_var);
    if (env != nullptr && env[0] != '\0') {
      // An explicit override is used as given: falling back would hide a typo.
      out.tried.push_back(std::string("$") + env_var + " = " + env);
      if (fs::is_directory(env, ec)) out.dir = env;
      return out;
    }
  }
  if (exe.empty()) return out;
  fs::path prefix = exe.parent_path();
  for (int level = 0; level < kPrefixLevels && prefix.has_parent_path(); ++level) {
    const fs::path up = prefix.parent_path();
    if (up == prefix) break;  // reached the root
    prefix = up;
    for (const auto& pkg : packages) {
      const fs::path candidate = prefix / "share" / pkg / sub;
      out.tried.push_back(candidate.string());
      if (fs::is_directory(candidate, ec)) {
        out.dir = candidate;
        return out;
      }
    }
  }
  return out;
}

DataLookup find_data_dir(const std::string& sub, const char* env_var,
                         const std::vector<std::string>& packages) {
  return find_data_dir_from(executable_path(), sub, env_var, packages);
}

DataLookup scenario_dir() {
  return find_data_dir("scenarios", kScenarioEnv, {"gfins", "gfins-fw"});
}

DataLookup scripts_dir() { return find_data_dir("scripts", kScriptsEnv); }

DataLookup examples_dir() { return find_data_dir("examples", kExamplesEnv); }

}  // namespace gfins::paths
