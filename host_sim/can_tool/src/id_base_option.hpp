// --id-base GROUP=0xBASE of gfins-can (docs/can-tool.md): an identifier group moved on top of a
// board's configuration, as the command SetIdBase moves it on the board.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "gfins/can/message_table.hpp"

namespace gfins::can_tool {

/// The IdGroup index of a group name (data, input, command, response; any case), or
/// can::kIdGroupCount when it names none.
std::size_t id_group_index(const std::string& name);

/// The value of an 11-bit identifier written in hexadecimal with its 0x (0x000..0x7FF, as the ICD
/// writes identifiers); nullopt for any other text.
std::optional<std::uint16_t> hex_id_value(const std::string& text);

/// "" when `text` is an 11-bit identifier written in hexadecimal with its 0x (0x000..0x7FF, as
/// the ICD writes identifiers), else what is wrong with it.
std::string hex_id_problem(const std::string& text);

/// "" when `spec` is GROUP=0xBASE, with the group's index and its base; else what is wrong.
std::string parse_id_base(const std::string& spec, std::size_t& group, std::uint16_t& base);

/// Moves the groups of `specs` (each GROUP=0xBASE, later ones winning) in `ids`. "" when the
/// groups then fit the 11 bits and do not overlap (can::id_bases_valid), else what is wrong, with
/// every group's range; `ids` is changed only on success.
std::string apply_id_bases(const std::vector<std::string>& specs, can::IdBases& ids);

}  // namespace gfins::can_tool
