#include "decode_session.hpp"

#include <chrono>
#include <thread>

namespace gfins::can_tool {

DecodeEnd decode_end(const Summary& s, bool input_error) {
  if (input_error) return DecodeEnd::kInputError;
  if (s.total_issues() != 0) return DecodeEnd::kProblems;
  if (s.frames == 0) return DecodeEnd::kNoFrames;
  return DecodeEnd::kOk;
}

std::uint64_t feed_live(hal::CanBus& bus, StreamDecoder& dec,
                        const std::function<bool()>& keep_going,
                        const std::function<std::int64_t()>& now_us, std::int64_t poll_ns) {
  std::uint64_t n = 0;
  while (keep_going()) {
    bus.service();
    const Result<hal::CanFrame> f = bus.receive(poll_ns);
    if (!f.is_ok()) {
      // kTimeout waited poll_ns already; an interface that is down answers at once, so wait
      // here instead of spinning until it comes back.
      if (f.status().code() != ErrorCode::kTimeout) {
        std::this_thread::sleep_for(std::chrono::nanoseconds(poll_ns));
      }
      continue;
    }
    dec.feed_frame(++n, now_us(), f.value());
  }
  return n;
}

}  // namespace gfins::can_tool
