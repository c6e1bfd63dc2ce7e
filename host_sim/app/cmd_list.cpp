// gfins-sim list: the scenario registry (host_sim/scenarios/*.toml) with each description.
#include "commands.hpp"
#include "common.hpp"

namespace gfins::sim::app {

int cmd_list() {
  const auto dir = builtin_scenario_dir();
  if (!dir.is_ok()) return fail(dir.error(), kExitError);
  for (const auto& n : builtin_scenarios(dir.value())) {
    const auto p = load(n);
    std::printf("%-24s %s\n", n.c_str(),
                p.is_ok() ? p.value().description.c_str() : p.error().message.c_str());
  }
  return kExitOk;
}

}  // namespace gfins::sim::app
