#include "run_options.hpp"

namespace gfins::sim::app {

HostResult<std::string> output_dir(const OutputOptions& o, const std::string& fallback) {
  if (o.dir_given && o.dir.empty()) {
    return HostError{
        ErrorCode::kInvalidArgument,
        "-o/--out is empty: give the output folder (or leave -o out for " + fallback + ")"};
  }
  return o.dir.empty() ? fallback : o.dir;
}

HostResult<NavScalar> nav_scalar(const std::string& name) {
  if (name == "float") return NavScalar::kFloat;
  if (name == "double") return NavScalar::kDouble;
  return HostError{ErrorCode::kInvalidArgument,
                   "--scalar '" + name + "': expected float (the board's core) or double"};
}

const char* scalar_text(NavScalar s) {
  return s == NavScalar::kFloat ? "float32 core (the board's)" : "double core (host reference)";
}

}  // namespace gfins::sim::app
