// The board's own build of gfins-fw (GFINS_SIM_BOARD=OFF): no boards beyond the firmware's.
#include "gfins/app/board.hpp"

namespace gfins::app {

void add_plugin_boards(BoardTable& /*t*/) {}

}  // namespace gfins::app
