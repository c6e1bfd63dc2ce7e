// Checks of the options run, paper63, montecarlo, covariance and gfins-replay share (inputs
// checked before work starts): each returns a message naming what is wrong.
#pragma once

#include <initializer_list>
#include <string>

#include "commands.hpp"
#include "gfins/host_sim/error.hpp"
#include "gfins/host_sim/scenario.hpp"

namespace gfins::sim::app {

/// `-o ""` is refused (it would write into the current folder under a default name the user did
/// not ask for); without -o the folder is `fallback`. Returns the folder to use.
HostResult<std::string> output_dir(const OutputOptions& o, const std::string& fallback);

/// "float" or "double" (CLI11 has checked the spelling; anything else is refused here too).
HostResult<NavScalar> nav_scalar(const std::string& name);

/// What a command that navigates a whole scenario streamed (aided, consistency) checks before
/// any work: the scenario (a calibration refused: nothing navigates), its output folder (made,
/// noting which of `outputs` it replaces), the core's scalar, a run of at least two samples.
struct StreamedCommand {
  Scenario scenario;
  std::string dir;
  NavScalar scalar = NavScalar::kFloat;
};
/// Returns kExitOk and fills `cmd`, or the exit code after the message (kExitBadInput,
/// kExitError when the folder cannot be made).
int prepare_streamed(const std::string& name, const OutputOptions& out,
                     const std::string& dir_prefix, std::initializer_list<const char*> outputs,
                     StreamedCommand& cmd);

/// What the scalar means, for summaries: "float32 (the board's core)" / "double (host reference)".
const char* scalar_text(NavScalar s);

}  // namespace gfins::sim::app
