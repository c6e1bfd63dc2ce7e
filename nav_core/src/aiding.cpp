#include "gfins/nav_core/filter/aiding.hpp"

namespace gfins::nav {
template class Aiding<float>;
// clang-tidy (scripts/check-tidy.sh) checks the template once, for float, the board's scalar:
// the double instantiation is the same source with T = double.
#ifndef GFINS_TIDY_ONE_SCALAR
template class Aiding<double>;
#endif
}  // namespace gfins::nav
