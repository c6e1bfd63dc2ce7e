// SimulatedAdc on the sample path allocates nothing: Monte-Carlo runs push millions of samples
// through the register-level model and the real driver, and the board's loop must not allocate
// either. Every heap call of the process is counted (support/heap_counter.hpp) over many
// conversions after start(), including frames with injected faults and a full recovery (reset +
// reconfigure).
#include <gtest/gtest.h>

#include <array>
#include <cmath>

#include "gfins/host_sim/chip/simulated_adc.hpp"
#include "support/heap_counter.hpp"

namespace {

TEST(SimulatedAdcNoAlloc, ConvertAndRecoverDoNotAllocate) {
  if (!gfins::testing::HeapCounter::available()) GTEST_SKIP() << "AddressSanitizer owns malloc";
  gfins::sim::SimulatedAdc adc{gfins::sim::SimulatedAdcConfig{}};
  ASSERT_TRUE(adc.start().is_ok());
  long ok = 0;
  long allocations = 0;
  {
    const gfins::testing::HeapWindow window;
    for (std::uint32_t k = 0; k < 20000; ++k) {
      if (k == 5000) adc.chip().corrupt_output_crc(3);
      if (k == 9000) adc.chip().power_on_reset();
      if (k == 12000) adc.inject_extra_edges(2);
      if (k == 15000) adc.drop_edges(2);
      std::array<double, 6> v{};
      for (int j = 0; j < 6; ++j) v[static_cast<std::size_t>(j)] = 5.0 * std::sin(1e-3 * k + j);
      const auto s = adc.convert(v, k, static_cast<std::int64_t>(k) * 1'000'000);
      if (s.is_ok()) ++ok;
    }
    allocations = window.allocations();
  }
  EXPECT_EQ(allocations, 0);
  EXPECT_EQ(ok, 20000 - 3);  // the reset frame and two lost edges produce no sample
  EXPECT_EQ(adc.driver().counters().recoveries, 1u);
}

}  // namespace
