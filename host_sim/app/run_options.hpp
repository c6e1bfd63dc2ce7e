// Checks of the options run, paper63, montecarlo, covariance and gfins-replay share (inputs
// checked before work starts): each returns a message naming what is wrong.
#pragma once

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

/// What the scalar means, for summaries: "float32 (the board's core)" / "double (host reference)".
const char* scalar_text(NavScalar s);

}  // namespace gfins::sim::app
