// The command lines' check for a finite number in a range (gfins-sim, gfins-replay). Its own
// header so that only the two files that build a command line include CLI11 (a large header
// library every other file of the commands would parse for nothing).
#pragma once

#include <CLI/CLI.hpp>

namespace gfins::sim::app {

/// A CLI11 check for a number in [lo, hi] that is finite: CLI::Range alone passes NaN (both of
/// its comparisons are false), and an "inf" or 1e308 parsed into a double would reach the
/// arithmetic. The message names the range.
CLI::Validator finite_range(double lo, double hi);

}  // namespace gfins::sim::app
