#include "gfins/nav_core/filter/error_state_filter.hpp"

namespace gfins::nav {
template class ErrorStateFilter<float>;
// clang-tidy (scripts/check-tidy.sh) checks the template once, for float, the board's scalar:
// the double instantiation is the same source with T = double.
#ifndef GFINS_TIDY_ONE_SCALAR
template class ErrorStateFilter<double>;
#endif
}  // namespace gfins::nav
