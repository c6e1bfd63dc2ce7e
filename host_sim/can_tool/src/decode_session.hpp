// What a decode run ends with, and the live source's read loop, apart from the command line so
// that tests can drive them with a fake bus.
#pragma once

#include <cstdint>
#include <functional>

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
/// only is kProblems (its lines are reported), not kNoFrames.
DecodeEnd decode_end(const Summary& s, bool input_error);

/// Feeds the frames `bus` delivers into `dec` while `keep_going()` is true; each receive waits at
/// most `poll_ns`, so `keep_going` is asked at least that often. Frames are numbered from 1 in
/// arrival order and stamped with `now_us()` (the host's receive time). Returns the frames fed.
std::uint64_t feed_live(hal::CanBus& bus, StreamDecoder& dec,
                        const std::function<bool()>& keep_going,
                        const std::function<std::int64_t()>& now_us, std::int64_t poll_ns);

}  // namespace gfins::can_tool
