#include "gfins/drivers/lnx/candump.hpp"

namespace gfins::drivers::lnx {
namespace {

int hex_digit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  return -1;
}

bool is_space(char c) { return c == ' ' || c == '\t'; }

// A character a Linux interface name can hold (net/core/dev.c, dev_valid_name: no '/', ':' or
// white space; control characters are refused here too, so no log line drives a terminal).
bool interface_char(char c) {
  const auto u = static_cast<unsigned char>(c);
  return u > 0x20 && u != 0x7F && c != '/' && c != ':';
}

bool valid_interface(std::string_view name) {
  if (name.empty() || name.size() > kMaxInterfaceName) return false;
  for (const char c : name) {
    if (!interface_char(c)) return false;
  }
  return true;
}

Status bad(const char* what) { return Status(ErrorCode::kInvalidArgument, what); }

/// Parses an unsigned decimal number of at most `max_digits` digits at the front of `s`.
bool take_decimal(std::string_view& s, std::size_t max_digits, std::uint64_t* v) {
  std::size_t n = 0;
  std::uint64_t x = 0;
  while (n < s.size() && s[n] >= '0' && s[n] <= '9') {
    if (n == max_digits) return false;
    x = x * 10 + static_cast<std::uint64_t>(s[n] - '0');
    ++n;
  }
  if (n == 0) return false;
  *v = x;
  s.remove_prefix(n);
  return true;
}

std::string_view take_token(std::string_view& s) {
  while (!s.empty() && is_space(s.front())) s.remove_prefix(1);
  std::size_t n = 0;
  while (n < s.size() && !is_space(s[n])) ++n;
  const std::string_view t = s.substr(0, n);
  s.remove_prefix(n);
  return t;
}

Status parse_frame(std::string_view t, CandumpRecord& r) {
  const std::size_t hash = t.find('#');
  if (hash == std::string_view::npos) return bad("candump: frame has no '#'");
  const std::string_view id = t.substr(0, hash);
  if (id.size() != 3 && id.size() != 8) {
    return bad("candump: identifier is not 3 or 8 hex digits");
  }
  std::uint32_t v = 0;
  for (char c : id) {
    const int d = hex_digit(c);
    if (d < 0) return bad("candump: identifier is not hexadecimal");
    v = (v << 4) | static_cast<std::uint32_t>(d);
  }
  if (id.size() == 3) {
    if (v > hal::CanFrame::kMaxStandardId) return bad("candump: 11-bit identifier above 0x7FF");
    r.frame.id = v;
    r.frame.extended = false;
  } else {
    if ((v & kCanErrFlag) != 0) {
      r.error_frame = true;
      v &= hal::CanFrame::kMaxExtendedId;
    } else if (v > hal::CanFrame::kMaxExtendedId) {
      return bad("candump: 29-bit identifier has flag bits set");
    }
    r.frame.id = v;
    r.frame.extended = true;
  }
  std::string_view d = t.substr(hash + 1);
  if (!d.empty() && d.front() == '#') {
    return Status(ErrorCode::kUnimplemented, "candump: CAN FD frame ('##') on a classic-CAN bus");
  }
  if (!d.empty() && (d.front() == 'R' || d.front() == 'r')) {
    r.remote = true;
    d.remove_prefix(1);
    if (!d.empty() && d.front() != '_') {
      const int len = hex_digit(d.front());
      if (len < 0 || len > 8) return bad("candump: remote frame length is not 0..8");
      r.frame.len = static_cast<std::uint8_t>(len);
      d.remove_prefix(1);
    }
  } else {
    std::uint8_t n = 0;
    while (!d.empty() && d.front() != '_') {
      if (d.front() == '.') {
        d.remove_prefix(1);
        continue;
      }
      if (d.size() < 2) return bad("candump: odd number of data hex digits");
      const int hi = hex_digit(d[0]);
      const int lo = hex_digit(d[1]);
      if (hi < 0 || lo < 0) return bad("candump: data is not hexadecimal");
      if (n == hal::CanFrame::kMaxLen) return bad("candump: more than 8 data bytes");
      r.frame.data[n++] = static_cast<std::uint8_t>((hi << 4) | lo);
      d.remove_prefix(2);
    }
    r.frame.len = n;
  }
  if (!d.empty()) {  // '_' + DLC
    if (d.size() != 2) return bad("candump: '_' must be followed by one DLC hex digit");
    const int dlc = hex_digit(d[1]);
    if (r.frame.len != hal::CanFrame::kMaxLen || dlc < 9) {
      return bad("candump: '_' DLC needs 8 data bytes and a DLC of 9..F");
    }
    r.len8_dlc = static_cast<std::uint8_t>(dlc);
  }
  return Status::ok();
}

}  // namespace

