#include "gfins/nav_core/filter/aiding.hpp"

namespace gfins::nav {
template class Aiding<float>;
// GFINS_NAV_FLOAT_ONLY: the board's scalar only. Set by a build without GFINS_NAV_DOUBLE (the
// bare-metal one) and by clang-tidy (scripts/check-tidy.sh), which checks the template once: the
// double instantiation is the same source with T = double.
#ifndef GFINS_NAV_FLOAT_ONLY
template class Aiding<double>;
#endif
}  // namespace gfins::nav
