// toml::parse behind one check of ours (header_check.hpp): every TOML text of the project goes
// through safe_parse, which finds what tomlplusplus 3.3 would mishandle first and throws a
// syntax error as toml::parse does, with its line and column.
#pragma once

#include <memory>
#include <string>
#include <string_view>

#include "gfins/toml/header_check.hpp"
#include "gfins/toml/toml.hpp"

namespace gfins::toml_text {

/// toml::parse(text, source) after unsafe_for_toml_parser; throws toml::parse_error for either.
inline toml::table safe_parse(std::string_view text, std::string_view source) {
  const TextProblem bad = unsafe_for_toml_parser(text);
  if (bad.what != nullptr) {
    const toml::source_position at{static_cast<toml::source_index>(bad.line),
                                   static_cast<toml::source_index>(bad.column)};
    throw toml::parse_error(bad.what, at, std::make_shared<const std::string>(source));
  }
  return toml::parse(text, source);
}

}  // namespace gfins::toml_text
