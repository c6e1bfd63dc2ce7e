#include "gfins/drivers/lnx/candump_line.hpp"

namespace gfins::drivers::lnx {
namespace {

constexpr char kHex[] = "0123456789ABCDEF";

// Appends `value` as `digits` decimal digits, zero-padded (more when it does not fit).
std::size_t put_decimal(char* p, std::uint64_t value, int digits) {
  char tmp[20];
  int n = 0;
  do {
    tmp[n++] = static_cast<char>('0' + value % 10);
    value /= 10;
  } while (value != 0);
  while (n < digits) tmp[n++] = '0';
  for (int i = 0; i < n; ++i) p[i] = tmp[n - 1 - i];
  return static_cast<std::size_t>(n);
}

std::size_t put_hex(char* p, std::uint32_t value, int digits) {
  for (int i = 0; i < digits; ++i) {
    p[i] = kHex[(value >> (4 * (digits - 1 - i))) & 0xF];
  }
  return static_cast<std::size_t>(digits);
}

}  // namespace

std::size_t format_candump_line(std::span<char> out, std::int64_t t_ns, std::string_view iface,
                                const hal::CanFrame& f) {
  if (t_ns < 0 || iface.empty() || iface.size() > 15) return 0;
  if (iface.find_first_of(" \t\n") != std::string_view::npos) return 0;
  if (f.len > hal::CanFrame::kMaxLen) return 0;
  if (f.id > (f.extended ? hal::CanFrame::kMaxExtendedId : hal::CanFrame::kMaxStandardId)) {
    return 0;
  }
  char line[kCandumpLineMax];
  char* p = line;
  const auto t = static_cast<std::uint64_t>(t_ns);
  *p++ = '(';
  p += put_decimal(p, t / 1000000000U, 10);
  *p++ = '.';
  p += put_decimal(p, (t % 1000000000U) / 1000U, 6);  // microseconds, truncated
  *p++ = ')';
  *p++ = ' ';
  for (const char c : iface) *p++ = c;
  *p++ = ' ';
  p += put_hex(p, f.id, f.extended ? 8 : 3);
  *p++ = '#';
  for (std::size_t i = 0; i < f.len; ++i) p += put_hex(p, f.data[i], 2);
  *p++ = '\n';
  const auto n = static_cast<std::size_t>(p - line);
  if (n > out.size()) return 0;
  for (std::size_t i = 0; i < n; ++i) out[i] = line[i];
  return n;
}

}  // namespace gfins::drivers::lnx
