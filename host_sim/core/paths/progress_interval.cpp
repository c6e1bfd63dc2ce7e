#include "gfins/host_sim/progress_interval.hpp"

#include <cstdlib>

namespace gfins::paths {

double progress_interval_s() {
  const char* env = std::getenv(kProgressIntervalEnv);
  if (env == nullptr || *env == '\0') return kDefaultProgressIntervalS;
  char* end = nullptr;
  const double v = std::strtod(env, &end);
  // strtod takes "nan" and "inf": the range test refuses both.
  if (*end != '\0' || !(v > 0.0 && v < kMaxProgressIntervalS)) return kDefaultProgressIntervalS;
  return v;
}

}  // namespace gfins::paths
