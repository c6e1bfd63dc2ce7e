// Replay: drives nav::NavPipeline<T> from a recorded (or any) stream of RawSample values.
//
// Driven by sample index, never by wall-clock: sample i is offered as soon as sample i − 1 has
// been processed, with the t_ns and seq it carries. The pipeline itself is deterministic, so the
// same input through a pipeline configured the same way gives the same NavState stream, bit for
// bit (replay_test proves it with an FNV-1a-64 hash of the output bytes).
//
// Per sample the replayer:
//   - reports a gap when seq is not the previous seq + 1 (wrapping at 2^32), with the sample
//     index, the expected and the seen counter and the number of samples missing;
//   - passes input_valid = false when the sample carries sample_flags::kCrcError (its counts are
//     not a measurement); saturation is detected by the pipeline itself from the codes;
//   - after process(), if the pipeline navigates and did not reject the sample, hashes its
//     state and hands it to the sink (a rejected sample produces no output).
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "gfins/host_sim/recording.hpp"
#include "gfins/nav_core/nav_state.hpp"
#include "gfins/nav_core/pipeline.hpp"
#include "gfins/sample/raw_sample.hpp"

namespace gfins::sim {

/// FNV-1a, 64 bits (offset basis 0xcbf29ce484222325, prime 0x100000001b3).
class Fnv1a64 {
 public:
  void add(std::span<const std::uint8_t> bytes);
  template <typename V>
  void add_value(const V& v);  // the object representation of a scalar, host byte order
  std::uint64_t value() const { return h_; }

 private:
  std::uint64_t h_ = 0xcbf29ce484222325ull;
};

/// Hashes every field of a NavState, field by field (never the padding between them).
template <typename T>
void hash_nav_state(Fnv1a64& h, const nav::NavState<T>& s);

/// One jump of the sample counter.
struct ReplayGap {
  std::uint64_t index = 0;         // index of the first sample after the hole
  std::uint32_t expected_seq = 0;  // previous seq + 1
  std::uint32_t seq = 0;           // seq actually seen
  std::uint32_t missing = 0;       // seq − expected_seq (wrapping)
};

struct ReplayReport {
  std::uint64_t samples = 0;            // samples offered to the pipeline
  std::uint64_t navigating = 0;         // samples after which the pipeline was navigating
  std::uint64_t invalid = 0;            // samples passed with input_valid = false (kCrcError)
  std::uint64_t flagged_saturated = 0;  // samples carrying sample_flags::kSaturated
  std::uint64_t missed_samples = 0;     // sum of ReplayGap::missing
  std::vector<ReplayGap> gaps;
  std::uint64_t output_hash = 0;  // FNV-1a-64 of every navigating state, in order
};

template <typename T>
class Replayer {
 public:
  /// Called after every sample that left the pipeline navigating: (sample index, state).
  using Sink = std::function<void(std::uint64_t, const nav::NavState<T>&)>;

  explicit Replayer(nav::NavPipeline<T>& pipeline, Sink sink = {})
      : pipeline_(pipeline), sink_(std::move(sink)) {}

  /// Offers one sample (index = how many were offered before). Call in stream order.
  void step(const RawSample& s);

  /// Offers every sample of `samples` in order; returns the report so far.
  const ReplayReport& run(std::span<const RawSample> samples);

  const ReplayReport& report() const { return report_; }
  /// Hash of the output so far (same as report().output_hash).
  std::uint64_t output_hash() const { return hash_.value(); }

 private:
  nav::NavPipeline<T>& pipeline_;
  Sink sink_;
  ReplayReport report_{};
  Fnv1a64 hash_{};
  std::uint32_t last_seq_ = 0;
  bool have_last_ = false;
};

/// Convenience: a fresh replay of `samples` through `pipeline`; returns the report.
template <typename T>
ReplayReport replay(nav::NavPipeline<T>& pipeline, std::span<const RawSample> samples,
                    typename Replayer<T>::Sink sink = {}) {
  Replayer<T> r(pipeline, std::move(sink));
  return r.run(samples);
}

/// Streams the recording at `path` block by block (memory: one block) through `pipeline`. On a
/// truncated or corrupt file the error names its byte offset; the pipeline has then consumed
/// every sample before the broken block (the checks of a block come before any of its samples
/// is offered).
template <typename T>
RecordingResult<ReplayReport> replay_recording(const std::string& path,
                                               nav::NavPipeline<T>& pipeline,
                                               typename Replayer<T>::Sink sink = {});

extern template class Replayer<float>;
extern template class Replayer<double>;
extern template void hash_nav_state<float>(Fnv1a64&, const nav::NavState<float>&);
extern template void hash_nav_state<double>(Fnv1a64&, const nav::NavState<double>&);
extern template RecordingResult<ReplayReport> replay_recording<float>(const std::string&,
                                                                      nav::NavPipeline<float>&,
                                                                      Replayer<float>::Sink);
extern template RecordingResult<ReplayReport> replay_recording<double>(const std::string&,
                                                                       nav::NavPipeline<double>&,
                                                                       Replayer<double>::Sink);

}  // namespace gfins::sim
