// What a decode run ends with, and the live source's read loop, apart from the command line so
// that tests can drive them with a fake bus.
#pragma once

#include <cstdint>
#include <cstdio>
#include <functional>
#include <string>
#include <string_view>

#include "decoder.hpp"
#include "gfins/hal/can_bus.hpp"

namespace gfins::can_tool {

/// How a decode ended; gfins-can maps it to its exit code (--help lists them).
enum class DecodeEnd : std::uint8_t {
  kOk,          // frames decoded, no problem found
  kInputError,  // a file, stdin or the interface could not be read (the rest was decoded)
  kProblems,    // decoded to the end, problems found (malformed lines, bad CRCs, drops, ...)
  kNoFrames,    // readable and without problems, but not one CAN frame arrived: an idle or
                // disconnected bus, a wrong interface or filter, an empty log
};

/// Precedence: an unreadable input, then problems, then "no frames". A log of malformed lines
/// only is kProblems (its lines are reported), not kNoFrames. With a node filter (`node` >= 0),
/// a decode in which that node sent no GfinsEpoch frame is kNoFrames too: nothing to show.
DecodeEnd decode_end(const Summary& s, bool input_error, int node = -1);

/// "0, 3" for the nodes of a Summary::nodes_seen mask ("none" when empty).
std::string node_list(std::uint16_t nodes_seen);

/// A file name as it appears in "FILE:LINE: kind: what" reports and error messages: kept as is
/// when it is printable ASCII without ':' or '"'; otherwise in double quotes with '"', '\\' and
/// every control or non-ASCII byte escaped (\n, \t, \r, \xHH), so one report stays one line and
/// the line number cannot be confused with part of the name.
std::string display_name(std::string_view name);

/// Feeds the candump log `path` ("-" = stdin) line by line into `dec`. Returns "" when it was
/// read to the end, else what went wrong, naming the file: "cannot open ...: <errno text>",
/// "... is a directory, not a candump log", "read error on ...: <errno text>" (the lines before a
/// read error are decoded).
std::string decode_log(const std::string& path, StreamDecoder& dec);

/// The end-of-run summary: counts of lines, frames, epochs, problems per kind, frames per
/// message, comment lines skipped, frames of a leading partial epoch, restarts.
void print_summary(const Summary& s, std::FILE* out);

/// Feeds the frames `bus` delivers into `dec` while `keep_going()` is true; each receive waits at
/// most `poll_ns`, so `keep_going` is asked at least that often. Frames are numbered from 1 in
/// arrival order and stamped with `now_us()` (the host's receive time). Returns the frames fed.
std::uint64_t feed_live(hal::CanBus& bus, StreamDecoder& dec,
                        const std::function<bool()>& keep_going,
                        const std::function<std::int64_t()>& now_us, std::int64_t poll_ns);

}  // namespace gfins::can_tool
