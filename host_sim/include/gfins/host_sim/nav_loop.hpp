// The one navigation loop of the host: every host user of nav::NavPipeline<T> (gfins-sim's
// default run, run, paper63, montecarlo; replay of recordings; the test helpers; the replay
// benchmark) offers its samples through NavLoop<T>::step(), so there is one place that decides
// what happens to a sample on the PC, as the firmware's real-time loop does on the board.
//
// Driven by sample index, never by wall-clock: sample i is offered as soon as sample i − 1 has
// been processed, with the t_ns and seq it carries. The pipeline is deterministic, so the same
// input through a pipeline configured the same way gives the same NavState stream, bit for bit
// (FNV-1a-64 of the output bytes, report().output_hash).
//
// Per sample the loop:
//   - hands the RawSample to NavPipeline::process(), the pipeline's one entry. The pipeline
//     counts sequence gaps (the only place that does) and rejects kCrcError frames and frames
//     with a count on a rail; a frame flagged sample_flags::kSaturated is rejected too (the loop
//     hands it on marked kCrcError, nav_loop.cpp says why);
//     the loop reads its counters to report each gap with the sample index, the expected and the
//     seen counter and the number of samples missing;
//   - if the pipeline navigates and did not reject the sample, hashes its state and hands it to
//     the sink with the sample's index (a rejected sample produces no output).
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "gfins/checksum/fnv1a.hpp"
#include "gfins/nav_core/nav_state.hpp"
#include "gfins/nav_core/pipeline.hpp"
#include "gfins/sample/raw_sample.hpp"

namespace gfins::sim {

using gfins::Fnv1a64;

/// Hashes every field of a NavState, field by field (never the padding between them).
template <typename T>
void hash_nav_state(Fnv1a64& h, const nav::NavState<T>& s);

/// One jump of the sample counter, as the pipeline counted it.
struct NavGap {
  std::uint64_t index = 0;         // index of the first sample after the hole
  std::uint32_t expected_seq = 0;  // previous seq + 1
  std::uint32_t seq = 0;           // seq actually seen
  std::uint32_t missing = 0;       // seq − expected_seq (wrapping)
};

struct NavReport {
  std::uint64_t samples = 0;            // samples offered to the pipeline
  std::uint64_t navigating = 0;         // samples that produced a navigation state
  std::uint64_t invalid = 0;            // samples carrying sample_flags::kCrcError
  std::uint64_t flagged_saturated = 0;  // samples carrying sample_flags::kSaturated
  std::uint64_t rejected = 0;           // samples the pipeline rejected (CRC error, saturated)
  std::uint64_t missed_samples = 0;     // sum of NavGap::missing
  std::uint64_t out_of_order = 0;       // counters that repeated or went back (not integrated)
  std::vector<NavGap> gaps;
  std::uint64_t output_hash = Fnv1a64::kOffsetBasis;  // FNV-1a-64 of every navigating state
  bool aided = false;  // the aiding filter ran (filter is its counters)
  nav::FilterCounters filter{};
  std::uint32_t motion_vetoes = 0;  // standstill decisions refused by the ZUPT's gate
  /// Frame records of a version-2 recording (the CAN frames the recording board's loop
  /// received: aiding inputs, commands): the host loop does not apply them (gfins-fw --replay
  /// does), so a replay here counts them and says so.
  std::uint64_t frames_not_applied = 0;
};

template <typename T>
class NavLoop {
 public:
  /// Called after every sample that produced a navigation state: (sample index, state).
  using Sink = std::function<void(std::uint64_t, const nav::NavState<T>&)>;

  explicit NavLoop(nav::NavPipeline<T>& pipeline, Sink sink = {})
      : pipeline_(pipeline), sink_(std::move(sink)) {}

  /// Offers one sample (index = how many were offered before). Call in stream order. Returns
  /// true when it produced a navigation state.
  bool step(const RawSample& s);

  /// The paper's §6.3 only: outputs in m/s² after the front end (no converter in that
  /// experiment; nav::NavPipeline::process_specific_force says why). Same report, hash and sink.
  bool step_specific_force(const nav::Vec6<T>& s_mps2, std::int64_t t_ns, std::uint32_t seq);

  /// Offers every sample of `samples` in order; returns the report so far.
  const NavReport& run(std::span<const RawSample> samples);

  /// The counters, with the aiding filter's as they are now.
  const NavReport& report() {
    report_.aided = pipeline_.aiding().started();
    if (report_.aided) {
      report_.filter = pipeline_.aiding().filter().counters();
      report_.motion_vetoes = pipeline_.aiding().motion_vetoes();
    }
    return report_;
  }
  nav::NavPipeline<T>& pipeline() { return pipeline_; }

 private:
  /// What every step does after the pipeline call: gap report, output hash, sink.
  bool finish(std::uint64_t index, std::uint32_t seq, const nav::PipelineCounters& before,
              nav::PipelinePhase phase);

  nav::NavPipeline<T>& pipeline_;
  Sink sink_;
  NavReport report_{};
  Fnv1a64 hash_{};
};

/// Convenience: a fresh loop over `samples` through `pipeline`; returns the report.
template <typename T>
NavReport run_samples(nav::NavPipeline<T>& pipeline, std::span<const RawSample> samples,
                      typename NavLoop<T>::Sink sink = {}) {
  NavLoop<T> loop(pipeline, std::move(sink));
  return loop.run(samples);
}

extern template class NavLoop<float>;
extern template class NavLoop<double>;
extern template void hash_nav_state<float>(Fnv1a64&, const nav::NavState<float>&);
extern template void hash_nav_state<double>(Fnv1a64&, const nav::NavState<double>&);

}  // namespace gfins::sim
