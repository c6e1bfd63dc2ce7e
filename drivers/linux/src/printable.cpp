// Escaping of outside text for messages (gfins/drivers/lnx/printable.hpp).
#include "gfins/drivers/lnx/printable.hpp"

#include <cstdio>
#include <string>
#include <string_view>

namespace gfins::drivers::lnx {
namespace {

// One UTF-8 sequence at s[i] (RFC 3629 §4: no overlong forms, no surrogates, at most U+10FFFF):
// its length, or 0 when the bytes there are not valid UTF-8.
std::size_t utf8_sequence(std::string_view s, std::size_t i, char32_t& cp) {
  const auto b = [&](std::size_t k) { return static_cast<unsigned char>(s[i + k]); };
  const unsigned char c = b(0);
  std::size_t n = 0;
  char32_t min = 0;
  if (c < 0x80) {
    cp = c;
    return 1;
  }
  if ((c & 0xE0) == 0xC0) {
    n = 2, cp = c & 0x1F, min = 0x80;
  } else if ((c & 0xF0) == 0xE0) {
    n = 3, cp = c & 0x0F, min = 0x800;
  } else if ((c & 0xF8) == 0xF0) {
    n = 4, cp = c & 0x07, min = 0x10000;
  } else {
    return 0;
  }
  if (i + n > s.size()) return 0;
  for (std::size_t k = 1; k < n; ++k) {
    if ((b(k) & 0xC0) != 0x80) return 0;
    cp = (cp << 6) | (b(k) & 0x3F);
  }
  if (cp < min || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) return 0;
  return n;
}

// C0 controls, DEL and the C1 controls (U+0080..U+009F: 0x9B is a terminal's CSI).
bool is_control(char32_t cp) { return cp < 0x20 || (cp >= 0x7F && cp <= 0x9F); }

}  // namespace

std::string escape_text(std::string_view s, bool quote, bool keep_layout, std::size_t max_chars) {
  std::string out;
  std::size_t shown = 0;
  for (std::size_t i = 0; i < s.size();) {
    if (shown == max_chars) {
      out += "...";
      break;
    }
    ++shown;
    char32_t cp = 0;
    const std::size_t n = utf8_sequence(s, i, cp);
    char hex[8];
    if (n == 0) {
      std::snprintf(hex, sizeof hex, "\\x%02X", static_cast<unsigned char>(s[i]));
      out += hex;
      ++i;
      continue;
    }
    if ((cp == '\n' || cp == '\t') && keep_layout) {
      out += static_cast<char>(cp);
    } else if (quote && (cp == '"' || cp == '\\')) {
      out += '\\';
      out += static_cast<char>(cp);
    } else if (cp == '\n') {
      out += "\\n";
    } else if (cp == '\t') {
      out += "\\t";
    } else if (cp == '\r') {
      out += "\\r";
    } else if (is_control(cp)) {
      std::snprintf(hex, sizeof hex, "\\u%04X", static_cast<unsigned>(cp));
      out += hex;
    } else {
      out.append(s.substr(i, n));
    }
    i += n;
  }
  return out;
}

bool clean_utf8(std::string_view s) {
  for (std::size_t i = 0; i < s.size();) {
    char32_t cp = 0;
    const std::size_t n = utf8_sequence(s, i, cp);
    if (n == 0 || is_control(cp)) return false;
    i += n;
  }
  return true;
}

std::string quote_text(std::string_view s) {
  // 60 characters name the value well enough; a longer one is cut (a message stays one line).
  constexpr std::size_t kMaxShown = 60;
  return "\"" + escape_text(s, true, false, kMaxShown) + "\"";
}

std::string printable_text(std::string_view s) {
  return escape_text(s, false, true, std::string_view::npos);
}

}  // namespace gfins::drivers::lnx
