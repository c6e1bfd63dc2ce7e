// The one call into tomlplusplus's printer, in a translation unit of its own (see toml_format.cpp).
#pragma once

#include <string>
#include "gfins/toml/toml.hpp"

namespace gfins::calib_file::detail {

// The TOML text of `root` as tomlplusplus prints it.
std::string toml_text_of(const toml::table& root);

}  // namespace gfins::calib_file::detail
