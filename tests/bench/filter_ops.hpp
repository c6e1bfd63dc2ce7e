// The filter rig (nav_core/baremetal/filter_rig.hpp, shared with the bare-metal probe) and the
// operation names the host drivers take on their command line.
#pragma once

#include <string>

#include "filter_rig.hpp"

namespace gfins::bench {

/// false when `name` is none of to_string()'s names.
inline bool parse_op(const std::string& name, FilterOp& op) {
  for (const FilterOp o : kFilterOps) {
    if (name == to_string(o)) {
      op = o;
      return true;
    }
  }
  return false;
}

}  // namespace gfins::bench
