// The scenario registry: a built-in name or a file path (scenario.hpp), the built-in folder found
// relative to the running program (data_paths.hpp), suggestions for an unknown name.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "gfins/drivers/lnx/text_file.hpp"
#include "gfins/host_sim/data_paths.hpp"
#include "gfins/host_sim/scenario.hpp"

namespace gfins::sim {
namespace {

namespace fs = std::filesystem;

// Where the built-in scenarios come from, for the message when none are found.
constexpr const char* kScenarioHint =
    "the scenarios are installed with gfins-tools (share/gfins/scenarios) and gfins-fw "
    "(share/gfins-fw/scenarios); set GFINS_SCENARIO_DIR to a folder of *.toml, or give a file "
    "path";

// Levenshtein distance by the two-row dynamic programme (Wagner-Fischer).
std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> prev(b.size() + 1), cur(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) prev[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    cur[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t subst = prev[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1);
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, subst});
    }
    std::swap(prev, cur);
  }
  return prev[b.size()];
}

HostResult<Scenario> load_file(const fs::path& path) {
  std::error_code ec;
  const bool there = fs::exists(path, ec);
  if (ec) {
    // Not "no such file": a symlink loop (ELOOP), a folder on the way that may not be searched
    // (EACCES), a name too long. The system's own words say which.
    return HostError{ErrorCode::kIoError, path.string() + ": cannot look at it: " + ec.message()};
  }
  if (!there) {
    return HostError{ErrorCode::kInvalidArgument, path.string() + ": no such scenario file"};
  }
  if (fs::is_directory(path, ec)) {
    return HostError{ErrorCode::kInvalidArgument,
                     path.string() + ": is a folder, not a scenario file (*.toml)"};
  }
  std::string text;
  const Status read =
      drivers::lnx::read_text_file(path.c_str(), drivers::lnx::kMaxConfigBytes, text);
  if (!read.is_ok()) {
    return HostError{
        read.code() == ErrorCode::kOutOfRange ? ErrorCode::kInvalidArgument : ErrorCode::kIoError,
        drivers::lnx::text_file_error(path.string(), read, drivers::lnx::kMaxConfigBytes,
                                      "a scenario")};
  }
  return parse_scenario(text, path.string());
}

std::string unknown_name_message(const std::string& name, const std::string& builtin_dir) {
  std::string m = "'" + name + "' is not a built-in scenario";
  const auto near = closest_names(name, builtin_scenarios(builtin_dir));
  if (!near.empty()) {
    m += "; closest:";
    for (std::size_t i = 0; i < near.size(); ++i) m += (i == 0 ? " " : ", ") + near[i];
  }
  m += "; `gfins-sim list` shows them all (in " + builtin_dir + ")";
  std::error_code ec;
  if (fs::exists(name, ec)) {
    m += "; for the file '" + name + "' in the current folder write ./" + name;
  }
  return m;
}

}  // namespace

bool is_scenario_path(std::string_view arg) {
  constexpr std::string_view kExt = ".toml";
  return arg.find('/') != std::string_view::npos ||
         (arg.size() >= kExt.size() && arg.substr(arg.size() - kExt.size()) == kExt);
}

HostResult<Scenario> load_scenario(const std::string& file_or_name,
                                   const std::string& builtin_dir) {
  if (file_or_name.empty()) {
    return HostError{ErrorCode::kInvalidArgument,
                     "empty scenario: give a built-in name (`gfins-sim list`) or a file path"};
  }
  if (is_scenario_path(file_or_name)) return load_file(file_or_name);
  const fs::path builtin = fs::path(builtin_dir) / (file_or_name + ".toml");
  std::error_code ec;
  if (builtin_dir.empty() || !fs::is_regular_file(builtin, ec)) {
    return HostError{ErrorCode::kInvalidArgument, unknown_name_message(file_or_name, builtin_dir)};
  }
  return load_file(builtin);
}

HostResult<std::string> builtin_scenario_dir() {
  const paths::DataLookup d = paths::scenario_dir();
  if (!d.found()) {
    return HostError{ErrorCode::kUnavailable, d.explain("built-in scenario", kScenarioHint)};
  }
  return d.dir.string();
}

HostResult<Scenario> load_scenario(const std::string& file_or_name) {
  if (is_scenario_path(file_or_name)) return load_file(file_or_name);
  const auto dir = builtin_scenario_dir();
  if (!dir.is_ok()) {
    return HostError{dir.error().code, "scenario '" + file_or_name + "': " + dir.error().message};
  }
  return load_scenario(file_or_name, dir.value());
}

std::vector<std::string> builtin_scenarios(const std::string& builtin_dir) {
  std::vector<std::string> names;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(builtin_dir, ec)) {
    if (e.path().extension() == ".toml") names.push_back(e.path().stem().string());
  }
  std::sort(names.begin(), names.end());
  return names;
}

std::vector<std::string> closest_names(std::string_view name, const std::vector<std::string>& names,
                                       std::size_t max_count) {
  // A typo changes a few letters; more than a third of the name is another name.
  const std::size_t limit = std::max<std::size_t>(2, name.size() / 3);
  std::vector<std::pair<std::size_t, std::string>> scored;
  for (const auto& n : names) {
    const bool contains = !name.empty() && (n.find(name) != std::string::npos ||
                                            name.find(n) != std::string_view::npos);
    const std::size_t d = edit_distance(name, n);
    if (d <= limit || contains) scored.emplace_back(d, n);
  }
  std::sort(scored.begin(), scored.end());
  std::vector<std::string> out;
  for (std::size_t i = 0; i < scored.size() && i < max_count; ++i) out.push_back(scored[i].second);
  return out;
}

}  // namespace gfins::sim
