// libFuzzer target: the firmware's configuration file (app::parse_config, docs/firmware.md).
// Invariants: a configuration the parser accepts passes every rule of app::check (the parser
// never hands the run a value it would refuse later), its worst-case bus load is a number, and
// a refusal's message is safe to print (no control character from the file reaches a terminal).
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "fuzz_check.hpp"
#include "gfins/app/config.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  constexpr const char* kTarget = "firmware_config";
  const auto r = gfins::app::parse_config(gfins::fuzz::as_text(data, size), "fuzz.toml");
  if (!r.ok()) {
    gfins::fuzz::check(!r.error.empty(), kTarget, "a refusal says why");
    gfins::fuzz::check(gfins::fuzz::printable_message(r.error), kTarget,
                       "a refusal's message is printable");
    return 0;
  }
  gfins::fuzz::check(gfins::app::validate(*r.config, "fuzz.toml").empty(), kTarget,
                     "an accepted configuration passes app::check");
  const double load = gfins::app::worst_case_bus_load(*r.config);
  gfins::fuzz::check(std::isfinite(load) && load >= 0.0, kTarget,
                     "an accepted configuration's bus load is a number");
  return 0;
}
