#include "gfins/nav_core/pipeline.hpp"

namespace gfins::nav {
template class NavPipeline<float>;
}  // namespace gfins::nav
