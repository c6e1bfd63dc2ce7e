// tomlplusplus 3.x (Debian 12's libtomlplusplus-dev) estimates the printed width of every float
// in an array as size_t(log10(|x|)) + 3 (toml_formatter.inl, used to decide whether an array
// goes on one line). For 0 < |x| < 1 that converts a negative double to size_t: undefined
// behaviour, which clang's -fsanitize=undefined reports as float-cast-overflow and aborts on
// (gcc's set does not include that check). Only that line-length estimate is affected, never a
// printed value: the round-trip tests read every value back bit for bit. This file holds nothing
// but the printer call, so the sanitizer build can leave out that one check here
// (firmware/calib_file/CMakeLists.txt) and keep it for every line of the project's own code.
#include "toml_format.hpp"

#include <sstream>

namespace gfins::calib_file::detail {

std::string toml_text_of(const toml::table& root) {
  std::ostringstream out;
  out << toml::toml_formatter(root);
  return out.str();
}

}  // namespace gfins::calib_file::detail
