#include "finite_range.hpp"

#include <cmath>
#include <string>

namespace gfins::sim::app {

CLI::Validator finite_range(double lo, double hi) {
  const std::string range =
      "[" + CLI::detail::to_string(lo) + ", " + CLI::detail::to_string(hi) + "]";
  return CLI::Validator(
      [lo, hi, range](std::string& text) -> std::string {
        double v = 0.0;
        if (!CLI::detail::lexical_cast(text, v) || !std::isfinite(v)) {
          return "'" + text + "' is not a finite number";
        }
        if (v < lo || v > hi) return "'" + text + "' is outside " + range;
        return {};
      },
      "FINITE in " + range);
}

}  // namespace gfins::sim::app
