// candump log lines, exactly as can-utils writes them (`candump -L`, the file sink) and reads them
// (canplayer, log2asc):
//
//   (1700000000.123456) can0 123#DEADBEEF
//
// seconds '.' microseconds (6 digits) in parentheses, the interface name, then the frame in the
// compact ASCII form of can-utils: 3 hex digits for an 11-bit identifier, 8 for a 29-bit one
// (an error frame has CAN_ERR_FLAG 0x20000000 set there), '#', the data bytes as hex pairs (an
// optional '.' between bytes), or 'R' with an optional length digit for a remote frame, and an
// optional '_' + DLC hex digit (9..F) after 8 bytes. '##' introduces a CAN FD frame, which this
// classic-CAN interface reports as unsupported. Formatting writes upper-case hex like candump.
// No heap: parsing returns views into the line, formatting writes into a caller's buffer.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "gfins/hal/can_bus.hpp"
#include "gfins/status/status.hpp"

namespace gfins::drivers::lnx {

inline constexpr std::uint32_t kCanErrFlag = 0x20000000u;  // linux/can.h CAN_ERR_FLAG
inline constexpr std::size_t kMaxCandumpLine = 96;         // enough for any classic frame line
inline constexpr std::size_t kMaxInterfaceName = 15;       // IFNAMSIZ - 1
/// Log time of simulated time 0 in every log a simulation writes (gfins-fw on the simulated
/// board, gfins-can-gen log, gfins-can gnss): 1700000000 s = 2023-11-14 22:13:20 UTC. A log
/// starting at 0 makes tools that expect wall-clock times misbehave (log2asc repeats its
/// header); a fixed epoch keeps a simulated run's file the same on every run.
inline constexpr std::int64_t kSimulatedLogEpochS = 1700000000;

struct CandumpRecord {
  std::int64_t seconds = 0;
  std::uint32_t micros = 0;
  std::string_view interface;  // view into the parsed line
  hal::CanFrame frame;         // id without flag bits; len = data length (or RTR length)
  bool remote = false;         // 'R': remote transmission request, no data
  bool error_frame = false;    // CAN_ERR_FLAG set in an 8-digit identifier
  std::uint8_t len8_dlc = 0;   // '_' suffix: raw DLC 9..15 of an 8-byte frame, else 0

  std::int64_t time_us() const { return seconds * 1000000 + micros; }
};

/// True for a line can-utils skips as a comment: blank, or not starting with '(' (canplayer and
/// log2asc skip every such line; leading blanks are allowed here, as the parser allows them).
/// A line holding control characters (binary data) is not a comment: it is reported malformed.
bool is_candump_comment(std::string_view line);

/// Parses one line (trailing "\r\n" ignored). Errors are kInvalidArgument with a message naming
/// the part that is wrong ("candump: identifier is not 3 or 8 hex digits", ...), or
/// kUnimplemented for a CAN FD frame.
Result<CandumpRecord> parse_candump_line(std::string_view line);

/// Writes "(sec.usec) iface ID#DATA" (no newline) into `out`; returns the length, or 0 when the
/// buffer is too small, the interface name is empty, too long or holds a character no Linux
/// interface name has (white space, a control character, '/', ':'), or the frame is
/// invalid (len > 8, identifier too large).
std::size_t format_candump_line(std::span<char> out, std::int64_t seconds, std::uint32_t micros,
                                std::string_view interface, const hal::CanFrame& f);

}  // namespace gfins::drivers::lnx
