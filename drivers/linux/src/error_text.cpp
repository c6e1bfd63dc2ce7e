#include "gfins/drivers/lnx/error_text.hpp"

#include <cstring>

namespace gfins::drivers::lnx {

std::string describe(std::string_view subject, const Status& status) {
  std::string out(subject);
  out += ": ";
  out += status.message();
  if (status.os_error() != 0) {
    out += ": ";
    out += std::strerror(status.os_error());
    out += " (errno " + std::to_string(status.os_error()) + ")";
  }
  return out;
}

}  // namespace gfins::drivers::lnx
