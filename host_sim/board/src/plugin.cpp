// The host build's gfins-fw (GFINS_SIM_BOARD=ON) links this: the simulated board joins the
// firmware's board table (gfins/app/board.hpp).
#include "gfins/app/board.hpp"
#include "gfins/host_sim/board/sim_board.hpp"

namespace gfins::app {

void add_plugin_boards(BoardTable& t) { sim_board::add_to(t); }

}  // namespace gfins::app
