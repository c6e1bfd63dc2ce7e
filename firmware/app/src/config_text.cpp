// Text rules of the configuration (gfins/app/config.hpp): UTF-8 paths without control
// characters, and values shown in messages escaped so that no NUL cuts a message and no control
// sequence reaches the terminal.
#include <string>
#include <string_view>

#include "gfins/app/config.hpp"
#include "gfins/drivers/lnx/printable.hpp"

namespace gfins::app {

std::string quote_text(std::string_view s) { return drivers::lnx::quote_text(s); }

std::string printable_text(std::string_view s) { return drivers::lnx::printable_text(s); }

bool valid_path(std::string_view s) {
  // PATH_MAX (4096 with the NUL) bounds every path the kernel accepts.
  constexpr std::size_t kMaxPathBytes = 4095;
  if (s.empty() || s.size() > kMaxPathBytes) return false;
  return drivers::lnx::clean_utf8(s);
}

}  // namespace gfins::app