bool is_candump_comment(std::string_view line) {
  while (!line.empty() && (line.back() == '\n' || line.back() == '\r')) line.remove_suffix(1);
  while (!line.empty() && is_space(line.front())) line.remove_prefix(1);
  if (line.empty()) return true;
  if (line.front() == '(') return false;
  for (char c : line) {
    const auto u = static_cast<unsigned char>(c);
    if ((u < 0x20 && c != '\t') || u == 0x7F) return false;
  }
  return true;
}

Result<CandumpRecord> parse_candump_line(std::string_view line) {
  while (!line.empty() && (line.back() == '\n' || line.back() == '\r')) line.remove_suffix(1);
  while (!line.empty() && is_space(line.front())) line.remove_prefix(1);
  if (line.empty()) return bad("candump: empty line");
  CandumpRecord r;
  if (line.front() != '(') return bad("candump: line does not start with '(' timestamp");
  line.remove_prefix(1);
  std::uint64_t sec = 0;
  std::uint64_t usec = 0;
  if (!take_decimal(line, 18, &sec)) return bad("candump: timestamp seconds are not a number");
  if (line.empty() || line.front() != '.') return bad("candump: timestamp has no '.'");
  line.remove_prefix(1);
  if (!take_decimal(line, 6, &usec)) {
    return bad("candump: timestamp fraction is not 1..6 decimal digits");
  }
  if (line.empty() || line.front() != ')') return bad("candump: timestamp has no ')'");
  line.remove_prefix(1);
  if (line.empty() || !is_space(line.front())) return bad("candump: no space after timestamp");
  // CandumpRecord::time_us() is seconds · 10^6 + micros in an int64: 9,223,372,036,853 s (about
  // 292,000 years) is the last second it holds.
  constexpr std::uint64_t kMaxSeconds = 9'223'372'036'853;
  if (sec > kMaxSeconds) return bad("candump: timestamp seconds beyond 9223372036853");
  r.seconds = static_cast<std::int64_t>(sec);
  r.micros = static_cast<std::uint32_t>(usec);
  r.interface = take_token(line);
  if (r.interface.empty()) return bad("candump: interface name missing");
  if (r.interface.size() > kMaxInterfaceName) return bad("candump: interface name too long");
  if (!valid_interface(r.interface)) {
    return bad("candump: interface name holds a control character, '/' or ':'");
  }
  const std::string_view frame = take_token(line);
  if (frame.empty()) return bad("candump: frame missing");
  const Status s = parse_frame(frame, r);
  if (!s.is_ok()) return s;
  // can-utils reads the line with sscanf and ignores what follows the frame (newer candump
  // versions append a direction flag " R"/" T"); so do we.
  return r;
}

std::size_t format_candump_line(std::span<char> out, std::int64_t seconds, std::uint32_t micros,
                                std::string_view interface, const hal::CanFrame& f) {
  if (!valid_interface(interface) || micros > 999999 || seconds < 0 ||
      f.len > hal::CanFrame::kMaxLen ||
      f.id > (f.extended ? hal::CanFrame::kMaxExtendedId : hal::CanFrame::kMaxStandardId)) {
    return 0;
  }
  static constexpr char kHex[] = "0123456789ABCDEF";
  char buf[kMaxCandumpLine];
  std::size_t n = 0;
  auto put = [&](char c) { buf[n++] = c; };
  put('(');
  // Seconds zero-padded to 10 digits, as candump's "%010llu".
  char digits[20];
  std::size_t nd = 0;
  auto s = static_cast<std::uint64_t>(seconds);
  do {
    digits[nd++] = static_cast<char>('0' + s % 10);
    s /= 10;
  } while (s != 0);
  for (std::size_t i = nd; i < 10; ++i) put('0');
  while (nd > 0) put(digits[--nd]);
  put('.');
  std::uint32_t div = 100000;
  for (int i = 0; i < 6; ++i) {
    put(static_cast<char>('0' + (micros / div) % 10));
    div /= 10;
  }
  put(')');
  put(' ');
  for (char c : interface) put(c);
  put(' ');
  const int id_digits = f.extended ? 8 : 3;
  for (int i = id_digits - 1; i >= 0; --i) put(kHex[(f.id >> (4 * i)) & 0xFu]);
  put('#');
  for (std::size_t i = 0; i < f.len; ++i) {
    put(kHex[f.data[i] >> 4]);
    put(kHex[f.data[i] & 0xFu]);
  }
  if (n > out.size()) return 0;
  for (std::size_t i = 0; i < n; ++i) out[i] = buf[i];
  return n;
}

}  // namespace gfins::drivers::lnx
