#include "gfins/nav_core/filter/aiding.hpp"

namespace gfins::nav {
template class Aiding<float>;
}  // namespace gfins::nav
