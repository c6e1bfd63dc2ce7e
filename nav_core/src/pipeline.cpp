#include "gfins/nav_core/pipeline.hpp"

namespace gfins::nav {
template class NavPipeline<float>;
template class NavPipeline<double>;
}  // namespace gfins::nav
