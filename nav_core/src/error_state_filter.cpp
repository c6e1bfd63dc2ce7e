#include "gfins/nav_core/filter/error_state_filter.hpp"

namespace gfins::nav {
template class ErrorStateFilter<float>;
}  // namespace gfins::nav
