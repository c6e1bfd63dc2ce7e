// libFuzzer target: candump log lines (drivers/lnx/candump.hpp, docs/can-interface.md) and the
// host decoder that reads them (gfins-can's StreamDecoder). When the first input byte is odd,
// every 8-byte frame is given its CRC-8 before the decoder sees it, so the fuzzer reaches the
// sequence, counter and range checks behind the CRC.
// Invariants: a data frame line that parses, formatted again, parses to the same time,
// interface and frame; the decoder's summary agrees with what it reported (issues, epochs,
// frame counts) and every decoded value is a number or NaN (not available), never infinite.
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "decoder.hpp"
#include "fuzz_check.hpp"
#include "gfins/can/signal_codec.hpp"
#include "gfins/drivers/lnx/candump.hpp"

namespace {

constexpr const char* kTarget = "can_log";
namespace lnx = gfins::drivers::lnx;

bool same_frame(const gfins::hal::CanFrame& a, const gfins::hal::CanFrame& b) {
  if (a.id != b.id || a.extended != b.extended || a.len != b.len) return false;
  for (std::size_t i = 0; i < a.len && i < a.data.size(); ++i) {
    if (a.data[i] != b.data[i]) return false;
  }
  return true;
}

void round_trip(const lnx::CandumpRecord& r) {
  if (r.remote || r.error_frame || r.len8_dlc != 0) return;  // not what the formatter writes
  std::array<char, lnx::kMaxCandumpLine> buf{};
  const std::size_t n = lnx::format_candump_line(buf, r.seconds, r.micros, r.interface, r.frame);
  gfins::fuzz::check(n > 0, kTarget, "a parsed data frame line formats");
  const auto again = lnx::parse_candump_line(std::string_view(buf.data(), n));
  gfins::fuzz::check(again.is_ok(), kTarget, "a formatted line parses");
  gfins::fuzz::check(again.value().time_us() == r.time_us(), kTarget, "the time survives");
  gfins::fuzz::check(again.value().interface == r.interface, kTarget, "the interface survives");
  gfins::fuzz::check(same_frame(again.value().frame, r.frame), kTarget, "the frame survives");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const bool seal = (data[0] & 1u) != 0;
  std::string_view text = gfins::fuzz::as_text(data + 1, size - 1);
  std::uint64_t issues = 0;
  std::uint64_t epochs = 0;
  const std::size_t columns = gfins::can_tool::columns().size();
  gfins::can_tool::StreamDecoder dec(
      [&](const gfins::can_tool::DecodedEpoch& e) {
        ++epochs;
        gfins::fuzz::check(e.values.size() == columns, kTarget, "one value per column");
        for (const double v : e.values) {
          gfins::fuzz::check(!std::isinf(v), kTarget, "no infinite value");
        }
      },
      [&](const gfins::can_tool::Issue& i) {
        ++issues;
        gfins::fuzz::check(gfins::fuzz::printable_message(i.text), kTarget,
                           "an issue's text is printable");
      });
  std::uint64_t line_no = 0;
  while (!text.empty()) {
    const std::size_t end = text.find('\n');
    const std::string_view line = text.substr(0, end);
    text = end == std::string_view::npos ? std::string_view{} : text.substr(end + 1);
    ++line_no;
    const auto r = lnx::parse_candump_line(line);
    if (r.is_ok()) round_trip(r.value());
    if (seal && r.is_ok() && !r.value().remote && !r.value().error_frame &&
        r.value().frame.len == 8 && !lnx::is_candump_comment(line)) {
      gfins::hal::CanFrame f = r.value().frame;
      gfins::can::seal_frame(f);
      dec.feed_frame(line_no, r.value().time_us(), f);
    } else {
      dec.feed_line(line_no, line);
    }
  }
  dec.finish();
  const gfins::can_tool::Summary& s = dec.summary();
  gfins::fuzz::check(s.total_issues() == issues, kTarget, "the summary counts every issue");
  gfins::fuzz::check(s.epochs == epochs, kTarget, "the summary counts every epoch");
  gfins::fuzz::check(s.frames_ok <= s.frames, kTarget, "good frames are frames");
  return 0;
}
