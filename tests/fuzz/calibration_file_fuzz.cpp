// libFuzzer target: the calibration file parser (calib_file::parse_calibration_text,
// docs/calibration-file.md). A file whose only fault is its checksum is re-checksummed from the
// parser's own message and parsed again, so the fuzzer reaches the range checks behind the
// checksum. Invariant: an accepted file, written back with to_toml_text, parses to the same data
// (an accepted file reloads identically) and its text is a fixed point.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "fuzz_check.hpp"
#include "gfins/calib_file/calibration_file.hpp"

namespace {

constexpr const char* kTarget = "calibration_file";

// The text of `message` between `open` and `close`, or "" when it has not both.
std::string between(const std::string& message, std::string_view open, std::string_view close) {
  const std::size_t at = message.find(open);
  if (at == std::string::npos) return {};
  const std::size_t from = at + open.size();
  const std::size_t to = message.find(close, from);
  return to == std::string::npos ? std::string() : message.substr(from, to - from);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using gfins::calib_file::parse_calibration_text;
  std::string text(gfins::fuzz::as_text(data, size));
  auto r = parse_calibration_text(text, "fuzz.toml");
  if (!r.is_ok()) {
    const std::string& msg = r.status().message();
    // "... integrity.checksum is "<stored>" but the values give "<computed>"; ..."
    const std::string stored = between(msg, "integrity.checksum is \"", "\" but");
    const std::string computed = between(msg, "the values give \"", "\"");
    if (msg.find("checksum mismatch") != std::string::npos) {
      gfins::fuzz::check(!computed.empty() && !stored.empty(), kTarget,
                         "a checksum mismatch names both checksums");
    }
    if (computed.empty() || stored.empty()) return 0;
    const std::size_t at = text.find(stored);
    if (at == std::string::npos) return 0;
    text.replace(at, stored.size(), computed);
    r = parse_calibration_text(text, "fuzz.toml");
    if (!r.is_ok()) return 0;
  }
  const std::string written = gfins::calib_file::to_toml_text(r.value());
  const auto again = parse_calibration_text(written, "written.toml");
  gfins::fuzz::check(again.is_ok(), kTarget, "an accepted file's canonical text is accepted");
  gfins::fuzz::check(again.value() == r.value(), kTarget, "an accepted file reloads identically");
  gfins::fuzz::check(gfins::calib_file::to_toml_text(again.value()) == written, kTarget,
                     "the canonical text is a fixed point");
  return 0;
}
