// The double instantiation (the host's reference runs), in a library of its own
// (gfins::nav_core_double) so that a program that runs the board's scalar only, such as the
// board's gfins-fw, neither compiles nor links it.
#include "gfins/nav_core/filter/error_state_filter.hpp"

namespace gfins::nav {
template class ErrorStateFilter<double>;
}  // namespace gfins::nav
