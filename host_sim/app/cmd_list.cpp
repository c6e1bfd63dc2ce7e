// gfins-sim list: the scenario registry (host_sim/scenarios/*.toml) with each description.
#include "commands.hpp"
#include "common.hpp"

namespace gfins::sim::app {

int cmd_list() {
  for (const auto& n : builtin_scenarios(GFINS_SCENARIO_DIR)) {
    const auto p = load(n);
    std::printf("%-24s %s\n", n.c_str(),
                p.is_ok() ? p.value().description.c_str() : p.error().message.c_str());
  }
  return kExitOk;
}

}  // namespace gfins::sim::app
