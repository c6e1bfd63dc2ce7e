// The host tool's contact with the OS beyond stdio: the live SocketCAN bus (drivers/linux
// SocketCan when the build has it) and starting the plot script without a shell (drivers/linux
// run_program when the build has it). Both are optional at build time so the decoder builds
// everywhere; without them the commands say what is missing.
#pragma once

#include <cstdio>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "gfins/hal/can_bus.hpp"
#include "gfins/status/status.hpp"

namespace gfins::can_tool {

/// Opens a SocketCAN interface (e.g. "can0", "vcan0") as a hal::CanBus.
Result<std::unique_ptr<hal::CanBus>> open_live_bus(const std::string& interface);

/// Runs `argv` (argv[0] = program) without a shell and waits; kUnavailable when it cannot be
/// started, kFailedPrecondition when it ran and failed (message says how, see `detail`).
Status run_without_shell(const std::vector<std::string>& argv, std::string* detail);

/// Calls `fn(line_number, line)` for every line of `f` (1-based, without the newline). A line
/// longer than `max_line` characters is passed truncated to `max_line + 1` characters, so the
/// parser reports it rather than the reader splitting it.
void for_each_line(std::FILE* f, const std::function<void(std::uint64_t, std::string_view)>& fn,
                   std::size_t max_line = 4096);

/// Where the plot script is: $GFINS_SCRIPTS_DIR, else PREFIX/share/gfins/scripts next to the
/// program (installed, or the build tree's share/gfins link); the bare name if neither exists.
std::filesystem::path find_script(const std::string& name);

}  // namespace gfins::can_tool
