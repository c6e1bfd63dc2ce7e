#include "run_options.hpp"

#include <utility>

#include "common.hpp"

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

int prepare_streamed(const std::string& name, const OutputOptions& out,
                     const std::string& dir_prefix, std::initializer_list<const char*> outputs,
                     StreamedCommand& cmd) {
  auto loaded = load(name);
  if (!loaded.is_ok()) return fail(loaded.error(), kExitBadInput);
  cmd.scenario = std::move(loaded).value();
  const Scenario& s = cmd.scenario;
  if (s.trajectory.kind == "calibration_poses") {
    return fail({ErrorCode::kInvalidArgument,
                 "scenario " + s.name + " is a calibration (calibration_poses): nothing navigates"},
                kExitBadInput);
  }
  const auto dir = output_dir(out, dir_prefix + s.name);
  if (!dir.is_ok()) return fail(dir.error(), kExitBadInput);
  const auto scalar = nav_scalar(out.scalar);
  if (!scalar.is_ok()) return fail(scalar.error(), kExitBadInput);
  if (auto c = check_run_size(s, false, /*in_memory=*/false); !c.is_ok()) {
    return fail(c.error(), kExitBadInput);
  }
  if (auto d = make_dir(dir.value(), "gfins-sim", outputs); !d.is_ok()) {
    return fail(d.error(), kExitError);
  }
  cmd.dir = dir.value();
  cmd.scalar = scalar.value();
  return kExitOk;
}

const char* scalar_text(NavScalar s) {
  return s == NavScalar::kFloat ? "float32 core (the board's)" : "double core (host reference)";
}

}  // namespace gfins::sim::app
