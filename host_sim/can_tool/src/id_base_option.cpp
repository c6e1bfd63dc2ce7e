#include "id_base_option.hpp"

#include <cctype>
#include <cstdio>

namespace gfins::can_tool {

std::size_t id_group_index(const std::string& name) {
  for (std::size_t g = 0; g < can::kIdGroupCount; ++g) {
    const std::string_view known = can::kIdGroupValues[g].name;
    bool same = known.size() == name.size();
    for (std::size_t i = 0; same && i < name.size(); ++i) {
      same = std::tolower(static_cast<unsigned char>(known[i])) ==
             std::tolower(static_cast<unsigned char>(name[i]));
    }
    if (same) return g;
  }
  return can::kIdGroupCount;
}

std::optional<std::uint16_t> hex_id_value(const std::string& text) {
  const bool hex = text.size() >= 3 && text.size() <= 5 && text[0] == '0' &&
                   (text[1] == 'x' || text[1] == 'X') &&
                   text.find_first_not_of("0123456789abcdefABCDEF", 2) == std::string::npos;
  if (!hex) return std::nullopt;
  const unsigned long v = std::stoul(text.substr(2), nullptr, 16);  // at most 3 hex digits
  if (v > 0x7FF) return std::nullopt;
  return static_cast<std::uint16_t>(v);
}

std::string hex_id_problem(const std::string& text) {
  if (hex_id_value(text)) return "";
  // Without the 0x a "300" would be decimal to strtoll and "0300" octal.
  return "an identifier 0x000..0x7FF, hexadecimal with its 0x";
}

std::string parse_id_base(const std::string& spec, std::size_t& group, std::uint16_t& base) {
  const std::size_t eq = spec.find('=');
  group = eq == std::string::npos ? can::kIdGroupCount : id_group_index(spec.substr(0, eq));
  if (group == can::kIdGroupCount) {
    return "GROUP=0xBASE with GROUP one of data, input, command, response";
  }
  const std::string value = spec.substr(eq + 1);
  const std::optional<std::uint16_t> v = hex_id_value(value);
  if (!v) return "its BASE must be " + hex_id_problem(value);
  base = *v;
  return "";
}

std::string apply_id_bases(const std::vector<std::string>& specs, can::IdBases& ids) {
  can::IdBases moved = ids;
  for (const std::string& spec : specs) {
    std::size_t g = 0;
    std::uint16_t base = 0;
    if (std::string p = parse_id_base(spec, g, base); !p.empty()) return p;
    moved.base[g] = base;
  }
  if (can::id_bases_valid(moved)) {
    ids = moved;
    return "";
  }
  std::string ranges;
  for (std::size_t g = 0; g < can::kIdGroupCount; ++g) {
    char r[64];
    std::snprintf(r, sizeof r, "%s%.*s 0x%03X..0x%03X", g == 0 ? "" : ", ",
                  static_cast<int>(can::kIdGroupValues[g].name.size()),
                  can::kIdGroupValues[g].name.data(), static_cast<unsigned>(moved.base[g]),
                  static_cast<unsigned>(moved.base[g] + can::id_span(g) - 1));
    ranges += r;
  }
  return "the identifier groups would overlap each other or pass 0x7FF (" + ranges + ")";
}

}  // namespace gfins::can_tool
