// How often the host programs and the simulated board print a progress line when stderr is not
// a terminal (docs/simulation.md, docs/firmware.md). One reading of the environment for all of
// them. std only.
#pragma once

namespace gfins::paths {

/// The environment variable that changes the interval (seconds; meant for tests).
inline constexpr const char* kProgressIntervalEnv = "GFINS_PROGRESS_INTERVAL_S";
/// The interval when the variable is absent or not a number in (0, kMaxProgressIntervalS).
inline constexpr double kDefaultProgressIntervalS = 5.0;
inline constexpr double kMaxProgressIntervalS = 1e6;

/// Seconds between two progress lines: $GFINS_PROGRESS_INTERVAL_S when the whole text is a number
/// in (0, 1e6), else kDefaultProgressIntervalS.
double progress_interval_s();

}  // namespace gfins::paths
