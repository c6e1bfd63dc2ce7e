#include "gfins/nav_core/geometry_impl.hpp"

namespace gfins::nav {
template class ArraySolver<float, 6>;
// clang-tidy (scripts/check-tidy.sh) checks the template once, for float, the board's scalar:
// the double instantiation is the same source with T = double.
#ifndef GFINS_TIDY_ONE_SCALAR
template class ArraySolver<double, 6>;
#endif
}  // namespace gfins::nav
