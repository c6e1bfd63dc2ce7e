// The firmware's own boards (registered by add_firmware_boards, board_parts.cpp).
#pragma once

#include "gfins/app/board.hpp"

namespace gfins::app {

BoardResult make_linux_board(const FwConfig& c);
BoardResult make_hil_board(const FwConfig& c);

}  // namespace gfins::app
