// One ADC frame as it crosses the sample seam: what the ADC driver produces on the board, what
// the host simulation and the replay produce on the PC, and the one input of the navigation
// pipeline (docs/architecture.md, data flow). A std-only vocabulary type shared by every layer,
// like Status.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

namespace gfins {

inline constexpr int kAdcChannels = 6;

/// Code range of a 24-bit two's-complement converter (ADS131M06 datasheet §8.5.1.9: output data
/// are 24-bit two's complement, positive full scale 7FFFFFh, negative full scale 800000h).
inline constexpr std::int32_t kAdcCodeMax = (1 << 23) - 1;
inline constexpr std::int32_t kAdcCodeMin = -(1 << 23);

/// Bits of RawSample::flags.
namespace sample_flags {
inline constexpr std::uint32_t kCrcError = 1u << 0;   // frame CRC mismatch: counts not valid
inline constexpr std::uint32_t kSaturated = 1u << 1;  // a channel at full scale
inline constexpr std::uint32_t kLateRead = 1u << 2;   // read after the next data-ready edge
inline constexpr std::uint32_t kSynthetic = 1u << 3;  // produced by a simulation, not hardware
/// Flags that make a frame not a measurement (the counts are garbage or clipped). The one rule,
/// applied by the core (NavPipeline::process) and by every loop that counts rejected samples
/// (the board's SampleLoop, the host's NavLoop): a frame carrying one of these, or with a channel
/// on a rail of the converter (a clipped input, whether or not the producer flagged it), is not
/// integrated.
inline constexpr std::uint32_t kNotMeasured = kCrcError | kSaturated;
}  // namespace sample_flags

struct RawSample {
  std::uint32_t seq = 0;  // ADC sample counter (wraps at 2^32)
  std::int64_t t_ns = 0;  // data-ready edge, CLOCK_MONOTONIC ns (scenario time in simulation)
  std::array<std::int32_t, kAdcChannels> counts{};  // 24-bit two's complement, sign-extended
  std::uint32_t flags = 0;                          // sample_flags bits
};

/// Channels whose code sits on a rail of the converter (bit j = channel j).
inline std::uint8_t rail_mask(const std::array<std::int32_t, kAdcChannels>& counts) {
  std::uint8_t m = 0;
  for (std::size_t j = 0; j < kAdcChannels; ++j) {
    if (counts[j] >= kAdcCodeMax || counts[j] <= kAdcCodeMin) {
      m = static_cast<std::uint8_t>(m | (1u << j));
    }
  }
  return m;
}

/// The rule of sample_flags::kNotMeasured: whether the core integrates this frame.
inline bool is_measurement(const RawSample& s) {
  return (s.flags & sample_flags::kNotMeasured) == 0 && rail_mask(s.counts) == 0;
}

}  // namespace gfins
