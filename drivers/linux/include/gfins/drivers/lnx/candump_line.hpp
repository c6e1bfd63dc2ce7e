// One CAN frame as a candump log line, byte for byte what can-utils' `candump -L` (and `-l`)
// writes for a classic frame on one interface:
//
//   (0000000012.345678) can0 123#0102A0FF        11-bit id: 3 hex digits
//   (0000000012.345678) can0 0001ABCD#           29-bit id: 8 hex digits, no data
//
// Seconds are zero-padded to 10 digits, microseconds to 6 (truncated, as the kernel's timeval
// is), hex digits upper case, data bytes without separators, a '\n' at the end. canplayer,
// log2asc and log2long read these lines back.
//
// Standard library only (no OS headers), so the CAN protocol library and host tools can use it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "gfins/hal/can_bus.hpp"

namespace gfins::drivers::lnx {

/// Longest line: "(" + 20-digit seconds + "." + 6 + ") " + 15-char name + " " + 8 + "#" + 16
/// + "\n" = 71 characters; rounded up.
inline constexpr std::size_t kCandumpLineMax = 80;

/// Writes the line for frame `f` sent at `t_ns` (ns since the log's epoch, >= 0) on interface
/// `iface` into `out`, and returns its length including the '\n' (no NUL is written). Returns 0
/// when `out` is too small, t_ns is negative, `iface` is empty or longer than 15 characters or
/// holds a space, or the frame is malformed (len > 8, id beyond its 11/29 bits).
std::size_t format_candump_line(std::span<char> out, std::int64_t t_ns, std::string_view iface,
                                const hal::CanFrame& f);

}  // namespace gfins::drivers::lnx
