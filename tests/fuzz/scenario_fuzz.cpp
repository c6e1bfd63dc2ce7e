// libFuzzer target: the scenario file parser (sim::parse_scenario, docs/scenarios.md).
// Invariants: an accepted scenario builds its trajectory (no late refusal after the run has
// started making outputs), the trajectory's truth is finite at the start, the middle and the end
// of the run, the duration and rate are positive and finite; a refusal's message is printable.
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "fuzz_check.hpp"
#include "gfins/host_sim/scenario.hpp"
#include "gfins/host_sim/trajectory.hpp"

namespace {

constexpr const char* kTarget = "scenario";

bool finite(const gfins::sim::TruthState& x) {
  return x.q_nb.coeffs().allFinite() && x.w_b.allFinite() && x.wdot_b.allFinite() &&
         x.r_n.allFinite() && x.v_n.allFinite() && x.a_n.allFinite();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto r = gfins::sim::parse_scenario(gfins::fuzz::as_text(data, size), "fuzz.toml");
  if (!r.is_ok()) {
    gfins::fuzz::check(gfins::fuzz::printable_message(r.error().message), kTarget,
                       "a refusal's message is printable");
    return 0;
  }
  const gfins::sim::Scenario& s = r.value();
  gfins::fuzz::check(std::isfinite(s.duration_s) && s.duration_s > 0.0, kTarget,
                     "an accepted duration is positive and finite");
  gfins::fuzz::check(std::isfinite(s.rate_hz) && s.rate_hz > 0.0, kTarget,
                     "an accepted rate is positive and finite");
  gfins::fuzz::check(gfins::fuzz::printable_message(s.description), kTarget,
                     "an accepted description is printable");
  const auto traj = gfins::sim::make_trajectory(s.trajectory);
  gfins::fuzz::check(traj.is_ok(), kTarget, "an accepted scenario builds its trajectory");
  for (const double t : {0.0, 0.5 * s.duration_s, s.duration_s}) {
    gfins::fuzz::check(finite(traj.value()->at(t)), kTarget,
                       "the trajectory's truth is finite over the run");
  }
  return 0;
}
