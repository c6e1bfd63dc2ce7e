#include "gfins/nav_core/pipeline.hpp"

namespace gfins::nav {
template class NavPipeline<float>;
// clang-tidy (scripts/check-tidy.sh) checks the template once, for float, the board's scalar:
// the double instantiation is the same source with T = double.
#ifndef GFINS_TIDY_ONE_SCALAR
template class NavPipeline<double>;
#endif
}  // namespace gfins::nav
