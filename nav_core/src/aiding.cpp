#include "gfins/nav_core/filter/aiding.hpp"

namespace gfins::nav {
template class Aiding<float>;
template class Aiding<double>;
}  // namespace gfins::nav
