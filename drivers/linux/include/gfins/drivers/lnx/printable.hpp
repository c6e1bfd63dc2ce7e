// Text from outside (a file's bytes, a file name, a command-line value) made safe to print in a
// message: control characters (C0, DEL, C1: 0x9B is a terminal's CSI) and invalid UTF-8
// escaped, so no NUL cuts a message and no control sequence reaches the user's terminal.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace gfins::drivers::lnx {

/// `s` with every control character and every byte of invalid UTF-8 escaped (TOML's \uXXXX and
/// short forms for controls, \xNN for a byte that is not UTF-8); `quote` also escapes '"' and
/// '\\'; `keep_layout` leaves '\n' and '\t' as they are (multi-line messages, help text). Stops
/// after `max_chars` characters with "...".
std::string escape_text(std::string_view s, bool quote, bool keep_layout, std::size_t max_chars);

/// True when `s` is valid UTF-8 (RFC 3629) without a control character.
bool clean_utf8(std::string_view s);

/// `s` in double quotes, escaped, cut to 60 characters: a value as a message shows it.
std::string quote_text(std::string_view s);

/// `s` with control characters other than '\n' and '\t', and invalid UTF-8, escaped.
std::string printable_text(std::string_view s);

}  // namespace gfins::drivers::lnx
