#include "gfins/nav_core/geometry_impl.hpp"

namespace gfins::nav {
template class ArraySolver<float, 6>;
}  // namespace gfins::nav
